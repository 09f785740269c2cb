"""The early-stopping classifier compiled over a batch of states: one call for many states.

For each state, the run :func:`.early.classify_state` makes, made here without Python between
its pieces: the same contact check and starting modes, the same pieces of the event loop
(:func:`stickslip.integrate.event_loop.event_loop`, called with the arguments that
:class:`~stickslip.integrate.runner.EventStepper` gives it: the chunk's end, its step size, its
room for transitions, again from its start where that was short), the same record of samples
(the window kept as :class:`~stickslip.integrate.runner.Record` keeps it), so that a state takes
the same steps and writes the same samples as there. After each piece the tests of
:class:`.early.EarlyStop` decide on those samples and on the breakaways' states
(:mod:`.batch_rules`): steady sliding reached (at rest, or linear), a known cycle reached or
recurred. What these tests cannot decide here is handed
back (:data:`PYTHON`): a state whose run ends early or reaches t_end, where the period rule
might find a new cycle, where a test is too near its threshold, or whose buffers run out; the
caller classifies it with :func:`.early.classify_state`, and calls again for the states after it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..analysis.period import MIN_PERIODS
from ..integrate import contacts as E
from ..integrate.contacts import TRANSITION_TO_SLIP
from ..integrate.bundles import Samples, TransitionLog
from ..integrate.event_loop import Controls, event_loop, fresh_progress
from ..integrate.runner import MIN_TRANSITION_ROOM, TRANSITIONS_PER_SECOND
from ..integrate.status import CHUNK_END, SUCCESS
from ..model.jit import loop
from .batch_rules import DOUBT, linear_test, matched_cycle, maybe_settled, minima_between, period_match, recurs, section

__all__ = ["Plan", "Work", "classify_states", "UNDECIDED", "AT_REST", "LINEAR", "MATCHED", "RECURRED", "PYTHON"]

#: What a state came to (:func:`classify_states`' codes).
UNDECIDED, AT_REST, LINEAR, MATCHED, RECURRED, PYTHON = 0, 1, 2, 3, 4, -1


class Plan(NamedTuple):
    """The numbers of a study that every state's run shares (from its context and options,
    :func:`.batch.classify_batch`): t_end, the sample interval dt [s], the samples of a chunk and
    of the window, the rows of the record, the tolerances, the largest step (one chunk) [s], the
    step cap, T_c [s], the match tolerance, whether steady sliding is stable, the observed
    coordinate, n, :data:`.early.LINEAR_CHUNKS`, :data:`.early.RULE_PERIODS`, the samples of a
    piece (:func:`.early.test_interval`) and :data:`.recurrence.RECURRENCE_FACTOR`."""

    t_end: float
    dt: float
    chunk: int
    window: int
    capacity: int
    rtol: float
    atol: float
    h_max: float
    max_steps: int
    period: float
    match_rtol: float
    stable: bool
    observed: int
    n: int
    linear_chunks: int
    rule_periods: float
    piece: int
    recurrence: float


class Work(NamedTuple):
    """The arrays a batch works in (allocated once by the caller, :func:`.batch.work_arrays`)."""

    progress: np.ndarray
    y: np.ndarray
    cst: np.ndarray
    saved_y: np.ndarray
    saved_cst: np.ndarray
    step: tuple
    slips: tuple
    scratch: tuple
    stats: np.ndarray
    record: Samples
    warm_samples: Samples
    warm_log: TransitionLog
    log: TransitionLog
    tr_times: np.ndarray
    chunks: np.ndarray
    crossings: np.ndarray
    breaks: np.ndarray
    break_states: np.ndarray


@loop
def _loop_call(md, cst, y, ctl, h, samples, row, log, work, start_modes):
    """One call of the event loop from ``y`` (copied into the step) as :func:`.event_loop.integrate_event`
    makes it: a fresh progress record (:func:`.event_loop.fresh_progress`) with ``h`` and the first
    sample ``row``, no slips homing."""
    fresh_progress(work.progress, h, row, 0)
    for i in range(y.size):
        work.step.y[i] = y[i]
    for i in range(work.slips.homing.size):
        work.slips.homing[i] = 0
    for i in range(work.stats.size):
        work.stats[i] = 0
    event_loop(ctl, md, cst, work.progress, work.step, work.slips, work.scratch, samples, log, work.stats, start_modes)
    for i in range(y.size):
        y[i] = work.step.y[i]


@loop
def _advance(md, plan, times, base, row, t, h, tau_stop, steps_left, work):
    """:meth:`~stickslip.integrate.runner.EventStepper.advance`: (status, τ, h, next row, transitions)
    of one chunk; transitions −1 where they outgrow :attr:`Work.log`."""
    y, cst = work.y, work.cst
    for i in range(y.size):
        work.saved_y[i] = y[i]
    for i in range(cst.size):
        work.saved_cst[i] = cst[i]
    ctl = Controls(t, tau_stop, plan.t_end - t, plan.rtol, plan.atol, plan.h_max, steps_left)
    rec = work.record
    samples = Samples(times[base:base + plan.capacity], rec.states, rec.modes, rec.forces)
    room = MIN_TRANSITION_ROOM + int(TRANSITIONS_PER_SECOND * max(tau_stop, 0.0))
    while True:
        if room > work.log.times.size:
            return 0, 0.0, h, row, -1
        lg = work.log
        log = TransitionLog(lg.times[:room], lg.kinds[:room], lg.contacts[:room], lg.states[:room])
        _loop_call(md, cst, y, ctl, h, samples, row, log, work, plan.n < 0)
        p = work.progress[0]
        if p.n_tr <= room:
            return p.status, p.tau, p.h, p.idx, p.n_tr
        room = p.n_tr  # again from the chunk's start with room for all its transitions
        for i in range(y.size):
            y[i] = work.saved_y[i]
        for i in range(cst.size):
            cst[i] = work.saved_cst[i]


@loop
def _window_start(chunks, count, limit):
    """:func:`.early._window_start` of the first ``count`` chunks (rows: first sample, first
    transition, samples)."""
    later = 0
    start = 0
    for k in range(count - 1, -1, -1):
        size = chunks[2, k]
        if size and later < limit:
            start = k
        later += size
    return start


@loop
def _keep_from(record, base, n, first):
    """:meth:`~stickslip.integrate.runner.Record.keep_from`: the new base."""
    shift = first - base
    if shift <= 0:
        return base
    for i in range(n - first):
        for q in range(record.states.shape[1]):
            record.states[i, q] = record.states[shift + i, q]
        record.modes[i] = record.modes[shift + i]
        for q in range(record.forces.shape[1]):
            record.forces[i, q] = record.forces[shift + i, q]
    return first


@loop
def _stuck(work, lo, a, b, first_tr, n_tr, t_a, t_b):
    """Whether a contact stuck in the samples lo + a … lo + b or a transition fell in (t_a, t_b]."""
    if work.record.modes[lo + a:lo + b + 1].any():
        return True
    for q in range(first_tr, n_tr):
        if work.tr_times[q] > t_a and work.tr_times[q] <= t_b:
            return True
    return False


@loop
def _steady(plan, linear, work, times, at, first, target):
    """Test 1 of :class:`.early.EarlyStop` (steady sliding reached): its code."""
    base, n, _, n_tr, _ = at
    window_first = work.chunks[0, first]
    m = plan.chunk
    if not (plan.stable and target - m - window_first >= 0 and target < n):
        return UNDECIDED
    lo = window_first - base
    states = work.record.states
    for j in range(plan.linear_chunks):
        a, b = target - (j + 1) * m - window_first, target - j * m - window_first
        if a < 0:
            return UNDECIDED
        rest, lin = linear_test(linear, states[lo + a], states[lo + b])
        if j == 0 and rest == DOUBT:
            return PYTHON
        if j == 0 and rest == 1:
            return AT_REST
        if _stuck(work, lo, a, b, work.chunks[1, first], n_tr, times[window_first + a], times[window_first + b]):
            return UNDECIDED
        if lin == DOUBT:
            return PYTHON
        if lin == 0:
            return UNDECIDED
    return LINEAR


@loop
def _recurred(plan, cycles, work, times, at, first, m):
    """Test 3 of :class:`.early.EarlyStop` (a known cycle recurred: on its breakaway state, or
    on the run's own state one period back), after the window's section (its ``m`` maxima in
    ``work.crossings``): (code, cycle)."""
    base, n, _, _, n_br = at
    room = work.breaks.shape[1]
    first_tr = work.chunks[1, first]
    if cycles[0].size == 0 or n_br < 1 or work.breaks[2, (n_br - 1) % room] < first_tr:
        return UNDECIDED, -1
    last = (n_br - 1) % room
    s2 = work.break_states[last]
    point_contacts, point_states = cycles[4], cycles[5]
    for c in range(point_contacts.size):  # the cycle's own breakaway state
        if point_contacts[c] == work.breaks[1, last]:
            r = recurs(point_states[c], s2, plan.recurrence, plan.atol, plan.rtol)
            if r == DOUBT:
                return PYTHON, -1
            if r == 1:
                return RECURRED, c
    q = n_br - 2
    while True:
        if q < 0 or n_br - q > room:  # no earlier breakaway, or the earlier ones' states were not kept
            return (UNDECIDED if q < 0 else PYTHON), -1
        i = q % room
        if work.breaks[2, i] < first_tr:
            return UNDECIDED, -1
        if work.breaks[1, i] == work.breaks[1, last]:
            r = recurs(work.break_states[i], s2, plan.recurrence, plan.atol, plan.rtol)
            if r == DOUBT:
                return PYTHON, -1
            if r == 1:
                break
        q -= 1
    t1, t2 = work.breaks[0, i], work.breaks[0, last]
    cross = work.crossings
    a = np.searchsorted(cross[0, :m], t1, side="right")
    b = np.searchsorted(cross[0, :m], t2, side="right")
    window_first = work.chunks[0, first]
    states = work.record.states
    j = plan.observed
    n_min = minima_between(times[base:base + plan.capacity], states[:, j], states[:, plan.n + j], window_first - base,
                           n - base, t1, t2, cross[3:5])
    c = period_match(cycles, t2 - t1, cross[1], a, b, cross[4], n_min, plan.match_rtol)
    if c == DOUBT:
        return PYTHON, -1
    return (RECURRED, c) if c >= 0 else (UNDECIDED, -1)


@loop
def _recurrent(plan, cycles, work, times, at, first, status, t, rule_due):
    """Tests 2, 3 and 4 of :class:`.early.EarlyStop` on the window's section: (code, cycle)."""
    if cycles[0].size == 0 and not rule_due and status != SUCCESS:
        return UNDECIDED, -1  # nothing to test
    base, n = at[0], at[1]
    window_first = work.chunks[0, first]
    lo, hi = window_first - base, n - base
    tv = times[base:base + plan.capacity]
    states = work.record.states
    j = plan.observed
    x, dx = states[:, j], states[:, plan.n + j]
    cross = work.crossings
    m = section(tv, x, dx, lo, hi, cross[3:5], cross[0], cross[1], cross[2])
    c = matched_cycle(cycles, cross[0], cross[1], cross[2], m, plan.match_rtol)
    if c == DOUBT:
        return PYTHON, -1
    if c >= 0:
        return MATCHED, c
    code, c = _recurred(plan, cycles, work, times, at, first, m)
    if code != UNDECIDED:
        return code, c
    if status == SUCCESS:  # the window's verdict at t_end
        return PYTHON, -1
    if not rule_due:
        return UNDECIDED, -1
    t_from = t - plan.rule_periods * plan.period
    recent = m
    while recent > 0 and cross[0, recent - 1] >= t_from:
        recent -= 1
    if m - recent > MIN_PERIODS and tv[lo] <= t_from:
        highest, lowest = -np.inf, np.inf
        for i in range(lo, hi):
            if tv[i] >= t_from:
                highest, lowest = max(highest, x[i]), min(lowest, x[i])
        if maybe_settled(cross[1, recent:m], cross[0, recent:m], highest - lowest):
            return PYTHON, -1
    return UNDECIDED, -1


@loop
def _decide(plan, linear, cycles, work, times, at, status, t, target, rule_due):
    """:meth:`.early.EarlyStop._decide` after a piece: (code, cycle). ``at``: (base, next sample,
    pieces, transitions, breakaways) of the record."""
    if status != CHUNK_END and status != SUCCESS:
        return PYTHON, -1
    first = _window_start(work.chunks, at[2], plan.window)
    code = _steady(plan, linear, work, times, at, first, target)
    if code != UNDECIDED:
        return code, -1
    return _recurrent(plan, cycles, work, times, at, first, status, t, rule_due)


@loop
def _start(md, cst0, plan, s0, work):
    """The state and contacts of a run from ``s0`` with its starting modes set (False: a contact is
    open at the start)."""
    y, cst = work.y, work.cst
    for i in range(y.size):
        y[i] = 0.0
    for i in range(s0.size):
        y[i] = s0[i]
    for i in range(cst.size):
        cst[i] = cst0[i]
    if E.contact_lost(y, md) >= 0:
        return False
    warm = Controls(0.0, 0.0, 0.0, plan.rtol, plan.atol, 1e-6, 10)
    _loop_call(md, cst, y, warm, 1e-7, work.warm_samples, 0, work.warm_log, work, plan.n >= 0)
    return True


@loop
def _log_piece(work, k, n_tr, n_br, n2):
    """Keep a piece's ``k`` transitions (from the run's ``n_tr``-th): their times, and the time,
    contact, number and state of each breakaway (the last ``work.breaks`` of the run). Returns
    the run's breakaways."""
    log, room = work.log, work.breaks.shape[1]
    for q in range(k):
        work.tr_times[n_tr + q] = log.times[q]
        if log.kinds[q] == TRANSITION_TO_SLIP:
            i = n_br % room
            work.breaks[0, i] = log.times[q]
            work.breaks[1, i] = log.contacts[q]
            work.breaks[2, i] = n_tr + q
            for c in range(n2):
                work.break_states[i, c] = log.states[q, c]
            n_br += 1
    return n_br


@loop
def _classify(md, cst0, plan, linear, cycles, times, s0, work, result, i):
    """Run state ``i`` (``s0``) piece by piece until it is decided; its code in ``result``."""
    codes, matched, t_decided, steps_taken, final = result
    if not _start(md, cst0, plan, s0, work):
        return PYTHON
    m, g, chunks = plan.chunk, plan.piece, work.chunks
    t, h, steps = 0.0, min(1e-3, plan.h_max), 0
    base, n, count, n_tr, n_br, next_rule = 0, 0, 0, 0, 0, m
    while True:
        if plan.capacity - (n - base) < 2 * m + 2 and count:
            base = _keep_from(work.record, base, n, chunks[0, _window_start(chunks, count, plan.window)])
        target = max(n + g - 1, g)
        if count >= chunks.shape[1]:
            return PYTHON
        status, tau, h, idx, k = _advance(md, plan, times, base, n - base, t, h, target * plan.dt - t,
                                          plan.max_steps - steps, work)
        if k < 0 or n_tr + k > work.tr_times.size:
            return PYTHON
        n_br = _log_piece(work, k, n_tr, n_br, 2 * plan.n)
        chunks[0, count], chunks[1, count], chunks[2, count] = n, n_tr, base + idx - n
        count += 1
        n, n_tr = base + idx, n_tr + k
        t = t + tau
        steps += int(work.stats[0] + work.stats[1])
        rule_due = target >= next_rule
        if rule_due:
            next_rule = target + m
        code, cycle = _decide(plan, linear, cycles, work, times, (base, n, count, n_tr, n_br), status, t, target,
                              rule_due)
        if code == UNDECIDED and status == CHUNK_END:
            continue
        if code == UNDECIDED:
            return PYTHON
        codes[i], matched[i], t_decided[i], steps_taken[i] = code, cycle, t, steps
        last = work.record.states[n - 1 - base] if chunks[2, count - 1] else work.y
        for q in range(final.shape[1]):
            final[i, q] = last[q]
        return code


@loop
def classify_states(md, cst0, plan, linear, cycles, times, states, first, work, result):
    """Classify ``states[first:]`` in order until one needs the Python classifier.

    Parameters
    ----------
    md : ModelData
    cst0 : ndarray (CST nc,)
        A fresh contact state (:func:`stickslip.model.bundle.contact_state`).
    plan : Plan
    linear : tuple
        (equilibrium (2n,), free (2k,) int, P (2k, 2k), Φ (2k, 2k), rest) of the context.
    cycles : tuple
        The known cycles: multiplicities (c,) int, periods (c,), amplitudes (c,), maxima (c, KMAX),
        the contact of each one's breakaway state (c,) int (−1: none) and that state (c, 2n)
        (:func:`.recurrence.point_arrays`).
    times : ndarray (K,)
        The sample times of a run [s].
    states : ndarray (N, 2n)
        Initial states.
    first : int
        The first state to classify.
    work : Work
    result : tuple
        Written for each state classified: codes (N,) int (:data:`AT_REST`, :data:`LINEAR`,
        :data:`MATCHED`, :data:`RECURRED`), the cycle matched (N,) int, the time decided (N,) [s], the steps taken
        (N,) int, the state it ended in (N, 2n + 2).

    Returns
    -------
    int
        The index of the first state left to the Python classifier (N: none).
    """
    for i in range(first, states.shape[0]):
        if _classify(md, cst0, plan, linear, cycles, times, states[i], work, result, i) == PYTHON:
            return i
    return states.shape[0]
