"""Compiled model kernels (numba), shared by every integrator and by the analysis.

All kernels are module-level functions on flat float64 arrays:

``s``      state (≥ 12): q = [x1, y1, x2, y2, φ, ψ] then dq/dt; extra entries are ignored.
``minv``   (6,) inverse masses/inertias, 0 for a locked DOF.
``damp``   (6,) viscous damping, diagonal of C.
``stiff``  (6,) stiffness, diagonal of K.
``p``      (8,) contact and friction data, indexed by the ``P_*`` constants.

The model in matrix form: M q̈ = f + Gᵀ F, f = −C q̇ − K q, with the 2×6
contact Jacobian

    G = [[1, 0, −1,  0, −r sin φ,  Y],
         [0, 1,  0, −1,  r cos φ, −X]],

X = x1 − x2 + r cos φ, Y = y1 − y2 + r sin φ, and relative velocity v_r = G q̇ + Ω (Y, −X)
(paper Eq. 9). Gᵀ F reproduces the right-hand sides of Eq. (1).
"""

from __future__ import annotations

import math

import numpy as np

from .jit import inlined_kernel, kernel
# Indices into the packed contact/friction array ``p`` (the assembled System's layout).
from .system import N_P, P_ALPHA, P_DELTA_MU, P_LAW, P_MU_K, P_N, P_OMEGA, P_R, P_SLIP_BAND  # noqa: F401

LAW_EXPONENTIAL = 0  # paper Eq. (4)
LAW_COULOMB = 1      # μ = μk in slip, μs = μk + Δμ in stick

MODE_SLIP = 0        # slip; inside the low-speed band the direction is quasi-static (departure)
MODE_STICK = 1       # stick: friction is the constraint force
MODE_SLIP_EXACT = 2  # slip with the exact direction v_r/|v_r| at every speed (approach to stick)
MODE_SLIP_QUASI_STATIC = 3  # slip with the quasi-static direction at every speed (see below)

#: Speed [m/s] below which v_r counts as exactly zero (round-off after projection, ~1e-16 of
#: the sliding speed Ω r of the paper's cases, is far below it).
SPEED_FLOOR = 1e-13

#: Default low-speed band [m/s]: below it the slip direction is the quasi-static one
#: (:func:`quasi_static_direction`) instead of v_r/|v_r|. Near v_r = 0 the direction of 2-D
#: friction relaxes on the time scale |v_r| / (λ μ N) → 0 (a stiff mode that forces explicit
#: steps of that size); inside the band the direction sits on its slow manifold, an O(|v_r|)
#: approximation. Measured at N = 50 N, Ω = 5 rad/s and Ω = 0.5 rad/s, N = 30/50/70/120 N
#: (100 s, rtol 1e-8, against band 1e-5 at rtol 1e-11): bands 1e-5, 1e-4 and 5e-4 give the
#: same errors (≤ 6e-9 in frequency), 1e-3 and above start to show the band
#: (docs/numerics.md); 5e-4 takes 15–65 % fewer steps than 1e-4 and 1e-5.
DEFAULT_SLIP_BAND = 5e-4

#: Relative size below which the smaller eigenvalue of G M⁻¹ Gᵀ counts as zero (rank 1, as in
#: Model 4, where it is exactly 0 up to round-off, ~1e-16 relative).
RANK_TOL = 1e-10

#: Largest angle [rad] that :func:`rotated` turns by with its Taylor series (sin a to a⁹, cos a
#: to a¹⁰: truncation ≤ a¹¹/11! ≈ 2.5e-19 relative at 0.1); larger angles call sin and cos.
SMALL_ANGLE = 0.1
#: Angle [rad] below which :func:`rotated` stops its series at a⁵ and a⁶ (truncation ≤ a⁶/5040
#: ≈ 1e-20 relative at 2⁻⁹).
TINY_ANGLE = 2.0 ** -9
_S3, _S5, _S7, _S9 = -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362880.0
_C2, _C4, _C6, _C8, _C10 = -0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40320.0, -1.0 / 3628800.0


@kernel
def contact_kinematics(s, p):
    """(sin φ, cos φ, X, Y): the contact point relative to O2 [m] (paper Eqs. 2, 8)."""
    sphi = math.sin(s[4])
    cphi = math.cos(s[4])
    X, Y = contact_position_at(s, sphi, cphi, p)
    return sphi, cphi, X, Y


