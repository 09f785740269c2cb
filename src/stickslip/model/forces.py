"""Friction forces of all contacts in their modes: slip, the low-speed band and stick.

* slip: F_c = −μ(|v_c|) N_c e_c with e_c = v_c/|v_c| (:func:`slip_force`); which modes and speeds
  take that direction is :func:`exact_direction`'s decision;
* inside the low-speed band: the quasi-static direction for a 2-D contact
  (:func:`quasi_static_direction`, found with the force that would hold the contact,
  :func:`band_forces`), the stored direction for a 1-D contact;
* stick: the Lagrange multipliers of all sticking contacts, solved together
  (:func:`~stickslip.model.stick.solve_stick_rows`);
* closed rigid contacts: their normal forces λ are multipliers too (:func:`rigid_normal_forces`),
  and so is the friction of one that slides, −μ λ e.

:func:`sliding_forces` computes the common case, every contact sliding outside the band, on the
caller's stack arrays (:func:`sliding_friction` its friction forces alone, for the queries);
:func:`general_forces_body` any mix of modes. Both fill the generalised force
f = f0 − C q̇ − K q + Σ G_cᵀ F_c, from which :mod:`stickslip.model.physics` writes the state
derivative and answers its per-contact queries.
"""

from __future__ import annotations

import math

import numpy as np

from . import csmath as csm
from .bundle import CST, H_BAND, gap_offset
from .frames import add_force_of, all_frames, contact_velocity, frame_with_bias
from .impact import inverse_mass_product
from .jit import inlined_kernel, kernel, standalone
from .kinematics import contact_dim, frame_for_sums, model_sizes, rigid_kernel
from .linalg import solve_in_order
from .model_data import MODE_SLIP, MODE_SLIP_EXACT, MODE_STICK, SPEED_FLOOR, base_force_of, is_stick, kinetic_coefficient
from .normal import MODE_OPEN, add_normal_forces, any_rigid_closed, is_open, is_rigid, normal_in_mode, open_in_mode
from .stack import CONTACTS, DOFS, ROWS, work_matrix, work_vectors
from .stick import solve_stick_rows

__all__ = ["exact_direction", "slip_force", "rotated", "quasi_static_direction", "general_forces_body", "band_forces",
           "general_forces", "sliding_friction", "sliding_forces", "rigid_normal_forces", "add_rigid_normal_forces"]


# ----------------------------------------------------------------------------- slip forces
@kernel
def exact_direction(mode, speed, band):
    """Whether slip in ``mode`` at |v| = ``speed`` takes the direction v/|v| (else the quasi-static one).

    ``MODE_SLIP``: exact above the low-speed band, quasi-static inside it (right after breakaway
    |v| grows like t² and the direction relaxes onto its slow manifold at once).
    ``MODE_SLIP_EXACT``: exact at every speed (the approach to stick). ``MODE_SLIP_QUASI_STATIC``:
    quasi-static at every speed (steps that start inside the band, so that the force law does
    not switch inside a step).
    """
    if mode == MODE_SLIP_EXACT:
        return speed > SPEED_FLOOR
    if mode == MODE_SLIP:
        return speed > band
    return False


@inlined_kernel
def slip_force(md, n, c, dim, speed, e0, e1, normal):
    """Slip friction force −μ(|v|) N e of contact ``c`` along the unit direction e [N]."""
    scale = -kinetic_coefficient(md, n, c, speed) * normal
    if dim == 2:
        return scale * e0, scale * e1
    return scale * e0, csm.zero(scale)


@inlined_kernel
def rotated(c, s, angle):
    """(cos(θ + a), sin(θ + a)) from (c, s) = (cos θ, sin θ) and the angle a [rad]."""
    ca = csm.cos(angle)
    sa = csm.sin(angle)
    return c * ca - s * sa, s * ca + c * sa


@kernel
def quasi_static_direction(a11, a12, a22, Fx, Fy, muN, ex, ey):
    """Slip direction on the slow manifold of the 2-D direction dynamics at |v| → 0.

    With F = −μ N e, dv/dt = −A (μ N e + F_s), A = G M⁻¹ Gᵀ (the contact's block), F_s the force
    that would keep v = 0. The direction angle θ obeys θ̇ = −g(θ)/|v| with g = e × A (μ N e + F_s),
    so for small |v| it sits at a stable root g = 0 (g' > 0), where v grows or shrinks along e
    itself. At breakaway e = −F_s/|F_s| is such a root. Newton from the previous direction
    (ex, ey), turning the unit vector by each step. Real arithmetic: the Jacobians take the band's
    direction from this same residual (:mod:`stickslip.model.derivatives`).
    """
    wx = a11 * Fx + a12 * Fy
    wy = a12 * Fx + a22 * Fy
    norm = math.sqrt(ex * ex + ey * ey)
    if norm > 0.0:
        c = ex / norm
        sn = ey / norm
    else:
        c = 1.0
        sn = 0.0
    for _ in range(8):
        c2 = c * c - sn * sn
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


