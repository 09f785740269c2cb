"""Ctrl-C at every instant of a command's life — start-up, compilation, run, write, figure — ends it
with exit code 130 and one line that says what is on disk at that moment, for simulate, basins,
orbit and lyapunov.

Most instants are hit exactly: the process sends itself SIGINT from inside the step of the
command being tested (a wrapper around the library function that runs then), so the signal
goes through the real handlers. The import and a cold numba compilation are tested on a
separate process (a fresh ``NUMBA_CACHE_DIR``: the compilation takes a minute, the test seconds).
"""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from typer.testing import CliRunner

import stickslip.cli.basins as basins_cli
import stickslip.cli.orbit as orbit_cli
import stickslip.cli.simulate as simulate_cli
import stickslip.cli.sweep as sweep_cli
import stickslip.plot.trajectory as trajectory_plot
from stickslip import load_trajectory
from stickslip.basins import basin_stability, box, engine
from stickslip.basins.store import load_basins
from stickslip.cli import app
from stickslip.integrate.runner import CHUNK_SAMPLE_NUMBERS, EventStepper, Record, ToTheEnd, run_chunks, run_event
from stickslip.model.library import load_model

from .test_memory import dof60_text

runner = CliRunner()


def ctrl_c() -> None:
    """What a user's Ctrl-C does: SIGINT to this process, taken by its current handler."""
    signal.raise_signal(signal.SIGINT)


def sends_ctrl_c(function, on_call: int = 1, times: int = 1):
    """``function`` that presses Ctrl-C (``times`` times) as its ``on_call``-th call starts."""
    calls = []

    def wrapper(*args, **kwargs):
        calls.append(1)
        if len(calls) == on_call:
            for _ in range(times):
                ctrl_c()
        return function(*args, **kwargs)
    return wrapper


def interrupted(res) -> str:
    """The one line of an interrupted command (exit 130, no traceback)."""
    assert res.exit_code == 130, res.output
    assert res.exception is None or isinstance(res.exception, SystemExit), res.exception
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("interrupted: "), res.output
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # nothing left installed
    return lines[0][len("interrupted: "):]


def files(folder) -> list:
    return sorted(p.name for p in folder.iterdir())


# ----------------------------------------------------------------------------- simulate
SIMULATE = ["simulate", "--model", "belt", "--t-end", "30"]


@pytest.mark.parametrize("target", ["build_system", "compile"])
def test_simulate_before_its_run_writes_nothing(target, tmp_path, monkeypatch):
    if target == "compile":  # the kernels are compiled or loaded as the run is prepared
        monkeypatch.setattr(EventStepper, "_warm_up", sends_ctrl_c(EventStepper._warm_up))
    else:
        monkeypatch.setattr(simulate_cli, target, sends_ctrl_c(simulate_cli.build_system))
    line = interrupted(runner.invoke(app, [*SIMULATE, "--out", str(tmp_path / "x.nc")]))
    assert line == "nothing was written" and files(tmp_path) == []


def test_simulate_during_its_run_keeps_the_part_done_and_draws_no_figure(tmp_path, monkeypatch):
    monkeypatch.setattr(EventStepper, "advance", sends_ctrl_c(EventStepper.advance, on_call=2))
    line = interrupted(runner.invoke(app, [*SIMULATE, "--t-end", "5000", "--out", str(tmp_path / "x.nc")]))
    kept = load_trajectory(tmp_path / "x.nc")
    assert 0 < kept.t[-1] < 5000 and kept.status.startswith("interrupted at t = ")
    assert line == f"the run up to t = {kept.t[-1]:g} s is in {tmp_path / 'x.nc'}"
    assert files(tmp_path) == ["x.nc"]


def test_simulate_interrupted_in_its_last_chunk_keeps_the_finished_run_and_stops(tmp_path, monkeypatch):
    """A Ctrl-C during the chunk that ends the run is not lost (it was: the command went on, exit 0)."""
    monkeypatch.setattr(EventStepper, "advance", sends_ctrl_c(EventStepper.advance, on_call=1))
    line = interrupted(runner.invoke(app, [*SIMULATE, "--t-end", "1", "--out", str(tmp_path / "x.nc")]))
    assert line == f"the finished run is in {tmp_path / 'x.nc'}"
    assert load_trajectory(tmp_path / "x.nc").t[-1] == 1.0 and files(tmp_path) == ["x.nc"]


