"""The event loop's slipping contacts between steps: departures from v = 0, approaches to it, stick.

The steps of :func:`stickslip.integrate.event_loop.event_loop` that concern a slipping contact,
each inlined into the loop (one call site each):

:func:`slip_roots`
    After a step is taken: each slipping contact's slip velocity and its rate at the step's end;
    a quasi-static departure that overshoots the low-speed band (the step is re-taken shorter);
    the first slip → stick root of an approach inside the step (the step is re-taken to end there).
:func:`arrivals`
    After a step is accepted: drift removed from the sticking contacts; each slipping contact's
    direction; a departure that leaves the band (or turns back inside it) continues with the exact
    direction; an approach whose extrapolated zero lies within the next step is homed onto it; one
    that has arrived sticks, or reverses.

What the loop keeps of each contact between steps is a :class:`SlipWatch`; its scalar state (step
size, re-takes, the step size before a homing episode) is the loop's progress record
(:data:`stickslip.integrate.event_loop.PROGRESS`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba.extending import overload

from ..model import physics as P
from ..model.bundle import CST, H_BAND
from ..model.jit import KERNEL_OPTIONS, inlined_kernel
from ..model.kinematics import model_sizes
from ..model.stack import on_heap
from . import contacts as E
from . import dormand_prince as DP
from .transitions import record_transition, settle

__all__ = ["SlipWatch", "slip_watch", "slip_roots", "arrivals", "shared_steps", "MAX_RETAKES", "DEPARTURE_OVERSHOOT",
           "MAX_HOMING_STEP", "HOMING_SHORTFALL"]

MAX_RETAKES = 30    # re-takes of one step while homing in on a slip → stick root
DEPARTURE_OVERSHOOT = 2.0  # a departure step may end at most this many low-speed bands above v = 0
#: [s] longest extrapolated step onto v = 0: a small fraction of any mechanical period of interest
#: (the plates' shortest natural period is 0.36 s).
MAX_HOMING_STEP = 1e-3
#: Fraction of the extrapolated time to v = 0 that a homing step of a 1-D contact leaves out. The
#: extrapolation with the acceleration at the step start is second-order accurate but, with a
#: falling friction law, |dv/dt| grows towards v = 0 and a full step overshoots; a step past the
#: zero of a 1-D slip velocity meets the sign change of the friction force and is rejected (seen
#: as 30 rejections in a row on one approach of the popp-stelter model, ending 7.6e-7 s early).
HOMING_SHORTFALL = 1e-2


class SlipWatch(NamedTuple):
    """What the event loop keeps of each contact's slip between steps.

    Attributes
    ----------
    start : ndarray (4 nc,)
        v_x, v_y [m/s], a_x, a_y [m/s²] of each contact at the step's start (the slip velocity and
        its rate; valid while the progress record's ``slips_ready``).
    end : ndarray (4 nc,)
        The same at the step's end.
    homing : ndarray (nc,) int64
        Consecutive steps homed onto each contact's v = 0.
    """

    start: np.ndarray
    end: np.ndarray
    homing: np.ndarray


def slip_watch(nc: int) -> SlipWatch:
    """A :class:`SlipWatch` for ``nc`` contacts, none homing."""
    return SlipWatch(np.empty(4 * nc), np.empty(4 * nc), np.zeros(nc, dtype=np.int64))


def shared_steps(kin, nc):  # pragma: no cover - resolved by numba (overload below)
    """Whether the steps of a model of ``nc`` contacts and kinematics data ``kin`` are shared by
    many contacts: a large model's (the heap flavour, :func:`~stickslip.model.stack.on_heap`:
    a reduced finite-element model) of more than one contact, in which some contact is nearly
    always on its way to v = 0 and a right-hand side costs O(nnz). Such a model's approaches
    (:func:`approach`) and stick projections (:func:`drifted`) follow the rules of many contacts;
    every other model keeps those of a few (decided at compile time by the class of ``kin``)."""
    raise NotImplementedError


@overload(shared_steps, jit_options=KERNEL_OPTIONS, inline="always")
def _shared_steps(kin, nc):
    if on_heap(getattr(kin, "instance_class", None)):
        return lambda kin, nc: nc > 1
    return lambda kin, nc: False


@inlined_kernel
def approach_root(c, h, step, slips, cst, md, scratch, q_ready):
    """(θ, q_ready): the first zero inside the step (length ``h``) of contact ``c``'s slip velocity
    projected on its direction at the step's start (−1.0: none), where the cubic through the
    values and rates at both ends may reach it (:func:`~.contacts.slip_event_possible`); the
    step's dense-output coefficients are formed first unless ``q_ready``."""
    start = slips.start
    end = slips.end
    v0x = start[4 * c]
    v0y = start[4 * c + 1]
    speed0 = math.sqrt(v0x * v0x + v0y * v0y)
    e0x = v0x / speed0
    e0y = v0y / speed0
    v1x = end[4 * c]
    v1y = end[4 * c + 1]
    a1x = end[4 * c + 2]
    a1y = end[4 * c + 3]
    if not E.slip_event_possible(speed0, h * (start[4 * c + 2] * e0x + start[4 * c + 3] * e0y),
                                 v1x * e0x + v1y * e0y, h * (a1x * e0x + a1y * e0y)):
        return -1.0, q_ready
    if not q_ready:
        DP.dense_coefficients(step.stages, step.dense)
        q_ready = True
    return E.first_crossing(E.EVENT_SLIP, c, step.y, step.dense, h, e0x, e0y, cst, md, scratch), q_ready