# ----------------------------------------------------------------------------- forces of all contacts
@inlined_kernel
def general_forces_body(s, cst, md, G, w, v, N, h, F, f):
    """Every contact's friction force at ``s`` in the modes of ``cst`` (any mix of slip, band and
    stick); fills the caller's work arrays (numbers of the state's type): the frame rows G (2 nc, n),
    drive velocities w (2 nc) [m/s], slip velocities v (2 nc) [m/s], normal forces N (nc) [N],
    velocity biases h (2 nc) [m/s²], friction forces F (2 nc) [N] and the generalised force
    f = f0 − C q̇ − K q + Σ G_cᵀ F_c (n). The model's sizes are read from ``md``.

    Order: slip forces with the exact direction, then those inside the low-speed band (their
    quasi-static direction sees the forces already known), then the stick multipliers of all
    sticking contacts together, then the normal forces of closed rigid contacts. Returns the
    smallest relative pivot of the last (:func:`rigid_normal_forces`; 1.0 without them).
    """
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    band = m[H_BAND]
    A = work_matrix(md.kin, ROWS, ROWS, s)
    all_frames(s, cst, md, n, nc, G, w, v, N, h, np.int64(1))
    base_force_of(md.kin, s, m, n, diagonal, f)
    add_normal_forces(s, cst, md, n, nc, N, f)
    in_band = False
    for c in range(nc):
        mode = np.int64(cst[CST * c])
        if mode == MODE_STICK:
            continue
        if mode == MODE_OPEN:
            F[2 * c] = csm.zero(s[0])
            F[2 * c + 1] = csm.zero(s[0])
            continue
        dim = contact_dim(md.kin, m, n, c)
        speed = csm.sqrt(v[2 * c] * v[2 * c] + v[2 * c + 1] * v[2 * c + 1])
        if exact_direction(mode, speed.real, band):
            inv = 1.0 / speed
            F0, F1 = slip_force(md, n, c, dim, speed, v[2 * c] * inv, v[2 * c + 1] * inv, N[c])
            F[2 * c] = F0
            F[2 * c + 1] = F1
            add_force_of(md.kin, c, G[2 * c:2 * c + 2], dim, n, F0, F1, f)
        else:
            in_band = True
    if in_band:
        band_forces(s, cst, md, G, w, v, N, h, F, f, A)
    if solve_stick_rows(s, md, n, nc, diagonal, cst, np.int64(-1), G, h, f, F, A)[0] > 0:
        for c in range(nc):
            if is_stick(cst, c):
                add_force_of(md.kin, c, G[2 * c:2 * c + 2], contact_dim(md.kin, m, n, c), n, F[2 * c], F[2 * c + 1], f)
    return add_rigid_normal_forces(s, cst, md, n, nc, diagonal, G, v, N, F, f, A)


@rigid_kernel(lambda s, cst, md, n, nc, diagonal, G, v, N, F, f, A: 1.0, inline="always")
def add_rigid_normal_forces(s, cst, md, n, nc, diagonal, G, v, N, F, f, A):  # pragma: no cover - compiled only
    """:func:`rigid_normal_forces` where some rigid contact is closed, returning its smallest
    relative pivot; 1.0 where none is (and, at compile time, for kinematics registered without
    rigid contacts)."""
    if any_rigid_closed(cst, md, n, nc):
        return rigid_normal_forces(s, cst, md, n, nc, diagonal, G, v, N, F, f, A)
    return 1.0


