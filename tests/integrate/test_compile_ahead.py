"""A cold start compiles independent kernels in two processes (stickslip.model.compile_ahead and its splits)."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import textwrap

import numba
import numpy as np
import pytest

import stickslip
from stickslip.integrate import loop_split, transitions
from stickslip.model import compile_ahead
from stickslip.model import physics
from stickslip.model.jit import KernelDispatcher
from stickslip.orbits import var_kernels
from stickslip.orbits.linear_flow import VARIATIONAL, flow_jacobian

MODEL_FILE = os.path.join(os.path.dirname(__file__), "..", "orbits", "two_mass_belt.toml")


def _available(kernel, sig) -> bool:
    """Whether the version ``sig`` of ``kernel`` is in this process or the cache."""
    if isinstance(kernel, KernelDispatcher):
        return kernel.available(sig)
    return sig in kernel.overloads or kernel._cache.load_overload(sig, kernel.targetctx) is not None


def _all_available(split, md) -> None:
    signatures = split.signatures(md)
    assert set(signatures) == set(split.kernels)
    for kernel in split.kernels:
        assert _available(kernel, signatures[kernel]), kernel


@pytest.mark.parametrize("model", ["two-plates", MODEL_FILE, "impact-oscillator"])
def test_the_helpers_signatures_are_the_ones_the_event_loop_compiles(model):
    """Every kernel the two processes compile ahead, with the argument types the split derives
    from the bundles of a run, is one the event loop or a run's results call (else the helper
    would compile in vain): once they are compiled (here or, loaded from the cache, by another
    process) that version of each is in this process or in the cache. A wrong type is not."""
    system = stickslip.load_model(model)
    run = stickslip.simulate(system, 0.5)
    assert run.slip_velocity.shape[0] == run.normal_force.shape[0] == run.t.size  # the results' kernels
    split, name = loop_split.split_for(system.data)
    _all_available(split, system.data)
    search = loop_split._loop_calls(system.data)[transitions.first_breakaway]
    search_sig = tuple(numba.typeof(a) for a in search)
    # the plates fix one contact: their loop probes its breakaway as the slip event and compiles no search
    assert (name == "ONE_CONTACT_LOOP") == (model == "two-plates")
    assert (name == "OPENING_LOOP") == (model == "impact-oscillator")  # a rigid contact opens and closes
    assert transitions.first_breakaway.available(search_sig) == (model != "two-plates")
    rhs = physics.rhs
    wrong = split.signatures(system.data)[rhs][:-1] + (numba.types.float64[:, ::1],)
    assert not rhs.available(wrong)


def test_the_variational_splits_signatures_are_the_ones_the_orbit_tools_compile():
    """As above for the variational equations: after a linearised flow across stick-slip
    transitions, every kernel of the split is there with the derived argument types (the api
    kernels, which Python calls, with their Python entry)."""
    system = stickslip.load_model(MODEL_FILE)
    run = stickslip.simulate(system, 30.0)
    assert len(run.transitions.time) > 2
    t0 = float(run.transitions.time[0]) - 0.1
    s0 = run.states[np.searchsorted(run.t, t0)]
    fj = flow_jacobian(system, s0, float(run.transitions.time[2]) + 0.1 - t0)
    assert len(fj.events) >= 2
    _all_available(VARIATIONAL, system.data)
    gradients = VARIATIONAL.signatures(system.data)[var_kernels.contact_gradients]
    assert not _available(var_kernels.contact_gradients, gradients[:3] + (numba.types.float32,) + gradients[4:])


def test_the_steady_splits_signatures_are_the_ones_stability_compiles_for_a_model_file():
    """As above for steady sliding's kernels: after a model file's stability, every kernel of the
    split is there with the derived argument types; for the plates, whose sizes are compile-time
    constants, the split does not apply."""
    from stickslip.stability.steady import STEADY

    system = stickslip.load_model(MODEL_FILE)
    stickslip.stability(system)
    assert STEADY.applies(system.data)
    _all_available(STEADY, system.data)
    assert not STEADY.applies(stickslip.load_model("two-plates").data)


COLD_RUN = textwrap.dedent("""
    import hashlib, json, sys, time
    import numpy as np
    from numba.core import event
    import stickslip
    from stickslip.model.compile_ahead import meanwhile
    outermost, depth, spans = [], [0], []
    class Outermost(event.Listener):
        def on_start(self, ev):
            if depth[0] == 0:
                outermost.append(ev.data["dispatcher"].py_func.__name__)
                spans.append([time.perf_counter(), None])
            depth[0] += 1
        def on_end(self, ev):
            depth[0] -= 1
            if depth[0] == 0:
                spans[-1][1] = time.perf_counter()
    work = []
    def prepare():
        work.append(time.perf_counter())
        time.sleep(0.3)
        work.append(time.perf_counter())
    nested = []
    class Every(event.Listener):
        def on_start(self, ev):
            nested.append(ev.data["dispatcher"].py_func.__name__)
        def on_end(self, ev):
            pass
    with event.install_listener("numba:compile", Outermost()), event.install_listener("numba:compile", Every()):
        with meanwhile(prepare):
            tr = stickslip.simulate(None, 5.0)
    print(json.dumps({"states": hashlib.sha256(np.ascontiguousarray(tr.states).tobytes()).hexdigest(),
                      "outermost": outermost, "compiled": nested, "spans": spans, "work": work}))
