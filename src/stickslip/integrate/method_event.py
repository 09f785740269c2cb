"""The ``event`` integrator: adaptive Dormand–Prince 5(4) with exact stick and located transitions.

One compiled loop (no Python per step):

* slip: Eq. (1) with the slip force Eq. (3); stick: all 12 states with the exact stick
  multiplier (DESIGN.md §1), q̇ re-projected onto v_r = 0 after each step to remove drift;
* error control on the free DOFs with ``rtol``/``atol`` (RMS norm, as scipy's RK45);
* transitions located on the 4th-order dense output to ``events.EVENT_TIME_TOL``; a step
  whose dense output shows slip velocity through zero is re-taken to end at the root, so no
  stage ever straddles the non-smooth point;
* uniform samples written from the dense output.

State layout inside the loop: 12 physical states, then the accumulated work of friction and of
damping [J] (``kernels.dynamics``), integrated with the same steps as quadratures.
"""

from __future__ import annotations

import math

import numpy as np

from ..model import kernels as K
from ..model.jit import kernel, loop
from . import dormand_prince as DP
from . import events as E

N_STATE = 14  # 12 states + work of friction + work of damping

STATUS_OK = 0
STATUS_STEP_UNDERFLOW = 1
STATUS_NOT_FINITE = 2
STATUS_MAX_STEPS = 3

SAFETY = 0.9        # standard step-size safety factor
MIN_FACTOR = 0.2    # largest step reduction after a rejection
MAX_FACTOR = 5.0    # largest step growth after an acceptance
MAX_RETAKES = 30    # re-takes of one step while homing in on a slip → stick root
DEPARTURE_OVERSHOOT = 2.0  # a departure step may end at most this many low-speed bands above v_r = 0
MAX_HOMING_STEP = 1e-3  # [s] longest extrapolated step onto v_r = 0; ≪ the 0.36 s shortest natural period of Table 1


@kernel
def _dp_step(y, k1, h, mode, ex, ey, minv, damp, stiff, p, Kst, ynew, ytmp):
    """One Dormand–Prince step from y with k1 = f(y); fills the stages Kst[0:7] and ynew.

    The five inner stages are one loop around one inlined right-hand side
    (``kernels._rhs_body``), their sin φ, cos φ those of ``y`` turned by the stage's change of
    φ (``kernels.rotated``, round-off equal to sin and cos) — as the fixed-step RK4 stages.
    """
    for i in range(y.shape[0]):
        Kst[0, i] = k1[i]
    sphi = math.sin(y[4])
    cphi = math.cos(y[4])
    for stage in range(1, 6):
        DP.stage_state(y, Kst, h, stage, ytmp)
        cs, sn = K.rotated(cphi, sphi, ytmp[4] - y[4])
        K._rhs_body(ytmp, sn, cs, mode, ex, ey, minv, damp, stiff, p, Kst[stage])
    DP.stage_state(y, Kst, h, np.int64(6), ynew)  # not a literal: one compiled version
    K.rhs(ynew, mode, ex, ey, minv, damp, stiff, p, Kst[6])


@kernel
def _error_norm(y, ynew, Kst, h, minv, rtol, atol):
    """RMS of the embedded error estimate over the free DOFs' positions and velocities."""
    total = 0.0
    count = 0
    for d in range(6):
        if minv[d] == 0.0:
            continue
        for i in (d, d + 6):
            scale = atol + rtol * max(abs(y[i]), abs(ynew[i]))
            total += (DP.local_error(Kst, h, i) / scale) ** 2
            count += 1
    if count == 0:
        return 0.0
    return math.sqrt(total / count)


@kernel
def _write_samples(idx, t_to, y0, Q, h, t_step, mode, ex, ey, minv, damp, stiff, p,
                   sample_times, out_s, out_mode, out_F, work):
    """Write the samples from index ``idx`` up to time t_to, from the step starting at t_step."""
    n_samples = sample_times.shape[0]
    while idx < n_samples and sample_times[idx] <= t_to:
        theta = (sample_times[idx] - t_step) / h if h > 0.0 else 0.0
        E.dense_state(y0, Q, h, theta, work)
        Fx, Fy = K.contact_force(work, mode, ex, ey, minv, damp, stiff, p)  # as _store_sample, one call less
        E.store_sample(idx, work, mode, Fx, Fy, out_s, out_mode, out_F)
        idx += 1
    return idx


