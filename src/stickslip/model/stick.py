"""The stick forces: the Lagrange multipliers of all sticking contacts, solved together.

For the sticking contacts S (and, for a query, one more contact held), the multipliers F_S keep
their slip velocities at zero, dv_S/dt = G_S q̈ + h_S = 0 with q̈ = M⁻¹ (f + G_Sᵀ F_S):

    (G_S M⁻¹ G_Sᵀ) F_S = −(h_S + G_S M⁻¹ f)

minimal-norm where the matrix is rank-deficient (:mod:`stickslip.model.linalg`).
:func:`solve_stick_rows` picks the solve: written out on the caller's stack for one or two rows
(:func:`small_stick_system`), :func:`stick_system` for more. A large model's heap kinematics class
(:mod:`stickslip.model.stack`) reads its matrices from the W = G M⁻¹ Gᵀ of all contact rows that it
carries and its right sides from the rows M⁻¹ g_r (:func:`heap_stick_system`,
:func:`heap_small_stick_system`), and projects its velocities onto stick with them
(:func:`heap_project_velocities`), where forming them costs M⁻¹ products.
"""

from __future__ import annotations

import numpy as np
from numba.extending import overload

from . import csmath as csm
from .jit import KERNEL_OPTIONS, inlined_kernel, kernel, standalone
from .frames import contact_velocity, row_times
from .kinematics import contact_dim, frame_for_sums
from .linalg import solve_psd_2x2, solve_stick_system
from .model_data import dot, gram_row, inverse_mass_of, inverse_mass_of_row, is_stick
from .stack import DOFS, ONE, ROWS, TWO, kinematics_class, on_heap, one_contact, work_matrix, work_vectors

__all__ = ["scatter_stick_forces", "pair_forces", "stick_system", "stick_rows", "small_stick_system",
           "heap_stick_system", "heap_small_stick_system", "solve_stick_rows", "heap_project_velocities",
           "heap_projection"]


# ----------------------------------------------------------------------------- stick forces
@inlined_kernel
def scatter_stick_forces(md, n, nc, cst, extra, x, F, zero):
    """F of the sticking contacts and contact ``extra`` from the solved rows ``x`` (in the order of
    the contacts; a 1-D contact's second component ``zero``)."""
    r = 0
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            dim = contact_dim(md.kin, md.m, n, c)
            F[2 * c] = x[r]
            F[2 * c + 1] = x[r + 1] if dim == 2 else zero
            r += dim


@inlined_kernel
def pair_forces(a00, a01, a11, b0, b1, r0, r1, F):
    """F of one stick row r0 (r1 < 0) or two, r0 and r1, from their G_S M⁻¹ G_Sᵀ entries and right
    sides b (the unused second components of 1-D contacts set to 0). Returns (a00, a01, a11),
    a01 = a11 = 0 for one row."""
    zero = csm.zero(b0)
    if r1 < 0:
        F[r0] = -b0 / a00 if a00.real > 0.0 else zero
        if r0 % 2 == 0:
            F[r0 + 1] = zero
        return a00, zero, zero
    x0, x1, rank = solve_psd_2x2(a00, a01, a11, -b0, -b1)
    F[r0] = x0
    F[r1] = x1
    if r0 % 2 == 0 and r1 != r0 + 1:  # two 1-D contacts: their unused second components
        F[r0 + 1] = zero
    if r1 % 2 == 0:
        F[r1 + 1] = zero
    return a00, a01, a11


