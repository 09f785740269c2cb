"""What every physics kernel reads: the contact modes and the packed model.

A contact's integration state ``cst`` (:data:`~stickslip.model.bundle.CST` numbers per contact)
starts with its mode, one of the ``MODE_*`` codes defined here; the packed model ``m``
(:mod:`stickslip.model.bundle`) holds each contact's friction law row and M⁻¹, M, C, K, f0. The
small kernels here read them: the friction law row and the static limit μs N of a contact,
whether it sticks, M⁻¹ f, the force without friction f0 − C q̇ − K q and the kinetic energy.

They sit below the frames (:mod:`stickslip.model.frames`), the friction forces
(:mod:`stickslip.model.forces`) and the right-hand side (:mod:`stickslip.model.physics`), which
all need them, so that none of those imports another in a circle. The integrators, orbits and
tests read the mode codes and :data:`SPEED_FLOOR` as ``physics.MODE_STICK`` …:
:mod:`stickslip.model.physics` re-exports them.
"""

from __future__ import annotations

import numpy as np

from . import csmath as csm
from .bundle import CST, C_LAW, contact_offsets, offsets
from .friction import LAW_WIDTH, friction_coefficient, static_coefficient
from numba.extending import overload

from .jit import KERNEL_OPTIONS, inlined_kernel, kernel
from .kinematics import model_sizes
from .stack import on_heap

__all__ = ["MODE_SLIP", "MODE_STICK", "MODE_SLIP_EXACT", "MODE_SLIP_QUASI_STATIC", "SPEED_FLOOR", "law_row",
           "kinetic_coefficient", "static_limit", "is_stick", "apply_inverse_mass", "base_force", "kinetic_energy",
           "inverse_mass_of_row", "inverse_mass_of", "dot", "gram_row", "base_force_of", "damping_power",
           "for_kinematics"]

MODE_SLIP = 0        # slip; inside the low-speed band the direction is quasi-static (departure)
MODE_STICK = 1       # stick: friction is the constraint force
MODE_SLIP_EXACT = 2  # slip with the exact direction v/|v| at every speed (approach to stick)
MODE_SLIP_QUASI_STATIC = 3  # slip with the quasi-static direction at every speed

#: Speed [m/s] below which a slip velocity counts as exactly zero (round-off after projection).
SPEED_FLOOR = 1e-13


# ----------------------------------------------------------------------------- model data
@inlined_kernel
def law_row(m, n, c):
    """Friction law row of contact ``c`` (a view of ``m``)."""
    o = contact_offsets(n, c)[0] + C_LAW
    return m[o:o + LAW_WIDTH]


@kernel
def kinetic_coefficient(md, n, c, speed):
    """Kinetic friction coefficient μ(|v| = ``speed``) [-] of contact ``c`` (float or complex speed)."""
    return friction_coefficient(speed, law_row(md.m, n, c), md.law)


@kernel
def static_limit(m, n, c, normal):
    """Largest admissible stick force μs N [N] of contact ``c`` (paper Eq. 10)."""
    return static_coefficient(law_row(m, n, c)) * normal.real


@kernel
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


def for_kinematics(kin, dense, heap):
    """The implementation of an overload below for the kinematics type ``kin``: ``heap`` for a heap
    kinematics class (:mod:`stickslip.model.stack`), ``dense`` for the others."""
    return heap if on_heap(getattr(kin, "instance_class", None)) else dense


def inverse_mass_of(kin, m, n, diagonal, f, a):  # pragma: no cover - resolved by numba (overload below)
    """a = M⁻¹ f for any vector f (n,) (locked DOFs: 0): :func:`apply_inverse_mass`; for a model of
    a heap kinematics class (:mod:`stickslip.model.stack`) with a full M, two triangular solves with
    its sparse Cholesky factor (``kin.factor_*``, :func:`~stickslip.model.mass_factor.mass_factor`):
    as many operations as the factor has entries (a reduced model's boundary DOFs times its modes)
    instead of n². ``a`` must not be ``f``."""
    raise NotImplementedError


def _inverse_mass_dense(kin, m, n, diagonal, f, a):
    apply_inverse_mass(m, n, diagonal, f, a)


@inlined_kernel
def partial_dots(v, x, length, s0, s1, s2, s3):
    """The four interleaved partial sums (s0 … s3) advanced by Σ_j v[j] x[j] over j < ``length``
    (one sum's chain of additions would wait on the adder at every entry; views read from 0 up,
    which the compiler can vectorise)."""
    j = 0
    while j + 4 <= length:
        s0 += v[j] * x[j]
        s1 += v[j + 1] * x[j + 1]
        s2 += v[j + 2] * x[j + 2]
        s3 += v[j + 3] * x[j + 3]
        j += 4
    for i in range(j, length):
        s0 += v[i] * x[i]
    return s0, s1, s2, s3


