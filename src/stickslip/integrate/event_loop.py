"""The ``event`` integrator: adaptive Dormand–Prince 5(4) with exact stick and located transitions.

One compiled loop for any friction-contact model (no Python per step):

* each contact slips or sticks on its own; the multipliers of all sticking contacts are solved
  together (:mod:`stickslip.model.physics`), and q̇ is re-projected onto their constraints after
  each step to remove drift;
* error control on the free DOFs with ``rtol``/``atol`` (RMS norm, as scipy's RK45);
* transitions located on the 4th-order dense output to ``contacts.EVENT_TIME_TOL``: a step whose
  dense output shows a slip velocity through zero is re-taken to end at the root, so no stage
  ever straddles the non-smooth point; a breakaway, and the opening or closing of a unilateral
  contact, cut the step at their root (the flow is smooth up to it);
* uniform samples written from the dense output.

Time inside the loop is *local*: the caller passes ``t_base`` and the loop integrates
τ = t − t_base from 0, so that step sizes and event tolerances are resolved against τ, not
against an absolute time whose unit in the last place grows with the run (at t ~ 4e4 s it
exceeds the event tolerance, and runs used to stop with a step-size underflow). The driver
calls the loop in chunks (:func:`stickslip.integrate.driver.simulate`), rebasing each; a chunk
ends at the first accepted step past ``tau_stop`` that is not in the middle of an approach, so
the steps taken are the same as in one long call.

State layout: the 2n physical states, then the accumulated work of friction and of damping [J],
integrated with the same steps as quadratures.
"""

from __future__ import annotations

import math

import numpy as np

from ..model import physics as P
from ..model.bundle import CST, H_BAND, offsets
from ..model.jit import inlined_kernel, kernel, standalone
from ..model.kinematics import model_sizes
from ..model.normal import is_unilateral
from . import contacts as E
from . import dormand_prince as DP
from .status import CHUNK_END, CONTACT_LOST, INCONSISTENT, MAX_STEPS, NOT_FINITE, STEP_UNDERFLOW, SUCCESS
from .transitions import (break_away, crossing_in_step, gap_crossing, jammed_contact, record_transition, settle,
                          switch_gap)

__all__ = ["integrate_event", "N_EXTRA"]

N_EXTRA = 2  # work of friction, work of damping

SAFETY = 0.9        # standard step-size safety factor
MIN_FACTOR = 0.2    # largest step reduction after a rejection
MAX_FACTOR = 5.0    # largest step growth after an acceptance
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


@standalone
@kernel
def dp_step(y, k1, h, cst, md, Kst, ynew, ytmp):
    """One Dormand–Prince step from y with k1 = f(y); fills the stages Kst[0:7] and ynew.

    The five inner stages are one loop around one inlined right-hand side.
    """
    for i in range(y.shape[0]):
        Kst[0, i] = k1[i]
    for stage in range(1, 6):
        DP.stage_state(y, Kst, h, stage, ytmp)
        P.rhs_body(ytmp, cst, md, Kst[stage])
    DP.stage_state(y, Kst, h, np.int64(6), ynew)  # not a literal: one compiled version
    P.rhs(ynew, cst, md, Kst[6])


@kernel
def error_norm(y, ynew, Kst, h, md, rtol, atol):
    """RMS of the embedded error estimate over the free DOFs' positions and velocities."""
    m = md.m
    n = model_sizes(md.kin, m)[0]
    o_free = offsets(n)[5]
    total = 0.0
    count = 0
    for d in range(n):
        if m[o_free + d] == 0.0:
            continue
        for i in (d, d + n):
            scale = atol + rtol * max(abs(y[i]), abs(ynew[i]))
            total += (DP.local_error(Kst, h, i) / scale) ** 2
            count += 1
    if count == 0:
        return 0.0
    return math.sqrt(total / count)