@kernel
def stick_system(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A):
    """Stick multipliers of the contacts in stick and of contact ``extra`` (≥ 0; −1: none), solved
    together: (G_S M⁻¹ G_Sᵀ) F_S = −(h_S + G_S M⁻¹ f), with h_S already in ``h``.

    Writes F of those contacts; ``A`` (≥ 2 nc square) receives G_S M⁻¹ G_Sᵀ (intact when k ≤ 2).
    ``f`` is the generalised force of everything else (not changed). Returns the rows k (0: none).
    """
    m = md.m
    MG = work_matrix(md.kin, ROWS, DOFS, s)
    a, b, x = work_vectors(md.kin, 3, s)
    V = work_matrix(md.kin, ROWS, ROWS, s)
    inverse_mass_of(md.kin, m, n, diagonal, f, a)
    k = np.int64(0)  # not a literal: numba would compile solve_psd for k = 0 first
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            for i in range(contact_dim(md.kin, m, n, c)):
                inverse_mass_of_row(md.kin, m, n, diagonal, G[2 * c + i], MG[k])
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
                gram_row(md.kin, G[2 * c + i], MG, k, n, A, r, csm.zero(s[0]))
                r += 1
    solve_stick_system(md.kin, A, b, x, V, k)
    scatter_stick_forces(md, n, nc, cst, extra, x, F, csm.zero(s[0]))
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
    a = work_vectors(md.kin, 1, s)[0]
    MG = work_matrix(md.kin, TWO, DOFS, s)
    inverse_mass_of(md.kin, m, n, diagonal, f, a)
    for r in range(1 if r1 < 0 else 2):  # one call site: numba's inliner takes two of an overload badly
        inverse_mass_of_row(md.kin, m, n, diagonal, G[r0 if r == 0 else r1], MG[r])
    mg0 = MG[0]
    mg1 = MG[1]
    a00 = csm.zero(s[0])
    b0 = h[r0]
    for j in range(n):
        a00 += G[r0, j] * mg0[j]
        b0 += G[r0, j] * a[j]
    a01 = csm.zero(s[0])
    a11 = csm.zero(s[0])
    b1 = csm.zero(b0)
    if r1 >= 0:
        b1 = h[r1]
        for j in range(n):
            a01 += G[r0, j] * mg1[j]
            a11 += G[r1, j] * mg1[j]
            b1 += G[r1, j] * a[j]
    return pair_forces(a00, a01, a11, b0, b1, r0, r1, F)


# ----------------------------------------------------------------------------- stick forces of a heap class
@kernel
def heap_inverse_mass(kin, m, n, diagonal, f, a):
    """a = M⁻¹ f (:func:`~stickslip.model.model_data.inverse_mass_of`) as a call: inlined into the
    heap stick kernels, numba mis-scopes the factor solve's accumulator (a pedantic IR warning)."""
    inverse_mass_of(kin, m, n, diagonal, f, a)


@inlined_kernel
def by_inverse_mass_rows(kin, n, k):
    """Whether the right sides of a heap class's stick system of ``k`` rows are cheaper as k dot
    products with the rows M⁻¹ g_r (``kin.inverse_mass_rows``, k n operations) than as one solve
    with the mass factor (twice its entries, and n) and k sparse row sums."""
    return k * n < 2 * kin.factor_values.shape[0] + n


@inlined_kernel
def stick_right_side(kin, row, by_rows, a, h, f, zero):
    """−(h_r + g_r·M⁻¹ f) of contact row ``row`` of a heap class: (M⁻¹ g_r)·f read from
    ``kin.inverse_mass_rows`` where ``by_rows``, else g_r·a over the row's nonzero entries with
    ``a`` = M⁻¹ f solved."""
    if by_rows:
        return -(h[row] + dot(kin.inverse_mass_rows[row], f, zero))
    return -row_times(kin, row, a, h[row])


