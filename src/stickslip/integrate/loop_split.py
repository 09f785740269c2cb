"""A cold start compiles the event loop's callees in two processes (:mod:`stickslip.model.compile_ahead`).

:data:`EVENT_LOOP`: the stick solve's subtree (:func:`~stickslip.integrate.contacts.try_stick`,
the release of an overloaded stick, the contact forces, the low-speed band's direction and the
starting modes) in the helper, the step's (the right-hand side, the Dormand–Prince step, the
crossings' probe, the samples) here. The two subtrees share ``general_forces``, which both
compile: the split is as even as the loop's call tree allows, and the loop's own body compiles
after both. The helper also compiles the kernels that a run's results call after the loop (each
contact's slip velocity and normal force at the samples), the release of overloaded sticks after
a transition, a breakaway, the error norm and the slip velocity's rate; this process the cut of a
step at an event and the step's small helpers (the dense-output coefficients, the slip-event
test): what neither side compiles, the loop compiles alone, after both. The kernels are named by
reference and their argument types derived from the bundles a run builds
(:func:`_loop_calls`). The run starts the helper (:func:`start_callees`) before it checks that no
contact is open at the start (a refused run ends it); this process, done with its side, does the
command's :func:`~stickslip.model.compile_ahead.meanwhile` work while the helper finishes.

A model whose kinematics class fixes one contact takes :data:`ONE_CONTACT_LOOP`: its loop probes
that contact's breakaway as it probes the slip event
(:func:`~stickslip.integrate.transitions.breakaway_search`) and calls no
:func:`~stickslip.integrate.transitions.first_breakaway`, so its helper does not compile one. A model with contacts that open and close takes
:data:`OPENING_LOOP`: its helper also compiles the switch of such a contact
(:func:`~stickslip.integrate.transitions.switch_unilateral`, a rigid contact's impact and
landing inside it), which the loop would otherwise compile alone after both sides.
"""

from __future__ import annotations

import numpy as np

from ..analysis.modes import contact_index_dtype
from ..model import physics as P
from ..model.bundle import H_N, H_NC, H_UNILATERAL, contact_state
from ..model.compile_ahead import ColdStart, Split, start_apart
from ..model.kinematics import allows_unilateral
from . import contacts as E
from . import dormand_prince as DP
from . import event_loop as L
from . import result as R
from . import transitions as T
from .bundles import Samples, transition_log

__all__ = ["EVENT_LOOP", "ONE_CONTACT_LOOP", "OPENING_LOOP", "split_for", "start_callees"]


def _loop_calls(md) -> dict:
    """The arguments with which the event loop (and a run's results after it) call the kernels of
    :data:`EVENT_LOOP`, for the model data ``md``: the bundles :func:`.event_loop.integrate_event`
    and :class:`.runner.Record` build."""
    n, nc = int(md.m[H_N]), int(md.m[H_NC])
    ns = 2 * n + L.N_EXTRA
    cst = contact_state(md.m)
    start, step, slips, scratch, stats = L.loop_arrays(np.zeros(ns), nc)
    y, F, N = step.y, scratch.F, scratch.N
    modes = R.mode_array(1, nc, bool(md.m[H_UNILATERAL]))
    samples = Samples(np.zeros(1), np.zeros((1, ns)), modes, np.zeros((1, 2 * nc)))
    log = transition_log(1, ns, contact_index_dtype(nc))
    i, f = np.int64(0), 0.0
    return {E.try_stick: (y, cst, i, md, f, F, N),
            E.release_most_overloaded: (y, cst, md, F, N),
            P.contact_forces: (y, cst, md, F, N, scratch.v),
            P.band_direction: (y, cst, i, md, f),
            E.initial_modes: (y, cst, md, f, f, F, N),
            R._slip_velocities: (samples.states, md, i),
            R._normal_forces: (samples.states, np.zeros((1, nc), np.int8), md, i),
            T.settle: (y, cst, md, scratch, f, log, i, stats),
            T.break_away: (y, cst, i, md, scratch, f, log, i, stats),
            T.first_breakaway: (step, f, cst, md, scratch),
            P.slip_velocity_and_rate: (y, y, i, md),
            L.error_norm: (y, y, step.stages, f, md, f, f),
            P.rhs: (y, cst, md, y),
            L.dp_step: (y, y, f, cst, md, step.stages, y, y),
            E.probed_crossing: (f, i, i, y, step.dense, f, f, f, cst, md, scratch),
            L.write_samples: (i, f, f, f, f, y, step.dense, cst, md, samples, scratch),
            L.cut_step: (f, i, f, f, f, step, cst, md, samples, scratch),
            DP.dense_coefficients: (step.stages, step.dense),
            E.slip_event_possible: (f, f, f, f),
            E.time_to_zero_of: (f, f, f, f),
            E.all_finite: (y,),
            L.homing_left: (slips.homing,)}