""")


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="the helper process runs only with two or more cores")
def test_a_cold_start_in_two_processes_runs_alike_and_compiles_the_stick_solve_once(tmp_path):
    """From an empty cache with the helper on: the same states bit for bit as a run in this
    process, and this process loads the helper's kernels from the cache instead of compiling them.
    The :func:`meanwhile` work runs between this process's compiling and the wait for the helper,
    outside the compile events (which the command line counts as compiling, the wait included)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), STICKSLIP_COMPILE_PROCESSES="2")
    out = subprocess.run([sys.executable, "-c", COLD_RUN], env=env, capture_output=True, text=True, check=True,
                         timeout=900)
    cold = json.loads(out.stdout.strip().splitlines()[-1])
    here = stickslip.simulate(None, 5.0)
    assert cold["states"] == hashlib.sha256(np.ascontiguousarray(here.states).tobytes()).hexdigest()
    assert "try_stick" not in cold["compiled"] and "stick_forces" not in cold["compiled"]
    # the friction forces, which both sides call, compiled once (by the helper) and loaded here from the cache
    assert "general_forces" not in cold["compiled"] and "band_forces" not in cold["compiled"]
    assert "rhs" in cold["compiled"] and "event_loop" in cold["outermost"]
    start, end = cold["work"]
    assert end - start >= 0.3
    assert all(stop <= start or begin >= end for begin, stop in cold["spans"]), (cold["spans"], cold["work"])
    assert any(stop <= start for _, stop in cold["spans"]) and any(begin >= end for begin, _ in cold["spans"])


OPEN_AT_START = textwrap.dedent("""
    import json, os
    from numba.core import event
    import stickslip
    from stickslip.integrate.driver import SimulationError
    from stickslip.integrate import runner
    from stickslip.model import model_from_spec
    started = []
    start = runner.start_callees
    runner.start_callees = lambda md: started.append(start(md)) or started[-1]
    compiled = []
    class Every(event.Listener):
        def on_start(self, ev):
            compiled.append(ev.data["dispatcher"].py_func.__name__)
        def on_end(self, ev):
            pass
    spec = {"dofs": ["x"], "mass": [[1.0]], "damping": [[0.1]], "stiffness": [[1.0]],
            "contact": [{"tangent": [[1.0]], "drive": [1.5], "normal_force": 1.0, "normal_gradient": [-2.0],
                         "friction": {"law": "coulomb", "mu_k": 0.8, "delta_mu": 0.2}}]}
    try:
        with event.install_listener("numba:compile", Every()):
            stickslip.simulate(model_from_spec(spec), 1.0, ic={"x": 0.6})
        refused = False
    except SimulationError:
        refused = True
    try:
        os.waitpid(-1, os.WNOHANG)
        children = True
    except ChildProcessError:
        children = False
    print(json.dumps({"refused": refused, "children": children, "compiled": compiled,
                      "helper": started[0] is not None}))
""")