@inlined_kernel
def slip_roots(progress, step, slips, cst, md, scratch, q_ready):
    """The slipping contacts over the step just taken (``step``, of length ``progress.h``).

    Writes each one's slip velocity and rate at the step's end into ``slips.end``; finds a
    quasi-static departure that ends more than :data:`DEPARTURE_OVERSHOOT` low-speed bands above
    v = 0 (the quasi-static direction is an O(|v|) approximation: leave it near the band's edge,
    not far above it; |v| grows like t² after breakaway), and the first slip → stick root of an
    approach with the exact direction (while departing from v = 0 there is nothing to detect).

    Returns (shrink, theta_slip, any_stick, q_ready): the factor to re-take the step with for a
    departure (−1.0: none), θ of the first root (−1.0: none), whether some contact sticks, and
    whether the step's dense-output coefficients are formed.
    """
    m = md.m
    nc = model_sizes(md.kin, m)[1]
    band = m[H_BAND]
    h = progress.h
    end = slips.end
    shrink = -1.0
    theta_slip = -1.0
    any_stick = False
    for c in range(nc):
        mode = np.int64(cst[CST * c])
        if mode == P.MODE_STICK:
            any_stick = True
            continue
        if mode == P.MODE_OPEN:
            continue
        v1x, v1y, a1x, a1y = P.slip_velocity_and_rate(step.ynew, step.stages[6], c, md)
        end[4 * c] = v1x
        end[4 * c + 1] = v1y
        end[4 * c + 2] = a1x
        end[4 * c + 3] = a1y
        if mode == P.MODE_SLIP_QUASI_STATIC and progress.retakes < MAX_RETAKES:
            speed1 = math.sqrt(v1x * v1x + v1y * v1y)
            if speed1 > DEPARTURE_OVERSHOOT * band:
                f_c = max(DP.MIN_FACTOR, math.sqrt(band / speed1))
                shrink = f_c if shrink < 0.0 else min(shrink, f_c)
        if mode == P.MODE_SLIP_EXACT:
            if not progress.slips_ready:  # the values at the step's start (sticking contacts left out)
                start = slips.start
                for c2 in range(nc):
                    if np.int64(cst[CST * c2]) != P.MODE_STICK:
                        vx, vy, ax, ay = P.slip_velocity_and_rate(step.y, step.k1, c2, md)
                        start[4 * c2] = vx
                        start[4 * c2 + 1] = vy
                        start[4 * c2 + 2] = ax
                        start[4 * c2 + 3] = ay
                progress.slips_ready = True
            th, q_ready = approach_root(c, h, step, slips, cst, md, scratch, q_ready)
            if th > 0.0 and (theta_slip < 0.0 or th < theta_slip):
                theta_slip = th
    return shrink, theta_slip, any_stick, q_ready