def _one_contact_calls(md) -> dict:
    """:func:`_loop_calls` less :func:`~.transitions.first_breakaway`, which the loop of a model
    of :data:`ONE_CONTACT_LOOP` does not call."""
    calls = _loop_calls(md)
    del calls[T.first_breakaway]
    return calls


_HELPER = (E.try_stick, E.release_most_overloaded, P.contact_forces, P.band_direction, E.initial_modes,
           R._slip_velocities, R._normal_forces, T.settle, T.break_away, T.first_breakaway, P.slip_velocity_and_rate,
           L.error_norm)
_OWN = (P.rhs, L.dp_step, E.probed_crossing, L.write_samples, L.cut_step, DP.dense_coefficients,
        E.slip_event_possible, E.time_to_zero_of, E.all_finite, L.homing_left)

#: The event loop's callees: the stick solve's subtree in the helper, the step's here.
EVENT_LOOP = Split(helper=_HELPER, own=_OWN, caller=L.event_loop, calls=_loop_calls)

#: :data:`EVENT_LOOP` for a model whose kinematics class fixes one contact
#: (:func:`~.transitions.one_contact`): without the breakaway search of many contacts.
ONE_CONTACT_LOOP = Split(helper=tuple(k for k in _HELPER if k is not T.first_breakaway), own=_OWN,
                         caller=L.event_loop, calls=_one_contact_calls)


def _opening_calls(md) -> dict:
    """:func:`_loop_calls` with :func:`~.transitions.switch_unilateral`, which the loop of a model
    of :data:`OPENING_LOOP` calls where a contact opens or closes."""
    calls = _loop_calls(md)
    y, cst, _, scratch, _, log, _, stats = calls[T.settle]  # the arrays the loop passes both
    i, f = np.int64(0), 0.0
    calls[T.switch_unilateral] = (y, cst, i, md, f, f, scratch, f, log, i, stats)
    return calls


#: :data:`EVENT_LOOP` for a model with contacts that open and close: the switch of a contact
#: (with a rigid one's impact and landing, each compiled once) in the helper too, where the loop
#: would compile it after both sides.
OPENING_LOOP = Split(helper=_HELPER + (T.switch_unilateral,), own=_OWN, caller=L.event_loop, calls=_opening_calls)


def split_for(md) -> tuple[Split, str]:
    """The split of the event loop's callees for the model data ``md`` and its name in this module."""
    if T.one_contact(type(md.kin)):
        return ONE_CONTACT_LOOP, "ONE_CONTACT_LOOP"
    if md.m[H_UNILATERAL] != 0.0 and allows_unilateral(type(md.kin)):
        return OPENING_LOOP, "OPENING_LOOP"
    return EVENT_LOOP, "EVENT_LOOP"


def start_callees(md) -> ColdStart | None:
    """:func:`start_apart` of the event loop's callees (:func:`split_for`)."""
    split, name = split_for(md)
    return start_apart(md, split, f"{__name__}:{name}")
