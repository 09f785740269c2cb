"""A cold start compiles the event loop's callees in two processes (:mod:`stickslip.model.compile_ahead`).

Nearly every callee of the loop calls the friction forces of all contacts
(:func:`~stickslip.model.forces.general_forces`, and their stick and band part inside,
:func:`~stickslip.model.forces.band_forces`), a chain that would otherwise compile in both
processes. So :data:`EVENT_LOOP` has stages: first the helper compiles the band part while this
process compiles what calls no friction force (the kernels a run's results call after the loop,
each contact's slip velocity and normal force at the samples; the slip velocity's rate, the
error norm, the step's small helpers: the dense-output coefficients, the slip-event test); then
the helper compiles the friction forces of all contacts while this process compiles the
projection onto stick and the slip velocity; last, each loading the friction forces from the
cache, the helper compiles the stick solve's subtree (the entry into stick, the release of an
overloaded stick, the contact forces, the low-speed band's direction, the starting modes, a
breakaway, the crossings' probe) and this process the step's (the right-hand side, the
Dormand–Prince step, the samples, the cut of a step at an event). What neither side compiles,
the loop compiles alone, after both. The kernels are named by reference and their argument
types derived from the bundles a run builds (:func:`_loop_calls`). The run starts the helper
(:func:`start_callees`) before it checks that no contact is open at the start (a refused run
ends it); this process, done with its side, does the command's
:func:`~stickslip.model.compile_ahead.meanwhile` work while the helper finishes.

A model whose kinematics class fixes one contact takes :data:`ONE_CONTACT_LOOP`: its loop probes
that contact's breakaway as it probes the slip event
(:func:`~stickslip.integrate.transitions.breakaway_search`) and calls no
:func:`~stickslip.integrate.transitions.first_breakaway`, so its helper does not compile one. A
model with contacts that open and close takes :data:`OPENING_LOOP`: a rigid contact's normal
force calls the friction forces, so the normal forces at the samples move to the helper's last
stage, the switch of such a contact (:func:`~stickslip.integrate.transitions.switch_unilateral`,
which the loop would otherwise compile alone after both sides) to this process's, and a rigid
contact's impact, which calls no friction force, is compiled here beside the helper's friction
forces.
"""

from __future__ import annotations

import numpy as np

from ..analysis.modes import contact_index_dtype
from ..model import physics as P
from ..model.bundle import H_N, H_NC, H_UNILATERAL, contact_state
from ..model.forces import band_forces, general_forces
from ..model.impact import impact
from ..model.compile_ahead import ColdStart, Split, start_apart
from ..model.kinematics import allows_unilateral
from ..model.stack import one_contact
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
    G, A = np.zeros((2 * nc, n)), np.zeros((2 * nc, 2 * nc))
    return {band_forces: (y, cst, md, G, F, F, N, F, F, F, A),
            general_forces: (y, cst, md, G, F, F, N, F, F, F),
            P.project_velocities: (y, cst, i, md),
            P.slip_velocity: (y, i, md),
            E.try_stick: (y, cst, i, md, f, F, N),
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


#: The stages before the last: the friction forces' stick and band part in the helper and what
#: calls none of the friction forces here, then the forces of all contacts (``general_forces``,
#: which every other callee calls) in the helper.
_EARLY = (R._slip_velocities, P.slip_velocity_and_rate, L.error_norm, DP.dense_coefficients, E.slip_event_possible,
          E.time_to_zero_of, E.all_finite, L.homing_left)
_STAGES = (((band_forces,), _EARLY + (R._normal_forces,)), ((general_forces,), (P.project_velocities, P.slip_velocity)))
_HELPER = (E.try_stick, E.release_most_overloaded, P.contact_forces, P.band_direction, E.initial_modes, T.settle,
           T.break_away, T.first_breakaway, E.probed_crossing)
_OWN = (P.rhs, L.dp_step, L.write_samples, L.cut_step)

#: The event loop's callees: the stick solve's subtree in the helper, the step's here.
EVENT_LOOP = Split(helper=_HELPER, own=_OWN, caller=L.event_loop, calls=_loop_calls, stages=_STAGES)

#: :data:`EVENT_LOOP` for a model whose kinematics class fixes one contact
#: (:func:`~stickslip.model.stack.one_contact`): without the breakaway search of many contacts.
ONE_CONTACT_LOOP = Split(helper=tuple(k for k in _HELPER if k is not T.first_breakaway), own=_OWN,
                         caller=L.event_loop, calls=_one_contact_calls, stages=_STAGES)


def _opening_calls(md) -> dict:
    """:func:`_loop_calls` with :func:`~.transitions.switch_unilateral`, which the loop of a model
    of :data:`OPENING_LOOP` calls where a contact opens or closes."""
    calls = _loop_calls(md)
    y, cst, _, scratch, _, log, _, stats = calls[T.settle]  # the arrays the loop passes both
    i, f = np.int64(0), 0.0
    calls[T.switch_unilateral] = (y, cst, i, md, f, f, scratch, f, log, i, stats)
    calls[impact] = (y, cst, i, md, f)
    return calls


#: :data:`EVENT_LOOP` for a model with contacts that open and close, whose normal forces (of
#: rigid contacts) call the friction forces: these in the last stage, with the switch of a contact
#: (a rigid one's impact, which calls neither, compiled here beside the helper's friction forces).
OPENING_LOOP = Split(helper=_HELPER + (R._normal_forces,), own=_OWN + (T.switch_unilateral,), caller=L.event_loop,
                     calls=_opening_calls, stages=(((band_forces,), _EARLY + (P.project_velocities, P.slip_velocity)),
                                                   ((general_forces,), (impact,))))


def split_for(md) -> tuple[Split, str]:
    """The split of the event loop's callees for the model data ``md`` and its name in this module."""
    if one_contact(type(md.kin)):
        return ONE_CONTACT_LOOP, "ONE_CONTACT_LOOP"
    if md.m[H_UNILATERAL] != 0.0 and allows_unilateral(type(md.kin)):
        return OPENING_LOOP, "OPENING_LOOP"
    return EVENT_LOOP, "EVENT_LOOP"


def start_callees(md) -> ColdStart | None:
    """:func:`start_apart` of the event loop's callees (:func:`split_for`)."""
    split, name = split_for(md)
    return start_apart(md, split, f"{__name__}:{name}")