@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="the helper process runs only with two or more cores")
def test_a_cold_start_whose_contact_is_open_at_the_start_ends_its_helper(tmp_path):
    """The helper starts before the check of the contacts' loads: where a contact is open at the
    start, the run is refused without compiling the loop, and the helper is gone."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), STICKSLIP_COMPILE_PROCESSES="2")
    out = subprocess.run([sys.executable, "-c", OPEN_AT_START], env=env, capture_output=True, text=True,
                         check=True, timeout=600)
    result = json.loads(out.stdout.strip().splitlines()[-1])
    assert result["helper"] and result["refused"] and not result["children"]
    assert "contact_lost" in result["compiled"] and "event_loop" not in result["compiled"]


def test_a_cold_starts_meanwhile_work_runs_once_before_it_waits_for_the_helper():
    """:func:`compile_ahead.meanwhile` work runs in the first cold start inside its block, after
    this side's kernels and before the wait; an error in it is ignored; outside the block it is gone."""
    calls = []

    class Helper:
        def wait(self, timeout):
            calls.append("wait")

        def end(self):
            calls.append("end")

    split = compile_ahead.Split(helper=(), own=(), caller=loop_split.EVENT_LOOP.caller, calls=lambda md: {})
    with compile_ahead.meanwhile(lambda: calls.append("work")), compile_ahead.meanwhile(lambda: 1 / 0):
        for _ in range(2):
            with compile_ahead.ColdStart(split, None, Helper()) as cold:
                cold.finish()
    assert calls == ["work", "wait", "end", "wait", "end"]
    with compile_ahead.ColdStart(split, None, Helper()) as cold:
        cold.finish()
    assert calls[-2:] == ["wait", "end"] and calls.count("work") == 1


def test_a_cold_start_compiles_its_stages_each_after_the_helpers_stage_before():
    """With earlier stages, this process compiles its kernels of a stage once the helper has
    marked its kernels of the stage before as cached, marks its own (which the helper waits for),
    and runs the meanwhile work after its last stage, before the wait for the helper's end."""
    calls = []

    class Kernel:
        def __init__(self, name):
            self.name = name

        def compile(self, signature):
            calls.append(("compile", self.name, signature))

    class Helper:
        def wait_for(self, marker, timeout):
            calls.append(("wait for", marker))

        def mark(self, marker):
            calls.append(("mark", marker))

        def wait(self, timeout):
            calls.append(("wait",))

        def end(self):
            calls.append(("end",))

    a, b, c, d = (Kernel(name) for name in "abcd")
    split = compile_ahead.Split(helper=(Kernel("h"),), own=(c, d), caller=loop_split.EVENT_LOOP.caller,
                                calls=lambda md: {}, stages=(((Kernel("h0"),), (a,)), ((Kernel("h1"),), (b,))))
    assert [k.name for k in split.kernels] == ["h0", "a", "h1", "b", "h", "c", "d"]
    with compile_ahead.meanwhile(lambda: calls.append(("work",))):
        with compile_ahead.ColdStart(split, {a: "sa", b: "sb", c: "sc", d: "sd"}, Helper()) as cold:
            cold.finish()
    assert calls == [("compile", "a", "sa"), ("mark", "own-0"), ("wait for", "helper-0"), ("compile", "b", "sb"),
                     ("mark", "own-1"), ("wait for", "helper-1"), ("compile", "c", "sc"), ("compile", "d", "sd"),
                     ("work",), ("wait",), ("end",)]