@standalone
@kernel
def rigid_normal_forces(s, cst, md, n, nc, diagonal, G, v, N, F, f, A):
    """Normal forces λ_R of the closed rigid contacts R: the multipliers that keep their gaps'
    accelerations at 0, with everything that depends on them (the friction of a sliding one,
    −μ λ e, and the response of the stick multipliers), added to N, F and f.

    Called with ``f``, ``F`` the forces at λ_R = 0 (every other force in its mode, the stick
    multipliers solved). Everything in the acceleration is affine in λ_R, so with r_j the
    generalised force of a unit λ_j (W_jᵀ, its sliding friction −μ G_jᵀ e_j, and the stick
    multipliers' response to both, solved with zero bias):

        q̈ = M⁻¹ (f + Σ_j λ_j r_j),   g̈_i = W_i q̈ = 0   →   D λ = −W M⁻¹ f,   D_ij = W_i M⁻¹ r_j

    (g affine in q, so g̈ = W q̈). D is W M⁻¹ Wᵀ (symmetric positive definite) when nothing slides;
    a sliding rigid contact adds −μ W M⁻¹ Gᵀ e, which can make a pivot of D non-positive: then
    the closed contact problem has no solution or two (Painlevé), reported by the return value,
    the smallest pivot relative to W_i M⁻¹ W_iᵀ (1 without friction; ≤ 0: inconsistent).
    """
    m = md.m
    band = m[H_BAND]
    R = work_matrix(md.kin, CONTACTS, DOFS, s)      # r_j
    RF = work_matrix(md.kin, CONTACTS, ROWS, s)     # the friction forces that come with a unit λ_j
    D = work_matrix(md.kin, CONTACTS, CONTACTS, s)
    a, d, zero_bias, Fs, lam, b, W = work_vectors(md.kin, 7, s)
    zero = csm.zero(s[0])
    inverse_mass_product(m, n, diagonal, f, a)
    for i in range(2 * nc):
        zero_bias[i] = zero
    k = np.int64(0)  # not a literal: one compiled version of solve_in_order
    for r in range(nc):
        if not is_rigid(md, n, r) or is_open(cst, r):
            continue
        og = gap_offset(n, r)
        for j in range(n):
            R[k, j] = m[og + j] + zero
        for i in range(2 * nc):
            RF[k, i] = zero
        dim = contact_dim(md.kin, m, n, r)
        if not is_stick(cst, r):
            speed = csm.sqrt(v[2 * r] * v[2 * r] + v[2 * r + 1] * v[2 * r + 1])
            if exact_direction(np.int64(cst[CST * r]), speed.real, band):
                e0 = v[2 * r] / speed
                e1 = v[2 * r + 1] / speed
            else:
                e0 = cst[CST * r + 1] + zero
                e1 = cst[CST * r + 2] + zero
            F0, F1 = slip_force(md, n, r, dim, speed, e0, e1, 1.0)
            RF[k, 2 * r] = F0
            RF[k, 2 * r + 1] = F1
            add_force_of(md.kin, r, G[2 * r:2 * r + 2], dim, n, F0, F1, R[k])
        if solve_stick_rows(s, md, n, nc, diagonal, cst, np.int64(-1), G, zero_bias, R[k], Fs, A)[0] > 0:
            for c in range(nc):
                if is_stick(cst, c):
                    RF[k, 2 * c] = Fs[2 * c]
                    RF[k, 2 * c + 1] = Fs[2 * c + 1]
                    add_force_of(md.kin, c, G[2 * c:2 * c + 2], contact_dim(md.kin, m, n, c), n, Fs[2 * c],
                                 Fs[2 * c + 1], R[k])
        k += 1
    i = 0
    for r in range(nc):  # row i: g̈_i = 0, scaled by W_i M⁻¹ W_iᵀ so that the pivots are relative
        if not is_rigid(md, n, r) or is_open(cst, r):
            continue
        og = gap_offset(n, r)
        for j in range(n):
            W[j] = m[og + j] + zero
        inverse_mass_product(m, n, diagonal, W, d)
        scale = zero
        acc = zero
        for j in range(n):
            scale += W[j] * d[j]
            acc += W[j] * a[j]
        b[i] = -acc / scale
        for jj in range(k):
            inverse_mass_product(m, n, diagonal, R[jj], d)
            acc = zero
            for j in range(n):
                acc += W[j] * d[j]
            D[i, jj] = acc / scale
        i += 1
    smallest = solve_in_order(D, b, lam, k)
    i = 0
    for r in range(nc):
        if is_rigid(md, n, r) and not is_open(cst, r):
            N[r] = lam[i]
            i += 1
    for jj in range(k):
        for j in range(n):
            f[j] += lam[jj] * R[jj, j]
        for j in range(2 * nc):
            F[j] += lam[jj] * RF[jj, j]
    return smallest