@kernel
def contact_position_at(s, sphi, cphi, p):
    """(X, Y) [m] with sin φ, cos φ of ``s[4]`` given."""
    r = p[P_R]
    return s[0] - s[2] + r * cphi, s[1] - s[3] + r * sphi


@kernel
def contact_rates(s, p, sphi, cphi):
    """(dX/dt, dY/dt) of the contact point relative to O2 [m/s]."""
    r = p[P_R]
    return s[6] - s[8] - r * sphi * s[10], s[7] - s[9] + r * cphi * s[10]


@kernel
def contact_position(s, p):
    """Contact point relative to O2, (X, Y) [m] (paper Eq. 2 components)."""
    _, _, X, Y = contact_kinematics(s, p)
    return X, Y


@kernel
def relative_velocity(s, p):
    """Relative velocity v_r of the upper plate against the lower one at the contact, Eq. (9) [m/s]."""
    sphi, cphi, X, Y = contact_kinematics(s, p)
    return relative_velocity_at(s, sphi, cphi, X, Y, p)


@inlined_kernel
def relative_velocity_at(s, sphi, cphi, X, Y, p):
    """:func:`relative_velocity` with the contact kinematics (sin φ, cos φ, X, Y) already computed."""
    dX, dY = contact_rates(s, p, sphi, cphi)
    w = p[P_OMEGA] + s[11]
    return dX + w * Y, dY - w * X


@kernel
def relative_velocity_acceleration(s, ds, p):
    """(v_r, dv_r/dt) [m/s, m/s²] at state ``s`` along the state derivative ``ds``, Eq. (9).

    One evaluation of the contact kinematics for both (the event integrator needs them
    together after every step).
    """
    r = p[P_R]
    sphi, cphi, X, Y = contact_kinematics(s, p)
    dphi = s[10]
    dX, dY = contact_rates(s, p, sphi, cphi)
    w = p[P_OMEGA] + s[11]
    ax = ds[6] - ds[8] - r * (cphi * dphi * dphi + sphi * ds[10]) + ds[11] * Y + w * dY
    ay = ds[7] - ds[9] + r * (cphi * ds[10] - sphi * dphi * dphi) - ds[11] * X - w * dX
    return dX + w * Y, dY - w * X, ax, ay


@kernel
def friction_coefficient(speed, p):
    """Kinetic friction coefficient μ(|v_r|) [-]: Eq. (4), or μk for the Coulomb law."""
    if p[P_LAW] == LAW_COULOMB:
        return p[P_MU_K]
    return p[P_MU_K] + p[P_DELTA_MU] * math.exp(-p[P_ALPHA] * speed)


@kernel
def static_limit(p):
    """Largest admissible stick force μs N [N], Eq. (10)."""
    return (p[P_MU_K] + p[P_DELTA_MU]) * p[P_N]


@kernel
def slip_force(speed, dx, dy, p):
    """Slip friction force F = −μ(|v_r|) N e along the unit slip direction e = (dx, dy), Eq. (3) [N]."""
    scale = -friction_coefficient(speed, p) * p[P_N]
    return scale * dx, scale * dy


