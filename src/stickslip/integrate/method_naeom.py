"""The ``naeom`` integrator: the paper's method of no alternated equations of motion (Sect. 3).

Fixed-step classic RK4 on all six DOF in both modes, in one compiled loop:

* slip: as ``aeom`` (``method_aeom.slip_step_with_event``, shared);
* stick: the friction force F = (Fx, Fy) is held constant over the step and *solved for* so that
  the relative velocity at the step end vanishes, v_r(t_n; F) = 0 (paper: "various values of
  F_fx and F_fy can be tried when integrating Eq. (1) until v_r = 0"). The solve is a 2-D
  Newton iteration on the residual v_r(t_n; F):

  - Jacobian: ∂v_r(t_n)/∂F = Δt G M⁻¹ Gᵀ + O(Δt²) (dynamics affine in F, Eq. 1), taken at the
    step start (simplified Newton, no extra integration); if an iteration fails to halve the
    residual, the exact Jacobian is formed by finite differences (two extra RK4 steps) for the
    rest of that solve (full Newton). Rank-1 Jacobians (Model 4) are solved minimal-norm
    (``kernels.solve_psd_2x2`` on the normal equations);
  - start value: linear extrapolation of the last two steps' forces (O(Δt²) accurate), or the
    exact multiplier ``kernels.stick_force`` at the first step of a stick phase;
  - stop when |v_r(t_n)| ≤ :data:`VR_TOL`, or when the Newton correction would change v_r(t_n)
    by less than that (the rest of v_r is out of the force's reach, rank-deficient G); after :data:`MAX_NEWTON` iterations the run stops
    with ``STATUS_SOLVE_FAILED`` and the runner raises :class:`~stickslip.SimulationError`.

  No projection is needed: v_r = 0 holds at every step end to ``VR_TOL`` by construction;
* transitions as ``aeom``: shared event functions, bisection on re-stepping. Breakaway is the
  root of ``events.EVENT_STICK`` (μs N − |F_stick| with the exact multiplier at the step-end
  state, Eq. 10), the slip direction e = −F_stick/|F_stick|;
* samples from the cubic Hermite interpolant of each step; in stick the friction written is the
  step's solved force (piecewise constant, what the method uses).
"""

from __future__ import annotations

import math

import numpy as np

from ..model import kernels as K
from ..model.jit import kernel, loop
from . import events as E
from .method_aeom import (MAX_BISECTIONS, N_STATE, _messages, after_slip_root, check_step, kernel_parameters,
                          next_step,
                          slip_step_with_event, stats_dict, warm_up, write_initial_samples, write_samples)
from .method_event import STATUS_MAX_STEPS, STATUS_NOT_FINITE, STATUS_OK, STATUS_STEP_UNDERFLOW, _record

__all__ = ["integrate_naeom", "run_naeom", "solve_stick_step", "VR_TOL", "MAX_NEWTON", "STATUS_SOLVE_FAILED"]

#: Tolerance [m/s] of the stick-force solve on |v_r(t_n)|. v_r is a difference of terms of
#: order Ω R ≈ 1 m/s (paper's cases), so its round-off is ~1e-16 m/s; 1e-12 m/s is 10⁴ times
#: that (reachable in a few iterations at every Δt) and, accumulated over 10⁷ steps of 100 s,
#: a position drift below 1e-10 m — far below every error of the method itself.
VR_TOL = 1e-12

#: Iteration cap of the stick-force solve. Simplified Newton contracts by O(Δt) per iteration
#: (2–3 iterations at Δt = 1e-4 s) and full Newton converges quadratically; 50 iterations
#: without reaching VR_TOL means the solve cannot converge (e.g. Δt far too large).
MAX_NEWTON = 50

#: A simplified-Newton iteration that does not shrink the residual by this factor switches the
#: solve to the finite-difference (exact) Jacobian.
CONTRACTION = 0.5

#: Relative force perturbation for the finite-difference Jacobian: ~√(machine ε) balances
#: truncation and round-off of the one-sided difference.
FD_REL_STEP = 1.5e-8

#: Status of a run whose stick-force solve did not converge (see :data:`MAX_NEWTON`).
STATUS_SOLVE_FAILED = 4


