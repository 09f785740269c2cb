"""A batch of states classified in one compiled call (:mod:`.batch_kernels`), the rest in Python.

:func:`classify_batch` gives the outcome rows :func:`.early.classify_state` gives, state by
state and in the same order, so that the cycles that later states match are the same: the
compiled call classifies states until one needs the Python classifier (a new cycle, a run that
ends early or at t_end, a test too near its threshold); that state is classified by
:func:`.early.classify_state`, the cycle it found joins the known ones, and the compiled call
goes on from the next state. A state classified in the compiled call gets the wall time of its
call shared equally among the states of the call.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..integrate.bundles import Samples, scratch, transition_log
from ..integrate.event_loop import N_EXTRA, PROGRESS
from ..integrate.dormand_prince import new_step
from ..integrate.result import mode_array
from ..integrate.runner import MIN_TRANSITION_ROOM, TRANSITIONS_PER_SECOND, EventStepper
from ..integrate.slip_watch import slip_watch
from ..analysis.modes import contact_index_dtype
from ..model.bundle import contact_state
from .batch_kernels import AT_REST, LINEAR, MATCHED, RECURRED, Plan, Work, classify_states
from .context import Context
from .cycles import KMAX, find_cycle
from .early import LINEAR_CHUNKS, RULE_PERIODS, Options, Outcome, classify_state, row_column, row_width, test_interval
from .recurrence import RECURRENCE_FACTOR, point_arrays

__all__ = ["classify_batch", "compiled_batch_applies"]

#: Room for the transitions of one state's run (its window's test for a contact that stuck reads
#: them); a state with more goes to the Python classifier.
TRANSITION_ROOM = 1 << 16

#: Breakaways whose states a run keeps for the recurrence test (its latest ones); a state whose
#: test would need earlier ones goes to the Python classifier.
BREAKAWAY_ROOM = 256

#: The kinematics classes whose batch kernel this process has prepared (a cold start compiles
#: the event loop's callees in two processes first, as a run does).
_PREPARED: set = set()


def compiled_batch_applies(model) -> bool:
    """Whether the compiled batch takes ``model``'s states (its modes fit one word per sample)."""
    return mode_array(0, model.n_contacts, model.unilateral).ndim == 1


def _plan(ctx: Context, model, opts: Options, times: np.ndarray) -> Plan:
    m = ctx.chunk
    return Plan(float(opts.t_end), float(ctx.dt), int(m), int(ctx.window),
                int(min(ctx.window + 3 * (2 * m + 2), times.size)), float(opts.rtol), float(opts.atol),
                float(m * ctx.dt), int(opts.max_steps), float(ctx.period), float(opts.match_rtol),
                bool(ctx.stable), int(model.observed_index), int(model.n), int(LINEAR_CHUNKS), float(RULE_PERIODS),
                int(test_interval(ctx)), float(RECURRENCE_FACTOR))