@kernel
def solve_psd_2x2(a11, a12, a22, b1, b2):
    """Minimal-norm solution of the symmetric positive semi-definite system A x = b.

    Full rank: the exact inverse. Rank 1 (smaller eigenvalue below RANK_TOL of the larger,
    Model 4): x = u (u·b)/λ1 along the eigenvector u of the non-zero eigenvalue λ1.
    Rank 0: x = 0. Returns (x1, x2, rank).
    """
    tr = a11 + a22
    if tr <= 0.0:
        return 0.0, 0.0, 0
    det = a11 * a22 - a12 * a12
    if det > RANK_TOL * tr * tr:  # λ1 λ2 > RANK_TOL tr² ≥ RANK_TOL λ1²: full rank without the eigenvalues
        return (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det, 2
    half_gap = math.sqrt(0.25 * (a11 - a22) ** 2 + a12 * a12)
    lam1 = 0.5 * tr + half_gap
    lam2 = 0.5 * tr - half_gap
    if lam2 > RANK_TOL * lam1:
        return (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det, 2
    # eigenvector of lam1: choose the better conditioned of the two row forms
    u1, u2 = a12, lam1 - a11
    w1, w2 = lam1 - a22, a12
    if w1 * w1 + w2 * w2 > u1 * u1 + u2 * u2:
        u1, u2 = w1, w2
    norm2 = u1 * u1 + u2 * u2
    if norm2 == 0.0:  # A = lam1 * I_1 along an axis (a12 = 0, one diagonal entry zero)
        if a11 >= a22:
            u1, u2, norm2 = 1.0, 0.0, 1.0
        else:
            u1, u2, norm2 = 0.0, 1.0, 1.0
    c = (u1 * b1 + u2 * b2) / (lam1 * norm2)
    return c * u1, c * u2, 1


@kernel
def constraint_metric(s, minv, p):
    """Entries (a11, a12, a22) of A = G M⁻¹ Gᵀ (2×2, symmetric PSD) [1/kg]."""
    sphi, cphi, X, Y = contact_kinematics(s, p)
    return constraint_metric_at(sphi, cphi, X, Y, minv, p)


@kernel
def constraint_metric_at(sphi, cphi, X, Y, minv, p):
    """:func:`constraint_metric` with the contact kinematics already computed."""
    r = p[P_R]
    a11 = minv[0] + minv[2] + minv[4] * (r * sphi) ** 2 + minv[5] * Y * Y
    a12 = -minv[4] * r * r * sphi * cphi - minv[5] * X * Y
    a22 = minv[1] + minv[3] + minv[4] * (r * cphi) ** 2 + minv[5] * X * X
    return a11, a12, a22


@kernel
def stick_force(s, minv, damp, stiff, p):
    """Friction force that keeps v_r = 0, the Lagrange multiplier of the stick constraint [N].

    From dv_r/dt = G q̈ + h = 0 with M q̈ = f + Gᵀ F (docs/numerics.md):
    (G M⁻¹ Gᵀ) F = −(h + G M⁻¹ f), h = Ġ q̇ + Ω d(Y, −X)/dt, solved minimal-norm (rank-1 safe).
    Returns (Fx, Fy, rank).
    """
    sphi, cphi, X, Y = contact_kinematics(s, p)
    return stick_force_at(s, sphi, cphi, X, Y, minv, damp, stiff, p)


@kernel
def stick_force_at(s, sphi, cphi, X, Y, minv, damp, stiff, p):
    """:func:`stick_force` with the contact kinematics already computed."""
    r = p[P_R]
    dphi = s[10]
    dX, dY = contact_rates(s, p, sphi, cphi)
    w = p[P_OMEGA] + s[11]
    h1 = -r * cphi * dphi * dphi + w * dY
    h2 = -r * sphi * dphi * dphi - w * dX
    # a = M⁻¹ f (accelerations without friction)
    a0 = minv[0] * (-damp[0] * s[6] - stiff[0] * s[0])
    a1 = minv[1] * (-damp[1] * s[7] - stiff[1] * s[1])
    a2 = minv[2] * (-damp[2] * s[8] - stiff[2] * s[2])
    a3 = minv[3] * (-damp[3] * s[9] - stiff[3] * s[3])
    a4 = minv[4] * (-damp[4] * s[10] - stiff[4] * s[4])
    a5 = minv[5] * (-damp[5] * s[11] - stiff[5] * s[5])
    g1 = a0 - a2 - r * sphi * a4 + Y * a5
    g2 = a1 - a3 + r * cphi * a4 - X * a5
    a11, a12, a22 = constraint_metric_at(sphi, cphi, X, Y, minv, p)
    return solve_psd_2x2(a11, a12, a22, -(h1 + g1), -(h2 + g2))


@kernel
def dynamics(s, Fx, Fy, minv, damp, stiff, p, ds):
    """Time derivative of the state under friction force (Fx, Fy), Eq. (1) as M q̈ = f + Gᵀ F.

    Writes ``ds[0:12]``; if ``len(ds) >= 14`` also the power of friction on the plates,
    F·(G q̇) [W], into ``ds[12]`` and the (negative) damping power −q̇ᵀ C q̇ [W] into ``ds[13]``,
    so that integrating them gives the energy balance ΔE = W_friction + W_damping.
    """
    sphi, cphi, X, Y = contact_kinematics(s, p)
    dynamics_at(s, Fx, Fy, sphi, cphi, X, Y, minv, damp, stiff, p, ds)


@inlined_kernel
def dynamics_at(s, Fx, Fy, sphi, cphi, X, Y, minv, damp, stiff, p, ds):
    """:func:`dynamics` with the contact kinematics (sin φ, cos φ, X, Y) already computed."""
    r = p[P_R]
    # generalised friction forces Gᵀ F
    Q0 = Fx
    Q1 = Fy
    Q2 = -Fx
    Q3 = -Fy
    Q4 = r * (-sphi * Fx + cphi * Fy)
    Q5 = Y * Fx - X * Fy
    ds[0] = s[6]
    ds[1] = s[7]
    ds[2] = s[8]
    ds[3] = s[9]
    ds[4] = s[10]
    ds[5] = s[11]
    ds[6] = minv[0] * (Q0 - damp[0] * s[6] - stiff[0] * s[0])
    ds[7] = minv[1] * (Q1 - damp[1] * s[7] - stiff[1] * s[1])
    ds[8] = minv[2] * (Q2 - damp[2] * s[8] - stiff[2] * s[2])
    ds[9] = minv[3] * (Q3 - damp[3] * s[9] - stiff[3] * s[3])
    ds[10] = minv[4] * (Q4 - damp[4] * s[10] - stiff[4] * s[4])
    ds[11] = minv[5] * (Q5 - damp[5] * s[11] - stiff[5] * s[5])
    if ds.shape[0] >= 14:
        # locked DOFs have q̇ = 0 at all times, so they add nothing to either power
        ds[12] = Q0 * s[6] + Q1 * s[7] + Q2 * s[8] + Q3 * s[9] + Q4 * s[10] + Q5 * s[11]
        ds[13] = -(damp[0] * s[6] * s[6] + damp[1] * s[7] * s[7] + damp[2] * s[8] * s[8]
                   + damp[3] * s[9] * s[9] + damp[4] * s[10] * s[10] + damp[5] * s[11] * s[11])


@inlined_kernel
def rotated(c, s, angle):
    """(cos(θ + a), sin(θ + a)) from (c, s) = (cos θ, sin θ) and the angle a [rad].

    Small angles (|a| ≤ :data:`SMALL_ANGLE`, e.g. a Newton step or the change of φ over an
    RK4 stage) take the Taylor series of sin a and cos a to round-off (truncation below 1e-18
    relative), a few multiply-adds instead of a call to ``sincos``; below :data:`TINY_ANGLE`
    (the usual RK4 stage: |a| ~ 1e-5 at Δt = 1e-3 s) three terms each suffice, which shortens
    the dependency chain of every stage. Larger angles take the library sin and cos.
    """
    a2 = angle * angle  # Horner in a² with the reciprocal factorials: multiplies only, no divisions
    if a2 <= TINY_ANGLE * TINY_ANGLE:
        sin_a = angle + angle * a2 * (_S3 + a2 * _S5)
        cos_a = 1.0 + a2 * (_C2 + a2 * (_C4 + a2 * _C6))
    elif a2 <= SMALL_ANGLE * SMALL_ANGLE:
        sin_a = angle + angle * a2 * (_S3 + a2 * (_S5 + a2 * (_S7 + a2 * _S9)))
        cos_a = 1.0 + a2 * (_C2 + a2 * (_C4 + a2 * (_C6 + a2 * (_C8 + a2 * _C10))))
    else:
        sin_a = math.sin(angle)
        cos_a = math.cos(angle)
    return c * cos_a - s * sin_a, s * cos_a + c * sin_a


@kernel
def quasi_static_direction(s, ex, ey, minv, damp, stiff, p):
    """Slip direction e on the slow manifold of the direction dynamics at |v_r| → 0.

    With F = −μ N e, dv_r/dt = −A (μ N e + F_s), A = G M⁻¹ Gᵀ, F_s the stick force. The
    direction angle θ obeys θ̇ = −g(θ)/|v_r| with g = e × A (μ N e + F_s), so for small |v_r| it
    sits at a stable root g = 0 (g' > 0), where v_r grows or shrinks along e itself. At breakaway
    e = −F_s/|F_s| is such a root. Newton from the previous direction (ex, ey).
    """
    sphi, cphi, X, Y = contact_kinematics(s, p)
    vx, vy = relative_velocity_at(s, sphi, cphi, X, Y, p)
    return quasi_static_direction_at(s, sphi, cphi, X, Y, vx, vy, ex, ey, minv, damp, stiff, p)


@kernel
def quasi_static_direction_at(s, sphi, cphi, X, Y, vx, vy, ex, ey, minv, damp, stiff, p):
    """:func:`quasi_static_direction` with the contact kinematics and v_r = (vx, vy) [m/s] at ``s``
    already computed.

    Newton on g(θ) works on the unit vector (cos θ, sin θ) and turns it by each step with
    :func:`rotated`: no atan2, and no sin/cos for steps below :data:`SMALL_ANGLE`.
    """
    a11, a12, a22 = constraint_metric_at(sphi, cphi, X, Y, minv, p)
    Fx, Fy, _ = stick_force_at(s, sphi, cphi, X, Y, minv, damp, stiff, p)
    wx = a11 * Fx + a12 * Fy
    wy = a12 * Fx + a22 * Fy
    muN = friction_coefficient(math.sqrt(vx * vx + vy * vy), p) * p[P_N]
    norm = math.sqrt(ex * ex + ey * ey)
    if norm > 0.0:
        c = ex / norm
        sn = ey / norm
    else:
        c = 1.0
        sn = 0.0
    for _ in range(8):
        c2 = c * c - sn * sn  # cos 2θ, sin 2θ
        s2 = 2.0 * c * sn
        g = muN * (a12 * c2 + 0.5 * (a22 - a11) * s2) + (c * wy - sn * wx)
        dg = muN * (-2.0 * a12 * s2 + (a22 - a11) * c2) - (c * wx + sn * wy)
        if dg <= 0.0:  # not near a stable root: keep the previous direction
            break
        step = g / dg
        c, sn = rotated(c, sn, -step)
        if abs(step) < 1e-14:  # converged to round-off of an angle
            break
    return c, sn


@kernel
def exact_direction(mode, speed, p):
    """Whether slip in ``mode`` at |v_r| = ``speed`` [m/s] takes the direction v_r/|v_r|.

    Otherwise it takes the quasi-static direction (:func:`quasi_static_direction`), found from
    the last known direction. ``MODE_SLIP``: exact above the low-speed band ``p[P_SLIP_BAND]``,
    quasi-static inside it (right after breakaway |v_r| grows like t² and the direction relaxes
    onto that manifold at once). ``MODE_SLIP_EXACT``: exact at every speed (on the approach to
    stick |v_r| falls linearly and the direction only relaxes logarithmically).
    ``MODE_SLIP_QUASI_STATIC``: quasi-static at every speed — the event integrator's steps that
    start inside the band, so that the force law does not switch inside a step when |v_r|
    creeps along the band's edge (seen in Model 3 near φ = 0, where G M⁻¹ Gᵀ is nearly
    singular: the switch made every step straddling the edge fail its error test).
    """
    if mode == MODE_SLIP_EXACT:
        return speed > SPEED_FLOOR
    if mode == MODE_SLIP:
        return speed > p[P_SLIP_BAND]
    return False


@kernel
def contact_force(s, mode, ex, ey, minv, damp, stiff, p):
    """Friction force in the given mode [N]: the stick multiplier, or Eq. (3) in slip with the
    direction of :func:`exact_direction` (``(ex, ey)``: the last known direction)."""
    sphi, cphi, X, Y = contact_kinematics(s, p)
    if mode == MODE_STICK:
        Fx, Fy, _ = stick_force_at(s, sphi, cphi, X, Y, minv, damp, stiff, p)
        return Fx, Fy
    vx, vy = relative_velocity_at(s, sphi, cphi, X, Y, p)
    return slip_force_at(s, sphi, cphi, X, Y, vx, vy, mode, ex, ey, minv, damp, stiff, p)


@inlined_kernel
def slip_force_at(s, sphi, cphi, X, Y, vx, vy, mode, ex, ey, minv, damp, stiff, p):
    """Slip force of ``mode`` [N], Eq. (3), with the contact kinematics and v_r = (vx, vy) [m/s]
    at ``s`` already computed; the direction as in :func:`contact_force`."""
    speed = math.sqrt(vx * vx + vy * vy)
    if exact_direction(mode, speed, p):
        inv_speed = 1.0 / speed
        return slip_force(speed, vx * inv_speed, vy * inv_speed, p)
    dx, dy = quasi_static_direction_at(s, sphi, cphi, X, Y, vx, vy, ex, ey, minv, damp, stiff, p)
    return slip_force(speed, dx, dy, p)


@kernel
def slip_direction(s, vx, vy, ex, ey, minv, damp, stiff, p):
    """Unit slip direction at state ``s`` with v_r = (vx, vy) [m/s]: v_r/|v_r| above the low-speed
    band, inside it the quasi-static one found from the last direction (ex, ey)."""
    speed = math.sqrt(vx * vx + vy * vy)
    if speed > p[P_SLIP_BAND]:
        return vx / speed, vy / speed
    sphi, cphi, X, Y = contact_kinematics(s, p)
    return quasi_static_direction_at(s, sphi, cphi, X, Y, vx, vy, ex, ey, minv, damp, stiff, p)


@kernel
def rhs(s, mode, ex, ey, minv, damp, stiff, p, ds):
    """State derivative in slip or stick; returns the friction force (Fx, Fy) used [N] and the
    relative velocity (vx, vy) at ``s`` [m/s], Eq. (9).

    One evaluation of the contact kinematics (one sin/cos of φ) for all of it, in stick, in slip
    and in the low-speed band (this function is the integrators' inner loop, and v_r at a step's
    end is what the event tests need).
    """
    return _rhs_body(s, math.sin(s[4]), math.cos(s[4]), mode, ex, ey, minv, damp, stiff, p, ds)


@kernel
def rhs_at(s, sphi, cphi, mode, ex, ey, minv, damp, stiff, p, ds):
    """:func:`rhs` with sin φ, cos φ of ``s[4]`` given: an RK4 stage turns them from the step start
    by the stage's change of φ (:func:`rotated`) instead of calling sin and cos."""
    return _rhs_body(s, sphi, cphi, mode, ex, ey, minv, damp, stiff, p, ds)


@inlined_kernel
def _rhs_body(s, sphi, cphi, mode, ex, ey, minv, damp, stiff, p, ds):
    """The body of :func:`rhs` and :func:`rhs_at`, inlined into both (no call in between)."""
    X, Y = contact_position_at(s, sphi, cphi, p)
    vx, vy = relative_velocity_at(s, sphi, cphi, X, Y, p)
    if mode == MODE_STICK:
        Fx, Fy, _ = stick_force_at(s, sphi, cphi, X, Y, minv, damp, stiff, p)
    else:
        Fx, Fy = slip_force_at(s, sphi, cphi, X, Y, vx, vy, mode, ex, ey, minv, damp, stiff, p)
    dynamics_at(s, Fx, Fy, sphi, cphi, X, Y, minv, damp, stiff, p, ds)
    return Fx, Fy, vx, vy


@kernel
def _kinetic_energy(s, minv):
    e = 0.0
    for i in range(6):
        if minv[i] != 0.0:
            e += 0.5 * s[6 + i] * s[6 + i] / minv[i]
    return e


@kernel
def project_velocity(s, minv, p):
    """Project q̇ onto v_r = 0 in the M-metric, in place (docs/numerics.md); returns ΔE_kin [J].

    Δq̇ = −M⁻¹ Gᵀ (G M⁻¹ Gᵀ)⁺ v_r, the smallest kinetic-energy change that removes v_r: an
    impulsive friction force Gᵀλ that stops the residual slip (a perfectly plastic tangential
    impact, ΔE_kin = −½ v_rᵀ A⁺ v_r ≤ 0). If ``s`` carries the work accumulators (length ≥ 14)
    the energy change is booked as work of friction, so the energy balance stays exact.
    Locked DOFs (zero inverse mass) are not touched.
    """
    e_before = _kinetic_energy(s, minv)
    vx, vy = relative_velocity(s, p)
    a11, a12, a22 = constraint_metric(s, minv, p)
    l1, l2, _ = solve_psd_2x2(a11, a12, a22, vx, vy)
    r = p[P_R]
    sphi, cphi, X, Y = contact_kinematics(s, p)
    s[6] -= minv[0] * l1
    s[7] -= minv[1] * l2
    s[8] += minv[2] * l1
    s[9] += minv[3] * l2
    s[10] -= minv[4] * r * (-sphi * l1 + cphi * l2)
    s[11] -= minv[5] * (Y * l1 - X * l2)
    delta = _kinetic_energy(s, minv) - e_before
    if s.shape[0] >= 14:
        s[12] += delta
    return delta


@kernel
def sliding_angle(s, p):
    """Angle of v_r against the circumferential sliding direction −e_n2 [rad] (Fig. 11).

    e_n2 = (−Y, X)/R is the direction of motion of the lower plate's surface at the contact
    (Eq. 8); in steady sliding v_r = −Ω R e_n2, so the angle is 0 there, and it is always 0 in
    the reduced model. Positive counter-clockwise; NaN when v_r = 0 (stick).
    """
    vx, vy = relative_velocity(s, p)
    X, Y = contact_position(s, p)
    # reference direction −e_n2 = (Y, −X)/R
    dot = vx * Y - vy * X
    cross = Y * vy + X * vx  # (Y, −X) × (vx, vy) = Y vy + X vx
    if vx == 0.0 and vy == 0.0:
        return np.nan
    return math.atan2(cross, dot)