@kernel
def rk4_force_step(y, h, Fx, Fy, minv, damp, stiff, p, ynew, ytmp, k1, k2, k3, k4):
    """RK4 step of Eq. (1) with the friction force (Fx, Fy) [N] held constant; writes ``ynew``."""
    n = y.shape[0]
    half = 0.5 * h
    K.dynamics(y, Fx, Fy, minv, damp, stiff, p, k1)
    for i in range(n):
        ytmp[i] = y[i] + half * k1[i]
    K.dynamics(ytmp, Fx, Fy, minv, damp, stiff, p, k2)
    for i in range(n):
        ytmp[i] = y[i] + half * k2[i]
    K.dynamics(ytmp, Fx, Fy, minv, damp, stiff, p, k3)
    for i in range(n):
        ytmp[i] = y[i] + h * k3[i]
    K.dynamics(ytmp, Fx, Fy, minv, damp, stiff, p, k4)
    sixth = h / 6.0
    for i in range(n):
        ynew[i] = y[i] + sixth * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@kernel
def solve_stick_step(y, h, Fx, Fy, minv, damp, stiff, p, ynew, ytmp, k1, k2, k3, k4, stats):
    """Find the constant force over a step of length ``h`` [s] that makes v_r(t_n) = 0.

    Parameters
    ----------
    y : ndarray (N_STATE,)
        Step start (in stick).
    Fx, Fy : float
        Start value of the iteration [N].
    stats : ndarray int64
        rhs calls are added at index 2, Newton iterations at index 6, the largest iteration
        count of one solve at index 7.

    Returns
    -------
    (Fx, Fy, iterations) : the solved force [N] and the iterations used, −1 if the solve did not
    reach |v_r(t_n)| ≤ VR_TOL within MAX_NEWTON iterations. ``ynew`` holds the step end.
    """
    a11, a12, a22 = K.constraint_metric(y, minv, p)
    j11 = h * a11
    j12 = h * a12
    j21 = h * a12
    j22 = h * a22
    exact = False
    res_prev = math.inf
    for it in range(1, MAX_NEWTON + 1):
        rk4_force_step(y, h, Fx, Fy, minv, damp, stiff, p, ynew, ytmp, k1, k2, k3, k4)
        stats[2] += 4
        vx, vy = K.relative_velocity(ynew, p)
        res = math.sqrt(vx * vx + vy * vy)
        if res <= VR_TOL:
            stats[6] += it
            if it > stats[7]:
                stats[7] = it
            return Fx, Fy, it
        if not exact and res > CONTRACTION * res_prev:
            exact = True
        if exact:
            # finite-difference Jacobian of v_r(t_n) with respect to (Fx, Fy)
            dx = FD_REL_STEP * max(abs(Fx), abs(Fy), K.static_limit(p))
            rk4_force_step(y, h, Fx + dx, Fy, minv, damp, stiff, p, ytmp, ytmp, k1, k2, k3, k4)
            ux, uy = K.relative_velocity(ytmp, p)
            rk4_force_step(y, h, Fx, Fy + dx, minv, damp, stiff, p, ytmp, ytmp, k1, k2, k3, k4)
            wx, wy = K.relative_velocity(ytmp, p)
            stats[2] += 8
            j11 = (ux - vx) / dx
            j21 = (uy - vy) / dx
            j12 = (wx - vx) / dx
            j22 = (wy - vy) / dx
        # Newton step J ΔF = −v_r, minimal-norm through the normal equations (rank-1 safe)
        n11 = j11 * j11 + j21 * j21
        n12 = j11 * j12 + j21 * j22
        n22 = j12 * j12 + j22 * j22
        b1 = -(j11 * vx + j21 * vy)
        b2 = -(j12 * vx + j22 * vy)
        dFx, dFy, _ = K.solve_psd_2x2(n11, n12, n22, b1, b2)
        # the part of v_r the force can still change, J ΔF: when it is below VR_TOL the rest of
        # v_r lies outside the range of J (rank-deficient G, e.g. Model 3 at φ ≈ 0, where no
        # friction force acts on v_r·e_x) and the least-squares solve has converged
        cx = j11 * dFx + j12 * dFy
        cy = j21 * dFx + j22 * dFy
        if math.sqrt(cx * cx + cy * cy) <= VR_TOL:
            stats[6] += it
            if it > stats[7]:
                stats[7] = it
            return Fx, Fy, it
        Fx += dFx
        Fy += dFy
        res_prev = res
    stats[6] += MAX_NEWTON
    return Fx, Fy, -1


