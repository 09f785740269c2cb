"""Work that would not fit in memory is refused up front, by the library, in one line that gives
the estimate and a setting that fits (computed from the memory available, not the one given).

The memory available is set by monkeypatching :func:`stickslip.memory.available_memory`: nothing
here allocates what it asks for. The estimates per item are checked against the sizes they are
made of, written out here from the arrays a run keeps (2n + 2 recorded states, a mode byte,
2 friction components per contact, ...); their factors were measured (stickslip/memory.py).
"""

import re

import numpy as np
import pytest
from typer.testing import CliRunner

import stickslip
from stickslip import memory
from stickslip.basins import basin_stability, box
from stickslip.cli import app
from stickslip.errors import MemoryLimitError, SimulationError
from stickslip.integrate import driver
from stickslip.integrate.driver import MAX_SAMPLES, check_samples
from stickslip.model.library import load_model
from stickslip.orbits import lyapunov_spectrum
from stickslip.stability.maps import stability_map
from stickslip.sweep import sweep

runner = CliRunner()
GB = 1e9


def dof60_text(n: int = 60) -> str:
    """A model file of ``n`` uncoupled unit masses on springs, the first on a belt (one contact)."""
    diag = lambda v: "[" + ", ".join("[" + ", ".join(str(v if i == j else 0.0) for j in range(n)) + "]"  # noqa: E731
                                     for i in range(n)) + "]"
    tangent = "[[" + ", ".join("1.0" if j == 0 else "0.0" for j in range(n)) + "]]"
    dofs = ", ".join(f'"q{i}"' for i in range(n))
    return (f'name = "dof{n}"\ndofs = [{dofs}]\nmass = {diag(1.0)}\ndamping = {diag(0.1)}\nstiffness = {diag(1.0)}\n'
            f'force = [{", ".join(["0.0"] * n)}]\n\n[[contact]]\nname = "belt"\ntangent = {tangent}\ndrive = [1.5]\n'
            'normal_force = 1.0\n[contact.friction]\nlaw = "exponential"\nmu_k = 0.5\ndelta_mu = 0.5\nalpha = 2.0\n')


@pytest.fixture(scope="module")
def dof60(tmp_path_factory):
    path = tmp_path_factory.mktemp("models") / "dof60.toml"
    path.write_text(dof60_text())
    return path


def limit(monkeypatch, gb: float) -> None:
    """This process has ``gb`` GB available, as far as stickslip can tell."""
    monkeypatch.setattr(memory, "available_memory", lambda: gb * GB)


def number(pattern: str, text: str) -> float:
    match = re.search(pattern, text)
    assert match, text
    return float(match.group(1))


#: Bytes per kept sample of a 60-DOF model with one contact, written out: the recorded states
#: (120 + 2 works) as float64, the mode byte, 2 friction components, the contiguous copy of the
#: 120 states, slip velocity (2) and normal force (1), and 14 float series of the analysis.
DOF60_SAMPLE = 8 * 122 + 1 + 8 * 2 + 8 * 120 + 8 * 3 + 8 * 14


def test_the_estimate_of_a_sample_is_the_arrays_a_run_keeps():
    assert memory.sample_bytes(60, 1) == DOF60_SAMPLE
    assert memory.sample_bytes(6, 1) == 8 * 14 + 1 + 16 + 8 * 12 + 24 + 8 * 14  # the plates: 361 B, 360 measured


def test_simulate_refuses_samples_that_do_not_fit_before_allocating_and_names_a_rate_that_fits(dof60, monkeypatch):
    limit(monkeypatch, 8.0)
    monkeypatch.setattr(driver, "initial_state", lambda *a: pytest.fail("the run was prepared"))
    with pytest.raises(MemoryLimitError) as info:
        stickslip.simulate(load_model(str(dof60)), 19999.0, sample_rate=1000.0)
    text = str(info.value)
    need = (19999 * 1000 + 1) * DOF60_SAMPLE
    assert f"≈ {need / GB:.3g} GB" in text and "8 GB of memory available" in text
    rate = number(r"lower the sample rate to at most ([0-9.e+]+) Hz", text)
    assert rate != 1000.0 and (19999 * rate + 1) * DOF60_SAMPLE <= 8 * GB  # the rate given fits...
    assert (19999 * rate * 1.01 + 1) * DOF60_SAMPLE > 8 * GB  # ...and is not far below the most that does
    length = number(r"shorten the run to at most ([0-9.e+]+) s", text)
    assert (length * 1000 + 1) * DOF60_SAMPLE <= 8 * GB


