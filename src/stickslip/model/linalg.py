"""Minimal-norm solutions of the small symmetric positive semi-definite systems of stick.

The stick multipliers of the sticking contacts solve (G_S M⁻¹ G_Sᵀ) F_S = b
(:mod:`stickslip.model.forces`), and the velocity projection onto stick solves a system with the
same matrix (:func:`stickslip.model.physics.project_velocities`). That matrix is rank-deficient
for some models (the plates' Model 4, where an eigenvalue is 0 up to round-off), so the solution
taken is the minimal-norm one: in closed form for one or two rows (:func:`solve_psd_2x2`, the
common case), by cyclic Jacobi rotations for more (:func:`solve_psd`). The normal forces of
closed rigid contacts solve a system that is not symmetric while they slide
(:func:`solve_in_order`). Generic in the number type:
decisions read real parts only, so a complex step through the solves stays exact.
"""

from __future__ import annotations

import math

from numba.extending import overload

from . import csmath as csm
from .jit import KERNEL_OPTIONS, kernel
from .stack import on_heap

__all__ = ["RANK_TOL", "JACOBI_SWEEPS", "solve_psd_2x2", "solve_psd", "solve_in_order", "solve_stick_system",
           "solve_by_cholesky"]

#: Relative size below which an eigenvalue of G_S M⁻¹ G_Sᵀ counts as zero (rank deficiency,
#: e.g. the plates' Model 4, where it is exactly 0 up to round-off ~1e-16 relative).
RANK_TOL = 1e-10

#: Sweeps of cyclic Jacobi before giving up (each sweep roughly squares the off-diagonal norm;
#: 30 is far more than the ~6–10 a small symmetric matrix needs).
JACOBI_SWEEPS = 30


# ----------------------------------------------------------------------------- linear algebra
@kernel
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


@kernel
def solve_in_order(A, b, x, k):
    """x (k,) with A[:k, :k] x = b[:k], by Gaussian elimination in the given order; returns the
    smallest pivot's real part (A and b are overwritten).

    No pivoting, on purpose: the callers' matrices (the normal-force system of closed rigid
    contacts, :func:`stickslip.model.forces.rigid_normal_forces`, and the impulse system of an
    impact) have positive leading principal minors exactly where the contact problem has one
    solution, so a pivot that is not positive is their finding (Painlevé-type inconsistency), not
    a numerical accident. A zero pivot leaves x = 0 for the rows after it.
    """
    smallest = math.inf
    for p in range(k):
        piv = A[p, p]
        smallest = min(smallest, piv.real)
        if piv.real == 0.0:
            for i in range(k):
                x[i] = csm.zero(b[0])
            return smallest
        for i in range(p + 1, k):
            factor = A[i, p] / piv
            for j in range(p, k):
                A[i, j] = A[i, j] - factor * A[p, j]
            b[i] = b[i] - factor * b[p]
    for i in range(k - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, k):
            acc = acc - A[i, j] * x[j]
        x[i] = acc / A[i, i]
    return smallest


def solve_stick_system(kin, A, b, x, V, k):  # pragma: no cover - resolved by numba (overload below)
    """:func:`solve_psd` of the stick system; for a model of a heap kinematics class
    (:mod:`stickslip.model.stack`: tens of sticking contacts) by Cholesky where that is provably the
    same solution (:func:`solve_by_cholesky`), at k³/3 operations instead of Jacobi's sweeps."""
    raise NotImplementedError


@overload(solve_stick_system, jit_options=KERNEL_OPTIONS, inline="always")
def _solve_stick_system(kin, A, b, x, V, k):
    if not on_heap(getattr(kin, "instance_class", None)):
        def by_jacobi(kin, A, b, x, V, k):
            return solve_psd(A, b, x, V, k)
        return by_jacobi

    def by_cholesky(kin, A, b, x, V, k):
        if k > 2 and solve_by_cholesky(A, b, x, V, k):
            return k
        return solve_psd(A, b, x, V, k)
    return by_cholesky


@kernel
def solve_by_cholesky(A, b, x, V, k):
    """x (k,) with A[:k, :k] x = b[:k] by the Cholesky factor A = L Lᵀ (L in V's lower triangle, L⁻¹
    transposed in its strict upper one), where A is far from singular; returns whether it was
    (else x is not written and :func:`solve_psd` is to be used; ``A`` is left intact).

    A is full rank by :func:`solve_psd`'s criterion, λ_min > RANK_TOL λ_max, where the bounds
    λ_max ≤ trace A and λ_min ≥ 1 / ‖A⁻¹‖_F ≥ 1 / ‖L⁻¹‖_F² already show it; then the minimal-norm
    solution is the one solution, and this is it to round-off."""
    trace = 0.0
    for j in range(k):
        trace += A[j, j].real
    for j in range(k):
        d = A[j, j]
        for p in range(j):
            d -= V[j, p] * V[j, p]
        if d.real <= 0.0:
            return False
        V[j, j] = csm.sqrt(d)
        for i in range(j + 1, k):
            acc = A[i, j]
            for p in range(j):
                acc -= V[i, p] * V[j, p]
            V[i, j] = acc / V[j, j]
    inverse_norm = 0.0  # ‖L⁻¹‖_F², column j of L⁻¹ into V[j, j + 1:] (its diagonal 1 / L_jj not stored)
    for j in range(k):
        y = 1.0 / V[j, j]
        inverse_norm += y.real * y.real
        for i in range(j + 1, k):
            acc = V[i, j] * y
            for p in range(j + 1, i):
                acc += V[i, p] * V[j, p]
            V[j, i] = -acc / V[i, i]
        for i in range(j + 1, k):
            inverse_norm += V[j, i].real * V[j, i].real
    if inverse_norm * trace * RANK_TOL >= 1.0:
        return False
    for i in range(k):  # L y = b
        acc = b[i]
        for p in range(i):
            acc -= V[i, p] * x[p]
        x[i] = acc / V[i, i]
    for i in range(k - 1, -1, -1):  # Lᵀ x = y
        acc = x[i]
        for p in range(i + 1, k):
            acc -= V[p, i] * x[p]
        x[i] = acc / V[i, i]
    return True