@kernel
def heap_stick_system(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A):
    """:func:`stick_system` of a heap kinematics class: its matrix G_S M⁻¹ G_Sᵀ the submatrix of the
    stick rows of W = G M⁻¹ Gᵀ (``kin.delassus``, formed once by the same sums:
    :func:`~stickslip.model.mass_factor.delassus`), its right sides g_r·M⁻¹ f by
    :func:`stick_right_side`, where forming it costs an M⁻¹ product per row; :func:`stick_system`
    where the class carries no W (it did not fit in memory)."""
    kin = md.kin
    if kin.delassus.shape[0] == 0:
        return stick_system(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A)
    a, b, x = work_vectors(kin, 3, s)
    V = work_matrix(kin, ROWS, ROWS, s)
    rows = work_matrix(kin, ONE, ROWS, n)[0]
    k = np.int64(0)  # not a literal: numba would compile solve_psd for k = 0 first
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            for i in range(contact_dim(kin, md.m, n, c)):
                rows[k] = 2 * c + i
                k += 1
    if k == 0:
        return 0
    by_rows = by_inverse_mass_rows(kin, n, k)
    if not by_rows:
        heap_inverse_mass(kin, md.m, n, diagonal, f, a)
    zero = csm.zero(s[0])
    W = kin.delassus
    for r in range(k):
        b[r] = stick_right_side(kin, rows[r], by_rows, a, h, f, zero)
        for r2 in range(k):
            A[r, r2] = W[rows[r], rows[r2]] + zero
    solve_stick_system(kin, A, b, x, V, k)
    scatter_stick_forces(md, n, nc, cst, extra, x, F, zero)
    return k


@inlined_kernel
def heap_small_stick_system(s, md, n, diagonal, r0, r1, G, h, f, F):
    """:func:`small_stick_system` of a heap kinematics class: the entries read from W and the right
    sides by :func:`stick_right_side` (:func:`heap_stick_system`); :func:`small_stick_system` where
    the class carries no W."""
    kin = md.kin
    if kin.delassus.shape[0] == 0:
        return small_stick_system(s, md, n, diagonal, r0, r1, G, h, f, F)
    a = work_vectors(kin, 1, s)[0]
    by_rows = by_inverse_mass_rows(kin, n, 1 if r1 < 0 else 2)
    if not by_rows:
        heap_inverse_mass(kin, md.m, n, diagonal, f, a)
    W = kin.delassus
    zero = csm.zero(s[0])
    a00 = W[r0, r0] + zero
    b0 = -stick_right_side(kin, r0, by_rows, a, h, f, zero)
    a01 = zero
    a11 = zero
    b1 = csm.zero(b0)
    if r1 >= 0:
        a01 = W[r0, r1] + zero
        a11 = W[r1, r1] + zero
        b1 = -stick_right_side(kin, r1, by_rows, a, h, f, zero)
    return pair_forces(a00, a01, a11, b0, b1, r0, r1, F)


def stick_system_of(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A):  # pragma: no cover - overload
    """:func:`stick_system`, or :func:`heap_stick_system` for a heap kinematics class (chosen when
    compiled); nothing for a class of one contact, whose stick rows are never more than two."""
    raise NotImplementedError


@overload(stick_system_of, jit_options=KERNEL_OPTIONS, inline="always")
def _stick_system_of(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A):
    kin_class = kinematics_class(md)
    if on_heap(kin_class):
        return lambda s, md, n, nc, diagonal, cst, extra, G, h, f, F, A: heap_stick_system(
            s, md, n, nc, diagonal, cst, extra, G, h, f, F, A)
    if one_contact(kin_class):  # at most two stick rows: never called (:func:`solve_stick_rows`)
        return lambda s, md, n, nc, diagonal, cst, extra, G, h, f, F, A: np.int64(0)
    return lambda s, md, n, nc, diagonal, cst, extra, G, h, f, F, A: stick_system(
        s, md, n, nc, diagonal, cst, extra, G, h, f, F, A)


def small_stick_system_of(s, md, n, diagonal, r0, r1, G, h, f, F):  # pragma: no cover - overload
    """:func:`small_stick_system`, or :func:`heap_small_stick_system` for a heap kinematics class
    (chosen when compiled)."""
    raise NotImplementedError


@overload(small_stick_system_of, jit_options=KERNEL_OPTIONS, inline="always")
def _small_stick_system_of(s, md, n, diagonal, r0, r1, G, h, f, F):
    if on_heap(kinematics_class(md)):
        return heap_small_stick_system.py_func
    return small_stick_system.py_func


