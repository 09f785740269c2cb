"""Long runs and interrupts of the event integrator.

Time inside the compiled loop is local to each chunk, so runs far from t = 0 keep the event
resolution of runs near it (absolute times of 1e4 s and more used to stop the run with a step-size
underflow: at t = 37,200.7 s for the defaults). Ctrl-C is answered between chunks with the part
done so far.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import stickslip
from stickslip.integrate.status import Status


def test_a_run_starting_at_t0_1e4_equals_the_same_run_from_0():
    late = stickslip.simulate(t0=1e4, t_end=1e4 + 30.0, sample_rate=10.0)
    early = stickslip.simulate(t_end=30.0, sample_rate=10.0)
    assert late.status == "success" and late.status_code is Status.SUCCESS
    np.testing.assert_allclose(late.t - 1e4, early.t, atol=1e-9)
    # the same equations from the same state: the same steps, up to the rounding of sample times
    assert np.max(np.abs(late.states - early.states)) < 1e-8
    assert len(late.transitions) == len(early.transitions) > 0
    np.testing.assert_allclose(late.transitions.time - 1e4, early.transitions.time, atol=1e-8)


def test_chunked_run_takes_the_same_steps_as_one_call(monkeypatch):
    from stickslip.integrate import runner

    one = stickslip.simulate(t_end=40.0, sample_rate=10.0)
    monkeypatch.setattr(runner, "FIRST_CHUNK", 0.7)
    monkeypatch.setattr(runner, "CHUNK_STEPS", 50)  # many short chunks
    many = stickslip.simulate(t_end=40.0, sample_rate=10.0)
    assert many.stats.accepted_steps == one.stats.accepted_steps
    assert many.stats.rejected_steps == one.stats.rejected_steps
    assert np.max(np.abs(many.states - one.states)) < 1e-10


def test_a_loaded_machine_gives_the_same_result(monkeypatch):
    # chunk lengths follow step counts, never the clock: a clock that jumps erratically (a loaded
    # machine) changes nothing, bit for bit
    import itertools
    import time

    quiet = stickslip.simulate(stickslip.Parameters(N=50.0, Omega=0.5), 60.0, sample_rate=20.0)
    ticks = itertools.accumulate(itertools.cycle([1e-6, 3.0, 1e-4, 0.7]))
    monkeypatch.setattr(time, "perf_counter", lambda: next(ticks))
    loaded = stickslip.simulate(stickslip.Parameters(N=50.0, Omega=0.5), 60.0, sample_rate=20.0)
    assert np.array_equal(loaded.states, quiet.states)
    assert np.array_equal(loaded.transitions.time, quiet.transitions.time)


@pytest.mark.slow
def test_a_run_over_1e5_s_finishes():
    traj = stickslip.simulate(t_end=1.2e5, sample_rate=0.1)
    assert traj.status_code is Status.SUCCESS
    assert traj.t[-1] == pytest.approx(1.2e5)
    assert traj.stats.slip_to_stick > 100_000  # stick-slip throughout


def test_ctrl_c_returns_the_part_done_within_a_second():
    code = textwrap.dedent("""
        import sys, time, stickslip
        stickslip.simulate(t_end=0.1)  # compile / load the kernels first
        print("ready", flush=True)
        t = time.perf_counter()
        traj = stickslip.simulate(t_end=1e6, sample_rate=0.01)
        print(traj.status_code.name, traj.t[-1], time.perf_counter() - t, flush=True)
    """)
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "PYTHONWARNINGS": "ignore"})
    assert proc.stdout.readline().strip() == "ready"
    time.sleep(1.5)
    sent = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    answered = time.perf_counter() - sent
    name, t_last, _ = out.split()
    assert name == "INTERRUPTED", err
    assert 0.0 < float(t_last) < 1e6
    assert answered < 3.0  # chunks aim at 0.25 s of wall time; the machine may be loaded
