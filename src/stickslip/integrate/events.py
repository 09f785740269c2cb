"""Transitions of the paper's fixed-step methods (AEOM, NAEOM) on the plates' own kernels.

The event codes, tolerances and the root-finding steps (dense output, Illinois regula falsi) are
the generic event integrator's (:mod:`.contacts`); this module holds what the fixed-step
methods add on the plates' kernels: event functions of the plates' state, the step's Hermite
interpolant (a dense output ``y(θ) = y0 + h Σ_j Q[:, j] θ^(j+1)`` with three columns) and the
bisection on re-stepping.

* slip → stick: ``slip_event`` is the projection of v_r on its direction at the start of the step.
  A sign change means the 2-D velocity passed (near) zero; at the located root, if |v_r| is below
  :data:`STICK_SPEED_TOL` and the stick force is admissible (|F| ≤ μs N, Eq. 10), stick begins;
  if it is not admissible, v_r is set to zero and slip departs as at breakaway.
* stick → slip: ``stick_event`` = μs N − |F_stick|; its root is breakaway (Eq. 10). Slip starts
  with v_r = 0 in the direction e = −F_stick/|F_stick|, so F is continuous.
"""

from __future__ import annotations

import math

import numpy as np

from ..model import kernels as K
from ..model.jit import kernel
# the event codes, tolerances and root-finding steps are those of the generic event integrator
from .contacts import (ARRIVAL_TIME_TOL, EVENT_CHECKS, EVENT_SLIP, EVENT_STICK, EVENT_TIME_TOL,  # noqa: F401
                       MAX_REFINEMENTS, STICK_SPEED_TOL, TRANSITION_TO_SLIP, TRANSITION_TO_STICK, dense_state,
                       illinois_update, regula_falsi_point)


#: Largest number of bisections of one transition bracket (fixed-step methods): the bracket
#: halves each time, so 200 is far more than the ~40 needed to go from Δt = 0.1 s to
#: EVENT_TIME_TOL.
MAX_BISECTIONS = 200

#: First half-width, as a fraction of the step, of the bracket that bisection on re-stepping
#: (the fixed-step methods) tries around the root of the event on the step's cubic Hermite
#: interpolant (:func:`bisection_point`), widened ×10 while the root lies outside. AEOM's
#: breakaway roots on the interpolant were measured within 1e-8 of the re-stepped ones at
#: Δt = 1e-4 s and within 1e-6 at Δt = 1e-3 s (Sect. 4.2.1 case); the width affects only the
#: number of trials, never the root.
ROOT_BRACKET = 1e-7


@kernel
def hermite_coefficients(y0, f0, y1, f1, h, Q):
    """Cubic Hermite interpolant of a step as ``y(θ) = y0 + h Σ_j Q[:, j] θ^(j+1)`` (3 columns).

    Matches y and dy/dt = f at both ends (θ = 0, 1); 3rd order in h, the form used by
    ``events.dense_state``.
    """
    for i in range(y0.shape[0]):
        d = (y1[i] - y0[i]) / h
        Q[i, 0] = f0[i]
        Q[i, 1] = 3.0 * d - 2.0 * f0[i] - f1[i]
        Q[i, 2] = f0[i] + f1[i] - 2.0 * d


@kernel
def all_finite(y):
    """Whether every entry of ``y`` is finite: one branch on Σ y_i·0, which is NaN exactly when
    some y_i is ±inf or NaN (and never overflows), instead of one per entry (checked every step)."""
    acc = 0.0
    for i in range(y.shape[0]):
        acc += y[i] * 0.0
    return acc == 0.0


@kernel
def store_sample(idx, y, mode, Fx, Fy, out_s, out_mode, out_F):
    """Write the state, the mode flag (1 = stick, 0 = slip) and the friction force of sample ``idx``."""
    for i in range(y.shape[0]):
        out_s[idx, i] = y[i]
    out_mode[idx] = 1 if mode == K.MODE_STICK else 0
    out_F[idx, 0] = Fx
    out_F[idx, 1] = Fy