@loop
def integrate_naeom(y0, t0, t_end, dt, minv, damp, stiff, p, max_steps, sample_times, out_s, out_mode, out_F):
    """Integrate from ``y0`` (length N_STATE) over [t0, t_end] with the fixed step ``dt`` [s].

    Returns
    -------
    status : int
        ``method_event.STATUS_*`` or :data:`STATUS_SOLVE_FAILED`.
    t : float
        Time reached [s].
    y : ndarray (N_STATE,)
        Final state.
    tr_t, tr_kind, tr_s :
        Transition instants [s], kinds (+1 to stick, −1 to slip) and states.
    stats : ndarray (8,) int64
        steps, 0, rhs calls (each RK4 stage counts one), re-taken (bisection) steps, slip → stick,
        stick → slip, total Newton iterations, most iterations of one solve.
    """
    n = y0.shape[0]
    y = y0.copy()
    ynew = np.empty(n)
    ytmp = np.empty(n)
    work = np.empty(n)
    k1 = np.empty(n)
    fnew = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    s1 = np.empty(n)
    Q = np.empty((n, 3))
    tr_t = np.empty(16)
    tr_kind = np.empty(16, dtype=np.int8)
    tr_s = np.empty((16, n))
    n_tr = np.int64(0)  # not a literal: one compiled version of the callees
    stats = np.zeros(8, dtype=np.int64)

    mode, ex, ey = E.initial_mode(y, minv, damp, stiff, p)
    Fx, Fy = K.contact_force(y, mode, ex, ey, minv, damp, stiff, p)
    K.dynamics(y, Fx, Fy, minv, damp, stiff, p, k1)
    stats[2] += 1
    idx = write_initial_samples(y, t0, mode, ex, ey, Fx, Fy, False, minv, damp, stiff, p,
                                sample_times, out_s, out_mode, out_F)
    # force history of the current stick phase for the start value: (mid-step time, F)
    n_hist = 0
    tm1 = 0.0
    F1x = 0.0
    F1y = 0.0
    tm2 = 0.0
    F2x = 0.0
    F2y = 0.0
    t = t0
    k_grid = 1
    status = STATUS_OK
    n_steps = 0
    while t < t_end:
        if n_steps >= max_steps:
            status = STATUS_MAX_STEPS
            break
        n_steps += 1
        h, k_grid = next_step(t, t0, dt, k_grid, t_end)
        if h <= 0.0:
            status = STATUS_STEP_UNDERFLOW
            break
        transition = 0
        if mode == K.MODE_SLIP:
            h, crossed = slip_step_with_event(y, k1, h, ex, ey, minv, damp, stiff, p, ynew, fnew,
                                              ytmp, k2, k3, k4, stats)
            idx = write_samples(idx, t, h, y, k1, ynew, fnew, mode, ex, ey, False, 0.0, 0.0, minv, damp,
                                stiff, p, sample_times, out_s, out_mode, out_F, Q, work)
            ex, ey = K.slip_direction(ynew, ex, ey, minv, damp, stiff, p)
            if crossed:
                stick, ex, ey = after_slip_root(ynew, ex, ey, minv, damp, stiff, p)
                if stick:
                    transition = E.TRANSITION_TO_STICK
                    n_hist = 0
        else:
            tm = t + 0.5 * h
            if n_hist >= 2:
                slope = (tm - tm1) / (tm1 - tm2)
                gx = F1x + slope * (F1x - F2x)
                gy = F1y + slope * (F1y - F2y)
            elif n_hist == 1:
                gx, gy = F1x, F1y
            else:
                gx, gy, _ = K.stick_force(y, minv, damp, stiff, p)
            Fx, Fy, it = solve_stick_step(y, h, gx, gy, minv, damp, stiff, p, ynew, ytmp, s1, k2, k3, k4, stats)
            if it < 0:
                status = STATUS_SOLVE_FAILED
                break
            if E.event_value(E.EVENT_STICK, ynew, 0.0, 0.0, minv, damp, stiff, p) <= 0.0:
                # breakaway (Eq. 10) inside the step: bisect θ on re-solved stick steps
                a = 0.0
                b = 1.0
                for _ in range(MAX_BISECTIONS):
                    if (b - a) * h <= E.EVENT_TIME_TOL:
                        break
                    c = 0.5 * (a + b)
                    Fx, Fy, it = solve_stick_step(y, c * h, Fx, Fy, minv, damp, stiff, p, ynew, ytmp, s1,
                                                  k2, k3, k4, stats)
                    stats[3] += 1
                    if it < 0:
                        break
                    if E.event_value(E.EVENT_STICK, ynew, 0.0, 0.0, minv, damp, stiff, p) > 0.0:
                        a = c
                    else:
                        b = c
                if it < 0:
                    status = STATUS_SOLVE_FAILED
                    break
                if b < 1.0:
                    Fx, Fy, it = solve_stick_step(y, b * h, Fx, Fy, minv, damp, stiff, p, ynew, ytmp, s1,
                                                  k2, k3, k4, stats)
                    stats[3] += 1
                    if it < 0:
                        status = STATUS_SOLVE_FAILED
                        break
                h = b * h
                transition = E.TRANSITION_TO_SLIP
            if idx < sample_times.shape[0] and sample_times[idx] <= t + h:
                # derivatives at both step ends under the solved force, for the Hermite samples
                K.dynamics(y, Fx, Fy, minv, damp, stiff, p, k1)
                K.dynamics(ynew, Fx, Fy, minv, damp, stiff, p, fnew)
                stats[2] += 2
                idx = write_samples(idx, t, h, y, k1, ynew, fnew, mode, ex, ey, True, Fx, Fy, minv, damp,
                                    stiff, p, sample_times, out_s, out_mode, out_F, Q, work)
            tm2, F2x, F2y = tm1, F1x, F1y
            tm1, F1x, F1y = t + 0.5 * h, Fx, Fy
            n_hist += 1
            if transition == E.TRANSITION_TO_SLIP:
                gx, gy, _ = K.stick_force(ynew, minv, damp, stiff, p)
                ex, ey = E.breakaway_direction(gx, gy)
        t += h
        stats[0] += 1
        for i in range(n):
            y[i] = ynew[i]
        if mode == K.MODE_SLIP:
            for i in range(n):
                k1[i] = fnew[i]
        if transition != 0:
            mode = K.MODE_STICK if transition == E.TRANSITION_TO_STICK else K.MODE_SLIP
            stats[4 if transition == E.TRANSITION_TO_STICK else 5] += 1
            tr_t, tr_kind, tr_s = _record(n_tr, t, transition, y, tr_t, tr_kind, tr_s)
            n_tr += 1
        if mode == K.MODE_SLIP and transition != 0:
            K.rhs(y, mode, ex, ey, minv, damp, stiff, p, k1)
            stats[2] += 1
        for i in range(n):
            if not math.isfinite(y[i]):
                status = STATUS_NOT_FINITE
        if status != STATUS_OK:
            break
    return status, t, y, tr_t[:n_tr].copy(), tr_kind[:n_tr].copy(), tr_s[:n_tr].copy(), stats


