"""`stickslip simulate`: defaults, JSON, files, and one-line errors for bad input."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from stickslip import load_trajectory
from stickslip.cli import app

runner = CliRunner()

JSON_KEYS = {"settled", "attractor", "period_count", "fundamental_frequency_hz", "dominant_frequency_hz",
             "settle_time_s", "evidence", "status", "model", "parameters", "t_end_s", "steady_from_s",
             "stick_fraction", "n_transitions", "contacts", "coordinate", "phi_min", "phi_max", "steps", "wall_time_s",
             "method", "confirmed_by", "compile_time_s"}


def run(*args):
    return runner.invoke(app, ["simulate", *args])


def test_json_summary_and_netcdf_round_trip(tmp_path):
    out = tmp_path / "a.nc"
    res = run("--t-end", "5", "--json", "--out", str(out))
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout.strip().splitlines()[-1])
    assert set(summary) == JSON_KEYS
    assert summary["method"] == "event" and summary["steps"] > 0
    assert (tmp_path / "a.png").stat().st_size > 10_000
    traj = load_trajectory(out)
    assert traj.params.N == 50.0 and traj.params.Omega == 5.0
    assert traj.steady.n_transitions == summary["n_transitions"]
    assert np.isclose(traj.steady.maximum, summary["phi_max"])


def test_human_summary_and_options(tmp_path):
    res = run("--t-end", "3", "--N", "30", "--omega", "0.5", "--set", "k_px=400", "--model", "x",
              "--no-plot", "--out", str(tmp_path / "b.nc"))
    assert res.exit_code == 0, res.output
    assert "fundamental frequency" in res.output
    traj = load_trajectory(tmp_path / "b.nc")
    assert (traj.params.N, traj.params.Omega, traj.params.k_px, traj.model) == (30.0, 0.5, 400.0, "x")
    assert not (tmp_path / "b.png").exists()


def test_config_file_and_continuation(tmp_path):
    cfg = tmp_path / "p.toml"
    cfg.write_text("[parameters]\nN = 70\nalpha = 2\n")
    first = tmp_path / "first.nc"
    assert run("--t-end", "2", "--config", str(cfg), "--no-plot", "--out", str(first)).exit_code == 0
    second = tmp_path / "second.nc"
    res = run("--t-end", "1", "--config", str(cfg), "--ic", str(first), "--no-plot", "--out", str(second))
    assert res.exit_code == 0, res.output
    a, b = load_trajectory(first), load_trajectory(second)
    assert np.allclose(b.states[0], a.states[-1])
    assert b.params.alpha == 2.0


@pytest.mark.parametrize(
    "args, words",
    [
        (["--N", "-5"], "must be > 0"),
        (["--N", "0"], "must be > 0"),
        (["--set", "m_p=-1"], "m_p"),
        (["--set", "alpha=nan"], "not finite"),
        (["--set", "bogus=1"], "unknown parameter"),
        (["--set", "N"], "NAME=VALUE"),
        (["--model", "z"], "unknown model"),
        (["--method", "euler"], "unknown method"),
        (["--t-end", "-1"], "--t-end"),
        (["--rtol", "0"], "rtol"),
        (["--rtol", "1e-20"], "rtol"),
        (["--dt", "-0.1"], "dt"),
        (["--ic", "somewhere"], "unknown initial condition"),
        (["--ic", "1,2,3"], "12 entries"),
        (["--ic", "missing.nc"], "does not exist"),
        (["--config", "missing.toml"], "does not exist"),
        (["--out", "run.txt"], ".nc"),
    ],
)
def test_bad_input_gives_one_line_error(args, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = run("--t-end", "1", "--no-plot", *args)
    assert res.exit_code != 0
    text = res.output
    assert words in text, text
    assert "Traceback" not in text


def test_file_that_is_not_ours(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "junk.nc").write_text("not a netcdf file")
    res = run("--t-end", "1", "--no-plot", "--ic", "junk.nc")
    assert res.exit_code != 0 and "not a stickslip NetCDF file" in res.output
    import xarray as xr

    xr.Dataset({"a": ("x", [1.0, 2.0])}).to_netcdf(tmp_path / "other.nc", engine="h5netcdf")
    res = run("--t-end", "1", "--no-plot", "--ic", "other.nc")
    assert res.exit_code != 0 and "not a stickslip trajectory" in res.output


def test_locked_dof_in_initial_state_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = run("--t-end", "1", "--no-plot", "--model", "rotation", "--ic", ",".join(["0.001"] + ["0"] * 11))
    assert res.exit_code != 0 and "locked" in res.output


# ----------------------------------------------------------------------------- continuing a run
def lines_of(res) -> list:
    return [ln for ln in res.output.splitlines() if ln.strip()]


@pytest.fixture(scope="module")
def saved_run(tmp_path_factory):
    """A rotation-model run with non-default parameters and settings, 0–2 s."""
    path = tmp_path_factory.mktemp("saved") / "first.nc"
    res = run("--model", "rotation", "--N", "30", "--omega", "0.5", "--set", "k_pphi=150", "--t-end", "2",
              "--sample-rate", "500", "--rtol", "1e-9", "--no-plot", "--out", str(path))
    assert res.exit_code == 0, res.output
    return path


def test_continuing_a_run_takes_its_model_parameters_settings_and_time(saved_run, tmp_path):
    first = load_trajectory(saved_run)
    out = tmp_path / "second.nc"
    res = run("--ic", str(saved_run), "--t-end", "1", "--no-plot", "--out", str(out))
    assert res.exit_code == 0, res.output
    assert f"continuing {saved_run} from t = 2 s" in res.output and "overridden" not in res.output
    second = load_trajectory(out)
    assert second.model == "rotation" and second.params == first.params
    assert (second.options["sample_rate"], second.options["rtol"]) == (500.0, 1e-9)
    assert second.t[0] == first.t[-1] == 2.0 and second.t[-1] == 3.0  # --t-end is the time added
    assert np.array_equal(second.states[0], first.states[-1])


def test_options_given_when_continuing_override_the_saved_ones_and_are_named(saved_run, tmp_path):
    out = tmp_path / "second.nc"
    res = run("--ic", str(saved_run), "--t-end", "1", "--N", "40", "--set", "alpha=3", "--rtol", "1e-8",
              "--no-plot", "--out", str(out))
    assert res.exit_code == 0, res.output
    assert "overridden: --set alpha, --N, --rtol" in res.output
    second, first = load_trajectory(out), load_trajectory(saved_run)
    assert (second.params.N, second.params.alpha, second.params.k_pphi) == (40.0, 3.0, first.params.k_pphi)
    assert (second.options["rtol"], second.options["sample_rate"]) == (1e-8, 500.0)


@pytest.mark.parametrize("extra", [[], ["--overwrite"]])
def test_the_input_run_is_never_overwritten(tmp_path, monkeypatch, extra):
    monkeypatch.chdir(tmp_path)
    assert run("--t-end", "1", "--no-plot").exit_code == 0
    before = (tmp_path / "run.nc").read_bytes()
    res = run("--ic", "run.nc", "--t-end", "1", "--no-plot", *extra)
    assert res.exit_code == 2 and len(lines_of(res)) == 1, res.output
    assert "--out run.nc is the file given to --ic" in res.output
    assert (tmp_path / "run.nc").read_bytes() == before


# ----------------------------------------------------------------------------- outputs
@pytest.mark.parametrize("existing", ["x.nc", "x.png"])
def test_an_existing_output_is_refused_without_overwrite(tmp_path, existing):
    (tmp_path / existing).write_text("the user's file")
    res = run("--t-end", "1", "--out", str(tmp_path / "x.nc"))
    assert res.exit_code == 2 and len(lines_of(res)) == 1, res.output
    assert f"{tmp_path / existing} exists; pass --overwrite" in res.output
    assert (tmp_path / existing).read_text() == "the user's file"
    assert run("--t-end", "1", "--out", str(tmp_path / "x.nc"), "--overwrite").exit_code == 0
    assert load_trajectory(tmp_path / "x.nc").t[-1] == 1.0


def test_json_alone_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = run("--t-end", "1", "--json")
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout.strip().splitlines()[-1])["steps"] > 0
    assert not list(tmp_path.iterdir())


# ----------------------------------------------------------------------------- option checks
@pytest.mark.parametrize("args, words", [
    (["--t-end", "1e9", "--sample-rate", "1e6"], "lower the sample rate to at most 0.0199 Hz or shorten the run to "
                                                 "at most 19.9 s"),
    (["--t-end", "1e300", "--sample-rate", "1e300"], "keeps more than 1e+308 samples"),
    (["--N", "30", "--set", "N=40"], "--set N=40 and --N 30 both set N"),
    (["--set", "N=30", "--set", "N=40"], "--set N is given twice"),
    (["--steady-from", "-1"], "--steady-from -1 s is outside the run, which goes from 0 to 1 s"),
    (["--steady-from", "0.999"], "the steady window 0.999 – 1 s holds 2 samples at 1000 Hz and its summary needs 8"),
    (["--sample-rate", "10"], "the steady window 0.5 – 1 s holds 6 samples at 10 Hz"),
    (["--steady-from", "5"], "--steady-from 5 s is outside the run"),
    (["--steady-from", "nan"], "--steady-from must be a finite number"),
    (["--perturb", "inf"], "--perturb must be a finite number"),
    (["--sample-rate", "0"], "sample_rate = 0.0 must be a finite number > 0"),
    (["--sample-rate", "nan"], "sample_rate = nan must be a finite number > 0"),
    (["--t-end", "auto", "--cap", "0"], "cap = 0.0 s must be a finite number > 0"),
    (["--t-end", "auto", "--cap", "nan", "--dt", "1e-3"], "cap = nan s must be a finite number > 0"),
    (["--dt", "1e-12"], "--dt 1e-12 s takes at least 1e+12 steps for --t-end 1 s"),
    (["--method", "aeom", "--dt", "1e-300"], "give --dt 1e-10 or more"),
])
def test_refused_options_say_why_in_one_line(args, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = run("--t-end", "1", *args)
    assert res.exit_code == 2 and len(lines_of(res)) == 1 and words in res.output, res.output
    assert not list(tmp_path.iterdir())


def test_the_steady_window_of_a_continuation_is_in_the_runs_time(saved_run, tmp_path):
    res = run("--ic", str(saved_run), "--t-end", "1", "--steady-from", "1", "--json")
    assert res.exit_code == 2 and "outside the run, which goes from 2 to 3 s" in res.output, res.output
    res = run("--ic", str(saved_run), "--t-end", "1", "--steady-from", "2.5", "--json")
    assert res.exit_code == 0, res.output


def test_a_sample_rate_that_aliases_the_modes_is_warned_about(tmp_path):
    res = run("--t-end", "20", "--sample-rate", "2", "--json")
    assert res.exit_code == 0, res.output
    warnings = [ln for ln in res.stderr.splitlines() if ln.strip()]
    # Table 1: the fastest linear mode is sqrt(k_px/m_p)/(2π) = 2.757 Hz, Nyquist 5.51 Hz
    assert len(warnings) == 1 and "2.757 Hz" in warnings[0] and "--sample-rate 6 or more" in warnings[0], warnings
    quiet = run("--t-end", "1", "--json")
    assert quiet.exit_code == 0 and not quiet.stderr.strip(), quiet.stderr


def test_a_run_that_stops_at_its_start_is_said_in_one_line(tmp_path):
    out = tmp_path / "x.nc"
    res = run("--t-end", "1", "--N", "1e300", "--no-plot", "--out", str(out))
    assert res.exit_code == 1, res.output
    assert lines_of(res) == ["error: the run stopped early: state became non-finite at t = 0 s; "
                             "it kept too few samples to write"]
    assert not out.exists()


def test_a_run_that_stops_early_is_kept_and_said_in_one_line(tmp_path, monkeypatch):
    import dataclasses

    import stickslip.cli.simulate as command

    library = command.run_simulation

    def stops_at_half_time(*args, **kwargs):
        traj = library(*args, **kwargs)
        keep = traj.t <= 0.5
        return dataclasses.replace(traj, t=traj.t[keep], states=traj.states[keep], mode=traj.mode[keep],
                                   friction=traj.friction[keep], work=traj.work[keep], steady_from=0.25,
                                   status="max_steps reached at t = 0.5 s")

    monkeypatch.setattr(command, "run_simulation", stops_at_half_time)
    out = tmp_path / "x.nc"
    res = run("--t-end", "1", "--out", str(out), "--json")
    assert res.exit_code == 1, res.output
    assert lines_of(res) == [f"error: the run stopped early: max_steps reached at t = 0.5 s; what it computed is in {out}"]
    kept = load_trajectory(out)
    assert kept.t[-1] == 0.5 and kept.status == "max_steps reached at t = 0.5 s"
    assert out.with_suffix(".png").is_file()


def test_a_library_warning_is_one_line(tmp_path, monkeypatch):
    import warnings

    import stickslip.cli.simulate as command

    library = command.run_simulation

    def warns(*args, **kwargs):
        warnings.warn("something to know\nover two lines", RuntimeWarning)
        return library(*args, **kwargs)

    monkeypatch.setattr(command, "run_simulation", warns)
    res = run("--t-end", "1", "--json")
    assert res.exit_code == 0, res.output
    assert [ln for ln in res.stderr.splitlines() if ln.strip()] == ["warning: something to know over two lines"]


def test_a_number_beyond_the_float_range_is_quoted_as_typed():
    """A 401-digit --t-end reads as inf: the error line quotes the digits typed, not 'inf'."""
    import subprocess
    import sys

    digits = "1" + "0" * 400
    for args, shown in ((["--t-end", digits], digits), ([f"--t-end=-{digits}"], f"-{digits}")):
        res = subprocess.run([sys.executable, "-c", "from stickslip.cli import app; app()", "simulate", "--model",
                              "belt", *args], capture_output=True, text=True, timeout=120)
        assert res.returncode == 2
        assert res.stderr.strip().splitlines() == [f"error: --t-end must be a finite number > 0, got {shown}"]