@inlined_kernel
def dot(v, x, zero):
    """Σ_j v[j] x[j] over the length of ``v``, from ``zero``, in :func:`partial_dots`."""
    s0, s1, s2, s3 = partial_dots(v, x, v.shape[0], zero, zero, zero, zero)
    return (s0 + s1) + (s2 + s3)


@inlined_kernel
def factor_row_dot(segments, k0, k1, values, a, zero):
    """Σ_p values[p] a[j_p] over one row of the mass factor given as its runs of consecutive DOFs
    ``segments[k0:k1]`` ([start, end, first]: j_p = first + p − start), in the partial sums of
    :func:`partial_dots` (a row of hundreds of modes; consecutive DOFs are read without indices)."""
    s0 = zero
    s1 = zero
    s2 = zero
    s3 = zero
    for k in range(k0, k1):
        start = segments[k, 0]
        length = segments[k, 1] - start
        s0, s1, s2, s3 = partial_dots(values[start:start + length], a[segments[k, 2]:segments[k, 2] + length],
                                      length, s0, s1, s2, s3)
    return (s0 + s1) + (s2 + s3)


def _inverse_mass_by_factor(kin, m, n, diagonal, f, a):
    if diagonal:
        apply_inverse_mass(m, n, diagonal, f, a)
        return
    order = kin.factor_order
    values = kin.factor_values
    pivots = kin.factor_diagonal
    starts = kin.factor_segment_rows
    segments = kin.factor_segments
    zero = csm.zero(f[0])
    for i in range(n):
        a[i] = zero
    for i in range(order.shape[0]):  # L y = P f, y_i kept at a[order[i]]
        dot = factor_row_dot(segments, starts[i], starts[i + 1], values, a, zero)
        a[order[i]] = (f[order[i]] - dot) / pivots[i]
    for i in range(order.shape[0] - 1, -1, -1):  # Lᵀ z = y, by the columns of Lᵀ (the rows of L)
        z = a[order[i]] / pivots[i]
        a[order[i]] = z
        for k in range(starts[i], starts[i + 1]):
            length = segments[k, 1] - segments[k, 0]
            v = values[segments[k, 0]:segments[k, 1]]
            x = a[segments[k, 2]:segments[k, 2] + length]
            for j in range(length):
                x[j] -= v[j] * z


@overload(inverse_mass_of, jit_options=KERNEL_OPTIONS, inline="always")
def _inverse_mass_of(kin, m, n, diagonal, f, a):
    return for_kinematics(kin, _inverse_mass_dense, _inverse_mass_by_factor)


def inverse_mass_of_row(kin, m, n, diagonal, g, out):  # pragma: no cover - resolved by numba (overload below)
    """out = M⁻¹ g for a contact row g (n,): :func:`apply_inverse_mass`; for a model of a heap
    kinematics class (hundreds of DOFs, :mod:`stickslip.model.stack`) the sums over the nonzero
    entries of g only (a contact row touches a few DOFs: n·nnz instead of n² operations), each
    taking column j of the symmetric M⁻¹ as its row j, contiguous in memory (equal to the round-off
    of the inverse)."""
    raise NotImplementedError


@overload(inverse_mass_of_row, jit_options=KERNEL_OPTIONS, inline="always")
def _inverse_mass_of_row(kin, m, n, diagonal, g, out):
    if not on_heap(getattr(kin, "instance_class", None)):
        def dense(kin, m, n, diagonal, g, out):
            apply_inverse_mass(m, n, diagonal, g, out)
        return dense

    def by_rows(kin, m, n, diagonal, g, out):
        if diagonal:
            apply_inverse_mass(m, n, diagonal, g, out)
            return
        o = offsets(n)[0]
        for i in range(n):
            out[i] = csm.zero(g[0])
        for j in range(n):
            gj = g[j]
            if gj != 0.0:
                row = o + j * n
                for i in range(n):
                    out[i] += m[row + i] * gj
    return by_rows


def gram_row(kin, g, MG, k, n, A, r, zero):  # pragma: no cover - resolved by numba (overload below)
    """A[r, r2] = g · MG[r2] for r2 < k (a row of G_S M⁻¹ G_Sᵀ), each sum from ``zero`` in the order
    of j; for a heap kinematics class over the nonzero entries of g only (as :func:`inverse_mass_of_row`)."""
    raise NotImplementedError