def _work(model, plan: Plan, times: np.ndarray) -> Work:
    """The arrays of :class:`.batch_kernels.Work` for ``model``."""
    n, nc = model.n, model.n_contacts
    ns = 2 * n + N_EXTRA
    cst = contact_state(model.data.m)
    room = MIN_TRANSITION_ROOM + int(TRANSITIONS_PER_SECOND * 2.0 * plan.h_max)  # a chunk asks for at most h_max
    crossings = plan.capacity // 2 + 2
    return Work(np.zeros(1, dtype=PROGRESS), np.zeros(ns), cst.copy(), np.zeros(ns), cst.copy(),
                new_step(np.zeros(ns)), slip_watch(nc), scratch(ns, nc), np.zeros(6, dtype=np.int64),
                Samples(np.empty(0), np.empty((plan.capacity, ns)), mode_array(plan.capacity, nc, model.unilateral),
                        np.empty((plan.capacity, 2 * nc))),
                Samples(np.empty(0), np.empty((1, ns)), mode_array(1, nc, model.unilateral), np.empty((1, 2 * nc))),
                transition_log(1, ns, contact_index_dtype(nc)), transition_log(room, ns, contact_index_dtype(nc)),
                np.empty(TRANSITION_ROOM), np.zeros((3, times.size // max(plan.piece - 1, 1) + 4), dtype=np.int64),
                np.empty((5, crossings)), np.empty((3, BREAKAWAY_ROOM)), np.empty((BREAKAWAY_ROOM, 2 * n)))


def _linear(ctx: Context, model) -> tuple:
    equilibrium = ctx.equilibrium if ctx.equilibrium is not None else np.zeros(2 * model.n)
    return (np.ascontiguousarray(equilibrium, dtype=float), np.ascontiguousarray(ctx.free, dtype=np.int64),
            np.ascontiguousarray(ctx.lyapunov, dtype=float), np.ascontiguousarray(ctx.flow, dtype=float),
            float(ctx.rest))


def _cycle_arrays(ctx: Context, model, cycles, opts: Options) -> tuple:
    peaks = np.zeros((len(cycles), KMAX))
    for i, c in enumerate(cycles):
        peaks[i, :c.multiplicity] = c.peaks
    return (np.array([c.multiplicity for c in cycles], dtype=np.int64), np.array([c.period for c in cycles], dtype=float),
            np.array([c.amplitude for c in cycles], dtype=float), peaks, *point_arrays(ctx, model, cycles, opts))


def _prepare(model, s0: np.ndarray, opts: Options) -> None:
    """On a model class's first batch in this process: a run's start, which on a cold start
    compiles the event loop's callees in two processes (:mod:`stickslip.integrate.loop_split`) and
    the loop with its Python entry, the version the batch kernel then links and the Python
    classifier calls."""
    kind = type(model.data.kin)
    if kind in _PREPARED:
        return
    EventStepper(model, s0, 0.0, float(opts.t_end), rtol=opts.rtol, atol=opts.atol, h_max=1.0, max_steps=10)
    _PREPARED.add(kind)


def _rows(result, lo: int, hi: int, cycles, n2: int, wall: float) -> np.ndarray:
    """The outcome rows (:meth:`.early.Outcome.to_row`) of the states lo ≤ i < hi decided in the
    compiled call: each one's kind of row (the cycle's for a match or a recurrence) with its time
    decided, steps, wall time and, for an equilibrium, the state it ended in."""
    codes, matched, t_decided, steps, final = (a[lo:hi] for a in result)
    zero = np.zeros(n2)
    kinds = [Outcome("equilibrium", "at-rest", 0.0, None, zero).to_row(),
             Outcome("equilibrium", "linear", 0.0, None, zero).to_row()]
    kinds += [Outcome("periodic", "matched", 0.0, c, c.state).to_row() for c in cycles]
    kinds += [Outcome("periodic", "recurred", 0.0, c, c.state).to_row() for c in cycles]
    kind = np.select([codes == AT_REST, codes == LINEAR, codes == MATCHED, codes == RECURRED],
                     [0, 1, 2 + matched, 2 + len(cycles) + matched])
    rows = np.array(kinds)[kind]
    rows[:, row_column("t_decided")] = t_decided
    rows[:, row_column("steps")] = steps
    rows[:, row_column("wall_time")] = wall
    state = row_column("state")
    steady = (codes == AT_REST) | (codes == LINEAR)
    rows[steady, state:state + n2] = final[steady]
    return rows


def classify_batch(ctx: Context, model, states: np.ndarray, cycles, opts: Options) -> tuple[np.ndarray, list]:
    """Outcome rows of ``states`` (m, 2n) in order, and the known cycles with those they found.

    The rows are those of :func:`.early.classify_state` called on each state in turn with the
    cycles known at that point (module docstring).
    """
    cycles = list(cycles)
    states = np.ascontiguousarray(states, dtype=float)
    count, n2 = states.shape[0], 2 * model.n
    rows = np.empty((count, row_width(model.n)))
    if count == 0:
        return rows, cycles
    times = np.arange(int(math.floor(float(opts.t_end) / ctx.dt)) + 2) * ctx.dt
    _prepare(model, states[0], opts)
    plan = _plan(ctx, model, opts, times)
    work, linear = _work(model, plan, times), _linear(ctx, model)
    cst0 = contact_state(model.data.m)
    result = (np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64), np.zeros(count),
              np.zeros(count, dtype=np.int64), np.zeros((count, n2)))
    first = 0
    while first < count:
        start = time.perf_counter()
        stop = classify_states(model.data, cst0, plan, linear, _cycle_arrays(ctx, model, cycles, opts), times, states,
                               first, work, result)
        if stop > first:
            rows[first:stop] = _rows(result, first, stop, cycles, n2, (time.perf_counter() - start) / (stop - first))
        if stop < count:
            o = classify_state(ctx, model, states[stop], cycles, opts)
            if o.verdict == "periodic" and find_cycle(cycles, o.cycle, opts.match_rtol) < 0:
                cycles.append(o.cycle)
            rows[stop] = o.to_row()
        first = stop + 1
    return rows, cycles