@kernel
def homing_left(homing):
    """Whether any contact is in the middle of homing in on v = 0 (a loop: ``homing.sum()`` would
    compile numpy's reduction with its axis checks)."""
    for c in range(homing.shape[0]):
        if homing[c] != 0:
            return True
    return False


@inlined_kernel
def store_sample(idx, y, cst, md, F, N, v, out_s, out_mode, out_F):
    """Write sample ``idx``: the state, the mode flags (bit c: contact c sticks) and each contact's
    friction force at ``y``."""
    nc = model_sizes(md.kin, md.m)[1]
    P.contact_forces(y, cst, md, F, N, v)
    for i in range(out_s.shape[1]):
        out_s[idx, i] = y[i]
    E.store_mode(out_mode, idx, cst, nc)
    for i in range(2 * nc):
        out_F[idx, i] = F[i]


@standalone
@kernel
def write_samples(idx, tau_to, y0, Q, h, tau_step, t_base, cst, md, sample_times, out_s, out_mode, out_F,
                  work, F, N, v):
    """Write the samples from index ``idx`` up to local time ``tau_to``, from the step starting at
    local time ``tau_step`` (samples are absolute times; ``t_base`` is the local origin)."""
    n_samples = sample_times.shape[0]
    while idx < n_samples and sample_times[idx] - t_base <= tau_to:
        theta = (sample_times[idx] - t_base - tau_step) / h if h > 0.0 else 0.0
        E.dense_state(y0, Q, h, theta, work)
        store_sample(idx, work, cst, md, F, N, v, out_s, out_mode, out_F)
        idx += 1
    return idx


@kernel
def cut_step(theta, idx, y, Q, h, tau, t_base, cst, md, sample_times, out_s, out_mode, out_F, work, F, N, v):
    """End the step at θ ∈ (0, 1] of its length ``h`` (an event's root): write the samples up to
    there and move ``y`` (the step's start) onto it. Returns (idx, local time of the cut)."""
    tau_cut = tau + theta * h
    idx = write_samples(idx, tau_cut, y, Q, h, tau, t_base, cst, md, sample_times, out_s, out_mode, out_F, work, F, N,
                        v)
    E.dense_state(y, Q, h, theta, work)
    for i in range(y.shape[0]):
        y[i] = work[i]
    return idx, tau_cut


def integrate_event(y0, cst, t_base, tau_stop, tau_end, md, rtol, atol, h_init, h_max, max_steps,
                    sample_times, idx0, out_s, out_mode, out_F, tr_t, tr_kind, tr_contact, tr_s, n_tr0,
                    start_modes=False):
    """Integrate from ``y0`` at local time 0 (absolute ``t_base``) towards ``tau_end``: allocates the
    work arrays and runs :func:`event_loop` (see there for arguments and results).

    Plain Python: a compiled wrapper would link the whole loop, physics included, into a module of
    its own and have LLVM optimise and emit all of it a second time on a cold start (2.5 s of a
    model file's first ``simulate``); a call from Python costs microseconds per chunk.
    """
    nc = out_F.shape[1] // 2
    ns = y0.shape[0]
    y = y0.copy()
    work = np.empty((5, ns))
    Kst = np.empty((7, ns))
    Q = np.empty((ns, 4))
    F = np.empty(2 * nc)
    N = np.empty(nc)
    vv = np.empty(2 * nc)
    va = np.empty((2, 4 * nc))
    homing = np.zeros(nc, dtype=np.int64)
    stats = np.zeros(6, dtype=np.int64)
    status, tau, h, idx, n_tr, lost = event_loop(
        y, cst, float(t_base), float(tau_stop), float(tau_end), md, float(rtol), float(atol), float(h_init),
        float(h_max), int(max_steps), sample_times, int(idx0), out_s, out_mode, out_F, tr_t, tr_kind, tr_contact,
        tr_s, int(n_tr0), work, Kst, Q, F, N, vv, va, homing, stats, bool(start_modes))
    return status, tau, y, h, idx, n_tr, stats, lost


