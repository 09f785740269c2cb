"""The physics of every friction-contact model, written once, compiled per kinematics class.

    M q̈ = f0 − C q̇ − K q + Σ_c G_c(q)ᵀ F_c,     v_c = G_c(q) q̇ − w_c(q)

with, for each contact c (1-D or 2-D slip velocity v_c, normal force N_c, friction law μ):

* slip: F_c = −μ(|v_c|) N_c e_c with e_c = v_c/|v_c| above the low-speed band, inside it the
  quasi-static direction (:func:`quasi_static_direction`) for 2-D contacts and the stored one for
  1-D contacts;
* stick: F_c is the Lagrange multiplier that keeps v_c = 0. The multipliers of all sticking
  contacts S are solved together from dv_S/dt = G_S q̈ + h_S = 0:

      (G_S M⁻¹ G_Sᵀ) F_S = −(h_S + G_S M⁻¹ f),   h = Ġ q̇ − ẇ   (the velocity bias)

  minimal-norm when G_S M⁻¹ G_Sᵀ is rank-deficient (:func:`solve_psd`), e.g. the plates' Model 4.
  The bias h is the derivative of v along q̇ at fixed q̇, taken by complex step of the model's
  frame (exact to round-off; zero for constant kinematics).

The kernels are generic in the number type: the same code runs on ``float64`` states (the
simulators) and on ``complex128`` states (Jacobians by complex step, :mod:`stickslip.model.derivatives`).
Branches read real parts only and no ``abs`` touches the state, so the complex step stays exact;
inside a complex evaluation the bias h is a central difference instead (:func:`frame_with_bias`).

Common arguments: ``s`` the state [q, q̇] (entries from 2n on are carried along: the integrators
keep the work of friction and damping there); ``cst`` (4 nc,) each contact's integration state
[mode, ex, ey, τ] (:data:`MODE_SLIP` …; the stored slip direction); ``md`` the model
(:class:`~stickslip.model.bundle.ModelData`). Work arrays live on each kernel's stack
(:mod:`stickslip.model.stack`).
"""

from __future__ import annotations

import math

import numpy as np

from . import csmath as csm
from .bundle import CST, C_LAW, H_BAND, H_CONSTANT, contact_offsets, offsets
from .friction import LAW_WIDTH, friction_coefficient, static_coefficient
from .jit import inlined_kernel, kernel
from .kinematics import contact_dim, contact_frame, model_sizes
from .stack import DOFS, ONE, ROWS, STATES, TWO, VECTORS, work_matrix

__all__ = ["MODE_SLIP", "MODE_STICK", "MODE_SLIP_EXACT", "MODE_SLIP_QUASI_STATIC", "SPEED_FLOOR", "RANK_TOL",
           "rhs", "rhs_body", "contact_forces", "normal_force", "stick_margin", "stick_forces", "project_velocities", "slip_velocity",
           "slip_velocity_and_rate", "slip_direction", "band_direction", "static_limit", "kinetic_energy", "solve_psd",
           "solve_psd_2x2", "contact_dim", "frame_with_bias", "COMPLEX_STEP"]

MODE_SLIP = 0        # slip; inside the low-speed band the direction is quasi-static (departure)
MODE_STICK = 1       # stick: friction is the constraint force
MODE_SLIP_EXACT = 2  # slip with the exact direction v/|v| at every speed (approach to stick)
MODE_SLIP_QUASI_STATIC = 3  # slip with the quasi-static direction at every speed

#: Speed [m/s] below which a slip velocity counts as exactly zero (round-off after projection).
SPEED_FLOOR = 1e-13

#: Relative size below which an eigenvalue of G_S M⁻¹ G_Sᵀ counts as zero (rank deficiency,
#: e.g. the plates' Model 4, where it is exactly 0 up to round-off ~1e-16 relative).
RANK_TOL = 1e-10

#: Complex step [-] of the velocity bias: h² ≪ round-off and h·|∂f| far above the smallest
#: normal double, so Im f(x + i h d)/h is the directional derivative exactly.
COMPLEX_STEP = 1e-150

#: Central-difference step [s] of the velocity bias inside a complex evaluation, scaled by
#: 1/max|q̇|: the positions move by ~1e-5 of their unit, truncation and round-off ~1e-10 relative.
BIAS_TIME_STEP = 1e-5

#: Sweeps of cyclic Jacobi before giving up (each sweep roughly squares the off-diagonal norm;
#: 30 is far more than the ~6–10 a small symmetric matrix needs).
JACOBI_SWEEPS = 30


# ----------------------------------------------------------------------------- model data
@inlined_kernel
def law_row(m, n, c):
    """Friction law row of contact ``c`` (a view of ``m``)."""
    o = contact_offsets(n, c)[0] + C_LAW
    return m[o:o + LAW_WIDTH]


@inlined_kernel
def static_limit(m, n, c, normal):
    """Largest admissible stick force μs N [N] of contact ``c`` (paper Eq. 10)."""
    return static_coefficient(law_row(m, n, c)) * normal.real