@kernel
def event_value(kind, y, e0x, e0y, minv, damp, stiff, p):
    """Event function of ``kind`` at state ``y`` (see module docstring)."""
    if kind == EVENT_SLIP:
        vx, vy = K.relative_velocity(y, p)
        return vx * e0x + vy * e0y
    Fx, Fy, _ = K.stick_force(y, minv, damp, stiff, p)
    return K.static_limit(p) - math.sqrt(Fx * Fx + Fy * Fy)


@kernel
def first_crossing(kind, y0, Q, h, e0x, e0y, minv, damp, stiff, p, work):
    """First θ ∈ (0, 1] where the event function turns ≤ 0, located to EVENT_TIME_TOL.

    The function is positive at θ = 0 by construction. Returns -1.0 if no sign change is seen
    at the EVENT_CHECKS sample points. Root refinement: Illinois regula falsi.
    """
    a = 0.0
    ga = event_value(kind, y0, e0x, e0y, minv, damp, stiff, p)
    b = -1.0
    gb = 0.0
    for j in range(1, EVENT_CHECKS + 1):
        theta = j / EVENT_CHECKS
        dense_state(y0, Q, h, theta, work)
        g = event_value(kind, work, e0x, e0y, minv, damp, stiff, p)
        if g <= 0.0:
            b = theta
            gb = g
            break
        a = theta
        ga = g
    if b < 0.0:
        return -1.0
    tol = EVENT_TIME_TOL / h if h > 0.0 else 0.0
    side = np.int64(0)  # not a literal: one compiled version of illinois_update
    for _ in range(MAX_REFINEMENTS):
        if gb == 0.0 or (b - a) <= tol:
            break
        c = regula_falsi_point(a, ga, b, gb)
        dense_state(y0, Q, h, c, work)
        gc = event_value(kind, work, e0x, e0y, minv, damp, stiff, p)
        a, ga, b, gb, side = illinois_update(a, ga, b, gb, c, gc, gc > 0.0, side)
    return b


@kernel
def interpolated_crossing(kind, y0, f0, y1, f1, h, e0x, e0y, minv, damp, stiff, p, Q, work):
    """Root θ ∈ (0, 1] of the event ``kind`` on the cubic Hermite interpolant of a step from
    (y0, f0 = dy/dt) to (y1, f1) of length ``h`` [s] (:func:`first_crossing`); −1.0 if the
    interpolant shows none. ``Q`` (n, 3) and ``work`` (n,) are work arrays.

    The estimate that bisection on re-stepping starts from (:func:`bisection_point`).
    """
    hermite_coefficients(y0, f0, y1, f1, h, Q)
    return first_crossing(kind, y0, Q, h, e0x, e0y, minv, damp, stiff, p, work)


@kernel
def bisection_point(a, b, estimate, h):
    """Next θ to re-take a step of length ``h`` [s] to, in bisection on re-stepping for the root
    bracketed by [a, b]; −1.0 once the bracket is shorter than :data:`EVENT_TIME_TOL`.

    ``estimate`` is the root on the step's interpolant (:func:`interpolated_crossing`; ≤ 0 for
    none). The trials first search outwards from it, at estimate ± w for w = ROOT_BRACKET,
    10 ROOT_BRACKET, … (each that lies inside (a, b), nearest first); once none does, [a, b] is
    halved. Every trial narrows the bracket, so a poor estimate costs a few trials and never
    the result. With a good one the halving starts from a bracket of ~1e-7 of the step instead
    of the whole step (AEOM at Δt = 1e-3 s: ~12 re-steps per breakaway instead of 31).
    """
    if (b - a) * h <= EVENT_TIME_TOL:
        return -1.0
    if estimate > 0.0:
        w = ROOT_BRACKET
        while w < 0.5:
            if a < estimate - w < b:
                return estimate - w
            if a < estimate + w < b:
                return estimate + w
            w *= 10.0
    return 0.5 * (a + b)


@kernel
def time_to_zero_of(vx, vy, ax, ay):
    """Time [s] to the closest approach of v_r = (vx, vy) to zero under constant dv_r/dt = (ax, ay).

    −(v·v)/(v·a); +inf unless v_r heads for zero within 60° of head-on (a turning slip
    direction is not an approach). Used to home the last step of an approach onto v_r = 0
    and to scale the steps of the approach.
    """
    va = vx * ax + vy * ay
    if va >= -0.5 * math.sqrt((vx * vx + vy * vy) * (ax * ax + ay * ay)):  # cos 60° = 0.5
        return math.inf
    return -(vx * vx + vy * vy) / va


