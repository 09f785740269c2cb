"""`--model NAME | FILE.toml`, `--ic NAME=VALUE`, `--set PATH=VALUE` and `stickslip models` from the command line."""

import json
import math

import pytest
from typer.testing import CliRunner

from stickslip import load_trajectory
from stickslip.model import load_model
from stickslip.cli import app

runner = CliRunner()

#: The model file of docs/models.md, written by hand: the mass on a belt (bSTAB friction case).
BELT_TOML = """\
name = "belt"
dofs = ["x"]              # names of q, in order; states are the dofs, then "d" + each dof
mass = [[1.0]]            # M, n×n
damping = [[0.1]]         # C, n×n
stiffness = [[1.0]]       # K, n×n, may be non-symmetric
force = [0.0]             # f0 (optional, default 0)

[[contact]]               # one table per contact
tangent = [[1.0]]         # G: 1 row (1-D friction) or 2 rows (2-D), n columns
drive = [1.5]             # w: surface velocity, one entry per row of G; v_r = G q̇ − drive
normal_force = 1.0        # N0
normal_gradient = [0.0]   # n (optional, default 0): N = N0 + n·q
[contact.friction]
law = "exponential"       # "coulomb" or "exponential"
mu_k = 0.5                # kinetic coefficient
delta_mu = 0.5            # static coefficient μs = mu_k + delta_mu
alpha = 2.0               # exponential only: μ = mu_k + delta_mu·exp(−alpha·|v|) + mu_v·|v|
mu_v = 0.0                # exponential only, optional viscous term
"""


def invoke(*args):
    return runner.invoke(app, list(args))


def one_error_line(res, code=2):
    assert res.exit_code == code, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.output, res.output
    return lines[0]


@pytest.fixture
def belt_file(tmp_path):
    path = tmp_path / "belt.toml"
    path.write_text(BELT_TOML)
    return path


def test_belt_file_from_x1_dx1_settles_to_the_closed_form_steady_sliding(belt_file, monkeypatch):
    monkeypatch.chdir(belt_file.parent)
    res = invoke("simulate", "--model", "belt.toml", "--ic", "x=1,dx=1", "--t-end", "500", "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert (s["status"], s["model"], s["attractor"], s["settled"]) == ("success", "belt", "equilibrium", True)
    assert s["parameters"]["contact.0.drive.0"] == 1.5
    # steady sliding of x'' + 0.1 x' + x = μ(1.5): x_e = 0.5 + 0.5 exp(-3); linearised damping
    # 0.1 + μ'(1.5) = 0.1 − 2·0.5·exp(−3), so the decay rate is half of it
    x_e = 0.5 + 0.5 * math.exp(-3.0)
    assert s["coordinate"] == "x" and s["x_min"] < x_e < s["x_max"] and s["x_max"] - s["x_min"] < 0.01
    assert s["evidence"]["stability"]["max_real_part"] == pytest.approx(-(0.1 - math.exp(-3.0)) / 2, rel=1e-6)
    assert not list(belt_file.parent.glob("*.nc"))  # --json alone writes nothing


def test_set_path_and_continuation_keep_the_file_model(belt_file, tmp_path):
    first = tmp_path / "a.nc"
    res = invoke("simulate", "--model", str(belt_file), "--set", "contact.0.drive=1.8", "--ic", "x=0.5",
                 "--t-end", "50", "--sample-rate", "20", "--no-plot", "--out", str(first))
    assert res.exit_code == 0, res.output
    traj = load_trajectory(first)
    assert traj.system.parameters["contact.0.drive.0"] == 1.8 and traj.state_names == ("x", "dx")
    second = tmp_path / "b.nc"
    res = invoke("simulate", "--ic", str(first), "--t-end", "10", "--sample-rate", "20", "--no-plot",
                 "--out", str(second))
    assert res.exit_code == 0, res.output
    more = load_trajectory(second)
    assert more.t[0] == pytest.approx(50.0) and more.t[-1] == pytest.approx(60.0)
    assert more.system.parameters == traj.system.parameters
    assert more.states[0] == pytest.approx(traj.states[-1], abs=1e-12)


def test_library_model_by_name_and_states_by_name(tmp_path):
    res = invoke("simulate", "--model", "popp-stelter", "--t-end", "20", "--sample-rate", "50", "--json")
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout.strip().splitlines()[-1])["model"] == "popp-stelter"


@pytest.mark.parametrize("args, words", [
    (["--model", "belt", "--ic", "x=1,y=2"], "unknown state 'y' of model 'belt'; states are x, dx"),
    (["--model", "belt", "--ic", "x=one"], "'x=one' is not NAME=NUMBER"),
    (["--model", "belt", "--N", "50"], "--N is a parameter of the two plates"),
    (["--model", "belt", "--set", "contact.0.speed=2"], "no key 'speed' under contact.0"),
    (["--model", "nosuch"], "unknown model 'nosuch'"),
    (["--model", "missing.toml"], "model file missing.toml does not exist"),
])
def test_bad_model_input_is_one_line(args, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    line = one_error_line(invoke("simulate", *args, "--t-end", "5", "--json"))
    assert words in line


@pytest.mark.parametrize("edit, words", [
    (("mass = [[1.0]]", "mass = [[-1.0]]"), "mass"),
    (("mass = [[1.0]]", ""), "mass"),
    (('law = "exponential"', 'law = "dahl"'), "dahl"),
    (("normal_force = 1.0", "normal_force = 0.0"), "normal_force"),
    (("damping = [[0.1]]", "damping = [[0.1, 0.2]]"), "damping"),
    (("mu_k = 0.5", 'mu_k = "half"'), "mu_k"),
])
def test_bad_model_file_is_one_line_naming_the_key(edit, words, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(BELT_TOML.replace(*edit))
    line = one_error_line(invoke("simulate", "--model", str(path), "--t-end", "5", "--json"))
    assert words in line and str(path) in line


def test_the_list_gives_each_model_the_description_of_the_model_built():
    listed = json.loads(invoke("models", "--json").stdout)
    assert {name: load_model(name).description for name in listed} == listed


def test_models_lists_the_library_and_shows_a_model():
    res = invoke("models", "--json")
    assert res.exit_code == 0, res.output
    assert list(json.loads(res.stdout)) == ["two-plates", "belt", "clearance-oscillator", "hoffmann",
                                                "impact-oscillator", "popp-stelter", "slider-belt", "sprag-slip"]
    res = invoke("models", "belt", "--json")
    assert res.exit_code == 0, res.output
    d = json.loads(res.stdout)
    assert d["states"] == ["x", "dx"] and d["parameters"]["contact.0.friction.mu_k"] == 0.5
    assert d["natural_frequencies_hz"] == pytest.approx([1 / (2 * math.pi)])
    res = invoke("models", "hoffmann")
    assert res.exit_code == 0 and "contact.0.gap_gradient.1" in res.output
    assert "unknown model 'x.y'" in one_error_line(invoke("models", "x.y"))