@inlined_kernel
def is_stick(cst, c):
    return np.int64(cst[CST * c]) == MODE_STICK


@inlined_kernel
def apply_inverse_mass(m, n, diagonal, f, a):
    """a = M⁻¹ f (locked DOFs: 0)."""
    o = offsets(n)[0]
    if diagonal:
        for i in range(n):
            a[i] = m[o + i * (n + 1)] * f[i]
    else:
        for i in range(n):
            acc = csm.zero(f[0])
            for j in range(n):
                acc += m[o + i * n + j] * f[j]
            a[i] = acc


@inlined_kernel
def base_force(s, m, n, diagonal, f):
    """f = f0 − C q̇ − K q, the generalised force without friction."""
    o_minv, o_mass, oc, ok, of, o_free, o_c = offsets(n)
    if diagonal:
        for i in range(n):
            f[i] = m[of + i] - m[oc + i * (n + 1)] * s[n + i] - m[ok + i * (n + 1)] * s[i]
    else:
        for i in range(n):
            acc = m[of + i] + csm.zero(s[0])
            for j in range(n):
                acc -= m[oc + i * n + j] * s[n + j] + m[ok + i * n + j] * s[j]
            f[i] = acc


@kernel
def kinetic_energy(s, md):
    """½ q̇ᵀ M q̇ [J]."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    o = offsets(n)[1]
    e = 0.0
    for i in range(n):
        if diagonal:
            e += 0.5 * m[o + i * (n + 1)] * s[n + i] * s[n + i]
        else:
            for j in range(n):
                e += 0.5 * s[n + i] * m[o + i * n + j] * s[n + j]
    return e


# ----------------------------------------------------------------------------- linear algebra
@inlined_kernel
def solve_psd_2x2(a11, a12, a22, b1, b2):
    """Minimal-norm solution of the symmetric positive semi-definite 2×2 system A x = b.

    Full rank: the exact inverse. Rank 1 (smaller eigenvalue below RANK_TOL of the larger):
    x = u (u·b)/λ1 along the eigenvector u of the non-zero eigenvalue λ1. Rank 0: x = 0.
    Returns (x1, x2, rank). Decisions read real parts (complex-step safe).
    """
    tr = a11 + a22
    if tr.real <= 0.0:
        return csm.zero(b1), csm.zero(b2), 0
    det = a11 * a22 - a12 * a12
    if det.real > RANK_TOL * (tr * tr).real:  # λ1 λ2 > RANK_TOL tr² ≥ RANK_TOL λ1²: full rank
        return (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det, 2
    half_gap = csm.sqrt(0.25 * (a11 - a22) ** 2 + a12 * a12)
    lam1 = 0.5 * tr + half_gap
    lam2 = 0.5 * tr - half_gap
    if lam2.real > RANK_TOL * lam1.real:
        return (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det, 2
    # eigenvector of lam1: the better conditioned of the two row forms
    u1, u2 = a12, lam1 - a11
    w1, w2 = lam1 - a22, a12
    if (w1 * w1 + w2 * w2).real > (u1 * u1 + u2 * u2).real:
        u1, u2 = w1, w2
    norm2 = u1 * u1 + u2 * u2
    if norm2.real == 0.0:  # A = lam1 along an axis (a12 = 0, one diagonal entry zero)
        one = 1.0 + csm.zero(a11)
        if a11.real >= a22.real:
            u1, u2, norm2 = one, csm.zero(a11), one
        else:
            u1, u2, norm2 = csm.zero(a11), one, one
    c = (u1 * b1 + u2 * b2) / (lam1 * norm2)
    return c * u1, c * u2, 1


@kernel
def solve_psd(A, b, x, V, k):
    """Minimal-norm solution x (k,) of the symmetric PSD system A[:k, :k] x = b[:k]; returns the rank.

    k ≤ 2 in closed form (:func:`solve_psd_2x2`); larger systems (several sticking 2-D contacts)
    by cyclic Jacobi rotations A → Vᵀ A V = Λ, x = V Λ⁺ Vᵀ b, eigenvalues below RANK_TOL of the
    largest treated as zero. ``A`` and ``V`` (≥ k × k) are overwritten when k > 2.
    """
    if k == 0:
        return 0
    if k == 1:
        if A[0, 0].real > 0.0:
            x[0] = b[0] / A[0, 0]
            return 1
        x[0] = csm.zero(b[0])
        return 0
    if k == 2:
        x0, x1, rank = solve_psd_2x2(A[0, 0], A[0, 1], A[1, 1], b[0], b[1])
        x[0] = x0
        x[1] = x1
        return rank
    for i in range(k):
        for j in range(k):
            V[i, j] = 1.0 if i == j else 0.0
    scale = 0.0
    for i in range(k):
        for j in range(k):
            scale += (A[i, j] * A[i, j]).real
    for _ in range(JACOBI_SWEEPS):
        off = 0.0
        for p in range(k):
            for q in range(p + 1, k):
                off += (A[p, q] * A[p, q]).real
        if off <= 1e-32 * scale:
            break
        for p in range(k):
            for q in range(p + 1, k):
                apq = A[p, q]
                if apq.real == 0.0:
                    continue
                theta = (A[q, q] - A[p, p]) / (2.0 * apq)
                sign = 1.0 if theta.real >= 0.0 else -1.0
                t = sign / (sign * theta + csm.sqrt(theta * theta + 1.0))
                c = 1.0 / csm.sqrt(t * t + 1.0)
                sn = t * c
                for r in range(k):  # A ← A J
                    arp = A[r, p]
                    arq = A[r, q]
                    A[r, p] = c * arp - sn * arq
                    A[r, q] = sn * arp + c * arq
                for r in range(k):  # A ← Jᵀ A
                    apr = A[p, r]
                    aqr = A[q, r]
                    A[p, r] = c * apr - sn * aqr
                    A[q, r] = sn * apr + c * aqr
                for r in range(k):  # V ← V J
                    vrp = V[r, p]
                    vrq = V[r, q]
                    V[r, p] = c * vrp - sn * vrq
                    V[r, q] = sn * vrp + c * vrq
    lam_max = 0.0
    for i in range(k):
        lam_max = max(lam_max, A[i, i].real)
    rank = 0
    for i in range(k):
        x[i] = csm.zero(b[0])
    for j in range(k):
        if A[j, j].real <= RANK_TOL * lam_max:
            continue
        rank += 1
        coef = csm.zero(b[0])
        for i in range(k):
            coef += V[i, j] * b[i]
        coef /= A[j, j]
        for i in range(k):
            x[i] += V[i, j] * coef
    return rank


# ----------------------------------------------------------------------------- frames
@inlined_kernel
def frame_velocity(s, n, dim, G2, w2):
    """(v0, v1) = G q̇ − w of one contact from its frame rows (v1 = 0 for a 1-D contact)."""
    v0 = -w2[0]
    for j in range(n):
        v0 += G2[0, j] * s[n + j]
    v1 = csm.zero(s[0])
    if dim == 2:
        v1 = -w2[1]
        for j in range(n):
            v1 += G2[1, j] * s[n + j]
    return v0, v1


@inlined_kernel
def _frame_bias_complex_step(s, c, md, G2, w2, h2):
    """Float state: the frame at q + iε q̇ gives G, w (real parts, exact) and h = Im[G q̇ − w]/ε
    (exact to round-off) in one evaluation; 0 for constant kinematics."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    if m[H_CONSTANT] != 0.0:
        h2[0] = 0.0
        h2[1] = 0.0
        return contact_frame(md.kin, s, c, m, G2, w2)
    zc = work_matrix(md.kin, ONE, STATES, 1j)[0]
    cG = work_matrix(md.kin, TWO, DOFS, 1j)
    cw = work_matrix(md.kin, ONE, TWO, 1j)[0]
    for j in range(n):
        zc[j] = complex(s[j], COMPLEX_STEP * s[n + j])
        zc[n + j] = s[n + j]
    normal = contact_frame(md.kin, zc, c, m, cG, cw)
    split_complex_frame(s, n, cG, cw, G2, w2, h2)
    return normal.real