@inlined_kernel
def approach(progress, c, mode, slips, theta_slip, v_arrive, cst, md):
    """Contact ``c`` slipping (``mode``) at the step's end: how it approaches v = 0.

    On an approach to stick the local error of the stiff direction dynamics is a function of h/τ
    (τ the extrapolated time to v = 0; self-similar), so the ratio is controlled, not h: the next
    step is the same fraction of the time left (``progress.factor``; no accept/reject ping-pong).
    Where v heads for zero within the next step (or a re-take landed short of it), the next step
    is the extrapolated time instead of letting the stiff direction dynamics near v = 0 shrink the
    steps geometrically (``progress.h_override``; a 1-D contact's a little short of it, as its
    slip velocity changes sign at zero and so does its force: a step past the zero is rejected).

    In a model whose steps many contacts share (:func:`shared_steps`: 40 contact nodes of a
    finite-element pad), some contact is nearly always on its way to v = 0: there the ratio is
    controlled for 2-D contacts only (a 1-D contact has no direction dynamics; its zero is found
    on the step's dense output, :func:`slip_roots`), and a contact homes only onto a zero that
    lies within the error controller's next step, never with a longer step. A longer homing step
    was rejected by the error control, shrunk, accepted and lengthened again onto the same zero,
    step after step (on such a pad 206 of its 219 rejections in 0.05 of a period; 14 without).
    Other models keep the rules above.

    Returns (homes, near): whether the next step homes onto its zero, and whether it has arrived
    (a located root, homing, or |v| at the error control's resolution ``v_arrive`` and falling;
    right after a departure |v| may still be below that resolution, but grows).
    """
    end = slips.end
    homing = slips.homing
    v1x = end[4 * c]
    v1y = end[4 * c + 1]
    a1x = end[4 * c + 2]
    a1y = end[4 * c + 3]
    speed = math.sqrt(v1x * v1x + v1y * v1y)
    near = (theta_slip > 0.0 or progress.retakes > 0 or homing[c] > 0
            or (speed <= v_arrive and v1x * a1x + v1y * a1y < 0.0))
    n, nc, _ = model_sizes(md.kin, md.m)
    dim = P.contact_dim(md.kin, md.m, n, c)
    shared = shared_steps(md.kin, nc)
    tau_c = E.time_to_zero_of(v1x, v1y, a1x, a1y)
    tau_start = cst[CST * c + 3]
    if tau_start < math.inf and tau_c < math.inf and (dim == 2 or not shared):
        progress.factor = min(progress.factor, progress.factor * tau_c / tau_start)
    cst[CST * c + 3] = tau_c if mode == P.MODE_SLIP_EXACT else math.inf
    if (theta_slip <= 0.0 and E.ARRIVAL_TIME_TOL < tau_c < MAX_HOMING_STEP and homing[c] < MAX_RETAKES
            and ((near and not shared) or tau_c < progress.h * progress.factor)):
        if progress.retakes == 0 and homing[c] == 0 and progress.h_free < 0.0:
            progress.h_free = progress.h
        if dim == 1:
            tau_c *= 1.0 - HOMING_SHORTFALL
        progress.h_override = tau_c if progress.h_override < 0.0 else min(progress.h_override, tau_c)
        homing[c] += 1
        return True, near
    return False, near


@inlined_kernel
def arrive(progress, c, t, y, cst, md, v_arrive, scratch, log, stats):
    """Contact ``c`` has arrived at v = 0 (to ``v_arrive``) at time ``t``: it sticks where the stick
    force is admissible (the transition recorded, the sticking set re-checked), or slip departs
    again along the inadmissible force's breakaway direction (a reversal). Returns whether its
    mode changed."""
    stick, nex, ney = E.try_stick(y, cst, c, md, v_arrive, scratch.F, scratch.N)
    if stick:
        cst[CST * c] = P.MODE_STICK
        cst[CST * c + 3] = math.inf
        stats[4] += 1
        record_transition(log, progress.n_tr, t, E.TRANSITION_TO_STICK, c, y)
        progress.n_tr = settle(y, cst, md, scratch, t, log, progress.n_tr + 1, stats)
        return True
    if nex != 0.0 or ney != 0.0:
        cst[CST * c] = P.MODE_SLIP_QUASI_STATIC
        cst[CST * c + 1] = nex
        cst[CST * c + 2] = ney
        cst[CST * c + 3] = math.inf
        return True
    return False