@overload(gram_row, jit_options=KERNEL_OPTIONS, inline="always")
def _gram_row(kin, g, MG, k, n, A, r, zero):
    if not on_heap(getattr(kin, "instance_class", None)):
        def dense(kin, g, MG, k, n, A, r, zero):
            for r2 in range(k):
                acc = zero
                for j in range(n):
                    acc += g[j] * MG[r2, j]
                A[r, r2] = acc
        return dense

    def by_columns(kin, g, MG, k, n, A, r, zero):
        for r2 in range(k):
            A[r, r2] = zero
        for j in range(n):
            gj = g[j]
            if gj != 0.0:
                for r2 in range(k):
                    A[r, r2] += gj * MG[r2, j]
    return by_columns


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


def base_force_of(kin, s, m, n, diagonal, f):  # pragma: no cover - resolved by numba (overload below)
    """:func:`base_force`; for a model of a heap kinematics class (:mod:`stickslip.model.stack`)
    the same sums over the entries of C and K in its pattern only (``kin.force_rows``,
    ``kin.force_columns``: the others are zero in both; their values ``kin.damping_values``,
    ``kin.stiffness_values`` in that order), each in the same order less its exact zeros."""
    raise NotImplementedError


def _base_force_dense(kin, s, m, n, diagonal, f):
    base_force(s, m, n, diagonal, f)


def _base_force_by_pattern(kin, s, m, n, diagonal, f):
    of = offsets(n)[4]
    rows = kin.force_rows
    columns = kin.force_columns
    damping = kin.damping_values
    stiffness = kin.stiffness_values
    for i in range(n):
        acc = m[of + i] + csm.zero(s[0])
        for p in range(rows[i], rows[i + 1]):
            j = columns[p]
            acc -= damping[p] * s[n + j] + stiffness[p] * s[j]
        f[i] = acc


@overload(base_force_of, jit_options=KERNEL_OPTIONS, inline="always")
def _base_force_of(kin, s, m, n, diagonal, f):
    return for_kinematics(kin, _base_force_dense, _base_force_by_pattern)


def damping_power(kin, s, m, n, diagonal):  # pragma: no cover - resolved by numba (overload below)
    """−q̇ᵀ C q̇ [W]; for a model of a heap kinematics class over the entries of its pattern only
    (:func:`base_force_of`), each sum in the same order less its exact zeros."""
    raise NotImplementedError


def _damping_power_dense(kin, s, m, n, diagonal):
    oc = offsets(n)[2]
    damping = csm.zero(s[0])
    if diagonal:
        for i in range(n):
            damping -= m[oc + i * (n + 1)] * s[n + i] * s[n + i]
    else:
        for i in range(n):
            for j in range(n):
                damping -= s[n + i] * m[oc + i * n + j] * s[n + j]
    return damping


def _damping_power_by_pattern(kin, s, m, n, diagonal):
    rows = kin.force_rows
    columns = kin.force_columns
    values = kin.damping_values
    damping = csm.zero(s[0])
    for i in range(n):
        for p in range(rows[i], rows[i + 1]):
            damping -= s[n + i] * values[p] * s[n + columns[p]]
    return damping


@overload(damping_power, jit_options=KERNEL_OPTIONS, inline="always")
def _damping_power(kin, s, m, n, diagonal):
    return for_kinematics(kin, _damping_power_dense, _damping_power_by_pattern)


def kinetic_energy_of(kin, s, m, n, diagonal):  # pragma: no cover - resolved by numba (overload below)
    """½ q̇ᵀ M q̇ [J]; for a model of a heap kinematics class over the entries of M in its pattern
    only (``kin.mass_rows``, ``kin.mass_columns``, ``kin.mass_values``), each sum in the same order
    less its exact zeros."""
    raise NotImplementedError


def _kinetic_energy_dense(kin, s, m, n, diagonal):
    o = offsets(n)[1]
    e = 0.0
    for i in range(n):
        if diagonal:
            e += 0.5 * m[o + i * (n + 1)] * s[n + i] * s[n + i]
        else:
            for j in range(n):
                e += 0.5 * s[n + i] * m[o + i * n + j] * s[n + j]
    return e


def _kinetic_energy_by_pattern(kin, s, m, n, diagonal):
    rows = kin.mass_rows
    columns = kin.mass_columns
    values = kin.mass_values
    e = 0.0
    for i in range(n):
        for p in range(rows[i], rows[i + 1]):
            e += 0.5 * s[n + i] * values[p] * s[n + columns[p]]
    return e


@overload(kinetic_energy_of, jit_options=KERNEL_OPTIONS, inline="always")
def _kinetic_energy_of(kin, s, m, n, diagonal):
    return for_kinematics(kin, _kinetic_energy_dense, _kinetic_energy_by_pattern)


@kernel
def kinetic_energy(s, md):
    """½ q̇ᵀ M q̇ [J]."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    return kinetic_energy_of(md.kin, s, m, n, diagonal)