def test_simulate_interrupted_while_writing_keeps_the_finished_run(tmp_path, monkeypatch):
    """The file is written whole and then the command stops (it was thrown away: "nothing was written")."""
    monkeypatch.setattr(simulate_cli, "netcdf_writer", sends_ctrl_c(simulate_cli.netcdf_writer))
    line = interrupted(runner.invoke(app, [*SIMULATE, "--out", str(tmp_path / "x.nc")]))
    assert line == f"the finished run is in {tmp_path / 'x.nc'}"
    assert load_trajectory(tmp_path / "x.nc").t[-1] == 30.0 and files(tmp_path) == ["x.nc"]


def test_a_second_ctrl_c_while_writing_stops_at_once_and_leaves_nothing(tmp_path, monkeypatch):
    monkeypatch.setattr(simulate_cli, "netcdf_writer", sends_ctrl_c(simulate_cli.netcdf_writer, times=2))
    line = interrupted(runner.invoke(app, [*SIMULATE, "--out", str(tmp_path / "x.nc")]))
    assert line == "nothing was written" and files(tmp_path) == []


def test_simulate_interrupted_while_drawing_says_the_run_is_kept(tmp_path, monkeypatch):
    """(It said "nothing was written" with the file there.)"""
    monkeypatch.setattr(trajectory_plot, "save_trajectory_figure", sends_ctrl_c(trajectory_plot.save_trajectory_figure))
    line = interrupted(runner.invoke(app, [*SIMULATE, "--out", str(tmp_path / "x.nc")]))
    assert line == f"the finished run is in {tmp_path / 'x.nc'}" and files(tmp_path) == ["x.nc"]


def test_an_existing_output_left_as_it_was_is_not_reported_as_written(tmp_path, monkeypatch):
    (tmp_path / "x.nc").write_text("the previous run")
    monkeypatch.setattr(EventStepper, "_warm_up", sends_ctrl_c(EventStepper._warm_up))
    line = interrupted(runner.invoke(app, [*SIMULATE, "--out", str(tmp_path / "x.nc"), "--overwrite"]))
    assert line == "nothing was written" and (tmp_path / "x.nc").read_text() == "the previous run"


def test_a_ctrl_c_that_surfaces_inside_a_compiled_call_is_one_line(tmp_path, monkeypatch):
    def boxed(*args, **kwargs):  # what numba makes of a KeyboardInterrupt raised as a kernel returns
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            raise SystemError("<built-in function integrate_event> returned a result with an exception set") from exc

    monkeypatch.setattr(simulate_cli, "run_simulation", boxed)
    assert interrupted(runner.invoke(app, [*SIMULATE, "--out", str(tmp_path / "x.nc")])) == "nothing was written"


def test_chunks_of_a_densely_sampled_large_model_stay_short(tmp_path):
    """A run answers Ctrl-C between chunks; a 60-DOF model sampled at 1 kHz spent ~1 s of samples in
    one chunk of 780 s. Chunks now hold at most CHUNK_SAMPLE_NUMBERS numbers of samples."""
    path = tmp_path / "dof60.toml"
    path.write_text(dof60_text())
    model = load_model(str(path))
    s0 = np.zeros(2 * model.n)
    s0[0] = 1.0
    times = np.arange(0.0, 300.0 + 1e-9, 1e-3)
    numbers = 2 * model.n + 2 + 1 + 2 * model.n_contacts

    def largest_chunk(stop) -> int:
        record = Record(model, times)
        stepper = EventStepper(model, s0, 0.0, 300.0, rtol=1e-8, atol=1e-10, h_max=300.0, max_steps=2**62)
        run_chunks(stepper, record, stop)
        assert record.n == times.size
        return max(k for _, _, k in record.chunks)

    out = run_event(model, s0, 0.0, 300.0, times, rtol=1e-8, atol=1e-10, dt=None, max_steps=2**62)
    bounded = max(k for _, _, k in out.record.chunks)
    assert bounded * numbers <= 1.05 * CHUNK_SAMPLE_NUMBERS  # a chunk ends at the first step past its end
    assert largest_chunk(ToTheEnd()) > 3 * bounded  # by steps alone