def test_a_split_runs_as_one_stage_where_the_helpers_earlier_kernels_are_there_already():
    """Where a command compiled the helper's kernels of the earlier stages before (for another
    purpose), waiting for them would leave the helper idle: the split runs as one stage, each
    side's kernels of every stage in order."""

    class Kernel:
        def __init__(self, name, there):
            self.name, self.there = name, there

        def available(self, signature):
            return self.there

    a, b, h, o = Kernel("a", False), Kernel("b", False), Kernel("h", False), Kernel("o", False)
    h0, h1 = Kernel("h0", True), Kernel("h1", False)
    split = compile_ahead.Split(helper=(h,), own=(o,), caller=loop_split.EVENT_LOOP.caller, calls=lambda md: {},
                                stages=(((h0,), (a,)), ((h1,), (b,))))
    signatures = dict.fromkeys(split.kernels)
    assert split.stages_to_run(signatures) == split.all_stages == (((h0,), (a,)), ((h1,), (b,)), ((h,), (o,)))
    h1.there = True
    assert split.stages_to_run(signatures) == split.one_stage == (((h0, h1, h), (a, b, o)),)


def test_a_helper_started_as_a_new_interpreter_compiles_from_the_pickled_model_data():
    """Where the helper is not forked (not Linux) it is a new interpreter that reads the model data
    pickled to a file; it compiles a stage once this process has marked its side of the stage
    before done, marks its own, ends with status 0, and its folder is removed."""
    system = stickslip.load_model("belt")
    stickslip.simulate(system, 0.5)  # its kernels are here or cached: the helper loads them
    split = loop_split.EVENT_LOOP
    assert split.stages
    helper = compile_ahead._spawned_helper(system.data, "stickslip.integrate.loop_split:EVENT_LOOP")
    assert helper is not None and helper.path.exists()
    helper.wait_for("helper-0", 300.0)
    assert (helper.folder / "helper-0").exists()
    helper.wait(1.0)
    assert helper.process.poll() is None  # waiting for this side's first stage
    for k in range(len(split.stages)):
        helper.mark(f"own-{k}")
    helper.wait(300.0)
    assert helper.process.returncode == 0
    assert all((helper.folder / f"helper-{k}").exists() for k in range(len(split.stages)))
    helper.end()
    assert not helper.path.exists() and not helper.folder.exists()


def test_the_helper_is_off_on_request(monkeypatch):
    monkeypatch.setenv("STICKSLIP_COMPILE_PROCESSES", "1")
    assert not compile_ahead.enabled()
    assert loop_split.start_callees(stickslip.load_model("belt").data) is None
    monkeypatch.setenv("STICKSLIP_COMPILE_PROCESSES", "2")
    assert compile_ahead.enabled() == ((os.cpu_count() or 1) >= 2)


def _compile_processes_setting():
    return os.environ.get("STICKSLIP_COMPILE_PROCESSES")


def test_pool_workers_compile_alone(monkeypatch):
    """The workers of a sweep fill the cores: each compiles a cold start by itself."""
    from stickslip.parallel import worker_pool

    monkeypatch.setenv("STICKSLIP_COMPILE_PROCESSES", "2")
    with worker_pool(1) as pool:
        assert pool.submit(_compile_processes_setting).result(timeout=120) == "1"


@pytest.mark.parametrize("value", ["0", "-1", "two", "1.5"])
def test_a_compile_processes_setting_that_is_no_positive_integer_is_one_line_and_exit_2(monkeypatch, value):
    from typer.testing import CliRunner

    from stickslip.cli import app
    from stickslip.errors import WorkersError

    monkeypatch.setenv("STICKSLIP_COMPILE_PROCESSES", value)
    with pytest.raises(WorkersError, match="STICKSLIP_COMPILE_PROCESSES=.* is not a positive integer"):
        compile_ahead.enabled()
    result = CliRunner().invoke(app, ["models"])
    assert result.exit_code == 2
    (line,) = result.output.strip().splitlines()
    assert line.startswith("error: STICKSLIP_COMPILE_PROCESSES=") and "set it to 1" in line