@kernel
def event_loop(y, cst, t_base, tau_stop, tau_end, md, rtol, atol, h_init, h_max, max_steps, sample_times, idx0,
               out_s, out_mode, out_F, tr_t, tr_kind, tr_contact, tr_s, n_tr0, work5, Kst, Q, F, N, vv, va2, homing,
               stats, start_modes):
    """The loop of :func:`integrate_event` (module docstring), free of reference counting.

    ``y`` (2n + 2,) is advanced in place from local time 0 (absolute ``t_base``) towards
    ``tau_end``; ``cst`` (CST nc,) is the contacts' integration state, updated in place (pass the
    one returned by the previous chunk). Samples from index ``idx0`` go to ``out_s``, ``out_mode``,
    ``out_F`` at the absolute ``sample_times``; transitions from number ``n_tr0`` to the ``tr_*``
    buffers as far as they have room. ``work5`` … ``homing`` are work arrays; ``stats`` (6,)
    receives accepted steps, rejected steps, rhs calls, step re-takes at slip → stick roots,
    slip → stick and stick → slip transitions. With ``start_modes``, ``cst`` is first set to the modes
    that ``y`` starts in (:func:`~stickslip.integrate.contacts.initial_modes`, which may project
    ``y``): the first call of a run, made with ``tau_end = 0``, does only that (one compiled
    module instead of two, on a cold start).

    Returns
    -------
    status : int
        :mod:`stickslip.integrate.status` code; CHUNK_END when stopped at ``tau_stop``.
    tau : float
        Local time reached [s].
    h : float
        Step size to continue with [s].
    idx : int
        Next sample index.
    n_tr : int
        Transitions found so far (counted past the buffers' room).
    lost : int
        Contact whose normal force reached 0 (status CONTACT_LOST), else −1.
    """
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    ns = y.shape[0]
    ynew = work5[0]
    ytmp = work5[1]
    work = work5[2]
    k1 = work5[3]
    va = va2[0]       # v0x, v0y, a0x, a0y per contact at the step start
    va1 = va2[1]      # the same at the step end
    n_tr = n_tr0
    band = m[H_BAND]

    if start_modes:
        E.initial_modes(y, cst, md, rtol, atol, F, N)
    P.rhs(y, cst, md, k1)
    stats[2] += 1
    tau = 0.0
    h = min(h_init, h_max)
    idx = idx0
    n_samples = sample_times.shape[0]
    while idx < n_samples and sample_times[idx] - t_base <= 0.0:
        store_sample(idx, y, cst, md, F, N, vv, out_s, out_mode, out_F)
        idx += 1

    status = SUCCESS
    lost = jammed_contact(y, cst, md)
    if lost >= 0:
        return INCONSISTENT, 0.0, h_init, idx, n_tr, lost
    retakes = 0
    h_override = -1.0   # step length imposed on the next step (homing), if > 0
    h_free = -1.0       # step size before a homing episode, if > 0
    rejected = False
    va_ready = False    # va holds the values at y (invalidated by projections and mode changes)
    n_steps = 0
    while tau < tau_end:
        if n_steps >= max_steps:
            status = MAX_STEPS
            break
        n_steps += 1
        h = min(h, h_max, tau_end - tau)
        if h <= 1e-14 * max(1.0, abs(tau)):  # below round-off of τ: no progress possible
            status = STEP_UNDERFLOW
            break
        dp_step(y, k1, h, cst, md, Kst, ynew, ytmp)
        stats[2] += 6
        err = error_norm(y, ynew, Kst, h, md, rtol, atol)
        if not math.isfinite(err):
            if h < 1e-10:
                status = NOT_FINITE
                break
            h *= MIN_FACTOR
            stats[1] += 1
            continue
        if err > 1.0:
            # a rejected re-take keeps homing: the root found before still lies ahead
            h *= max(MIN_FACTOR, SAFETY * err ** -0.2)
            stats[1] += 1
            rejected = True
            continue
        factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err ** -0.2)
        if rejected:
            factor = min(factor, 1.0)  # no growth right after a rejection (Hairer's DOPRI5 rule)
            rejected = False
        q_ready = False  # the dense-output coefficients are formed only when needed

        # ---- a normal force through zero: the model ends there (contact lost)
        theta_lost = -1.0
        for c in range(nc):
            if not is_unilateral(md, n, c) and P.normal_force(ynew, c, md) <= 0.0:
                th = crossing_in_step(E.EVENT_NORMAL, c, y, Kst, Q, q_ready, h, cst, md, work, F, N)
                q_ready = True
                if theta_lost < 0.0 or th < theta_lost:
                    theta_lost = th
                    lost = c
        if theta_lost > 0.0:
            idx, tau = cut_step(theta_lost, idx, y, Q, h, tau, t_base, cst, md, sample_times, out_s, out_mode, out_F,
                                work, F, N, vv)
            stats[0] += 1
            status = CONTACT_LOST
            break

        # ---- slip contacts: departure overshoot, slip → stick roots inside the step
        retake = -1.0
        theta_slip = -1.0
        any_stick = False
        for c in range(nc):
            mode = np.int64(cst[CST * c])
            if mode == P.MODE_STICK:
                any_stick = True
                continue
            if mode == P.MODE_OPEN:
                continue
            v1x, v1y, a1x, a1y = P.slip_velocity_and_rate(ynew, Kst[6], c, md)
            va1[4 * c] = v1x
            va1[4 * c + 1] = v1y
            va1[4 * c + 2] = a1x
            va1[4 * c + 3] = a1y
            if mode == P.MODE_SLIP_QUASI_STATIC and retakes < MAX_RETAKES:
                speed1 = math.sqrt(v1x * v1x + v1y * v1y)
                if speed1 > DEPARTURE_OVERSHOOT * band:
                    # the quasi-static direction is an O(|v|) approximation: leave it near the
                    # band's edge, not far above it; |v| grows like t² after breakaway
                    f_c = max(MIN_FACTOR, math.sqrt(band / speed1))
                    retake = f_c if retake < 0.0 else min(retake, f_c)
            if mode == P.MODE_SLIP_EXACT:  # while departing from v = 0 there is nothing to detect
                if not va_ready:
                    for c2 in range(nc):
                        if np.int64(cst[CST * c2]) != P.MODE_STICK:
                            vx, vy, ax, ay = P.slip_velocity_and_rate(y, k1, c2, md)
                            va[4 * c2] = vx
                            va[4 * c2 + 1] = vy
                            va[4 * c2 + 2] = ax
                            va[4 * c2 + 3] = ay
                    va_ready = True
                v0x = va[4 * c]
                v0y = va[4 * c + 1]
                speed0 = math.sqrt(v0x * v0x + v0y * v0y)
                e0x = v0x / speed0
                e0y = v0y / speed0
                if E.slip_event_possible(speed0, h * (va[4 * c + 2] * e0x + va[4 * c + 3] * e0y),
                                         v1x * e0x + v1y * e0y, h * (a1x * e0x + a1y * e0y)):
                    if not q_ready:
                        DP.dense_coefficients(Kst, Q)
                        q_ready = True
                    th = E.first_crossing(E.EVENT_SLIP, c, y, Q, h, e0x, e0y, cst, md, work, F, N)
                    if th > 0.0 and (theta_slip < 0.0 or th < theta_slip):
                        theta_slip = th
        if retake > 0.0:
            h *= retake
            retakes += 1
            stats[3] += 1
            continue
        if theta_slip > 0.0 and (1.0 - theta_slip) * h > E.EVENT_TIME_TOL and retakes < MAX_RETAKES:
            # a slip velocity passes zero inside the step: re-take it to end at the root
            if retakes == 0 and h_override < 0.0 and h_free < 0.0:
                h_free = h  # the error controller's step, restored after the event
            h *= theta_slip
            retakes += 1
            stats[3] += 1
            continue

        # ---- unilateral contacts: opening or closing inside the step cuts it at the root
        theta_g, c_g, q_ready = gap_crossing(y, k1, ynew, Kst, Q, q_ready, h, cst, md, work, F, N)

        # ---- sticking contacts: breakaway inside the step cuts it at the root
        theta_b = -1.0
        c_b = np.int64(-1)  # not a literal: numba would type the call below for it first
        if any_stick:
            if not q_ready:
                DP.dense_coefficients(Kst, Q)
                q_ready = True
            for c in range(nc):
                if np.int64(cst[CST * c]) == P.MODE_STICK:
                    th = E.first_crossing(E.EVENT_STICK, c, y, Q, h, 0.0, 0.0, cst, md, work, F, N)
                    if th > 0.0 and (theta_b < 0.0 or th < theta_b):
                        theta_b = th
                        c_b = c
        cut = theta_g > 0.0 and (theta_b < 0.0 or theta_g <= theta_b)
        if cut:
            # a unilateral contact opens or closes inside the step: cut the step at the root
            idx, tau = cut_step(theta_g, idx, y, Q, h, tau, t_base, cst, md, sample_times, out_s, out_mode, out_F,
                                work, F, N, vv)
            n_tr, gap_status, flight = switch_gap(y, cst, c_g, md, rtol, atol, F, N, t_base + tau, tr_t, tr_kind,
                                                  tr_contact, tr_s, n_tr, stats, ytmp)
            if gap_status != SUCCESS:
                stats[0] += 1
                status = gap_status
                lost = c_g
                break
            if flight < math.inf:  # a bounce: the next step ends inside its flight
                h_override = 0.5 * flight
        elif theta_b > 0.0:
            # breakaway inside the step: the flow is smooth up to it, so cut the step at the root
            cut = True
            idx, tau = cut_step(theta_b, idx, y, Q, h, tau, t_base, cst, md, sample_times, out_s, out_mode, out_F,
                                work, F, N, vv)
            n_tr = break_away(y, cst, c_b, md, F, N, t_base + tau, tr_t, tr_kind, tr_contact, tr_s, n_tr, stats)
        else:
            # ---- accept the whole step
            if idx < n_samples and sample_times[idx] - t_base <= tau + h:
                if not q_ready:
                    DP.dense_coefficients(Kst, Q)
                idx = write_samples(idx, tau + h, y, Q, h, tau, t_base, cst, md, sample_times, out_s, out_mode,
                                    out_F, work, F, N, vv)
            tau += h
            for i in range(ns):
                y[i] = ynew[i]
                k1[i] = Kst[6, i]
            stats[0] += 1
            for i in range(4 * nc):
                va[i] = va1[i]
            va_ready = True
            changed = False
            if any_stick:
                P.project_velocities(y, cst, np.int64(-1), md)  # remove constraint drift
                changed = True
            v_arrive = E.arrival_speed(y, n, rtol, atol)
            homing_any = False
            for c in range(nc):
                mode = np.int64(cst[CST * c])
                if mode == P.MODE_STICK or mode == P.MODE_OPEN:
                    continue
                v1x = va1[4 * c]
                v1y = va1[4 * c + 1]
                a1x = va1[4 * c + 2]
                a1y = va1[4 * c + 3]
                speed = math.sqrt(v1x * v1x + v1y * v1y)
                ex, ey = P.slip_direction(y, cst, c, md, v1x, v1y)
                cst[CST * c + 1] = ex
                cst[CST * c + 2] = ey
                if mode == P.MODE_SLIP_QUASI_STATIC:
                    if speed > band or v1x * a1x + v1y * a1y < 0.0:
                        # departed, or |v| falls again inside the band (an approach, which may end
                        # in stick or a reversal: watched in exact mode): the exact direction from
                        # the next step on (the force law changes between steps, never inside one)
                        cst[CST * c] = P.MODE_SLIP_EXACT
                        changed = True
                    cst[CST * c + 3] = math.inf
                    continue
                # arrived: a located root, homing, or |v| at the error control's resolution and
                # falling (right after a departure |v| may still be below that resolution, but grows)
                near = (theta_slip > 0.0 or retakes > 0 or homing[c] > 0
                        or (speed <= v_arrive and v1x * a1x + v1y * a1y < 0.0))
                tau_c = E.time_to_zero_of(v1x, v1y, a1x, a1y)
                tau_start = cst[CST * c + 3]
                if tau_start < math.inf and tau_c < math.inf:
                    # approach to stick: the local error of the stiff direction dynamics is a function
                    # of h/τ (self-similar), so control that ratio, not h: the next step is the same
                    # fraction of the time left (no accept/reject ping-pong)
                    factor = min(factor, factor * tau_c / tau_start)
                cst[CST * c + 3] = tau_c if mode == P.MODE_SLIP_EXACT else math.inf
                if (theta_slip <= 0.0 and E.ARRIVAL_TIME_TOL < tau_c < MAX_HOMING_STEP and homing[c] < MAX_RETAKES
                        and (near or tau_c < h * factor)):
                    # v heads for zero within the next step (or a re-take landed short of it): step
                    # exactly the extrapolated time instead of letting the stiff direction dynamics
                    # near v = 0 shrink the steps geometrically
                    if retakes == 0 and homing[c] == 0 and h_free < 0.0:
                        h_free = h
                    if P.contact_dim(md.kin, m, n, c) == 1:
                        # a 1-D slip velocity changes sign at zero and so does its force: a step past
                        # the zero is rejected, so aim just short of it (the time left shrinks by
                        # HOMING_SHORTFALL per homing step)
                        tau_c *= 1.0 - HOMING_SHORTFALL
                    h_override = tau_c if h_override < 0.0 else min(h_override, tau_c)
                    homing[c] += 1
                    homing_any = True
                elif near:
                    homing[c] = 0
                    stick, nex, ney = E.try_stick(y, cst, c, md, v_arrive, F, N)
                    if stick:
                        cst[CST * c] = P.MODE_STICK
                        cst[CST * c + 3] = math.inf
                        stats[4] += 1
                        record_transition(n_tr, t_base + tau, E.TRANSITION_TO_STICK, c, y, tr_t, tr_kind,
                                          tr_contact, tr_s)
                        n_tr += 1
                        n_tr = settle(y, cst, md, F, N, t_base + tau, tr_t, tr_kind, tr_contact, tr_s, n_tr, stats)
                        changed = True
                    elif nex != 0.0 or ney != 0.0:
                        # v reached zero but stick cannot hold: slip departs again (reversal)
                        cst[CST * c] = P.MODE_SLIP_QUASI_STATIC
                        cst[CST * c + 1] = nex
                        cst[CST * c + 2] = ney
                        cst[CST * c + 3] = math.inf
                        changed = True
                    else:
                        continue
            if changed:
                P.rhs(y, cst, md, k1)
                stats[2] += 1
                va_ready = False
            if not homing_any and h_free > 0.0 and h_override < 0.0:
                # the homing steps were short by construction, not by the error estimate: resume from
                # the step size before them
                h_override = max(h * factor, h_free)
                h_free = -1.0
            retakes = 0
        if cut:  # a new smooth piece starts at the root
            stats[0] += 1
            P.rhs(y, cst, md, k1)
            stats[2] += 1
            va_ready = False
            retakes = 0
            homing_any = False
        if not E.all_finite(y):
            status = NOT_FINITE
            break
        lost = jammed_contact(y, cst, md)
        if lost >= 0:
            status = INCONSISTENT
            break
        if h_override > 0.0:
            h = h_override
            h_override = -1.0
        else:
            h *= factor
            if tau_stop <= tau < tau_end and h_free < 0.0 and not homing_left(homing):
                status = CHUNK_END
                break
    return status, tau, h, idx, n_tr, lost