def run_naeom(system, y0: np.ndarray, t0: float, t_end: float, sample_times: np.ndarray,
              rtol: float, atol: float, dt: float | None, max_steps: int):
    """Runner of ``method="naeom"`` for :func:`stickslip.simulate` (signature of ``_run_event``).

    ``rtol``/``atol`` are not used (fixed step ``dt`` [s], validated by
    :func:`~stickslip.integrate.method_aeom.check_step`).

    Raises
    ------
    SimulationError
        If the per-step stick-force solve does not converge (:data:`MAX_NEWTON`).
    """
    from .driver import SimulationError
    from .result import Transitions

    dt = check_step("naeom", system, dt)
    compile_time = warm_up(integrate_naeom, system, t0, dt)
    n = sample_times.size
    out_s = np.zeros((n, N_STATE))
    out_mode = np.zeros(n, dtype=np.int8)
    out_F = np.zeros((n, 2))
    y = np.zeros(N_STATE)
    y[:12] = y0
    status, t_reached, _, tr_t, tr_kind, tr_s, st = integrate_naeom(
        y, t0, t_end, dt, system.minv, system.damp, system.stiff, kernel_parameters(system, dt), max_steps,
        sample_times, out_s, out_mode, out_F)
    if status == STATUS_SOLVE_FAILED:
        raise SimulationError(
            f"naeom: the stick-force solve did not reach |v_r| ≤ {VR_TOL:g} m/s in {MAX_NEWTON} Newton "
            f"iterations at t = {t_reached:.6g} s (dt = {dt:g} s); give a smaller dt"
        )
    keep = sample_times <= t_reached
    return (_messages(status, t_reached), keep, out_s, out_mode, out_F,
            Transitions(tr_t, tr_kind, tr_s[:, :12]), stats_dict(st, compile_time))