@kernel
def _store_sample(idx, y, mode, ex, ey, minv, damp, stiff, p, out_s, out_mode, out_F):
    """Write sample ``idx`` with the friction force of ``mode`` at state ``y``."""
    Fx, Fy = K.contact_force(y, mode, ex, ey, minv, damp, stiff, p)
    E.store_sample(idx, y, mode, Fx, Fy, out_s, out_mode, out_F)


@kernel
def record_transition(n, t, kind, y, tr_t, tr_kind, tr_s):
    """Write transition ``n`` (time [s], kind, state) into the buffers if they have room.

    The loops count on past the capacity and :func:`with_transition_room` runs again with room
    for all: buffers that grew inside the loop would be loop-carried arrays, which numba
    reference-counts on every iteration (measured ~8 % of a fixed-step run).
    """
    if n < tr_t.shape[0]:
        tr_t[n] = t
        tr_kind[n] = kind
        for i in range(tr_s.shape[1]):
            tr_s[n, i] = y[i]


#: Initial room for transitions per simulated second (the paper's stick-slip cycles have 2 per
#: period of ≥ 0.36 s); a run with more is run again with room for all (deterministic, same result).
TRANSITIONS_PER_SECOND = 64
MIN_TRANSITION_ROOM = 1024


def with_transition_room(run, duration: float, n_state: int = N_STATE):
    """Call ``run(tr_t, tr_kind, tr_s)`` with transition buffers for a run of ``duration`` [s],
    again with bigger ones if the transitions it found exceeded their room.

    ``run`` returns ``(result, n_transitions)``. Returns ``(result, tr_t, tr_kind, tr_s)`` trimmed
    to the transitions recorded.
    """
    capacity = MIN_TRANSITION_ROOM + int(TRANSITIONS_PER_SECOND * duration)
    while True:
        tr_t = np.empty(capacity)
        tr_kind = np.empty(capacity, dtype=np.int8)
        tr_s = np.empty((capacity, n_state))
        result, n_tr = run(tr_t, tr_kind, tr_s)
        if n_tr <= capacity:
            return result, tr_t[:n_tr], tr_kind[:n_tr], tr_s[:n_tr]
        capacity = n_tr


