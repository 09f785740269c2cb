"""The transitions the event loop applies between its steps: events inside a step, the openings,
closings and impacts of unilateral contacts, the re-check of the sticking set, and their records.

Split from :mod:`stickslip.integrate.event_loop` (the loop itself) by responsibility: what happens
at a located event, not how steps are taken.
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import overload

from ..model import physics as P
from ..model.bundle import CST
from ..model.jit import KERNEL_OPTIONS, inlined_kernel, kernel, standalone
from ..model.kinematics import has_unilateral, model_sizes, rigid_kernel, unilateral_kernel
from ..model.normal import is_unilateral
from ..model.stack import kinematics_class, one_contact
from . import contacts as E
from . import dormand_prince as DP
from .status import INCONSISTENT, SUCCESS

__all__ = ["crossing_in_step", "record_transition", "settle", "break_away", "switch_gap", "jammed_contact",
           "gap_crossing", "breakaway_search", "first_breakaway"]


@inlined_kernel
def crossing_in_step(kind, c, step, q_ready, h, cst, md, scratch):
    """θ ∈ (0, 1] of the first crossing of event ``kind`` of contact ``c`` inside the step ``step``
    (a :class:`~.dormand_prince.Step` of length ``h``) whose end is past it (1.0 where the sample
    points see no sign change: the root is at the end); forms the step's dense-output
    coefficients first unless ``q_ready``."""
    if not q_ready:
        DP.dense_coefficients(step.stages, step.dense)
    th = E.first_crossing(kind, c, step.y, step.dense, h, 0.0, 0.0, cst, md, scratch)
    return 1.0 if th <= 0.0 else th


@standalone
@kernel
def record_transition(log, n_tr, t, kind, contact, y):
    """Write transition ``n_tr`` (time [s], kind, contact, state) into the :class:`~.bundles.TransitionLog`
    ``log`` if it has room; the caller counts on and runs again with room for all (buffers that
    grew inside the loop would be loop-carried arrays, which numba reference-counts on every
    iteration)."""
    if n_tr < log.times.shape[0]:
        log.times[n_tr] = t
        log.kinds[n_tr] = kind
        log.contacts[n_tr] = contact
        states = log.states
        for i in range(states.shape[1]):
            states[n_tr, i] = y[i]


@standalone
@kernel
def settle(y, cst, md, scratch, t, log, n_tr, stats):
    """Release sticking contacts whose joint stick force exceeds the static limit (the most
    overloaded first) and record their breakaways at time ``t`` in ``log``; returns the
    transition count."""
    for _ in range(max(E.MAX_SETTLE, cst.shape[0] // CST)):
        c = E.release_most_overloaded(y, cst, md, scratch.F, scratch.N)
        if c < 0:
            break
        record_transition(log, n_tr, t, E.TRANSITION_TO_SLIP, c, y)
        n_tr += 1
        stats[5] += 1
    return n_tr


@standalone
@kernel
def break_away(y, cst, c, md, scratch, t, log, n_tr, stats):
    """Sticking contact ``c`` breaks away at ``y`` (time ``t``, the root of its stick margin): the
    velocities are projected onto the stick constraints, ``c`` slips quasi-statically along its
    stick force's direction, and the breakaway and any release it causes (:func:`settle`) are
    recorded; returns the transition count. A kernel of its own (a rare branch of the loop), so
    that a cold start compiles it beside the loop instead of inside it."""
    m = md.m
    n = model_sizes(md.kin, m)[0]
    F = scratch.F
    P.project_velocities(y, cst, np.int64(-1), md)
    P.stick_forces(y, cst, np.int64(-1), md, F, scratch.N)
    ex, ey = E.breakaway_direction(F[2 * c], F[2 * c + 1], P.contact_dim(md.kin, m, n, c))
    cst[CST * c] = P.MODE_SLIP_QUASI_STATIC
    cst[CST * c + 1] = ex
    cst[CST * c + 2] = ey
    cst[CST * c + 3] = math.inf
    stats[5] += 1
    record_transition(log, n_tr, t, E.TRANSITION_TO_SLIP, c, y)
    return settle(y, cst, md, scratch, t, log, n_tr + 1, stats)


@unilateral_kernel(lambda y, cst, c, md, rtol, atol, scratch, t, log, n_tr, stats: (n_tr, SUCCESS, math.inf),
                   inline="always")
def switch_gap(y, cst, c, md, rtol, atol, scratch, t, log, n_tr, stats):  # pragma: no cover
    """:func:`switch_unilateral` for kinematics that may have unilateral contacts (nothing for the
    others, whose kernels then compile none of it)."""
    return switch_unilateral(y, cst, c, md, rtol, atol, scratch, t, log, n_tr, stats)


@standalone
@kernel
def switch_unilateral(y, cst, c, md, rtol, atol, scratch, t, log, n_tr, stats):
    """Unilateral contact ``c`` opens (if closed) or closes (if open) at state ``y``, time ``t``:
    change its mode, record the transitions in ``log`` (a sticking contact that opens first leaves
    stick; a contact that closes with v_c = 0 and an admissible stick force sticks; a rigid one
    closes with an impact, recorded with the state before it, then ``open`` where it bounces off
    or ``close`` where it stays, with the state after it), re-check the sticking set.

    Returns (transition count, status, flight): status SUCCESS, or INCONSISTENT where a rigid
    contact's impact has no consistent impulse; flight the predicted time [s] to a bounced
    contact's next landing (∞ otherwise), which bounds the next step. A standalone kernel: the
    event loop calls its one compiled copy instead of optimising it again in its own module."""
    flight = math.inf
    if P.is_open(cst, c) and P.rigid(c, md):
        record_transition(log, n_tr, t, E.TRANSITION_IMPACT, c, y)
        n_tr += 1
        phase, sticks, impulse, before, after, flight = E.land(y, cst, c, md, rtol, atol, scratch.F, scratch.N,
                                                               scratch.state)
        if phase == E.LAND_INCONSISTENT:
            return n_tr, INCONSISTENT, flight
        kind = E.TRANSITION_OPEN if phase == E.LAND_OPEN else E.TRANSITION_CLOSE
        record_transition(log, n_tr, t, kind, c, y)
        n_tr += 1
        if sticks:
            stats[4] += 1
            record_transition(log, n_tr, t, E.TRANSITION_TO_STICK, c, y)
            n_tr += 1
    elif P.is_open(cst, c):
        record_transition(log, n_tr, t, E.TRANSITION_CLOSE, c, y)
        n_tr += 1
        if E.close_contact(y, cst, c, md, rtol, atol, scratch.F, scratch.N):
            stats[4] += 1
            record_transition(log, n_tr, t, E.TRANSITION_TO_STICK, c, y)
            n_tr += 1
    else:
        if np.int64(cst[CST * c]) == P.MODE_STICK:
            stats[5] += 1
            record_transition(log, n_tr, t, E.TRANSITION_TO_SLIP, c, y)
            n_tr += 1
        cst[CST * c] = P.MODE_OPEN
        cst[CST * c + 3] = math.inf
        record_transition(log, n_tr, t, E.TRANSITION_OPEN, c, y)
        n_tr += 1
    P.project_velocities(y, cst, np.int64(-1), md)  # the sticking set's constraints, after the change
    n_tr = settle(y, cst, md, scratch, t, log, n_tr, stats)
    return n_tr, SUCCESS, flight


@rigid_kernel(lambda y, cst, md: np.int64(-1))
def jammed_contact(y, cst, md):  # pragma: no cover - compiled only
    """A closed rigid contact whose normal force has no consistent solution at ``y`` (Painlevé:
    the relative pivot of its normal-force system is not positive), or −1."""
    m = md.m
    n, nc, _ = model_sizes(md.kin, m)
    if P.rigid_pivot(y, cst, md) > 0.0:
        return np.int64(-1)
    for c in range(nc):
        if P.rigid(c, md) and not P.is_open(cst, c):
            return np.int64(c)
    return np.int64(-1)


def breakaway_search(step, h, cst, md, scratch):  # pragma: no cover - resolved by numba (overload below)
    """(θ, contact) of the first breakaway of a sticking contact inside the step ``step`` (a
    :class:`~.dormand_prince.Step` of length ``h`` with its dense-output coefficients formed);
    θ = −1.0 and contact −1 for none.

    Chosen at compile time by the model's kinematics class: where it fixes the contact count at one
    (:func:`~stickslip.model.stack.one_contact`), that contact's stick margin is probed as the
    loop probes the slip event (:func:`~.contacts.first_crossing`, compiled for it anyway), so such
    a model compiles no more for its breakaways; else :func:`first_breakaway`, which samples the
    margins of all sticking contacts from one solve of the forces per point. Both find the same
    root for one contact.
    """
    raise NotImplementedError("breakaway_search is called from compiled code only")


@overload(breakaway_search, jit_options=KERNEL_OPTIONS, inline="always")
def _breakaway_search(step, h, cst, md, scratch):
    if not one_contact(kinematics_class(md)):
        return lambda step, h, cst, md, scratch: first_breakaway(step, h, cst, md, scratch)

    def alone(step, h, cst, md, scratch):
        c = np.int64(0)
        if np.int64(cst[0]) == P.MODE_STICK:
            th = E.first_crossing(E.EVENT_STICK, c, step.y, step.dense, h, 0.0, 0.0, cst, md, scratch)
            if th > 0.0:
                return th, c
        return -1.0, np.int64(-1)
    return alone


@standalone
@kernel
def first_breakaway(step, h, cst, md, scratch):
    """(θ, contact) of the first breakaway of a sticking contact inside the step ``step`` (a
    :class:`~.dormand_prince.Step` of length ``h`` with its dense-output coefficients formed);
    θ = −1.0 and contact −1 for none.

    The stick margins of all sticking contacts are sampled together at the EVENT_CHECKS points of
    :func:`~.contacts.first_crossing`, one solve of the forces per point
    (:func:`~stickslip.model.physics.stick_margins`), up to the first point where one is ≤ 0;
    only the contacts whose margin turned there are refined, each as ``first_crossing`` refines
    it. A contact whose margin turns at a later point has its root past that point, so the first
    root among them is the first of all, and each root is the one ``first_crossing`` finds: the
    same values, without one solve of every contact's forces per contact and point.
    """
    nc = np.int64(model_sizes(md.kin, md.m)[1])  # not a literal: one compiled version of stick_margins
    g = scratch.g  # g[c]: the margins at the point sampled last, g[nc + c]: at the one before
    a = 0.0
    b = -1.0
    for j in range(1, E.EVENT_CHECKS + 1):
        theta = j / E.EVENT_CHECKS
        E.dense_state(step.y, step.dense, h, theta, scratch.state)
        P.stick_margins(scratch.state, cst, md, g, np.int64(0))
        if _any_margin_spent(cst, g, nc):
            b = theta
            break
        a = theta
        for c in range(nc):
            g[nc + c] = g[c]
    if b < 0.0:
        return -1.0, np.int64(-1)
    if a == 0.0:
        P.stick_margins(step.y, cst, md, g, nc)
    theta_b = -1.0
    c_b = np.int64(-1)
    for c in range(nc):
        if np.int64(cst[CST * c]) == P.MODE_STICK and g[c] <= 0.0:
            bracket = (a, g[nc + c], b, g[c])
            th = E.refined_crossing(np.int64(E.EVENT_STICK), c, step.y, step.dense, h, bracket, 0.0, 0.0, cst, md,
                                    scratch)
            if th > 0.0 and (theta_b < 0.0 or th < theta_b):
                theta_b = th
                c_b = c
    return theta_b, c_b


@kernel
def _any_margin_spent(cst, g, nc):
    """Whether some sticking contact's stick margin g[c] is ≤ 0."""
    for c in range(nc):
        if np.int64(cst[CST * c]) == P.MODE_STICK and g[c] <= 0.0:
            return True
    return False