@standalone
@kernel
def band_forces(s, cst, md, G, w, v, N, h, F, f, A):
    """Slip forces of the contacts inside the low-speed band into F and f (after those with the
    exact direction, whose forces are in ``f`` already): the
    quasi-static direction for a 2-D contact, found with the force that would hold it (the others
    as they are), the stored direction for a 1-D contact. ``A`` (≥ 2 nc square): work."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    band = m[H_BAND]
    for c in range(nc):
        mode = np.int64(cst[CST * c])
        if mode == MODE_STICK or mode == MODE_OPEN:
            continue
        dim = contact_dim(md.kin, m, n, c)
        speed = csm.sqrt(v[2 * c] * v[2 * c] + v[2 * c + 1] * v[2 * c + 1])
        if exact_direction(mode, speed.real, band):
            continue
        ex = cst[CST * c + 1]
        ey = cst[CST * c + 2]
        if dim == 2:
            frame_with_bias(s, c, md, G[2 * c:2 * c + 2], w[2 * c:2 * c + 2], h[2 * c:2 * c + 2])
            k, a00, a01, a11 = solve_stick_rows(s, md, n, nc, diagonal, cst, c, G, h, f, F, A)
            if k == 2:
                muN = (kinetic_coefficient(md, n, c, speed) * N[c]).real
                ex, ey = quasi_static_direction(a00.real, a01.real, a11.real,
                                                F[2 * c].real, F[2 * c + 1].real, muN, ex, ey)
        F0, F1 = slip_force(md, n, c, dim, speed, ex, ey, N[c])
        F[2 * c] = F0
        F[2 * c + 1] = F1
        add_force_of(md.kin, c, G[2 * c:2 * c + 2], dim, n, F0, F1, f)


@standalone
@kernel
def general_forces(s, cst, md, G, w, v, N, h, F, f):
    """:func:`general_forces_body` as a call (for the queries and the right-hand side's path for
    stick and the band)."""
    return general_forces_body(s, cst, md, G, w, v, N, h, F, f)


@inlined_kernel
def sliding_friction(s, cst, md, n, nc, G, w, v, N, F):
    """The friction forces of the common case, every contact sliding outside the low-speed band:
    fills w, v, N and F, and G but for a heap class (whose rows the sums read from its lists:
    :func:`~stickslip.model.kinematics.frame_for_sums`), and returns True; returns False (arrays
    incomplete) as soon as a contact sticks or is inside the band, or when a rigid contact is closed
    (its normal force is a multiplier)."""
    m = md.m
    for c in range(nc):
        if is_stick(cst, c):
            return False
    if any_rigid_closed(cst, md, n, nc):
        return False
    band = m[H_BAND]
    for c in range(nc):
        G2 = G[2 * c:2 * c + 2]
        normal = frame_for_sums(md.kin, s, c, m, G2, w[2 * c:2 * c + 2])
        dim = contact_dim(md.kin, m, n, c)
        v0, v1 = contact_velocity(md.kin, s, n, c, dim, G2, w[2 * c:2 * c + 2])
        v[2 * c] = v0
        v[2 * c + 1] = v1
        normal = normal_in_mode(s, cst, md, n, c, normal)
        N[c] = normal
        if open_in_mode(cst, md, c):  # no normal force, no friction
            F[2 * c] = csm.zero(normal)
            F[2 * c + 1] = csm.zero(normal)
            continue
        speed = csm.sqrt(v0 * v0 + v1 * v1)
        if not exact_direction(np.int64(cst[CST * c]), speed.real, band):
            return False
        inv = 1.0 / speed
        F0, F1 = slip_force(md, n, c, dim, speed, v0 * inv, v1 * inv, normal)
        F[2 * c] = F0
        F[2 * c + 1] = F1
    return True


@inlined_kernel
def sliding_forces(s, cst, md, n, nc, diagonal, G, w, v, N, F, f):
    """:func:`sliding_friction` and the generalised force f = f0 − C q̇ − K q + Σ G_cᵀ F_c on the
    caller's (stack) arrays; False (arrays incomplete) when a contact sticks or is in the band."""
    if not sliding_friction(s, cst, md, n, nc, G, w, v, N, F):
        return False
    m = md.m
    base_force_of(md.kin, s, m, n, diagonal, f)
    for c in range(nc):
        add_force_of(md.kin, c, G[2 * c:2 * c + 2], contact_dim(md.kin, m, n, c), n, F[2 * c], F[2 * c + 1], f)
    add_normal_forces(s, cst, md, n, nc, N, f)
    return True
