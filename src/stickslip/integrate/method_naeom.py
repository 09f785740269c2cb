"""The ``naeom`` integrator: the paper's method of no alternated equations of motion (Sect. 3).

Fixed-step classic RK4 on all six DOF in both modes; the loop, the slip steps and the samples
are shared with ``aeom`` (:mod:`~stickslip.integrate.fixed_step`). What is specific to NAEOM:

* stick: the friction force F = (Fx, Fy) is held constant over the step and *solved for* so that
  the relative velocity at the step end vanishes, v_r(t_n; F) = 0 (paper: "various values of
  F_fx and F_fy can be tried when integrating Eq. (1) until v_r = 0"). The solve is a 2-D
  Newton iteration on the residual v_r(t_n; F):

  - Jacobian: ∂v_r(t_n)/∂F = Δt G M⁻¹ Gᵀ + O(Δt²) (dynamics affine in F, Eq. 1), taken at the
    step start (simplified Newton, no extra integration); if an iteration fails to halve the
    residual, the exact Jacobian is formed by finite differences (two extra RK4 steps) for the
    rest of that solve (full Newton). Rank-1 Jacobians (Model 4) are solved minimal-norm
    (``physics.solve_psd_2x2`` on the normal equations);
  - start value: linear extrapolation of the last two steps' forces (O(Δt²) accurate), or the
    exact stick multiplier at the first step of a stick phase;
  - stop when |v_r(t_n)| ≤ :data:`VR_TOL`, or when the Newton correction would change v_r(t_n)
    by less than that (the rest of v_r is out of the force's reach, rank-deficient G); after :data:`MAX_NEWTON` iterations the run stops
    with ``STATUS_SOLVE_FAILED`` and the runner raises :class:`~stickslip.SimulationError`.

  No projection is needed: v_r = 0 holds at every step end to ``VR_TOL`` by construction;
* breakaway as in ``aeom``: the root of ``events.EVENT_STICK`` (μs N − |F_stick| with the exact
  multiplier at the step-end state, Eq. 10), bisected on re-solved steps;
* in stick the friction written to the samples is the step's solved force (piecewise constant,
  what the method uses).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..model import physics as P
from ..model.jit import kernel
from . import events as E
from . import rk4
from .status import SOLVE_FAILED as STATUS_SOLVE_FAILED
from .step_physics import constraint_metric, contact_limit, derivative_under_force, stick_force

__all__ = ["ForceStep", "naeom_stick_branch", "solve_stick_step", "rk4_force_step", "VR_TOL", "MAX_NEWTON", "STATUS_SOLVE_FAILED"]

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


@kernel
def rk4_force_step(y, h, Fx, Fy, md, ynew, ytmp, K):
    """RK4 step of Eq. (1) with the friction force (Fx, Fy) [N] held constant; writes ``ynew`` and
    the stages ``K`` (4, n) (:mod:`.rk4`)."""
    derivative_under_force(y, Fx, Fy, md, K[0])
    for stage in range(3):
        rk4.stage_state(y, K, stage, h, ytmp)
        derivative_under_force(ytmp, Fx, Fy, md, K[stage + 1])
    rk4.combine(y, h, K, ynew)


@kernel
def solve_stick_step(y, h, Fx, Fy, md, ynew, ytmp, K, stats):
    """Find the constant force over a step of length ``h`` [s] that makes v_r(t_n) = 0.

    Parameters
    ----------
    y : ndarray (N_STATE,)
        Step start (in stick).
    Fx, Fy : float
        Start value of the iteration [N].
    md : ModelData
        The model (one contact).
    stats : ndarray int64
        rhs calls are added at index 2, Newton iterations at index 6, the largest iteration
        count of one solve at index 7.

    Returns
    -------
    (Fx, Fy, iterations) : the solved force [N] and the iterations used, −1 if the solve did not
    reach |v_r(t_n)| ≤ VR_TOL within MAX_NEWTON iterations. ``ynew`` holds the step end.
    """
    a11, a12, a22 = constraint_metric(y, md)
    contact = np.int64(0)
    j11 = h * a11
    j12 = h * a12
    j21 = h * a12
    j22 = h * a22
    exact = False
    res_prev = math.inf
    for it in range(1, MAX_NEWTON + 1):
        rk4_force_step(y, h, Fx, Fy, md, ynew, ytmp, K)
        stats[2] += 4
        vx, vy = P.slip_velocity(ynew, contact, md)
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
            dx = FD_REL_STEP * max(abs(Fx), abs(Fy), contact_limit(y, md))
            rk4_force_step(y, h, Fx + dx, Fy, md, ytmp, ytmp, K)
            ux, uy = P.slip_velocity(ytmp, contact, md)
            rk4_force_step(y, h, Fx, Fy + dx, md, ytmp, ytmp, K)
            wx, wy = P.slip_velocity(ytmp, contact, md)
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
        dFx, dFy, _ = P.solve_psd_2x2(n11, n12, n22, b1, b2)
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


class ForceStep(NamedTuple):
    """The arrays of NAEOM's constant-force steps in stick (n states).

    Attributes
    ----------
    y : ndarray (n,)
        The state at the step's start.
    ynew : ndarray (n,)
        The state at its end.
    ytmp : ndarray (n,)
        The state of the stage being evaluated.
    K : ndarray (4, n)
        RK4 stages (:func:`rk4_force_step`).
    history : ndarray (7,)
        The force history of the stick phase (:func:`naeom_stick_branch`).
    """

    y: np.ndarray
    ynew: np.ndarray
    ytmp: np.ndarray
    K: np.ndarray
    history: np.ndarray


@kernel
def naeom_stick_branch(step, t, h, stick, md, dense, scratch, stats):
    """A NAEOM stick step from ``step.y`` at time ``t`` [s] of length ``h`` [s], breakaway bisected.

    ``step.history`` (7,) is the force history of the current stick phase, updated here: the
    number of steps so far, then (mid-step time, Fx, Fy) of the last two steps. The start value of
    the force solve is its linear extrapolation (O(Δt²)), or the exact stick multiplier at the
    first step of a stick phase (``stick``: the contact state in stick).

    Returns (h_taken, transition, Fx, Fy, solved): the step length taken [s], 0 or
    ``events.TRANSITION_TO_SLIP``, the solved force [N], and False if a solve failed
    (:data:`MAX_NEWTON`). ``step.ynew`` holds the step end. Breakaway is bisected on re-solved
    steps, the first trials around the root on the step's interpolant (``events.bisection_point``);
    ``step.K`` (4, n), ``dense`` (n, 3) and ``scratch`` (:class:`~.bundles.Scratch`) are work
    arrays.
    """
    y, hist, ynew, ytmp, K = step.y, step.history, step.ynew, step.ytmp, step.K
    F, N = scratch.F, scratch.N
    n_hist = hist[0]
    tm = t + 0.5 * h
    if n_hist >= 2:
        slope = (tm - hist[1]) / (hist[1] - hist[4])
        gx = hist[2] + slope * (hist[2] - hist[5])
        gy = hist[3] + slope * (hist[3] - hist[6])
    elif n_hist == 1:
        gx, gy = hist[2], hist[3]
    else:
        gx, gy, _ = stick_force(y, stick, md, F, N)
    Fx, Fy, it = solve_stick_step(y, h, gx, gy, md, ynew, ytmp, K, stats)
    if it < 0:
        return h, 0, Fx, Fy, False
    transition = 0
    if E.stick_margin(ynew, stick, md, F, N) <= 0.0:
        # the step's Hermite interpolant under the solved force gives the first trials
        derivative_under_force(y, Fx, Fy, md, K[0])
        derivative_under_force(ynew, Fx, Fy, md, K[1])
        estimate = E.interpolated_crossing(E.EVENT_STICK, y, K[0], ynew, K[1], h, stick, md, dense, scratch)
        a, b, at, c = E.first_trial(estimate, h)
        while c >= 0.0:
            Fx, Fy, it = solve_stick_step(y, c * h, Fx, Fy, md, ynew, ytmp, K, stats)
            stats[3] += 1
            if it < 0:
                return h, 0, Fx, Fy, False
            a, b, at, c = E.narrowed(a, b, c, E.stick_margin(ynew, stick, md, F, N) > 0.0, estimate, h)
        if at != b:  # the last step re-taken ends before the root: re-take it to b
            Fx, Fy, it = solve_stick_step(y, b * h, Fx, Fy, md, ynew, ytmp, K, stats)
            stats[3] += 1
            if it < 0:
                return h, 0, Fx, Fy, False
        h = b * h
        transition = E.TRANSITION_TO_SLIP
    hist[4], hist[5], hist[6] = hist[1], hist[2], hist[3]
    hist[1], hist[2], hist[3] = t + 0.5 * h, Fx, Fy
    hist[0] = n_hist + 1.0
    return h, transition, Fx, Fy, True
