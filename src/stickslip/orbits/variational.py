"""The linearised flow map across stick↔slip transitions: variational equations with saltation matrices.

The linearised flow ∂Φ(s0, t)/∂s0 of the non-smooth stick-slip system is the product of the
linearised flows of the smooth segments between transitions and of one jump matrix per
transition (docs/orbits.md, "Saltation monodromy", has the derivation):

* **smooth segments**: δṡ = J(s) δs, J the Jacobian of the right-hand side of the segment's
  mode (slip: paper Eq. 1 with Eq. 3 and the direction v_r/|v_r| of Eq. 9; stick: Eq. 1 with
  the stick multiplier of docs/numerics.md; the low-speed band after breakaway: the
  quasi-static direction of :func:`stickslip.model.kernels.quasi_static_direction`). The slip
  Jacobian is analytic in the friction force (its 1/|v_r| direction term grows without bound on the
  approach to stick, but times the time left, |v_r|/|dv_r/dt|, it stays O(1), so an explicit
  adaptive method takes geometrically shrinking steps, ~15 per decade of |v_r|); the smooth
  parts (the stick multiplier, the residual of the quasi-static direction) are differenced
  centrally. Segments are integrated by a compiled Dormand–Prince 5(4) with dense-output event
  location (:func:`integrate_variational`; scipy's DOP853 via ``SEGMENT_METHOD`` as a check).
* **stick → slip** (breakaway, h = μs N − |F_stick| = 0, paper Eq. 10): the saltation matrix
  S = I + (f⁺ − f⁻) ∇hᵀ / (∇h · f⁻).
* **leaving the low-speed band** (h = |v_r| − band, kernel switch from the quasi-static to the
  exact direction): the same formula with the two slip fields.
* **slip → stick** (v_r → 0, two conditions): the transverse slip-velocity variation
  β = u·δv_r (u ⊥ the arrival direction e) is removed by the friction impulse along u that the
  1/|v_r| direction dynamics deliver in the limit, then the saltation matrix with the scalar
  event function h = e·v_r (the event integrator's own), then the linearised projection onto
  the stick manifold v_r = 0 (in the M-metric, as :func:`kernels.project_velocity`).

The nominal trajectory and its transitions come from the ``event`` integrator
(:func:`stickslip.simulate`); each smooth segment is re-integrated together with its
variational equations from the integrator's state at the segment start, and the
re-integrated segment end is checked against the integrator's.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time as _time
import types

import numpy as np
from numba import njit
from scipy.integrate import solve_ivp

from .. import __version__
from ..integrate import dormand_prince as DP
from ..integrate import events as E
from ..integrate.events import STICK_SPEED_TOL
from ..model import kernels as K
from ..model.kernels import DEFAULT_SLIP_BAND
from ..model.parameters import Parameters
from ..model.system import System, assemble
from ..model.variants import STATE_NAMES
from .layout import free_states, stick_projected
from .section import OrbitError, flow

__all__ = ["FlowJacobian", "flow_jacobian", "free_states", "propagate", "state_jacobian",
           "saltation_matrix"]

#: |v_r| [m/s] at which the integration of an approach to stick stops and the arrival jump is
#: applied. The rest of the approach, τ = ρ_c/|dv_r/dt| (~1e-8 s for |dv_r/dt| ~ 10 m/s²), is
#: added to first order in τ by :func:`arrival_jump`; without that term the trivial multiplier
#: was off by ≈ 10 ρ_c (measured at ρ_c = 1e-7 and 1e-8 m/s), with it by 3e-8 at both. The
#: nominal v_r is resolved to ~1e-10 m/s at rtol 1e-10 (|q̇| ~ 1), so its direction at ρ_c is
#: known to ~1e-3 rad, which enters the jump only through the O(τ) term.
ARRIVAL_SPEED = 1e-7

#: Relative central-difference step for the smooth parts of the Jacobian (stick multiplier,
#: quasi-static direction residual): ε^(1/3) ≈ 6e-6 balances truncation (step²) and round-off
#: (ε/step) at ~4e-11 relative.
FD_REL_STEP = 6e-6

#: Integration tolerances of the variational segments: rtol 1e-10 as the event integrator used
#: for the flow maps of shooting (re-integrated segment ends agree with its states to ~1e-9 σ,
#: measured); atol 1e-13 on the states (≥ 1e-4 in SI on the paper's orbits) and 1e-10 on the
#: variations (entries O(0.1) to O(10) in SI). rtol 1e-11 with atol 1e-14/1e-12 was tried:
#: the round-off of the differenced stick Jacobian (~5e-11 relative) then defeats the error
#: control (3286 instead of 19 steps in the stick phase of the N = 50 N orbit).
VAR_RTOL = 1e-10
VAR_ATOL_STATE = 1e-13
VAR_ATOL_PHI = 1e-10

#: Largest mismatch between the re-integrated segment end and the event integrator's, scaled by
#: the state scale σ, and of the transition instants [s], before the result is refused: a larger
#: one means the two integrations followed different event sequences (e.g. a velocity reversal
#: through v_r = 0 that the integrator does not record as a transition).
MATCH_TOL = 1e-6
MATCH_TIME_TOL = 1e-6


# --------------------------------------------------------------------------------------------
# Compiled Jacobian kernels (state (≥ 12,), SI units)
# --------------------------------------------------------------------------------------------


@njit(cache=True)
def velocity_gradient(s, p, Dv):
    """∂v_r/∂s (2 × 12) of the relative velocity, paper Eq. (9) [1/s, m/s per rad, 1, m]."""
    r = p[K.P_R]
    sphi, cphi, X, Y = K.contact_kinematics(s, p)
    w = p[K.P_OMEGA] + s[11]
    dphi = s[10]
    for i in range(2):
        for j in range(12):
            Dv[i, j] = 0.0
    # v_x = dX + w Y,  dX = ẋ1 − ẋ2 − r sin φ φ̇,  Y = y1 − y2 + r sin φ
    Dv[0, 1] = w
    Dv[0, 3] = -w
    Dv[0, 4] = -r * cphi * dphi + w * r * cphi
    Dv[0, 6] = 1.0
    Dv[0, 8] = -1.0
    Dv[0, 10] = -r * sphi
    Dv[0, 11] = Y
    # v_y = dY − w X,  dY = ẏ1 − ẏ2 + r cos φ φ̇,  X = x1 − x2 + r cos φ
    Dv[1, 0] = -w
    Dv[1, 2] = w
    Dv[1, 4] = -r * sphi * dphi + w * r * sphi
    Dv[1, 7] = 1.0
    Dv[1, 9] = -1.0
    Dv[1, 10] = r * cphi
    Dv[1, 11] = -X


@njit(cache=True)
def friction_slope(speed, p):
    """dμ/d|v_r| of the kinetic friction coefficient [s/m]: Eq. (4), 0 for Coulomb."""
    if p[K.P_LAW] == K.LAW_COULOMB:
        return 0.0
    return -p[K.P_ALPHA] * p[K.P_DELTA_MU] * math.exp(-p[K.P_ALPHA] * speed)


@njit(cache=True)
def fixed_force_jacobian(s, Fx, Fy, minv, damp, stiff, p, J):
    """∂f/∂s (12 × 12) of Eq. (1) at a fixed friction force (Fx, Fy) [N]."""
    r = p[K.P_R]
    sphi, cphi, _, _ = K.contact_kinematics(s, p)
    for i in range(12):
        for j in range(12):
            J[i, j] = 0.0
    for i in range(6):
        J[i, 6 + i] = 1.0
        J[6 + i, 6 + i] = -minv[i] * damp[i]
        J[6 + i, i] = -minv[i] * stiff[i]
    # Q4 = r (−sin φ Fx + cos φ Fy)
    J[10, 4] += minv[4] * r * (-cphi * Fx - sphi * Fy)
    # Q5 = Y Fx − X Fy, ∂X/∂q = (1, 0, −1, 0, −r sin φ, 0), ∂Y/∂q = (0, 1, 0, −1, r cos φ, 0)
    J[11, 0] += -minv[5] * Fy
    J[11, 1] += minv[5] * Fx
    J[11, 2] += minv[5] * Fy
    J[11, 3] += -minv[5] * Fx
    J[11, 4] += minv[5] * r * (cphi * Fx + sphi * Fy)


@njit(cache=True)
def force_input(s, minv, p, B):
    """∂f/∂F (12 × 2) of Eq. (1): the rows M⁻¹ Gᵀ of the velocity equations [1/kg, 1/(kg m)]."""
    r = p[K.P_R]
    sphi, cphi, X, Y = K.contact_kinematics(s, p)
    for i in range(12):
        B[i, 0] = 0.0
        B[i, 1] = 0.0
    B[6, 0] = minv[0]
    B[7, 1] = minv[1]
    B[8, 0] = -minv[2]
    B[9, 1] = -minv[3]
    B[10, 0] = -minv[4] * r * sphi
    B[10, 1] = minv[4] * r * cphi
    B[11, 0] = minv[5] * Y
    B[11, 1] = -minv[5] * X


@njit(cache=True)
def stick_force_gradient(s, minv, damp, stiff, p, steps, dF):
    """∂F_stick/∂s (2 × 12) by central differences (the multiplier is smooth in s) [N per unit]."""
    sp = s[:12].copy()
    for j in range(12):
        h = steps[j]
        if h == 0.0:
            dF[0, j] = 0.0
            dF[1, j] = 0.0
            continue
        sp[j] = s[j] + h
        fxp, fyp, _ = K.stick_force(sp, minv, damp, stiff, p)
        sp[j] = s[j] - h
        fxm, fym, _ = K.stick_force(sp, minv, damp, stiff, p)
        sp[j] = s[j]
        dF[0, j] = (fxp - fxm) / (2.0 * h)
        dF[1, j] = (fyp - fym) / (2.0 * h)


@njit(cache=True)
def slip_force_gradient(s, p, Dv, dF):
    """∂F/∂s (2 × 12) of the slip force F = −μ(|v_r|) N v_r/|v_r| (Eq. 3), analytic:
    −N [μ' e eᵀ + μ (I − e eᵀ)/|v_r|] ∂v_r/∂s."""
    vx, vy = K.relative_velocity(s, p)
    speed = math.sqrt(vx * vx + vy * vy)
    ex = vx / speed
    ey = vy / speed
    mu = K.friction_coefficient(speed, p)
    dmu = friction_slope(speed, p)
    N = p[K.P_N]
    c = mu / speed
    m11 = -N * (dmu * ex * ex + c * (1.0 - ex * ex))
    m12 = -N * (dmu * ex * ey - c * ex * ey)
    m22 = -N * (dmu * ey * ey + c * (1.0 - ey * ey))
    for j in range(12):
        dF[0, j] = m11 * Dv[0, j] + m12 * Dv[1, j]
        dF[1, j] = m12 * Dv[0, j] + m22 * Dv[1, j]


@njit(cache=True)
def _direction_residual(s, theta, muN, minv, damp, stiff, p):
    """g(θ) = e × A (μN e + F_stick), e = (cos θ, sin θ): zero on the quasi-static direction."""
    a11, a12, a22 = K.constraint_metric(s, minv, p)
    Fx, Fy, _ = K.stick_force(s, minv, damp, stiff, p)
    wx = a11 * Fx + a12 * Fy
    wy = a12 * Fx + a22 * Fy
    c2 = math.cos(2.0 * theta)
    s2 = math.sin(2.0 * theta)
    return muN * (a12 * c2 + 0.5 * (a22 - a11) * s2) + (math.cos(theta) * wy - math.sin(theta) * wx)


@njit(cache=True)
def band_force_gradient(s, ex, ey, minv, damp, stiff, p, steps, Dv, dF):
    """∂F/∂s (2 × 12) inside the low-speed band, F = −μ(|v_r|) N e_q(s), e_q the quasi-static
    direction (root of g(θ) = 0, kernels.quasi_static_direction): ∂θ/∂s = −(∂g/∂s)/(∂g/∂θ),
    ∂g/∂s by central differences at fixed θ and μ, plus the μ(|v_r|) dependence analytically."""
    qx, qy = K.quasi_static_direction(s, ex, ey, minv, damp, stiff, p)
    theta = math.atan2(qy, qx)
    vx, vy = K.relative_velocity(s, p)
    speed = math.sqrt(vx * vx + vy * vy)
    if speed > 0.0:
        ux, uy = vx / speed, vy / speed
    else:
        ux, uy = qx, qy
    N = p[K.P_N]
    mu = K.friction_coefficient(speed, p)
    dmu = friction_slope(speed, p)
    muN = mu * N
    a11, a12, a22 = K.constraint_metric(s, minv, p)
    Fx, Fy, _ = K.stick_force(s, minv, damp, stiff, p)
    wx = a11 * Fx + a12 * Fy
    wy = a12 * Fx + a22 * Fy
    c2 = math.cos(2.0 * theta)
    s2 = math.sin(2.0 * theta)
    dg_dtheta = muN * (-2.0 * a12 * s2 + (a22 - a11) * c2) - (math.cos(theta) * wx + math.sin(theta) * wy)
    dg_dmuN = a12 * c2 + 0.5 * (a22 - a11) * s2
    sp = s[:12].copy()
    for j in range(12):
        dspeed = ux * Dv[0, j] + uy * Dv[1, j]
        h = steps[j]
        dg = dg_dmuN * N * dmu * dspeed
        if h != 0.0:
            sp[j] = s[j] + h
            gp = _direction_residual(sp, theta, muN, minv, damp, stiff, p)
            sp[j] = s[j] - h
            gm = _direction_residual(sp, theta, muN, minv, damp, stiff, p)
            sp[j] = s[j]
            dg += (gp - gm) / (2.0 * h)
        # the kernel keeps the previous direction where g has no stable root (g' ≤ 0: rank 1,
        # where the friction only acts along A's range, or the breakaway instant itself)
        dtheta = -dg / dg_dtheta if dg_dtheta > 0.0 else 0.0
        # F = −μ N (cos θ, sin θ)
        dF[0, j] = -N * dmu * dspeed * qx + muN * math.sin(theta) * dtheta
        dF[1, j] = -N * dmu * dspeed * qy - muN * math.cos(theta) * dtheta


@njit(cache=True)
def state_jacobian(s, mode, ex, ey, minv, damp, stiff, p, steps, J):
    """Jacobian ∂f/∂s (12 × 12) of the right-hand side :func:`kernels.rhs` in ``mode``.

    Same branch logic as the kernel: stick multiplier in ``MODE_STICK``; the exact direction
    v_r/|v_r| above the low-speed band (or in ``MODE_SLIP_EXACT`` above ``SPEED_FLOOR``); the
    quasi-static direction inside the band. ``steps`` (12,) are the central-difference steps
    of the smooth parts [SI units], 0 for locked states.
    """
    Dv = np.empty((2, 12))
    B = np.empty((12, 2))
    dF = np.empty((2, 12))
    velocity_gradient(s, p, Dv)
    vx, vy = K.relative_velocity(s, p)
    speed = math.sqrt(vx * vx + vy * vy)
    if mode == K.MODE_STICK:
        Fx, Fy, _ = K.stick_force(s, minv, damp, stiff, p)
        stick_force_gradient(s, minv, damp, stiff, p, steps, dF)
    elif speed > p[K.P_SLIP_BAND] or (mode == K.MODE_SLIP_EXACT and speed > K.SPEED_FLOOR):
        Fx, Fy = K.slip_force(speed, vx / speed, vy / speed, p)
        slip_force_gradient(s, p, Dv, dF)
    else:
        Fx, Fy = K.contact_force(s, mode, ex, ey, minv, damp, stiff, p)
        band_force_gradient(s, ex, ey, minv, damp, stiff, p, steps, Dv, dF)
    fixed_force_jacobian(s, Fx, Fy, minv, damp, stiff, p, J)
    force_input(s, minv, p, B)
    for i in range(6, 12):
        for j in range(12):
            J[i, j] += B[i, 0] * dF[0, j] + B[i, 1] * dF[1, j]


@njit(cache=True)
def variational_rhs(y, mode, ex, ey, minv, damp, stiff, p, steps, dy, J):
    """d/dt of y = [s (12), Φ (12 × 12, row-major)]: ṡ = f(s), Φ̇ = J(s) Φ. Fills ``J``."""
    s = y[:12]
    ds = np.empty(12)
    K.rhs(s, mode, ex, ey, minv, damp, stiff, p, ds)
    state_jacobian(s, mode, ex, ey, minv, damp, stiff, p, steps, J)
    for i in range(12):
        dy[i] = ds[i]
    for i in range(12):
        for k in range(12):
            acc = 0.0
            for j in range(12):
                acc += J[i, j] * y[12 + 12 * j + k]
            dy[12 + 12 * i + k] = acc


EV_NONE = 0
EV_SPEED = 1      # |v_r| − level
EV_BREAKAWAY = 2  # μs N − |F_stick|

#: Points per step at which the dense output is checked for an event (as events.EVENT_CHECKS):
#: a step may carry |v_r| through a minimum without ending below the level.
EV_CHECKS = 4

#: Event instants are located on the dense output to this time [s] (events.EVENT_TIME_TOL).
EV_TIME_TOL = 1e-13


@njit(cache=True)
def _ev_value(kind, y, level, minv, damp, stiff, p):
    if kind == EV_SPEED:
        vx, vy = K.relative_velocity(y, p)
        return math.sqrt(vx * vx + vy * vy) - level
    if kind == EV_BREAKAWAY:
        Fx, Fy, _ = K.stick_force(y, minv, damp, stiff, p)
        return K.static_limit(p) - math.sqrt(Fx * Fx + Fy * Fy)
    return 0.0


@njit(cache=True)
def integrate_variational(y0, t0, t1, mode, ex, ey, minv, damp, stiff, p, steps, rtol, atol,
                          ev_kind, ev_level, ev_dir, max_steps):
    """Dormand–Prince 5(4) on y = [s, Φ] (156,) from t0 towards t1, stopping at an event.

    Event ``ev_kind`` (EV_SPEED: |v_r| − ev_level; EV_BREAKAWAY: μsN − |F_stick|) crossing zero
    in direction ``ev_dir`` (+1 upward, −1 downward), checked at EV_CHECKS points of each
    accepted step's dense output and located by Illinois regula falsi to EV_TIME_TOL.
    Error control: RMS over all components with ``atol`` (156,) + rtol·|y| (as scipy).

    Returns (status, t, y): status 0 reached t1, 1 event at t, 2 step underflow, 3 max_steps.
    """
    n = y0.shape[0]
    y = y0.copy()
    ynew = np.empty(n)
    ytmp = np.empty(n)
    work = np.empty(n)
    Kst = np.empty((7, n))
    Q = np.empty((n, 4))
    J = np.empty((12, 12))
    variational_rhs(y, mode, ex, ey, minv, damp, stiff, p, steps, Kst[0], J)
    t = t0
    h = min(1e-4, t1 - t0)  # the controller grows it ×5 per step
    g0 = _ev_value(ev_kind, y, ev_level, minv, damp, stiff, p)
    n_steps = 0
    while t < t1:
        if n_steps >= max_steps:
            return 3, t, y
        n_steps += 1
        h = min(h, t1 - t)
        if h <= 1e-15 * max(1.0, abs(t)):
            return 2, t, y
        for stage in range(1, 6):
            DP.stage_state(y, Kst, h, stage, ytmp)
            variational_rhs(ytmp, mode, ex, ey, minv, damp, stiff, p, steps, Kst[stage], J)
        DP.stage_state(y, Kst, h, np.int64(6), ynew)  # not a literal: one compiled version
        variational_rhs(ynew, mode, ex, ey, minv, damp, stiff, p, steps, Kst[6], J)
        total = 0.0
        for i in range(n):
            sc = atol[i] + rtol * max(abs(y[i]), abs(ynew[i]))
            total += (DP.local_error(Kst, h, i) / sc) ** 2
        err_norm = math.sqrt(total / n)
        if not math.isfinite(err_norm) or err_norm > 1.0:
            fac = 0.2 if not math.isfinite(err_norm) else max(0.2, 0.9 * err_norm ** -0.2)
            h *= fac
            continue
        if ev_kind != EV_NONE:
            DP.dense_coefficients(Kst, Q)
            a = 0.0
            ga = g0
            b = -1.0
            gb = 0.0
            for k in range(1, EV_CHECKS + 1):
                th = k / EV_CHECKS
                if k == EV_CHECKS:
                    g = _ev_value(ev_kind, ynew, ev_level, minv, damp, stiff, p)
                else:
                    E.dense_state(y, Q, h, th, work)
                    g = _ev_value(ev_kind, work, ev_level, minv, damp, stiff, p)
                if ev_dir * ga < 0.0 and ev_dir * g >= 0.0:
                    b = th
                    gb = g
                    break
                a = th
                ga = g
            if b > 0.0:
                tol = EV_TIME_TOL / h
                side = np.int64(0)
                for _ in range(E.MAX_REFINEMENTS):
                    if gb == 0.0 or (b - a) <= tol:
                        break
                    c = E.regula_falsi_point(a, ga, b, gb)
                    E.dense_state(y, Q, h, c, work)
                    gc = _ev_value(ev_kind, work, ev_level, minv, damp, stiff, p)
                    a, ga, b, gb, side = E.illinois_update(a, ga, b, gb, c, gc, ev_dir * gc < 0.0, side)
                E.dense_state(y, Q, h, b, work)
                return 1, t + b * h, work.copy()
            g0 = _ev_value(ev_kind, ynew, ev_level, minv, damp, stiff, p)
        t += h
        for i in range(n):
            y[i] = ynew[i]
            Kst[0, i] = Kst[6, i]
        h *= 5.0 if err_norm == 0.0 else min(5.0, 0.9 * err_norm ** -0.2)
    return 0, t, y


# --------------------------------------------------------------------------------------------
# Jump matrices (pure functions of states; numpy)
# --------------------------------------------------------------------------------------------


def field(system: System, s: np.ndarray, mode: int, e=(1.0, 0.0)) -> np.ndarray:
    """Right-hand side f(s) (12,) of :func:`kernels.rhs` in ``mode`` (e: stored slip direction)."""
    ds = np.zeros(12)
    K.rhs(np.ascontiguousarray(s[:12], dtype=float), int(mode), float(e[0]), float(e[1]), system.minv,
          system.damp, system.stiff, system.p, ds)
    return ds


def saltation_matrix(f_minus: np.ndarray, f_plus: np.ndarray, grad_h: np.ndarray) -> np.ndarray:
    """S = I + (f⁺ − f⁻) ∇hᵀ / (∇h · f⁻) (12 × 12) for a transversal crossing of h(s) = 0.

    Parameters
    ----------
    f_minus, f_plus : ndarray (12,)
        Vector fields before and after the event at the event state [SI units / s].
    grad_h : ndarray (12,)
        Gradient of the event function [unit of h per SI unit].

    Raises
    ------
    OrbitError
        If the crossing is tangential (∇h · f⁻ = 0): no saltation matrix exists (grazing).
    """
    rate = float(grad_h @ f_minus)
    if rate == 0.0 or not np.isfinite(rate):
        raise OrbitError("tangential event crossing (dh/dt = 0): grazing, no saltation matrix")
    return np.eye(f_minus.size) + np.outer(f_plus - f_minus, grad_h) / rate


def _velocity_gradient(system: System, s: np.ndarray) -> np.ndarray:
    Dv = np.empty((2, 12))
    velocity_gradient(np.ascontiguousarray(s[:12], dtype=float), system.p, Dv)
    return Dv


def _force_input(system: System, s: np.ndarray) -> np.ndarray:
    B = np.empty((12, 2))
    force_input(np.ascontiguousarray(s[:12], dtype=float), system.minv, system.p, B)
    return B


def _metric(system: System, s: np.ndarray) -> np.ndarray:
    a11, a12, a22 = K.constraint_metric(np.ascontiguousarray(s[:12], dtype=float), system.minv, system.p)
    return np.array([[a11, a12], [a12, a22]])


def stick_projection(system: System, s: np.ndarray) -> np.ndarray:
    """Linearised projection onto the stick manifold v_r = 0 at a state on it (12 × 12):
    P = I − [0; M⁻¹ Gᵀ A⁺ ∂v_r/∂s] (the derivative of :func:`kernels.project_velocity`; the
    derivative of A⁺ multiplies v_r = 0). A⁺ is the minimal-norm inverse (rank 1 in Model 4)."""
    A = _metric(system, s)
    Ainv = np.linalg.pinv(A, rcond=K.RANK_TOL, hermitian=True)
    return np.eye(12) - _force_input(system, s) @ Ainv @ _velocity_gradient(system, s)


def arrival_jump(system: System, s_c: np.ndarray, s_stick: np.ndarray, departure=None) -> np.ndarray:
    """Jump matrix (12 × 12) of the variations at slip → stick (docs/orbits.md).

    Parameters
    ----------
    s_c : ndarray (12,)
        Slip state where the approach integration stopped (|v_r| = ARRIVAL_SPEED), direction
        e = v_r/|v_r| ≈ the arrival direction.
    s_stick : ndarray (12,)
        The integrator's state at the onset of stick (on v_r = 0).

    Three factors, applied right to left: (1) the transverse slip-velocity variation
    β = u·δv_r, u ⊥ e, is removed by the friction impulse M⁻¹ Gᵀ u J, J = −β/(uᵀ A u), that
    the direction dynamics (rate μN uᵀAu/|v_r| → ∞) deliver before arrival; (2) the saltation
    matrix of h = e·v_r with f⁻ the slip and f⁺ the stick field; (3) the linearised projection
    onto v_r = 0 (removes the residual O(|v_r|) of the first two).

    With ``departure`` = e_b (unit 2-vector) the stick is inadmissible (|F_stick| > μs N at
    v_r = 0: a velocity reversal, after which the integrator's slip departs along e_b): f⁺ is
    then that departing slip field and there is no projection (the perturbed motion leaves
    v_r = 0 at its own instant, δv_r⁺ = v̇_r⁺ δt).
    """
    vx, vy = K.relative_velocity(np.ascontiguousarray(s_c[:12], dtype=float), system.p)
    speed = math.hypot(vx, vy)
    e = np.array([vx, vy]) / speed
    u = np.array([-e[1], e[0]])
    A = _metric(system, s_c)
    Dv = _velocity_gradient(system, s_c)
    B = _force_input(system, s_c)
    kill = np.eye(12)
    auu = float(u @ A @ u)
    if auu > K.RANK_TOL * np.trace(A):  # rank 1 (Model 4, belt): friction cannot act along u
        kill -= np.outer(B @ u, u @ Dv) / auu
    f_minus = field(system, s_c, K.MODE_SLIP_EXACT)
    f_plus = field(system, s_c, K.MODE_STICK) if departure is None else _band_field(system, s_c, departure)
    grad_h = e @ Dv
    # the rest of the approach, τ = |v_r| / (−e · dv_r/dt), with the regular part of the slip
    # Jacobian (direction frozen at e; its 1/|v_r| part is the impulse above): first order in τ
    approach = -float(grad_h @ f_minus)  # −e · dv_r/dt [m/s²], > 0 on an approach
    if not approach > 0.0:
        raise OrbitError("the slip velocity does not head into zero at the stick arrival (grazing); "
                         "no saltation matrix")
    tau = speed / approach
    Fx, Fy = K.slip_force(speed, e[0], e[1], system.p)
    J = np.empty((12, 12))
    fixed_force_jacobian(np.ascontiguousarray(s_c[:12], dtype=float), Fx, Fy, system.minv, system.damp,
                         system.stiff, system.p, J)
    J += B @ (-system.p[K.P_N] * friction_slope(speed, system.p) * np.outer(e, grad_h))
    S = saltation_matrix(f_minus, f_plus, grad_h)
    if departure is not None:
        return S @ (np.eye(12) + tau * J) @ kill
    return stick_projection(system, s_stick) @ S @ (np.eye(12) + tau * J) @ kill


def breakaway_jump(system: System, s_b: np.ndarray, steps: np.ndarray) -> tuple[np.ndarray, tuple]:
    """Saltation matrix (12 × 12) at stick → slip, h = μs N − |F_stick| (Eq. 10), at the
    breakaway state ``s_b``; f⁺ is the slip field with the breakaway direction
    e = −F_stick/|F_stick|. Returns (S, e)."""
    s = np.ascontiguousarray(s_b[:12], dtype=float)
    Fx, Fy, _ = K.stick_force(s, system.minv, system.damp, system.stiff, system.p)
    norm = math.hypot(Fx, Fy)
    e = (-Fx / norm, -Fy / norm)
    dF = np.empty((2, 12))
    stick_force_gradient(s, system.minv, system.damp, system.stiff, system.p, steps, dF)
    grad_h = -(Fx * dF[0] + Fy * dF[1]) / norm
    f_minus = field(system, s, K.MODE_STICK)
    f_plus = field(system, s, K.MODE_SLIP, e)
    return saltation_matrix(f_minus, f_plus, grad_h) @ stick_projection(system, s), e


def band_exit_jump(system: System, s: np.ndarray, e) -> np.ndarray:
    """Saltation matrix (12 × 12) where |v_r| leaves the low-speed band (h = |v_r| − band):
    the kernel's slip force switches from the quasi-static to the exact direction."""
    s = np.ascontiguousarray(s[:12], dtype=float)
    vx, vy = K.relative_velocity(s, system.p)
    speed = math.hypot(vx, vy)
    grad_h = (np.array([vx, vy]) / speed) @ _velocity_gradient(system, s)
    # the quasi-static side, evaluated as the kernel does just inside the band
    f_minus = _band_field(system, s, e)
    f_plus = field(system, s, K.MODE_SLIP_EXACT)
    return saltation_matrix(f_minus, f_plus, grad_h)


def _band_field(system: System, s: np.ndarray, e) -> np.ndarray:
    vx, vy = K.relative_velocity(s, system.p)
    speed = math.hypot(vx, vy)
    qx, qy = K.quasi_static_direction(s, e[0], e[1], system.minv, system.damp, system.stiff, system.p)
    Fx, Fy = K.slip_force(speed, qx, qy, system.p)
    ds = np.zeros(12)
    K.dynamics(s, Fx, Fy, system.minv, system.damp, system.stiff, system.p, ds)
    return ds


# --------------------------------------------------------------------------------------------
# Segment integration
# --------------------------------------------------------------------------------------------


#: Integrator of the variational segments: "compiled" (:func:`integrate_variational`, Dormand–Prince
#: 5(4) in numba) or a scipy ``solve_ivp`` method name (e.g. "DOP853", used as a cross-check).
SEGMENT_METHOD = "compiled"

#: Step cap of one compiled segment (a 1 s piece takes ~10³ steps at rtol 1e-10).
MAX_SEGMENT_STEPS = 1_000_000


def _integrate_segment(system, y0, t_span, mode, e, steps, *, events=(), rtol=None, method=None):
    """Integrate [s, Φ] over ``t_span`` in ``mode``; stop at the (single) terminal event.

    Returns an object with ``status`` (0 end reached, 1 event), ``t`` (array, last = end time),
    ``y`` (156, 1+) and ``t_events`` (list of one array), like ``solve_ivp``'s result.
    """
    rtol = VAR_RTOL if rtol is None else rtol
    method = SEGMENT_METHOD if method is None else method
    atol = np.full(156, VAR_ATOL_PHI)
    atol[:12] = VAR_ATOL_STATE
    if method == "compiled":
        kind, level, direction = (EV_NONE, 0.0, 1) if not events else (events[0].kind, events[0].level,
                                                                         events[0].direction)
        status, t_end, y_end = integrate_variational(
            np.ascontiguousarray(y0, dtype=float), float(t_span[0]), float(t_span[1]), int(mode), float(e[0]),
            float(e[1]), system.minv, system.damp, system.stiff, system.p, steps, rtol, atol, kind, float(level),
            float(direction), MAX_SEGMENT_STEPS)
        if status > 1:
            raise OrbitError(f"variational integration failed in mode {mode} at t = {t_end} s "
                             f"({'step underflow' if status == 2 else 'too many steps'})")
        return types.SimpleNamespace(status=status, t=np.array([t_span[0], t_end]), y=y_end[:, None],
                                     t_events=[np.array([t_end]) if status == 1 else np.array([])])
    J = np.empty((12, 12))
    dy = np.empty(156)
    args = (int(mode), float(e[0]), float(e[1]), system.minv, system.damp, system.stiff, system.p, steps)

    def fun(t, y):
        variational_rhs(y, *args, dy, J)
        return dy.copy()

    sol = solve_ivp(fun, t_span, y0, method=method, rtol=rtol, atol=atol, events=list(events))
    if sol.status < 0:
        raise OrbitError(f"variational integration failed in mode {mode}: {sol.message}")
    return sol


def _speed_event(system, level, direction):
    def ev(t, y):
        vx, vy = K.relative_velocity(y[:12].copy(), system.p)
        return math.hypot(vx, vy) - level
    ev.terminal = True
    ev.direction = direction
    ev.kind, ev.level = EV_SPEED, float(level)
    return ev


def _breakaway_event(system):
    limit = K.static_limit(system.p)

    def ev(t, y):
        Fx, Fy, _ = K.stick_force(y[:12].copy(), system.minv, system.damp, system.stiff, system.p)
        return limit - math.hypot(Fx, Fy)
    ev.terminal = True
    ev.direction = -1
    ev.kind, ev.level = EV_BREAKAWAY, 0.0
    return ev


@dataclasses.dataclass(frozen=True, eq=False)
class FlowJacobian:
    """Linearised flow ∂Φ(s0, t)/∂s0 across stick↔slip transitions.

    Attributes
    ----------
    matrix : ndarray (12, 12)
        ∂s(t)/∂s0 in SI units (rows and columns of locked states are zero).
    state0, state : ndarray (12,)
        Initial and final state [SI].
    duration : float
        t [s].
    events : tuple of (float, str)
        (instant [s], kind) of every jump applied: "stick", "breakaway", "band".
    mismatch : float
        Largest scaled difference between a re-integrated segment end and the event
        integrator's state there [-] (a consistency check).
    wall_time : float
        Seconds taken.
    """

    matrix: np.ndarray
    state0: np.ndarray
    state: np.ndarray
    duration: float
    events: tuple
    mismatch: float
    wall_time: float

    def to_xarray(self):
        """``xarray.Dataset``: the matrix (12 × 12, SI), initial and final state, the jumps."""
        import xarray as xr

        data = {
            "flow_jacobian": (("state", "state_0"), self.matrix,
                              {"long_name": "linearised flow d s(t) / d s(0) (variational equations + saltation)",
                               "units": "SI"}),
            "state_initial": ("state", self.state0, {"long_name": "initial state", "units": "SI"}),
            "state_final": ("state", self.state, {"long_name": "final state", "units": "SI"}),
        }
        attrs = {"title": "stickslip linearised flow map", "stickslip_version": __version__,
                 "duration": self.duration, "duration_units": "s", "events": json.dumps(self.events),
                 "mismatch": self.mismatch, "wall_time_s": self.wall_time}
        return xr.Dataset(data, coords={"state": list(STATE_NAMES), "state_0": list(STATE_NAMES)}, attrs=attrs)


def _default_steps(system: System, scale) -> np.ndarray:
    """Difference steps (12,) of the smooth Jacobian parts: FD_REL_STEP × a state scale."""
    free = free_states(system)
    steps = np.zeros(12)
    if scale is None:
        # characteristic magnitudes of the paper's cases: 1e-3 m / 1e-2 rad, 1e-2 m/s / 0.1 rad/s
        scale12 = np.array([1e-3, 1e-3, 1e-3, 1e-3, 1e-2, 1e-2, 1e-2, 1e-2, 1e-2, 1e-2, 1e-1, 1e-1])
        steps[free] = FD_REL_STEP * scale12[free]
    else:
        steps[free] = FD_REL_STEP * np.asarray(scale, dtype=float)
    return steps


def flow_jacobian(params: Parameters, model, s0, duration: float, *, rtol: float = 1e-10,
                  atol: float | None = None, slip_band: float = DEFAULT_SLIP_BAND,
                  scale=None) -> FlowJacobian:
    """Linearised flow map ∂Φ(s0, t)/∂s0 from the variational equations with saltation matrices.

    Parameters
    ----------
    params : Parameters
    model : str
        Model variant.
    s0 : array-like (12,)
        Initial state [SI]. If it sticks (|v_r| ≤ STICK_SPEED_TOL and the stick force is
        admissible) the variations start projected onto v_r = 0.
    duration : float
        t [s].
    rtol, atol : float
        Tolerances of the ``event`` run that gives the transitions (``atol`` default 1e-3 rtol).
    slip_band : float
        Low-speed band [m/s] (as in :func:`stickslip.simulate`).
    scale : array-like (2 n_free,), optional
        State scales σ of the free states [SI] for the difference steps and the consistency
        check (default: typical magnitudes of the paper's cases).

    Returns
    -------
    FlowJacobian

    Raises
    ------
    OrbitError
        If a run fails, an event is grazing, or the re-integration departs from the event
        integrator's trajectory (different event sequence).
    """
    t_start = _time.perf_counter()
    atol = 1e-3 * rtol if atol is None else float(atol)
    system = assemble(params, model, slip_band)
    free = free_states(system)
    s0 = np.asarray(s0, dtype=float).copy()
    end, tr = flow(params, model, s0, float(duration), rtol=rtol, atol=atol, slip_band=slip_band)
    Phi = np.zeros((12, 12))
    Phi[free, free] = 1.0
    Phi, events, mismatch = propagate(system, s0, float(duration), tr, end, Phi, scale=scale)
    M = np.zeros((12, 12))
    M[np.ix_(free, free)] = Phi[np.ix_(free, free)]
    return FlowJacobian(matrix=M, state0=s0, state=np.asarray(end).copy(), duration=float(duration),
                        events=tuple(events), mismatch=mismatch, wall_time=_time.perf_counter() - t_start)


def propagate(system: System, s0, T: float, tr, end, Phi: np.ndarray, *, scale=None, after=None,
              max_interval: float = np.inf):
    """Carry the variations ``Phi`` (12 × k) along the event integrator's run from ``s0``.

    Parameters
    ----------
    system : System
    s0 : ndarray (12,)
        Initial state [SI].
    T : float
        Duration [s].
    tr : Transitions
        The run's transitions (instants, kinds, states).
    end : ndarray (12,)
        The run's final state (checked against the re-integration).
    Phi : ndarray (12, k)
        Initial variations (columns) [SI].
    scale : array-like (2 n_free,), optional
        State scales σ (difference steps, consistency checks).
    after : callable (t, Phi) -> Phi, optional
        Called after every smooth piece and every jump (e.g. QR re-orthonormalisation).
    max_interval : float
        Longest smooth piece integrated in one call [s] (``after`` is called at least that often).

    Returns
    -------
    Phi : ndarray (12, k)
    events : list of (float, str)
    mismatch : float
        Largest scaled difference between re-integrated and recorded states [-].
    """
    free = free_states(system)
    steps = _default_steps(system, scale)
    sigma = steps / FD_REL_STEP
    sigma[sigma == 0.0] = 1.0
    after = (lambda t, P: P) if after is None else after
    events = []
    mismatch = 0.0
    k_cols = Phi.shape[1]

    def check(s_var, s_ref, which=free):
        nonlocal mismatch
        d = float(np.max(np.abs(s_var[which] - s_ref[which]) / sigma[which]))
        mismatch = max(mismatch, d)
        if d > MATCH_TOL:
            raise OrbitError(
                f"the variational re-integration left the event integrator's trajectory (scaled "
                f"difference {d:.1e} > {MATCH_TOL:.0e}): the event sequence differs (grazing or "
                "a velocity reversal through v_r = 0?)"
            )

    def run(y, P, t0, t1, mode, e, evs=()):
        yv = np.concatenate([y, P.ravel()]) if k_cols == 12 else np.concatenate([y, _pad(P).ravel()])
        sol = _integrate_segment(system, yv, (t0, t1), mode, e, steps, events=evs)
        P_new = sol.y[12:, -1].reshape(12, 12)
        return sol, sol.y[:12, -1].copy(), (P_new if k_cols == 12 else P_new[:, :k_cols])

    y = np.asarray(s0, dtype=float).copy()
    vx, vy = K.relative_velocity(y, system.p)
    Fx, Fy, _ = K.stick_force(y, system.minv, system.damp, system.stiff, system.p)
    if math.hypot(vx, vy) <= STICK_SPEED_TOL and math.hypot(Fx, Fy) <= K.static_limit(system.p):
        mode, e = K.MODE_STICK, (0.0, 0.0)
        y = stick_projected(system, y)
        Phi = stick_projection(system, y) @ Phi
    elif math.hypot(vx, vy) > STICK_SPEED_TOL:
        mode, e = K.MODE_SLIP_EXACT, (vx, vy)
    else:
        mode, e = K.MODE_SLIP, (-Fx, -Fy)  # departs along the breakaway direction
    t = 0.0
    k = 0  # next transition
    n_tr = len(tr)
    while t < T:
        t_next = float(tr.time[k]) if k < n_tr else T
        t_cap = t + max_interval
        if mode == K.MODE_STICK:
            if t_cap < t_next or k >= n_tr:
                t1 = min(t_cap, t_next)
                sol, y, Phi = run(y, Phi, t, t1, mode, e)
                t = t1
                Phi = after(t, Phi)
                continue
            sol, y_b, Phi = run(y, Phi, t, t_next + 1.0, mode, e, [_breakaway_event(system)])
            if sol.status != 1 or abs(sol.t_events[0][0] - t_next) > MATCH_TIME_TOL:
                raise OrbitError(f"breakaway of the re-integration at {sol.t[-1]:.9f} s, event integrator {t_next:.9f} s")
            s_b = tr.state[k]
            check(y_b, s_b)
            Sb, e = breakaway_jump(system, s_b, steps)
            Phi = after(t_next, Sb @ Phi)
            events.append((t_next, "breakaway"))
            y, t, mode, k = s_b.copy(), t_next, K.MODE_SLIP, k + 1
        elif mode == K.MODE_SLIP:
            # departure inside the low-speed band: quasi-static direction until |v_r| = band
            t1 = min(t_cap, t_next)
            sol, y, Phi = run(y, Phi, t, t1, mode, e, [_speed_event(system, system.p[K.P_SLIP_BAND], 1)])
            if sol.status == 1:
                t = float(sol.t[-1])
                Phi = band_exit_jump(system, y, e) @ Phi
                events.append((t, "band"))
                mode = K.MODE_SLIP_EXACT
            elif t1 == t_next and k < n_tr:
                raise OrbitError("slip → stick inside the low-speed band is not supported")
            else:
                t = t1
            Phi = after(t, Phi)
        else:
            expect_stick = k < n_tr and t_cap >= t_next
            t1 = t_next + 1.0 if expect_stick else min(t_cap, t_next)
            sol, s_c, Phi_c = run(y, Phi, t, t1, mode, e, [_speed_event(system, ARRIVAL_SPEED, -1)])
            t_ev = float(sol.t[-1])
            if sol.status == 1 and expect_stick and abs(t_ev - t_next) <= MATCH_TIME_TOL:
                s_s = tr.state[k]
                # positions only (extrapolated over the rest of the approach to the integrator's
                # instant): the velocities differ by that O(τ) rest and by the integrator's
                # projection of its arrival residual (≤ STICK_SPEED_TOL)
                s_x = s_c + (t_next - t_ev) * field(system, s_c, K.MODE_SLIP_EXACT)
                check(s_x, s_s, system.variant.free_indices)
                Phi = after(t_next, arrival_jump(system, s_c, s_s) @ Phi_c)
                events.append((t_next, "stick"))
                y, t, mode, e, k = s_s.copy(), t_next, K.MODE_STICK, (0.0, 0.0), k + 1
            elif sol.status == 1 and t_ev < t_next - MATCH_TIME_TOL:
                # v_r reaches 0 before the next recorded transition: the stick force must be
                # inadmissible there (a velocity reversal, which the integrator does not record)
                s_r = stick_projected(system, s_c)
                Fx, Fy, _ = K.stick_force(s_r, system.minv, system.damp, system.stiff, system.p)
                norm = math.hypot(Fx, Fy)
                if norm <= K.static_limit(system.p):
                    raise OrbitError(f"the re-integration reaches an admissible stick at {t_ev:.9f} s, the event "
                                     f"integrator does not (next transition {t_next:.9f} s): the event "
                                     "sequences differ (e.g. a return to v_r ≈ 0 inside the low-speed band)")
                e_b = (-Fx / norm, -Fy / norm)
                Phi = after(t_ev, arrival_jump(system, s_c, s_r, departure=e_b) @ Phi_c)
                events.append((t_ev, "reversal"))
                y, t, mode, e = s_r, t_ev, K.MODE_SLIP, e_b
            elif sol.status == 0 and not expect_stick:
                y, t, Phi = s_c, t1, after(t1, Phi_c)
            else:
                raise OrbitError(f"arrival at stick of the re-integration at {t_ev:.9f} s, "
                                 f"event integrator {t_next:.9f} s")
    check(y, end)
    return Phi, events, mismatch


def _pad(P: np.ndarray) -> np.ndarray:
    out = np.zeros((12, 12))
    out[:, :P.shape[1]] = P
    return out


#: Names that moved to :mod:`.problem` (the shooting problem and an orbit's monodromy), still
#: importable from here.
_MOVED = ("METHODS", "Monodromy", "monodromy", "fd_monodromy", "sorted_eigenvalues")


def __getattr__(name):
    if name in _MOVED:
        from . import problem

        return getattr(problem, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