@inlined_kernel
def drifted(y, cst, md, nc, rtol, atol):
    """Whether the velocities at ``y`` are projected onto the sticking contacts' constraints after
    a step: always, except in a model whose steps many contacts share (:func:`shared_steps`): there
    where some sticking contact's |v| exceeds the error control's velocity resolution atol + rtol
    max|q̇_i| (the projection costs about a right-hand side, and the derivative again another).
    The stick forces hold dv/dt = 0, so a sticking contact's v changes only by the steps' errors,
    and is removed as soon as it exceeds what the integration resolves."""
    if not shared_steps(md.kin, nc):
        return True
    n = model_sizes(md.kin, md.m)[0]
    qd = 0.0
    for i in range(n, 2 * n):
        qd = max(qd, abs(y[i]))
    tol = atol + rtol * qd
    for c in range(nc):
        if np.int64(cst[CST * c]) == P.MODE_STICK:
            vx, vy = P.slip_velocity(y, c, md)
            if vx * vx + vy * vy > tol * tol:
                return True
    return False


@inlined_kernel
def arrivals(progress, controls, step, slips, cst, md, scratch, log, theta_slip, any_stick, stats):
    """The contacts after an accepted step (``step.y``, local time ``progress.tau``).

    The velocities are projected onto the sticking contacts' constraints (``any_stick``: drift
    removed, :func:`drifted`); each slipping contact gets its slip direction there; a
    quasi-static one that has departed (|v| above the low-speed band) or whose |v| falls again inside the band (an
    approach, which may end in stick or a reversal) is watched with the exact direction from the
    next step on (the force law changes between steps, never inside one); the others
    :func:`approach` v = 0 and :func:`arrive`. Then the derivative again where a mode changed or
    the velocities were projected, and the error controller's step resumed after a homing
    episode (the homing steps were short by construction, not by the error estimate).
    ``theta_slip``: the step ended at a located root.
    """
    m = md.m
    n, nc, _ = model_sizes(md.kin, m)
    y = step.y
    end = slips.end
    band = m[H_BAND]
    changed = any_stick and drifted(y, cst, md, nc, controls.rtol, controls.atol)
    if changed:
        P.project_velocities(y, cst, np.int64(-1), md)
    v_arrive = E.arrival_speed(y, n, controls.rtol, controls.atol)
    t = controls.t_base + progress.tau
    homing = False
    for c in range(nc):
        mode = np.int64(cst[CST * c])
        if mode == P.MODE_STICK or mode == P.MODE_OPEN:
            continue
        v1x = end[4 * c]
        v1y = end[4 * c + 1]
        ex, ey = P.slip_direction(y, cst, c, md, v1x, v1y)
        cst[CST * c + 1] = ex
        cst[CST * c + 2] = ey
        if mode == P.MODE_SLIP_QUASI_STATIC:
            if math.sqrt(v1x * v1x + v1y * v1y) > band or v1x * end[4 * c + 2] + v1y * end[4 * c + 3] < 0.0:
                cst[CST * c] = P.MODE_SLIP_EXACT
                changed = True
            cst[CST * c + 3] = math.inf
            continue
        homes, near = approach(progress, c, mode, slips, theta_slip, v_arrive, cst, md)
        if homes:
            homing = True
        elif near:
            slips.homing[c] = 0
            if arrive(progress, c, t, y, cst, md, v_arrive, scratch, log, stats):
                changed = True
    if changed:
        P.rhs(y, cst, md, step.k1)
        stats[2] += 1
        progress.slips_ready = False
    if not homing and progress.h_free > 0.0 and progress.h_override < 0.0:
        progress.h_override = max(progress.h * progress.factor, progress.h_free)
        progress.h_free = -1.0
    progress.retakes = 0