@loop
def integrate_event(y0, t0, t_end, minv, damp, stiff, p, rtol, atol, h_init, h_max, max_steps,
                    sample_times, out_s, out_mode, out_F, tr_t, tr_kind, tr_s):
    """Integrate from ``y0`` (length N_STATE) over [t0, t_end]; see the module docstring.

    Samples go to ``out_s``, ``out_mode``, ``out_F`` at ``sample_times``; transitions to
    ``tr_t``, ``tr_kind``, ``tr_s`` as far as they have room (:func:`record_transition`).

    Returns
    -------
    status : int
    t : float
        Time reached.
    y : ndarray (N_STATE,)
        Final state.
    mode, ex, ey :
        Final mode and stored slip direction.
    n_transitions : int
        Transitions found (instants [s], kinds +1 to stick, −1 to slip, and states are in the
        buffers up to their room).
    stats : ndarray (6,) int64
        accepted steps, rejected steps, rhs calls, step re-takes at slip → stick roots,
        slip → stick transitions, stick → slip transitions.
    """
    n = y0.shape[0]
    y = y0.copy()
    ynew = np.empty(n)
    ytmp = np.empty(n)
    work = np.empty(n)
    Kst = np.empty((7, n))
    Q = np.empty((n, 4))
    k1 = np.empty(n)
    n_tr = np.int64(0)  # not a literal: one compiled version of the callees
    stats = np.zeros(6, dtype=np.int64)

    mode, ex, ey = E.initial_mode(y, minv, damp, stiff, p)
    vx, vy = K.relative_velocity(y, p)
    if mode == K.MODE_SLIP:
        if math.sqrt(vx * vx + vy * vy) > E.STICK_SPEED_TOL:
            # a run that starts sliding is not departing from v_r = 0: watch it for stick at once
            mode = K.MODE_SLIP_EXACT
        else:
            mode = K.MODE_SLIP_QUASI_STATIC
    K.rhs(y, mode, ex, ey, minv, damp, stiff, p, k1)
    stats[2] += 1
    t = t0
    h = min(h_init, h_max)
    idx = np.int64(0)
    # samples at exactly t0
    while idx < sample_times.shape[0] and sample_times[idx] <= t0:
        _store_sample(idx, y, mode, ex, ey, minv, damp, stiff, p, out_s, out_mode, out_F)
        idx += 1

    n_samples = sample_times.shape[0]
    status = STATUS_OK
    retakes = 0
    homing = 0          # homing steps taken towards v_r = 0 since the last event
    h_override = -1.0   # step length imposed on the next step (homing), if > 0
    h_free = -1.0       # step size before a homing episode, if > 0
    tau_start = math.inf  # extrapolated time to v_r = 0 at the start of the step (approach)
    rejected = False    # whether the last attempt was rejected
    # v_r and dv_r/dt at the step start: those of the last accepted step's end, while y and k1
    # are still that end (invalidated by any projection or change of mode)
    v0_ready = False
    v0x = v0y = a0x = a0y = 0.0
    n_steps = 0
    while t < t_end:
        if n_steps >= max_steps:
            status = STATUS_MAX_STEPS
            break
        n_steps += 1
        h = min(h, h_max, t_end - t)
        if h <= 1e-14 * max(1.0, abs(t)):  # below round-off of t: no progress possible
            status = STATUS_STEP_UNDERFLOW
            break
        _dp_step(y, k1, h, mode, ex, ey, minv, damp, stiff, p, Kst, ynew, ytmp)
        stats[2] += 6
        err = _error_norm(y, ynew, Kst, h, minv, rtol, atol)
        if not math.isfinite(err):
            if h < 1e-10:
                status = STATUS_NOT_FINITE
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

        if mode != K.MODE_STICK:
            theta = -1.0
            # v_r and dv_r/dt at the end of the step: the event pre-check, and after acceptance
            # the new slip direction and the time to v_r = 0
            v1x, v1y, a1x, a1y = K.relative_velocity_acceleration(ynew, Kst[6], p)
            if mode == K.MODE_SLIP_QUASI_STATIC and retakes < MAX_RETAKES:
                speed1 = math.sqrt(v1x * v1x + v1y * v1y)
                if speed1 > DEPARTURE_OVERSHOOT * p[K.P_SLIP_BAND]:
                    # the quasi-static direction is an O(|v_r|) approximation: leave it near the
                    # band's edge, not far above it; |v_r| grows like t² after breakaway
                    h *= max(MIN_FACTOR, math.sqrt(p[K.P_SLIP_BAND] / speed1))
                    retakes += 1
                    stats[3] += 1
                    continue
            if mode == K.MODE_SLIP_EXACT:  # while departing from v_r = 0 there is nothing to detect
                if not v0_ready:
                    v0x, v0y, a0x, a0y = K.relative_velocity_acceleration(y, k1, p)
                    v0_ready = True
                speed0 = math.sqrt(v0x * v0x + v0y * v0y)
                e0x = v0x / speed0
                e0y = v0y / speed0
                if E.slip_event_possible(speed0, h * (a0x * e0x + a0y * e0y), v1x * e0x + v1y * e0y,
                                         h * (a1x * e0x + a1y * e0y)):
                    DP.dense_coefficients(Kst, Q)
                    q_ready = True
                    theta = E.first_crossing(E.EVENT_SLIP, y, Q, h, e0x, e0y, minv, damp, stiff, p, work)
            if theta > 0.0 and (1.0 - theta) * h > E.EVENT_TIME_TOL and retakes < MAX_RETAKES:
                # the slip velocity passes zero inside the step: re-take it to end at the root
                if retakes == 0 and homing == 0:
                    h_free = h  # the error controller's step, restored after the event
                h *= theta
                retakes += 1
                stats[3] += 1
                continue
            if idx < n_samples and sample_times[idx] <= t + h:
                if not q_ready:
                    DP.dense_coefficients(Kst, Q)
                idx = _write_samples(idx, t + h, y, Q, h, t, mode, ex, ey, minv, damp, stiff, p,
                                     sample_times, out_s, out_mode, out_F, work)
            t += h
            for i in range(n):
                y[i] = ynew[i]
                k1[i] = Kst[6, i]
            stats[0] += 1
            v0x, v0y, a0x, a0y = v1x, v1y, a1x, a1y
            v0_ready = True
            speed = math.sqrt(v1x * v1x + v1y * v1y)
            ex, ey = K.slip_direction(y, v1x, v1y, ex, ey, minv, damp, stiff, p)
            if mode == K.MODE_SLIP_QUASI_STATIC:
                if speed > p[K.P_SLIP_BAND] or v1x * a1x + v1y * a1y < 0.0:
                    # departed, or |v_r| falls again inside the band (an approach, which may end
                    # in stick or a reversal: watched in exact mode): the exact direction from
                    # the next step on (the force law changes between steps, never inside one)
                    mode = K.MODE_SLIP_EXACT
                    K.rhs(y, mode, ex, ey, minv, damp, stiff, p, k1)
                    stats[2] += 1
                    v0_ready = False
            else:
                v_arrive = E.arrival_speed(y, rtol, atol)
                # arrived: a located root, homing, or |v_r| at the error control's resolution
                # and falling (right after a departure |v_r| may still be below that
                # resolution at loose tolerances, but it grows)
                near = (theta > 0.0 or retakes > 0 or homing > 0
                        or (speed <= v_arrive and v1x * a1x + v1y * a1y < 0.0))
                tau = E.time_to_zero_of(v1x, v1y, a1x, a1y)
                if tau_start < math.inf and tau < math.inf:
                    # approach to stick: the local error of the stiff direction dynamics is a
                    # function of h/τ (self-similar), so control that ratio, not h: the next
                    # step is the same fraction of the time left (no accept/reject ping-pong)
                    factor = min(factor, factor * tau / tau_start)
                tau_start = tau
                if (theta <= 0.0 and E.ARRIVAL_TIME_TOL < tau < MAX_HOMING_STEP and homing < MAX_RETAKES
                        and (near or tau < h * factor)):
                    # v_r heads for zero within the next step (or a re-take landed short of it):
                    # step exactly the extrapolated time instead of letting the stiff direction
                    # dynamics near v_r = 0 shrink the steps geometrically
                    if retakes == 0 and homing == 0:
                        h_free = h
                    h_override = tau
                    homing += 1
                elif near:
                    homing = 0
                    v0_ready = False  # y may be projected, k1 recomputed
                    stick, nex, ney = E.try_stick(y, minv, damp, stiff, p, v_arrive)
                    if stick:
                        mode = K.MODE_STICK
                        stats[4] += 1
                        record_transition(n_tr, t, E.TRANSITION_TO_STICK, y, tr_t, tr_kind, tr_s)
                        n_tr += 1
                    elif nex != 0.0 or ney != 0.0:
                        # v_r reached zero but stick cannot hold: slip departs again (reversal)
                        mode = K.MODE_SLIP_QUASI_STATIC
                        ex, ey = nex, ney
                    if stick or nex != 0.0 or ney != 0.0:
                        K.rhs(y, mode, ex, ey, minv, damp, stiff, p, k1)
                        stats[2] += 1
                    if h_free > 0.0:
                        # the homing steps were short by construction, not by the error
                        # estimate: resume from the step size before them
                        h_override = max(h * factor, h_free)
                        h_free = -1.0
            retakes = 0
            if mode != K.MODE_SLIP_EXACT:
                tau_start = math.inf
        else:
            DP.dense_coefficients(Kst, Q)
            theta = E.first_crossing(E.EVENT_STICK, y, Q, h, 0.0, 0.0, minv, damp, stiff, p, work)
            if theta > 0.0:
                # breakaway inside the step: the stick flow is smooth, so cut the step at the root
                t_root = t + theta * h
                idx = _write_samples(idx, t_root, y, Q, h, t, mode, ex, ey, minv, damp, stiff, p,
                                     sample_times, out_s, out_mode, out_F, work)
                E.dense_state(y, Q, h, theta, work)
                for i in range(n):
                    y[i] = work[i]
                K.project_velocity(y, minv, p)
                t = t_root
                Fx, Fy, _ = K.stick_force(y, minv, damp, stiff, p)
                ex, ey = E.breakaway_direction(Fx, Fy)
                mode = K.MODE_SLIP_QUASI_STATIC
                stats[5] += 1
                record_transition(n_tr, t, E.TRANSITION_TO_SLIP, y, tr_t, tr_kind, tr_s)
                n_tr += 1
            else:
                idx = _write_samples(idx, t + h, y, Q, h, t, mode, ex, ey, minv, damp, stiff, p,
                                     sample_times, out_s, out_mode, out_F, work)
                t += h
                for i in range(n):
                    y[i] = ynew[i]
                K.project_velocity(y, minv, p)  # remove constraint drift
            stats[0] += 1
            K.rhs(y, mode, ex, ey, minv, damp, stiff, p, k1)
            stats[2] += 1
            v0_ready = False
        if not E.all_finite(y):
            status = STATUS_NOT_FINITE
        if status != STATUS_OK:
            break
        if h_override > 0.0:
            h = h_override
            h_override = -1.0
        else:
            h *= factor
    return status, t, y, mode, ex, ey, n_tr, stats