@unilateral_kernel(lambda step, q_ready, h, cst, md, scratch: (-1.0, np.int64(-1), q_ready), inline="always")
def gap_crossing(step, q_ready, h, cst, md, scratch):  # pragma: no cover
    """(θ, contact, q_ready) of the first opening or closing of a unilateral contact inside the step
    ``step`` (a :class:`~.dormand_prince.Step` of length ``h``), θ = −1.0 and contact −1 for none.
    Besides a contact whose indicator has turned at the step's end, a flight (or a touch) that
    begins and ends inside the step is found where the step's Hermite interpolant of the gap dips
    and the dense output there confirms it. Nothing for pressed-only kinematics, whose kernels then
    compile none of it."""
    theta_g = -1.0
    c_g = np.int64(-1)
    n, nc, _ = model_sizes(md.kin, md.m)
    if not has_unilateral(md.kin, md.m):
        return theta_g, c_g, q_ready
    for c in range(nc):
        if not is_unilateral(md, n, c):
            continue
        if E.leaves_state(step.ynew, cst, c, md):
            th = crossing_in_step(E.EVENT_GAP, c, step, q_ready, h, cst, md, scratch)
        else:
            probe = E.gap_dip(step.y, step.k1, step.ynew, step.stages[6], h, cst, c, md)
            if probe < 0.0:
                continue
            if not q_ready:
                DP.dense_coefficients(step.stages, step.dense)
            th = E.probed_crossing(probe, E.EVENT_GAP, c, step.y, step.dense, h, 0.0, 0.0, cst, md, scratch)
        q_ready = True
        if th > 0.0 and (theta_g < 0.0 or th < theta_g):
            theta_g = th
            c_g = np.int64(c)
    return theta_g, c_g, q_ready