def test_the_command_line_says_it_in_one_line_and_checks_once(dof60, monkeypatch, tmp_path):
    calls = []
    monkeypatch.setattr(memory, "available_memory", lambda: calls.append(1) or 8 * GB)
    res = runner.invoke(app, ["simulate", "--model", str(dof60), "--t-end", "19999", "--sample-rate", "1000",
                              "--out", str(tmp_path / "r.nc")])
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: the run (2e+07 samples of model 'dof60'"), res.output
    assert "lower the sample rate to at most" in lines[0] and calls == [1]  # the library's one check
    assert not list(tmp_path.iterdir())


def test_too_many_samples_for_any_memory_name_both_settings():
    plates = stickslip.simulate(None, 0.01).system
    with pytest.raises(SimulationError, match=r"keeps 1e\+15 samples, more than the 2e\+07 a run may keep; lower the "
                                              r"sample rate to at most 0.0199 Hz or shorten the run to at most 19.9 s"):
        check_samples(plates, 1e9, 1e6)
    assert check_samples(plates, 19.9, 1e6) <= MAX_SAMPLES


def test_a_caller_that_sets_the_rate_itself_is_told_only_the_length():
    belt = load_model("belt")
    with pytest.raises(SimulationError) as info:
        check_samples(belt, 1e300, 200.0, run="the transient (t_transient, --t-transient)", rate_settable=False)
    text = str(info.value)
    assert "shorten the transient (t_transient, --t-transient) to at most 9.99e+04 s" in text
    assert "sample rate" not in text and "sample_rate" not in text and len(text) < 300


def test_lyapunov_names_its_own_options(monkeypatch):
    with pytest.raises(SimulationError) as info:
        lyapunov_spectrum("belt", t_transient=1e300)
    text = str(info.value)
    assert "shorten the transient (t_transient, --t-transient) to at most" in text
    assert "sample rate" not in text and "sample_rate" not in text
    limit(monkeypatch, 1.0)
    with pytest.raises(MemoryLimitError, match=r"shorten t_average \(--t-average\) to at most"):
        lyapunov_spectrum("belt", t_transient=1.0, t_average=1e300)


def test_a_basin_study_is_refused_before_a_model_is_rebuilt_and_told_the_n_that_fits(dof60, monkeypatch):
    model = load_model(str(dof60))
    limit(monkeypatch, 20.0)
    monkeypatch.setattr("stickslip.basins.engine._models", lambda *a: pytest.fail("models were rebuilt"))
    states = box(model, {"q0": (-1.0, 1.0)}, n=10_000_000)
    with pytest.raises(MemoryLimitError) as info:
        basin_stability(model, states, executor="serial")
    text = str(info.value)
    per = memory.state_bytes(60, 173 + 120)  # an outcome row of 10 + 16 + 2n + 3 · 49 numbers
    n = int(number(r"give --n (\d+)", text))
    assert n * per + memory.param_bytes(60) <= 20 * GB < (n + 1000) * per
    assert f"≈ {1e7 * per / GB + memory.param_bytes(60) / GB:.3g} GB" in text


def test_ten_to_the_fourteen_states_are_refused_at_once_from_the_command_line(dof60, monkeypatch, tmp_path):
    limit(monkeypatch, 20.0)
    res = runner.invoke(app, ["basins", "--model", str(dof60), "--box", "q0=-1:1", "--n", "10000000",
                              "--param", "contact.0.drive=1.2:2:1000000", "--out", str(tmp_path / "b.nc")])
    assert res.exit_code == 2 and res.output.startswith("error: a basin study of 1e+07 states × 1e+06 parameter"), \
        res.output
    assert "give fewer states and parameter values" in res.output and not list(tmp_path.iterdir())


def test_drawing_states_checks_its_own_arrays(dof60, monkeypatch):
    model = load_model(str(dof60))
    limit(monkeypatch, 1.0)
    spec = box(model, {"q0": (-1.0, 1.0)}, n=10_000_000)
    with pytest.raises(MemoryLimitError, match="initial states of model 'dof60'"):
        spec.states(model, np.zeros(60))


def test_a_sweep_is_refused_with_the_points_that_fit(monkeypatch):
    limit(monkeypatch, 0.1)
    grid = {"N": np.linspace(10, 100, 1000).tolist(), "Omega": np.linspace(1, 10, 1000).tolist()}
    with pytest.raises(MemoryLimitError) as info:
        sweep(grid, executor="serial", t_end=10.0)
    points = number(r"give at most ([0-9.e+]+) points", str(info.value))
    assert 1 <= points < 1e6


def test_a_stability_map_is_refused_with_the_axis_size_that_fits(monkeypatch):
    limit(monkeypatch, 0.05)
    with pytest.raises(MemoryLimitError) as info:
        stability_map(None, np.linspace(10, 100, 3000), np.linspace(1, 10, 3000))
    side = int(number(r"e\.g\. (\d+) values per axis", str(info.value)))
    assert 2 <= side < 3000


def test_an_unreadable_memory_size_lets_work_through(monkeypatch):
    monkeypatch.setattr(memory, "available_memory", lambda: None)
    memory.check_memory(1e30, "anything", "nothing")