@inlined_kernel
def split_complex_frame(s, n, cG, cw, G2, w2, h2):
    """G, w = real parts of the frame at q + iε q̇; h = Im[G q̇ − w]/ε."""
    h0 = -cw[0].imag
    h1 = -cw[1].imag
    for j in range(n):
        h0 += cG[0, j].imag * s[n + j]
        h1 += cG[1, j].imag * s[n + j]
        G2[0, j] = cG[0, j].real
        G2[1, j] = cG[1, j].real
    w2[0] = cw[0].real
    w2[1] = cw[1].real
    h2[0] = h0 / COMPLEX_STEP
    h2[1] = h1 / COMPLEX_STEP


@inlined_kernel
def max_rate(s, n):
    """max |Re q̇_j| of a (complex) state."""
    speed = 0.0
    for j in range(n):
        speed = max(speed, abs(s[n + j].real))
    return speed


@kernel
def _frame_bias_central(s, c, md, G2, w2, h2):
    """Complex state (inside a complex-step Jacobian): the frame itself, and h as the central
    difference of G(q ± ε q̇) q̇ − w(q ± ε q̇) over 2ε, ε = BIAS_TIME_STEP / max|q̇| (~1e-10 relative)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    h2[0] = 0j
    h2[1] = 0j
    if m[H_CONSTANT] == 0.0:
        zc = work_matrix(md.kin, ONE, STATES, s)[0]
        cG = work_matrix(md.kin, TWO, DOFS, s)
        cw = work_matrix(md.kin, ONE, TWO, s)[0]
        eps = BIAS_TIME_STEP / max(max_rate(s, n), 1e-300)
        for side in (1.0, -1.0):
            for j in range(n):
                zc[j] = s[j] + side * eps * s[n + j]
                zc[n + j] = s[n + j]
            contact_frame(md.kin, zc, c, m, cG, cw)
            v0, v1 = frame_velocity(s, n, 2, cG, cw)
            h2[0] += side * v0 / (2.0 * eps)
            h2[1] += side * v1 / (2.0 * eps)
    return contact_frame(md.kin, s, c, m, G2, w2)


@kernel
def frame_with_bias(s, c, md, G2, w2, h2):
    """Contact ``c``'s frame (G, w; returns N) and velocity bias h = Ġ q̇ − ẇ = dv/dt at q̈ = 0:
    by complex step in a float evaluation, by central difference inside a complex one."""
    if isinstance(s[0], complex):  # resolved at compile time: one branch per number type
        return _frame_bias_central(s, c, md, G2, w2, h2)
    return _frame_bias_complex_step(s, c, md, G2, w2, h2)


@inlined_kernel
def all_frames(s, cst, md, n, nc, G, w, v, N, h, with_bias):
    """Each contact's G (rows 2c, 2c+1), w, v = G q̇ − w (entries 2c, 2c+1) and N (entry c) at
    ``s``; with the velocity bias h for contacts in stick (all contacts if ``with_bias`` is 2)."""
    m = md.m
    for c in range(nc):
        G2 = G[2 * c:2 * c + 2]
        w2 = w[2 * c:2 * c + 2]
        if with_bias == 2 or (with_bias == 1 and is_stick(cst, c)):
            N[c] = frame_with_bias(s, c, md, G2, w2, h[2 * c:2 * c + 2])
        else:
            N[c] = contact_frame(md.kin, s, c, m, G2, w2)
        v0, v1 = frame_velocity(s, n, contact_dim(md.kin, m, n, c), G2, w2)
        v[2 * c] = v0
        v[2 * c + 1] = v1


# ----------------------------------------------------------------------------- slip forces
@inlined_kernel
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
def slip_force(m, n, c, dim, speed, e0, e1, normal):
    """Slip friction force −μ(|v|) N e of contact ``c`` along the unit direction e [N]."""
    scale = -friction_coefficient(speed, law_row(m, n, c)) * normal
    if dim == 2:
        return scale * e0, scale * e1
    return scale * e0, csm.zero(scale)


@inlined_kernel
def add_contact_force(G2, dim, n, F0, F1, f):
    """f += G_cᵀ F_c for one contact's frame rows G2."""
    for j in range(n):
        f[j] += G2[0, j] * F0
    if dim == 2:
        for j in range(n):
            f[j] += G2[1, j] * F1


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