@standalone
@kernel
def solve_stick_rows(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A):
    """Stick multipliers of the sticking contacts and contact ``extra`` (F written for those), by
    :func:`small_stick_system` when there are at most two rows, else :func:`stick_system`. Returns
    (k, a00, a01, a11): the rows and, for k = 2, the entries of G_S M⁻¹ G_Sᵀ."""
    k, r0, r1 = stick_rows(md, md.m, n, nc, cst, extra)
    zero = csm.zero(s[0])
    if k == 0:
        return 0, zero, zero, zero
    if k <= 2:
        a00, a01, a11 = small_stick_system_of(s, md, n, diagonal, r0, r1, G, h, f, F)
        return k, a00, a01, a11
    stick_system_of(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A)
    return k, zero, zero, zero


# ----------------------------------------------------------------------------- projection onto stick, heap class
@kernel
def heap_project_velocities(s, cst, extra, md):
    """:func:`~stickslip.model.physics.project_velocities` of a heap kinematics class that carries W
    (returns NaN where it does not: the caller projects as for the small models).

    Δq̇ = −Σ_r x_r M⁻¹ g_r over the stick rows r, with (G_S M⁻¹ G_Sᵀ) x = v_S read from W and the rows
    M⁻¹ g_r from ``kin.inverse_mass_rows``; the slip velocities over the rows' nonzero entries. The
    kinetic energy change is ΔE = q̇ᵀ M Δq̇ + ½ Δq̇ᵀ M Δq̇ = −½ Σ_r x_r (g_r·q̇ + g_r·q̇'), as M Δq̇ =
    −G_Sᵀ x: two sparse sums per row instead of the two n-by-n quadratic forms of the energies."""
    kin = md.kin
    if kin.delassus.shape[0] == 0:
        return np.nan
    m = md.m
    n = kin.ndof
    G2 = work_matrix(kin, TWO, DOFS, s)  # not written: the heap class's frame carries no rows
    A = work_matrix(kin, ROWS, ROWS, s)
    V = work_matrix(kin, ROWS, ROWS, s)
    w, b, x, before = work_vectors(kin, 4, s)
    rows = work_matrix(kin, ONE, ROWS, n)[0]
    k = np.int64(0)  # not a literal: numba would compile solve_psd for k = 0 first
    for c in range(kin.ncontacts):
        if is_stick(cst, c) or c == extra:
            w2 = w[2 * c:2 * c + 2]
            frame_for_sums(kin, s, c, m, G2, w2)
            dim = contact_dim(kin, m, n, c)
            v0, v1 = contact_velocity(kin, s, n, c, dim, G2, w2)
            for i in range(dim):
                rows[k] = 2 * c + i
                b[k] = v0 if i == 0 else v1
                before[k] = b[k] + w2[i]
                k += 1
    if k == 0:
        return 0.0
    W = kin.delassus
    for r in range(k):
        for r2 in range(k):
            A[r, r2] = W[rows[r], rows[r2]]
    solve_stick_system(kin, A, b, x, V, k)
    R = kin.inverse_mass_rows
    for r in range(k):
        response = R[rows[r]]
        for j in range(n):
            s[n + j] -= response[j] * x[r]
    delta = 0.0
    for r in range(k):
        after = row_times(kin, rows[r], s[n:2 * n], 0.0)
        delta -= 0.5 * x[r] * (before[r] + after)
    if s.shape[0] >= 2 * n + 2:
        s[2 * n] += delta
    return delta


def heap_projection(s, cst, extra, md):  # pragma: no cover - resolved by numba (overload below)
    """:func:`heap_project_velocities` for a heap kinematics class (chosen when compiled); NaN for
    the others (the caller projects)."""
    raise NotImplementedError


@overload(heap_projection, jit_options=KERNEL_OPTIONS, inline="always")
def _heap_projection(s, cst, extra, md):
    if on_heap(kinematics_class(md)):
        return lambda s, cst, extra, md: heap_project_velocities(s, cst, extra, md)
    return lambda s, cst, extra, md: np.nan
