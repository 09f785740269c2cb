"""Recurrence at breakaways: a run repeats when the state at a breakaway (stick → slip) recurs.

A contact that sticks holds its slip velocity at 0, so the runs that reach a stick-slip cycle pass
through the cycle's own breakaway state (the belt's to the last bit). The early-stopping
classifier (:mod:`.early`, test 3) decides a run onto a known cycle when its latest breakaway
recurs: on the breakaway state of the cycle itself (:func:`cycle_point`: found once per cycle by a
short run from the cycle's state, and kept only where it provably repeats with the cycle's
period and features), or on an earlier breakaway of the run one period back whose period matches
the cycle (:func:`.cycles.period_matches`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..analysis.peaks import find_peaks
from ..integrate.contacts import TRANSITION_TO_SLIP
from ..integrate.result import Transitions
from ..integrate.runner import EventStepper, Record, ToTheEnd, run_chunks
from ..integrate.status import SUCCESS
from .cycles import Cycle, Section, period_matches, section_of

__all__ = ["RECURRENCE_FACTOR", "POINT_PERIODS", "Point", "recurs", "recurrence_tolerance", "earlier_recurrence",
           "period_cycle", "cycle_point", "point_arrays"]

#: The state at a breakaway recurs when each of its 2n components is within this many times the
#: integration tolerance (atol + rtol |s_i|) of the other's (the belt's breakaway states on its
#: cycle agree to the last bit; a run still converging onto a cycle differs by far more).
RECURRENCE_FACTOR = 100.0

#: Periods of the run from a cycle's state that looks for the cycle's breakaway state.
POINT_PERIODS = 3

#: The cycles' points found in this process (a few per study).
_POINTS: dict = {}


class Point(NamedTuple):
    """A state on a cycle at a breakaway of ``contact`` (its 2n entries)."""

    contact: int
    state: np.ndarray


def recurrence_tolerance(s1: np.ndarray, s2: np.ndarray, atol: float, rtol: float) -> np.ndarray:
    """Per component, how far the states at two breakaways may differ and still recur."""
    return RECURRENCE_FACTOR * (atol + rtol * np.maximum(np.abs(s1), np.abs(s2)))


def recurs(s1: np.ndarray, s2: np.ndarray, atol: float, rtol: float) -> bool:
    """Whether the states s1, s2 (2n,) at two breakaways recur (:func:`recurrence_tolerance`)."""
    return bool(np.all(np.abs(s2 - s1) <= recurrence_tolerance(s1, s2, atol, rtol)))


def earlier_recurrence(tr: Transitions, n2: int, atol: float, rtol: float) -> tuple[int, int] | None:
    """(i, last): the latest breakaway of ``tr`` and the latest earlier one of the same contact
    whose state it recurs on; None where there is none."""
    slips = np.flatnonzero(tr.kind == TRANSITION_TO_SLIP)
    if slips.size < 2:
        return None
    last = slips[-1]
    s2 = tr.state[last, :n2]
    for i in slips[-2::-1]:
        if tr.contact[i] == tr.contact[last] and recurs(tr.state[i, :n2], s2, atol, rtol):
            return int(i), int(last)
    return None


def period_cycle(cycles, t1: float, t2: float, t: np.ndarray, x: np.ndarray, dx: np.ndarray, section: Section,
                 rtol: float) -> int:
    """Index of the first of ``cycles`` that the period (t1, t2] of a run that recurs matches
    (:func:`.cycles.period_matches`; the samples t, x, dx and their ``section``), −1 for none."""
    inside = (section.times > t1) & (section.times <= t2)
    low = find_peaks(t, -x, -dx)
    minima = -low.value[(low.time > t1) & (low.time <= t2)]
    for c, cycle in enumerate(cycles):
        if period_matches(cycle, float(t2 - t1), section.maxima[inside], minima, rtol):
            return c
    return -1


def _find_point(ctx, model, cycle: Cycle, opts) -> Point | None:
    """The run of :data:`POINT_PERIODS` periods from the cycle's state: its latest breakaway, where
    it recurs on an earlier one whose period matches ``cycle``."""
    n, n2, j = model.n, 2 * model.n, model.observed_index
    t_end = POINT_PERIODS * cycle.period
    stepper = EventStepper(model, cycle.state, 0.0, t_end, rtol=opts.rtol, atol=opts.atol, h_max=ctx.chunk * ctx.dt,
                           max_steps=opts.max_steps)
    if stepper.open_contact >= 0:
        return None
    record = Record(model, np.arange(int(math.floor(t_end / ctx.dt)) + 2) * ctx.dt)
    status, _, _ = run_chunks(stepper, record, ToTheEnd(), interrupt=False)
    tr = record.transitions()
    found = earlier_recurrence(tr, n2, opts.atol, opts.rtol) if status == SUCCESS else None
    if found is None:
        return None
    i, last = found
    t, s, _, _ = record.samples()
    x, dx = s[:, j], s[:, n + j]
    if period_cycle([cycle], tr.time[i], tr.time[last], t, x, dx, section_of(t, x, dx), opts.match_rtol) != 0:
        return None
    return Point(int(tr.contact[last]), tr.state[last, :n2].copy())


def cycle_point(ctx, model, cycle: Cycle, opts) -> Point | None:
    """The breakaway state of ``cycle`` (None where the run from its state does not provably
    repeat with its period and features: a cycle without stick, or one not reached to the
    recurrence tolerance), found once per process."""
    key = (ctx.key, float(opts.rtol), float(opts.atol), float(opts.match_rtol), int(opts.max_steps), cycle.multiplicity,
           cycle.period, cycle.amplitude, cycle.state.tobytes())
    if key not in _POINTS:
        if len(_POINTS) >= 256:
            _POINTS.clear()
        _POINTS[key] = _find_point(ctx, model, cycle, opts)
    return _POINTS[key]


def point_arrays(ctx, model, cycles, opts) -> tuple[np.ndarray, np.ndarray]:
    """The cycles' points as arrays for compiled code: contacts (c,) int (−1: none), states (c, 2n)."""
    contacts = np.full(len(cycles), -1, dtype=np.int64)
    states = np.zeros((len(cycles), 2 * model.n))
    for c, cycle in enumerate(cycles):
        p = cycle_point(ctx, model, cycle, opts)
        if p is not None:
            contacts[c], states[c] = p.contact, p.state
    return contacts, states