# ----------------------------------------------------------------------------- stick forces
@kernel
def stick_system(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A):
    """Stick multipliers of the contacts in stick and of contact ``extra`` (≥ 0; −1: none), solved
    together: (G_S M⁻¹ G_Sᵀ) F_S = −(h_S + G_S M⁻¹ f), with h_S already in ``h``.

    Writes F of those contacts; ``A`` (≥ 2 nc square) receives G_S M⁻¹ G_Sᵀ (intact when k ≤ 2).
    ``f`` is the generalised force of everything else (not changed). Returns the rows k (0: none).
    """
    m = md.m
    MG = work_matrix(md.kin, ROWS, DOFS, s)
    vec = work_matrix(md.kin, VECTORS, VECTORS, s)
    a = vec[0]
    b = vec[1]
    x = vec[2]
    V = work_matrix(md.kin, ROWS, ROWS, s)
    apply_inverse_mass(m, n, diagonal, f, a)
    k = 0
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            for i in range(contact_dim(md.kin, m, n, c)):
                apply_inverse_mass(m, n, diagonal, G[2 * c + i], MG[k])
                acc = h[2 * c + i]
                for j in range(n):
                    acc += G[2 * c + i, j] * a[j]
                b[k] = -acc
                k += 1
    if k == 0:
        return 0
    r = 0
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            for i in range(contact_dim(md.kin, m, n, c)):
                for r2 in range(k):
                    acc = csm.zero(s[0])
                    for j in range(n):
                        acc += G[2 * c + i, j] * MG[r2, j]
                    A[r, r2] = acc
                r += 1
    solve_psd(A, b, x, V, k)
    r = 0
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            dim = contact_dim(md.kin, m, n, c)
            F[2 * c] = x[r]
            F[2 * c + 1] = x[r + 1] if dim == 2 else csm.zero(s[0])
            r += dim
    return k


@inlined_kernel
def stick_rows(md, m, n, nc, cst, extra):
    """Stick rows of the sticking contacts and contact ``extra`` (≥ 0; −1: none): their number k and,
    when k ≤ 2, the first two (contact c's row i is 2c + i; −1 for none)."""
    k = 0
    r0 = -1
    r1 = -1
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            for i in range(contact_dim(md.kin, m, n, c)):
                if k == 0:
                    r0 = 2 * c + i
                elif k == 1:
                    r1 = 2 * c + i
                k += 1
    return k, r0, r1