# ----------------------------------------------------------------------------- basins
BASINS = ["basins", "--model", "belt", "--box", "x=-2:2", "--box", "dx=-2:2", "--n", "200", "--executor", "serial",
          "--no-progress"]


def test_basins_before_its_first_state_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.setattr(basins_cli, "build_system", sends_ctrl_c(basins_cli.build_system))
    assert interrupted(runner.invoke(app, [*BASINS, "--out", str(tmp_path / "b.nc")])) == "nothing was written"
    assert files(tmp_path) == []


def test_basins_during_its_runs_says_how_many_states_the_file_holds(tmp_path, monkeypatch):
    monkeypatch.setattr(engine, "evaluate_batch", sends_ctrl_c(engine.evaluate_batch, on_call=2))  # the timed batch
    out = tmp_path / "b.nc"
    line = interrupted(runner.invoke(app, [*BASINS, "--out", str(out)]))
    ds = load_basins(out)
    done = int(ds.attrs["states_done"])
    assert 0 < done < 200 and not int(ds.attrs["complete"])
    assert line == f"{out} holds {done} of 200 states classified; run the same command again to resume"
    assert runner.invoke(app, [*BASINS, "--out", str(out), "--no-plot"]).exit_code == 0  # and it resumes


def test_basins_interrupted_after_its_last_batch_keeps_the_whole_study(tmp_path, monkeypatch):
    """(It said "nothing was written" and left no .nc, its journal full.)"""
    monkeypatch.setattr(engine, "write_dataset", sends_ctrl_c(engine.write_dataset))  # the final write
    out = tmp_path / "b.nc"
    line = interrupted(runner.invoke(app, [*BASINS, "--out", str(out)]))
    assert line == f"{out} holds all 200 states, classified"
    assert int(load_basins(out).attrs["complete"]) and files(tmp_path) == ["b.nc"]


def test_basins_interrupted_while_drawing_keeps_the_whole_study(tmp_path, monkeypatch):
    monkeypatch.setattr(basins_cli, "save_basins_figure", sends_ctrl_c(basins_cli.save_basins_figure))
    out = tmp_path / "b.nc"
    assert interrupted(runner.invoke(app, [*BASINS, "--out", str(out)])) == f"{out} holds all 200 states, classified"


def test_an_interrupted_study_counts_only_the_states_it_computed(tmp_path, monkeypatch):
    """(The summary said "states computed / resumed: 3000 / 0" after 25 were.)"""
    belt = load_model("belt")
    monkeypatch.setattr(engine, "evaluate_batch", sends_ctrl_c(engine.evaluate_batch, on_call=2))
    res = basin_stability(belt, box(belt, {"x": (-2, 2), "dx": (-2, 2)}, n=200), out=tmp_path / "b.nc",
                          executor="serial")
    assert res.timings["interrupted"] and not res.complete
    assert res.timings["states_computed"] == int(res.dataset.attrs["states_done"]) < 200


# ----------------------------------------------------------------------------- orbit, lyapunov
ORBIT = ["orbit", "--search-time", "2"]
LYAPUNOV = ["lyapunov", "--t-transient", "1", "--t-average", "1"]


@pytest.mark.parametrize("command, holds", [(ORBIT, "the orbit"), (LYAPUNOV, "the spectrum")])
def test_orbit_and_lyapunov_during_their_runs_write_nothing(command, holds, tmp_path, monkeypatch):
    monkeypatch.setattr(EventStepper, "advance", sends_ctrl_c(EventStepper.advance))
    assert interrupted(runner.invoke(app, [*command, "--out", str(tmp_path / "o.nc")])) == "nothing was written"
    assert files(tmp_path) == []