@kernel
def slip_event_possible(g0, dg0, g1, dg1):
    """Whether the slip event g = v_r·e0 may reach zero inside a step (cheap pre-check).

    ``g0, g1`` are its values at the ends of the step and ``dg0, dg1`` its derivatives with
    respect to θ ∈ [0, 1] (h × dv_r/dt · e0). The cubic Hermite interpolant of these four
    numbers is checked at θ = 1/4, 1/2, 3/4 and at the end; a possible crossing is any value
    at or below half the smaller end value (so a dip towards zero that the cubic only
    approximates still gets the full check on the step's dense output by
    :func:`first_crossing`). A monotone approach (g falls from g0 to g1 > 0) needs no check.
    """
    if g1 <= 0.0:
        return True
    floor = 0.5 * min(g0, g1)
    for j in range(1, 4):
        th = 0.25 * j
        th2 = th * th
        th3 = th2 * th
        h00 = 2.0 * th3 - 3.0 * th2 + 1.0
        h10 = th3 - 2.0 * th2 + th
        h01 = -2.0 * th3 + 3.0 * th2
        h11 = th3 - th2
        if h00 * g0 + h10 * dg0 + h01 * g1 + h11 * dg1 <= floor:
            return True
    return False


@kernel
def breakaway_direction(Fx, Fy):
    """Slip direction at breakaway e = −F_stick/|F_stick| (docs/numerics.md)."""
    norm = math.sqrt(Fx * Fx + Fy * Fy)
    if norm == 0.0:
        return 1.0, 0.0
    return -Fx / norm, -Fy / norm


@kernel
def arrival_speed(y, rtol, atol):
    """|v_r| [m/s] at or below which slip has arrived at v_r = 0 for an integration at (rtol, atol).

    The larger of STICK_SPEED_TOL and ten times the velocity resolution of the error control,
    atol + rtol max|q̇_i|: below that, v_r is integration noise, its direction wanders and no
    step can home further (seen at rtol 1e-8 with |q̇| ~ 3.5 rad/s: |v_r| hovered at 2e-8).
    """
    qd = 0.0
    for i in range(6, 12):
        qd = max(qd, abs(y[i]))
    return max(STICK_SPEED_TOL, 10.0 * (atol + rtol * qd))


@kernel
def try_stick(y, minv, damp, stiff, p, speed_tol):
    """At a zero of the slip velocity: project and test stick admissibility (Eq. 10).

    If |v_r| > ``speed_tol`` [m/s] nothing happens and ``(False, 0, 0)`` is returned. Otherwise
    ``y`` is projected onto v_r = 0 in place (the residual ≤ speed_tol removed by an
    impulsive friction force, booked as friction work) and either ``(True, 0, 0)`` (stick is
    admissible) or ``(False, ex, ey)`` with the breakaway direction of the inadmissible stick
    force, along which slip departs again (a velocity reversal through zero).
    """
    vx, vy = K.relative_velocity(y, p)
    if math.sqrt(vx * vx + vy * vy) > speed_tol:
        return False, 0.0, 0.0
    K.project_velocity(y, minv, p)
    Fx, Fy, _ = K.stick_force(y, minv, damp, stiff, p)
    if math.sqrt(Fx * Fx + Fy * Fy) <= K.static_limit(p):
        return True, 0.0, 0.0
    ex, ey = breakaway_direction(Fx, Fy)
    return False, ex, ey


@kernel
def initial_mode(y, minv, damp, stiff, p):
    """Mode a state starts in: stick if v_r = 0 (to STICK_SPEED_TOL) and stick is admissible.

    Returns (mode, ex, ey); in slip, (ex, ey) is the direction used while |v_r| is ~0.
    """
    stick, ex, ey = try_stick(y, minv, damp, stiff, p, STICK_SPEED_TOL)
    if stick:
        return K.MODE_STICK, 0.0, 0.0
    vx, vy = K.relative_velocity(y, p)
    speed = math.sqrt(vx * vx + vy * vy)
    if speed > K.SPEED_FLOOR:
        return K.MODE_SLIP, vx / speed, vy / speed
    return K.MODE_SLIP, ex, ey