@inlined_kernel
def small_stick_system(s, md, n, diagonal, r0, r1, G, h, f, F):
    """:func:`stick_system` for one or two stick rows (``r0``, and ``r1`` ≥ 0 or −1), written out on
    the caller's stack: the common case of stick. Returns (a00, a01, a11), the entries of
    G_S M⁻¹ G_Sᵀ (a01 = a11 = 0 for one row)."""
    m = md.m
    vec = work_matrix(md.kin, VECTORS, VECTORS, s)
    a = vec[0]
    mg0 = vec[1]
    mg1 = vec[2]
    apply_inverse_mass(m, n, diagonal, f, a)
    apply_inverse_mass(m, n, diagonal, G[r0], mg0)
    a00 = csm.zero(s[0])
    b0 = h[r0]
    for j in range(n):
        a00 += G[r0, j] * mg0[j]
        b0 += G[r0, j] * a[j]
    zero = csm.zero(b0)
    if r1 < 0:
        F[r0] = -b0 / a00 if a00.real > 0.0 else zero
        if r0 % 2 == 0:
            F[r0 + 1] = zero
        return a00, zero, zero
    apply_inverse_mass(m, n, diagonal, G[r1], mg1)
    a01 = csm.zero(s[0])
    a11 = csm.zero(s[0])
    b1 = h[r1]
    for j in range(n):
        a01 += G[r0, j] * mg1[j]
        a11 += G[r1, j] * mg1[j]
        b1 += G[r1, j] * a[j]
    x0, x1, rank = solve_psd_2x2(a00, a01, a11, -b0, -b1)
    F[r0] = x0
    F[r1] = x1
    if r0 % 2 == 0 and r1 != r0 + 1:  # two 1-D contacts: their unused second components
        F[r0 + 1] = zero
    if r1 % 2 == 0:
        F[r1 + 1] = zero
    return a00, a01, a11


@inlined_kernel
def solve_stick_rows(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A):
    """Stick multipliers of the sticking contacts and contact ``extra`` (F written for those), by
    :func:`small_stick_system` when there are at most two rows, else :func:`stick_system`. Returns
    (k, a00, a01, a11): the rows and, for k = 2, the entries of G_S M⁻¹ G_Sᵀ."""
    k, r0, r1 = stick_rows(md, md.m, n, nc, cst, extra)
    zero = csm.zero(s[0])
    if k == 0:
        return 0, zero, zero, zero
    if k <= 2:
        a00, a01, a11 = small_stick_system(s, md, n, diagonal, r0, r1, G, h, f, F)
        return k, a00, a01, a11
    stick_system(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A)
    return k, zero, zero, zero


@inlined_kernel
def general_forces_body(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f):
    """Every contact's friction force at ``s`` in the modes of ``cst`` (any mix of slip, band and
    stick); fills G, w, v, N, h, F and the total generalised force f = f0 − C q̇ − K q + Σ G_cᵀ F_c.

    Order: slip forces with the exact direction, then those inside the low-speed band (their
    quasi-static direction sees the forces already known), then the stick multipliers of all
    sticking contacts together.
    """
    m = md.m
    band = m[H_BAND]
    A = work_matrix(md.kin, ROWS, ROWS, s)
    all_frames(s, cst, md, n, nc, G, w, v, N, h, np.int64(1))
    base_force(s, m, n, diagonal, f)
    in_band = False
    for c in range(nc):
        mode = np.int64(cst[CST * c])
        if mode == MODE_STICK:
            continue
        dim = contact_dim(md.kin, m, n, c)
        speed = csm.sqrt(v[2 * c] * v[2 * c] + v[2 * c + 1] * v[2 * c + 1])
        if exact_direction(mode, speed.real, band):
            inv = 1.0 / speed
            F0, F1 = slip_force(m, n, c, dim, speed, v[2 * c] * inv, v[2 * c + 1] * inv, N[c])
            F[2 * c] = F0
            F[2 * c + 1] = F1
            add_contact_force(G[2 * c:2 * c + 2], dim, n, F0, F1, f)
        else:
            in_band = True
    if in_band:
        band_forces(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f, A)
    if solve_stick_rows(s, md, n, nc, diagonal, cst, np.int64(-1), G, h, f, F, A)[0] > 0:
        for c in range(nc):
            if is_stick(cst, c):
                add_contact_force(G[2 * c:2 * c + 2], contact_dim(md.kin, m, n, c), n, F[2 * c], F[2 * c + 1], f)