@pytest.mark.parametrize("command, holds", [(ORBIT, "the orbit"), (LYAPUNOV, "the spectrum")])
@pytest.mark.parametrize("target", ["netcdf_writer", "figure"])
def test_orbit_and_lyapunov_interrupted_while_writing_keep_their_file(command, holds, target, tmp_path, monkeypatch):
    """(Both said "nothing was written" with the file there.)"""
    if target == "figure":
        name = "save_orbit_figure" if command is ORBIT else "save_lyapunov_spectrum_figure"
        monkeypatch.setattr(orbit_cli, name, sends_ctrl_c(getattr(orbit_cli, name)))
    else:
        monkeypatch.setattr(orbit_cli, target, sends_ctrl_c(orbit_cli.netcdf_writer))
    out = tmp_path / "o.nc"
    assert interrupted(runner.invoke(app, [*command, "--out", str(out)])) == f"{holds} is in {out}"
    assert files(tmp_path) == ["o.nc"] and out.stat().st_size > 1000


def test_a_sweep_interrupted_while_drawing_says_its_file_is_finished(tmp_path, monkeypatch):
    """A resumable command's line reads its output: finished (its journal gone), or part of it."""
    monkeypatch.setattr(sweep_cli, "save_sweep_figure", sends_ctrl_c(sweep_cli.save_sweep_figure))
    out = tmp_path / "s.nc"
    line = interrupted(runner.invoke(app, ["sweep", "--grid", "N=30,50", "--grid", "Omega=0.5", "--t-end", "2",
                                           "--executor", "serial", "--no-progress", "--out", str(out)]))
    assert line == f"the finished sweep is in {out}"


# ----------------------------------------------------------------------------- start-up, compilation
def _stickslip_after(module: str, *args) -> list:
    """The command line, sending itself SIGINT as ``module`` starts to be imported."""
    code = ("import os, signal, sys\n"
            "class Hook:\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            f"        if name == {module!r}:\n"
            "            os.kill(os.getpid(), signal.SIGINT)\n"
            "sys.meta_path.insert(0, Hook())\n"
            "from stickslip.cli import app\n"
            "app()\n")
    return [sys.executable, "-c", code, *args]


@pytest.mark.parametrize("module", ["stickslip.analysis", "stickslip.cli.simulate"])
def test_ctrl_c_while_importing_is_one_line(module, tmp_path):
    """(It was a KeyboardInterrupt traceback from whatever module was being imported.)"""
    res = subprocess.run(_stickslip_after(module, *SIMULATE, "--out", str(tmp_path / "x.nc")), capture_output=True,
                         text=True, timeout=120)
    assert res.returncode in (130, -signal.SIGINT), res.stderr  # the shell sees 130 either way
    assert res.stderr.strip() == "interrupted: nothing was written" and files(tmp_path) == []


def test_ctrl_c_while_numba_compiles_is_one_line(tmp_path):
    """numba compiles in Python between LLVM passes, so KeyboardInterrupt reaches it within about a
    second (docs/reliability.md); here the kernels of a model file compile in a fresh cache."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    (tmp_path / "out").mkdir()
    proc = subprocess.Popen([sys.executable, "-c", "from stickslip.cli import app; app()", *SIMULATE, "--no-plot",
                             "--out", str(tmp_path / "out" / "x.nc")], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60

    def cached() -> int:
        return sum(len(names) for _, _, names in os.walk(tmp_path / "cache"))

    while cached() < 6 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)  # the first small kernels are saved; the event loop's (a minute) is compiling
    proc.send_signal(signal.SIGINT)
    try:
        _, stderr = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 130, stderr
    assert stderr.strip() == "interrupted: nothing was written" and files(tmp_path / "out") == []


def test_ctrl_c_inside_a_finaliser_is_not_lost():
    """A KeyboardInterrupt raised while a ``__del__`` runs (numba frees LLVM objects that way all
    through a compilation) is delivered again after it, instead of "Exception ignored" and going on."""
    code = ("import os, signal, stickslip\n"
            "class Freed:\n"
            "    def __del__(self):\n"
            "        os.kill(os.getpid(), signal.SIGINT)\n"
            "        sum(range(1000))\n"
            "try:\n"
            "    obj = Freed(); del obj\n"
            "    sum(range(10**8))\n"
            "    print('went on')\n"
            "except KeyboardInterrupt:\n"
            "    print('interrupted')\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert res.stdout.strip() == "interrupted" and res.stderr == "", (res.stdout, res.stderr)