@kernel
def band_forces(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f, A):
    """Slip forces of the contacts inside the low-speed band (after those with the exact direction,
    whose forces are in ``f`` already): the quasi-static direction for a 2-D contact, found with the
    force that would hold it (the others as they are), the stored direction for a 1-D contact."""
    m = md.m
    band = m[H_BAND]
    for c in range(nc):
        mode = np.int64(cst[CST * c])
        if mode == MODE_STICK:
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
                muN = (friction_coefficient(speed, law_row(m, n, c)) * N[c]).real
                ex, ey = quasi_static_direction(a00.real, a01.real, a11.real,
                                                F[2 * c].real, F[2 * c + 1].real, muN, ex, ey)
        F0, F1 = slip_force(m, n, c, dim, speed, ex, ey, N[c])
        F[2 * c] = F0
        F[2 * c + 1] = F1
        add_contact_force(G[2 * c:2 * c + 2], dim, n, F0, F1, f)


@kernel
def general_forces(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f):
    """:func:`general_forces_body` as a call (for the queries; :func:`general_rhs` inlines it)."""
    general_forces_body(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f)


# ----------------------------------------------------------------------------- derivative
@inlined_kernel
def write_derivative(s, md, n, nc, diagonal, v, w, F, f, ds):
    """ds = [q̇, M⁻¹ f]; with room, the friction power Σ F_c·(G_c q̇) = Σ F_c·(v_c + w_c) and the
    damping power −q̇ᵀ C q̇ [W] at 2n, 2n + 1 (integrated, they close the energy balance)."""
    m = md.m
    for i in range(n):
        ds[i] = s[n + i]
    apply_inverse_mass(m, n, diagonal, f, ds[n:2 * n])
    if ds.shape[0] >= 2 * n + 2:
        power = csm.zero(s[0])
        for i in range(2 * nc):
            power += F[i] * (v[i] + w[i])
        ds[2 * n] = power
        oc = offsets(n)[2]
        damping = csm.zero(s[0])
        if diagonal:
            for i in range(n):
                damping -= m[oc + i * (n + 1)] * s[n + i] * s[n + i]
        else:
            for i in range(n):
                for j in range(n):
                    damping -= s[n + i] * m[oc + i * n + j] * s[n + j]
        ds[2 * n + 1] = damping


@kernel
def general_rhs(s, cst, md, ds):
    """:func:`rhs` for any mix of modes (the path of stick and of the low-speed band)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    vec = work_matrix(md.kin, VECTORS, VECTORS, s)
    w = vec[0]
    v = vec[1]
    N = vec[2]
    h = vec[3]
    F = vec[4]
    f = vec[5]
    general_forces_body(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f)
    write_derivative(s, md, n, nc, diagonal, v, w, F, f, ds)


@inlined_kernel
def sliding_forces(s, cst, md, n, nc, diagonal, G, w, v, N, F, f):
    """The common case on the caller's (stack) arrays: every contact sliding outside the low-speed
    band. Fills G, w, v, N, F and f = f0 − C q̇ − K q + Σ G_cᵀ F_c and returns True; returns False
    (arrays incomplete) as soon as a contact sticks or is inside the band."""
    m = md.m
    for c in range(nc):
        if is_stick(cst, c):
            return False
    band = m[H_BAND]
    base_force(s, m, n, diagonal, f)
    for c in range(nc):
        G2 = G[2 * c:2 * c + 2]
        normal = contact_frame(md.kin, s, c, m, G2, w[2 * c:2 * c + 2])
        N[c] = normal
        dim = contact_dim(md.kin, m, n, c)
        v0, v1 = frame_velocity(s, n, dim, G2, w[2 * c:2 * c + 2])
        v[2 * c] = v0
        v[2 * c + 1] = v1
        speed = csm.sqrt(v0 * v0 + v1 * v1)
        if not exact_direction(np.int64(cst[CST * c]), speed.real, band):
            return False
        inv = 1.0 / speed
        F0, F1 = slip_force(m, n, c, dim, speed, v0 * inv, v1 * inv, normal)
        F[2 * c] = F0
        F[2 * c + 1] = F1
        add_contact_force(G2, dim, n, F0, F1, f)
    return True


@inlined_kernel
def rhs_body(s, cst, md, ds):
    """Body of :func:`rhs`, inlined into the integrators' stage loops.

    The common case, every contact sliding outside the low-speed band, is computed here on
    stack arrays (kept in registers); stick and the band go to :func:`general_rhs`.
    """
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    vec = work_matrix(md.kin, VECTORS, VECTORS, s)
    w = vec[0]
    v = vec[1]
    N = vec[2]
    F = vec[3]
    f = vec[4]
    if sliding_forces(s, cst, md, n, nc, diagonal, G, w, v, N, F, f):
        write_derivative(s, md, n, nc, diagonal, v, w, F, f, ds)
    else:
        general_rhs(s, cst, md, ds)


@kernel
def rhs(s, cst, md, ds):
    """State derivative ds/dt = [q̇, M⁻¹ (f0 − C q̇ − K q + Σ G_cᵀ F_c)] in the modes of ``cst``.

    Writes ds[0:2n] and, when ``ds`` has room, the friction and damping power at 2n, 2n + 1.
    """
    rhs_body(s, cst, md, ds)


# ----------------------------------------------------------------------------- queries
@kernel
def contact_forces(s, cst, md, F_out, N_out, v_out):
    """Each contact's friction force F (2 nc,) [N], normal force N (nc,) [N] and slip velocity
    v (2 nc,) [m/s] at ``s`` in the modes of ``cst`` (contact c at entries 2c, 2c+1 / c)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    vec = work_matrix(md.kin, VECTORS, VECTORS, s)
    w = vec[0]
    v = vec[1]
    N = vec[2]
    h = vec[3]
    F = vec[4]
    f = vec[5]
    if not sliding_forces(s, cst, md, n, nc, diagonal, G, w, v, N, F, f):
        general_forces(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f)
    for c in range(nc):
        N_out[c] = N[c]
        for i in range(2):
            F_out[2 * c + i] = F[2 * c + i]
            v_out[2 * c + i] = v[2 * c + i]


@kernel
def stick_forces(s, cst, extra, md, F_out, N_out):
    """Stick multipliers F (2 nc,) [N] of the sticking contacts and contact ``extra`` (≥ 0, or −1),
    the other contacts slipping in their modes; N_out (nc,) the normal forces. Returns the rows."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    A = work_matrix(md.kin, ROWS, ROWS, s)
    vec = work_matrix(md.kin, VECTORS, VECTORS, s)
    w = vec[0]
    v = vec[1]
    N = vec[2]
    h = vec[3]
    F = vec[4]
    f = vec[5]
    general_forces(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f)
    if extra >= 0 and not is_stick(cst, extra):
        # solve again with the extra contact held: remove the forces of the contacts to be solved
        for c in range(nc):
            if is_stick(cst, c) or c == extra:
                add_contact_force(G[2 * c:2 * c + 2], contact_dim(md.kin, m, n, c), n, -F[2 * c], -F[2 * c + 1], f)
        frame_with_bias(s, extra, md, G[2 * extra:2 * extra + 2], w[2 * extra:2 * extra + 2],
                        h[2 * extra:2 * extra + 2])
        k = solve_stick_rows(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A)[0]
    else:
        k = stick_rows(md, m, n, nc, cst, np.int64(-1))[0]
    for c in range(nc):
        N_out[c] = N[c]
        F_out[2 * c] = F[2 * c]
        F_out[2 * c + 1] = F[2 * c + 1]
    return k


@kernel
def stick_margin(s, cst, c, md):
    """μs N_c − |F_c| [N] of sticking contact ``c`` at ``s``: the stick → slip event (paper Eq. 10),
    with the multipliers of all sticking contacts solved together."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    vec = work_matrix(md.kin, VECTORS, VECTORS, s)
    w = vec[0]
    v = vec[1]
    N = vec[2]
    h = vec[3]
    F = vec[4]
    f = vec[5]
    general_forces_body(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f)
    return static_limit(m, n, c, N[c]) - math.sqrt(F[2 * c] * F[2 * c] + F[2 * c + 1] * F[2 * c + 1])


@kernel
def slip_velocity(s, c, md):
    """Slip velocity (v0, v1) of contact ``c`` at ``s`` [m/s] (v1 = 0 for a 1-D contact)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G2 = work_matrix(md.kin, TWO, DOFS, s)
    w2 = work_matrix(md.kin, ONE, TWO, s)[0]
    contact_frame(md.kin, s, c, m, G2, w2)
    return frame_velocity(s, n, contact_dim(md.kin, m, n, c), G2, w2)


@kernel
def normal_force(s, c, md):
    """Normal force N_c [N] of contact ``c`` at ``s``."""
    G2 = work_matrix(md.kin, TWO, DOFS, s)
    w2 = work_matrix(md.kin, ONE, TWO, s)[0]
    return contact_frame(md.kin, s, c, md.m, G2, w2)


@kernel
def slip_velocity_and_rate(s, ds, c, md):
    """(v0, v1, a0, a1): slip velocity of contact ``c`` [m/s] and its rate dv/dt [m/s²] along the
    state derivative ``ds`` (one complex-step frame: v = Re, dv/dt = Im / ε of G(q + iε q̇)(q̇ + iε q̈)
    − w(q + iε q̇))."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    zc = work_matrix(md.kin, ONE, STATES, 1j)[0]
    cG = work_matrix(md.kin, TWO, DOFS, 1j)
    cw = work_matrix(md.kin, ONE, TWO, 1j)[0]
    for j in range(n):
        zc[j] = complex(s[j], COMPLEX_STEP * ds[j])
        zc[n + j] = s[n + j]
    contact_frame(md.kin, zc, c, m, cG, cw)
    # Re and Im of G (q̇ + iε q̈) − w, written out: Im needs Im G q̇ + Re G ε q̈ only
    v0 = -cw[0].real
    v1 = -cw[1].real
    a0 = -cw[0].imag
    a1 = -cw[1].imag
    for j in range(n):
        qd = s[n + j]
        qdd = COMPLEX_STEP * ds[n + j]
        v0 += cG[0, j].real * qd
        v1 += cG[1, j].real * qd
        a0 += cG[0, j].imag * qd + cG[0, j].real * qdd
        a1 += cG[1, j].imag * qd + cG[1, j].real * qdd
    if contact_dim(md.kin, m, n, c) == 1:
        v1 = 0.0
        a1 = 0.0
    return v0, v1, a0 / COMPLEX_STEP, a1 / COMPLEX_STEP


@kernel
def band_direction(s, cst, c, md, speed):
    """Slip direction (e0, e1) of slipping contact ``c`` inside the low-speed band (|v| = ``speed``):
    the quasi-static one for a 2-D contact, the stored one for a 1-D contact."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    ex = cst[CST * c + 1]
    ey = cst[CST * c + 2]
    if contact_dim(md.kin, m, n, c) == 1:
        return ex, 0.0
    G = work_matrix(md.kin, ROWS, DOFS, s)
    A = work_matrix(md.kin, ROWS, ROWS, s)
    vec = work_matrix(md.kin, VECTORS, VECTORS, s)
    w = vec[0]
    v = vec[1]
    N = vec[2]
    h = vec[3]
    F = vec[4]
    f = vec[5]
    general_forces(s, cst, md, n, nc, diagonal, G, w, v, N, h, F, f)
    for c2 in range(nc):  # solve again with this contact held: remove the forces to be solved
        if is_stick(cst, c2) or c2 == c:
            add_contact_force(G[2 * c2:2 * c2 + 2], contact_dim(md.kin, m, n, c2), n, -F[2 * c2], -F[2 * c2 + 1], f)
    frame_with_bias(s, c, md, G[2 * c:2 * c + 2], w[2 * c:2 * c + 2], h[2 * c:2 * c + 2])
    k, a00, a01, a11 = solve_stick_rows(s, md, n, nc, diagonal, cst, c, G, h, f, F, A)
    if k != 2:
        return ex, ey
    muN = friction_coefficient(speed, law_row(m, n, c)) * N[c]
    return quasi_static_direction(a00, a01, a11, F[2 * c], F[2 * c + 1], muN, ex, ey)


@kernel
def slip_direction(s, cst, c, md, v0, v1):
    """Unit slip direction (e0, e1) of slipping contact ``c`` with slip velocity (v0, v1) at ``s``:
    v/|v| above the low-speed band, inside it :func:`band_direction`."""
    speed = math.sqrt(v0 * v0 + v1 * v1)
    if speed > md.m[H_BAND]:
        return v0 / speed, v1 / speed
    return band_direction(s, cst, c, md, speed)


@kernel
def project_velocities(s, cst, extra, md):
    """Project q̇ onto v_c = 0 for every sticking contact and contact ``extra`` (≥ 0; −1: none),
    in the M-metric, in place; returns the kinetic energy change [J] (≤ 0).

    Δq̇ = −M⁻¹ G_Sᵀ (G_S M⁻¹ G_Sᵀ)⁺ v_S: the smallest kinetic-energy change that removes v_S, an
    impulsive friction force (a perfectly plastic tangential impact). If ``s`` carries the work
    accumulators (length ≥ 2n + 2) the change is booked as work of friction, so the energy balance
    stays exact. Locked DOFs (zero rows of M⁻¹) are not touched.
    """
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    MG = work_matrix(md.kin, ROWS, DOFS, s)
    A = work_matrix(md.kin, ROWS, ROWS, s)
    V = work_matrix(md.kin, ROWS, ROWS, s)
    vec = work_matrix(md.kin, VECTORS, VECTORS, s)
    w = vec[0]
    b = vec[1]
    x = vec[2]
    k = 0
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            G2 = G[2 * c:2 * c + 2]
            contact_frame(md.kin, s, c, m, G2, w[2 * c:2 * c + 2])
            dim = contact_dim(md.kin, m, n, c)
            v0, v1 = frame_velocity(s, n, dim, G2, w[2 * c:2 * c + 2])
            for i in range(dim):
                apply_inverse_mass(m, n, diagonal, G[2 * c + i], MG[k])
                b[k] = v0 if i == 0 else v1
                k += 1
    if k == 0:
        return 0.0
    e_before = kinetic_energy(s, md)
    r = 0
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            for i in range(contact_dim(md.kin, m, n, c)):
                for r2 in range(k):
                    acc = 0.0
                    for j in range(n):
                        acc += G[2 * c + i, j] * MG[r2, j]
                    A[r, r2] = acc
                r += 1
    solve_psd(A, b, x, V, k)
    for r in range(k):
        for j in range(n):
            s[n + j] -= MG[r, j] * x[r]
    delta = kinetic_energy(s, md) - e_before
    if s.shape[0] >= 2 * n + 2:
        s[2 * n] += delta
    return delta
