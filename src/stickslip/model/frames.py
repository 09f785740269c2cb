"""Contact frames with their velocity bias: v = G q̇ − w and h = Ġ q̇ − ẇ.

Each contact's frame (tangent rows G, drive w, normal force N) comes from the model's kinematics
(:func:`stickslip.model.kinematics.contact_frame`). The stick multipliers also need the velocity
bias h, the derivative of v along q̇ at fixed q̇ (dv/dt at q̈ = 0). :func:`frame_with_bias` gives
both: in closed form where the kinematics class registered a bias function, otherwise in a float evaluation by a complex step of the frame at q + iε q̇ (exact to round-off,
:data:`COMPLEX_STEP`), inside a complex evaluation (a complex-step Jacobian, whose state is
complex already) by a central difference (:data:`BIAS_TIME_STEP`); h = 0 for constant
kinematics. :func:`all_frames` fills the frames of every contact for the friction forces
(:mod:`stickslip.model.forces`). A contact's slip velocity and its force's share of the generalised
force, G_c q̇ − w_c and G_cᵀ F_c, are :func:`contact_velocity` and :func:`add_force_of`: over a heap
kinematics class's nonzero row entries where a large model's rows are mostly zero.
"""

from __future__ import annotations

from numba import types
from numba.extending import overload

from . import csmath as csm
from .bundle import H_CONSTANT
from .jit import KERNEL_OPTIONS, inlined_kernel, kernel
from .frame_pointers import pointer_bias
from .kinematics import (bias_at_run_time, contact_dim, contact_frame, frame_for_sums, heap_normal_and_drive, model_sizes,
                         registered_frame_bias)
from .model_data import for_kinematics, is_stick
from .normal import normal_in_mode
from .stack import DOFS, ONE, STATES, TWO, kinematics_class, on_heap, work_matrix

__all__ = ["COMPLEX_STEP", "BIAS_TIME_STEP", "rows_velocity", "frame_velocity", "contact_velocity", "add_contact_force",
           "add_force_of", "row_times", "split_complex_frame", "max_rate", "frame_with_bias", "bias_frame_for_sums",
           "heap_velocity_and_rate", "all_frames"]

#: Complex step [-] of the velocity bias: h² ≪ round-off and h·|∂f| far above the smallest
#: normal double, so Im f(x + i h d)/h is the directional derivative exactly.
COMPLEX_STEP = 1e-150

#: Central-difference step [s] of the velocity bias inside a complex evaluation, scaled by
#: 1/max|q̇|: the positions move by ~1e-5 of their unit, truncation and round-off ~1e-10 relative.
BIAS_TIME_STEP = 1e-5


# ----------------------------------------------------------------------------- frames
@inlined_kernel
def rows_velocity(s, n, dim, G2, w2):
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


@kernel
def frame_velocity(s, n, dim, G2, w2):
    """:func:`rows_velocity` as a call."""
    return rows_velocity(s, n, dim, G2, w2)


def contact_velocity(kin, s, n, c, dim, G2, w2):  # pragma: no cover - resolved by numba (overload below)
    """(v0, v1) = G_c q̇ − w_c of contact ``c``: :func:`frame_velocity` over its frame rows G2; for a
    heap kinematics class (:mod:`stickslip.model.stack`), the same sums over the rows' nonzero
    entries (``kin.row_*``), as a reduced model's contact row touches a few of its n DOFs."""
    raise NotImplementedError


def _velocity_dense(kin, s, n, c, dim, G2, w2):
    # the loops inlined rather than a call of the kernel frame_velocity, which from inside an
    # inlined overload stays a call that LLVM does not inline, in the right-hand side's loop
    return rows_velocity(s, n, dim, G2, w2)


@inlined_kernel
def row_times(kin, row, a, acc):
    """acc + g·a for the contact row ``row`` (2c or 2c + 1) of a heap kinematics class, over its
    nonzero entries (``kin.row_*``) in the order of their columns."""
    columns = kin.row_columns
    values = kin.row_values
    for p in range(kin.row_starts[row], kin.row_starts[row + 1]):
        acc += values[p] * a[columns[p]]
    return acc


def _velocity_by_rows(kin, s, n, c, dim, G2, w2):
    v0 = row_times(kin, 2 * c, s[n:], -w2[0])
    v1 = csm.zero(s[0])
    if dim == 2:
        v1 = row_times(kin, 2 * c + 1, s[n:], -w2[1])
    return v0, v1


@overload(contact_velocity, jit_options=KERNEL_OPTIONS, inline="always")
def _contact_velocity(kin, s, n, c, dim, G2, w2):
    return for_kinematics(kin, _velocity_dense, _velocity_by_rows)


@inlined_kernel
def add_contact_force(G2, dim, n, F0, F1, f):
    """f += G_cᵀ F_c for one contact's frame rows G2."""
    for j in range(n):
        f[j] += G2[0, j] * F0
    if dim == 2:
        for j in range(n):
            f[j] += G2[1, j] * F1


def add_force_of(kin, c, G2, dim, n, F0, F1, f):  # pragma: no cover - resolved by numba (overload below)
    """f += G_cᵀ F_c of contact ``c``: :func:`add_contact_force`; for a heap kinematics class over the
    nonzero entries of its rows (:func:`contact_velocity`)."""
    raise NotImplementedError


def _force_dense(kin, c, G2, dim, n, F0, F1, f):
    add_contact_force(G2, dim, n, F0, F1, f)


def _force_by_rows(kin, c, G2, dim, n, F0, F1, f):
    starts = kin.row_starts
    columns = kin.row_columns
    values = kin.row_values
    for p in range(starts[2 * c], starts[2 * c + 1]):
        f[columns[p]] += values[p] * F0
    if dim == 2:
        for p in range(starts[2 * c + 1], starts[2 * c + 2]):
            f[columns[p]] += values[p] * F1


@overload(add_force_of, jit_options=KERNEL_OPTIONS, inline="always")
def _add_force_of(kin, c, G2, dim, n, F0, F1, f):
    return for_kinematics(kin, _force_dense, _force_by_rows)


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


def frame_with_bias(s, c, md, G2, w2, h2):  # pragma: no cover - resolved by numba (overload below)
    """Contact ``c``'s frame (G, w; returns N) and velocity bias h = Ġ q̇ − ẇ = dv/dt at q̈ = 0:
    in closed form where the kinematics class registered one, else by complex step in a float
    evaluation and by central difference inside a complex one."""
    raise NotImplementedError("frame_with_bias is called from compiled code only")


@overload(frame_with_bias, jit_options=KERNEL_OPTIONS)
def _frame_with_bias(s, c, md, G2, w2, h2):
    kin_type = md.types[md.fields.index("kin")]
    closed_form = registered_frame_bias(kin_type)
    if closed_form is not None:  # chosen at compile time, like the frame itself
        def with_closed_form(s, c, md, G2, w2, h2):
            return closed_form(md.kin, s, c, md.m, G2, w2, h2)
        return with_closed_form
    if isinstance(s.dtype, types.Complex):
        if bias_at_run_time(kin_type):  # a frame compiled apart: its bias function where it has one
            def central_or_pointer(s, c, md, G2, w2, h2):
                if md.kin.bias_complex != 0:
                    return pointer_bias(md.kin, s, c, md.m, G2, w2, h2)
                return _frame_bias_central(s, c, md, G2, w2, h2)
            return central_or_pointer

        def by_central_difference(s, c, md, G2, w2, h2):
            return _frame_bias_central(s, c, md, G2, w2, h2)
        return by_central_difference
    if bias_at_run_time(kin_type):
        def step_or_pointer(s, c, md, G2, w2, h2):
            if md.kin.bias != 0:
                return pointer_bias(md.kin, s, c, md.m, G2, w2, h2)
            return _frame_bias_complex_step(s, c, md, G2, w2, h2)
        return step_or_pointer

    def by_complex_step(s, c, md, G2, w2, h2):
        return _frame_bias_complex_step(s, c, md, G2, w2, h2)
    return by_complex_step


def bias_frame_for_sums(s, c, md, G2, w2, h2):  # pragma: no cover - resolved by numba (overload below)
    """:func:`frame_with_bias`; for a heap kinematics class (constant frames: h = 0) that carries W
    = G M⁻¹ Gᵀ, without the rows G2 (its sums and stick systems read its row lists and W:
    :func:`~stickslip.model.kinematics.frame_for_sums`)."""
    raise NotImplementedError


@overload(bias_frame_for_sums, jit_options=KERNEL_OPTIONS, inline="always")
def _bias_frame_for_sums(s, c, md, G2, w2, h2):
    if not on_heap(kinematics_class(md)):
        return lambda s, c, md, G2, w2, h2: frame_with_bias(s, c, md, G2, w2, h2)

    def without_rows(s, c, md, G2, w2, h2):
        if md.kin.delassus.shape[0] == 0:  # the stick systems are formed from the rows
            return frame_with_bias(s, c, md, G2, w2, h2)
        h2[0] = csm.zero(s[0])
        h2[1] = csm.zero(s[0])
        return heap_normal_and_drive(md.kin, s, c, md.m, w2)
    return without_rows


@inlined_kernel
def heap_velocity_and_rate(s, ds, c, md):
    """(v0, v1, a0, a1) of :func:`~stickslip.model.physics.slip_velocity_and_rate` for a heap
    kinematics class (constant frames: h = 0): G_c q̇ − w_c and G_c q̈ over the rows' nonzero
    entries (``kin.row_*``)."""
    kin = md.kin
    n = kin.ndof
    w2 = work_matrix(kin, ONE, TWO, s)[0]
    heap_normal_and_drive(kin, s, c, md.m, w2)
    v0 = row_times(kin, 2 * c, s[n:], -w2[0])
    a0 = row_times(kin, 2 * c, ds[n:], 0.0)
    v1 = 0.0
    a1 = 0.0
    if contact_dim(kin, md.m, n, c) == 2:
        v1 = row_times(kin, 2 * c + 1, s[n:], -w2[1])
        a1 = row_times(kin, 2 * c + 1, ds[n:], 0.0)
    return v0, v1, a0, a1


@inlined_kernel
def all_frames(s, cst, md, n, nc, G, w, v, N, h, with_bias):
    """Each contact's G (rows 2c, 2c+1), w, v = G q̇ − w (entries 2c, 2c+1) and N (entry c) at
    ``s``; with the velocity bias h for contacts in stick (all contacts if ``with_bias`` is 2).
    A unilateral contact's N is its normal force λ in the mode of ``cst`` (0 while open).

    A heap kinematics class writes no rows G where it carries W = G M⁻¹ Gᵀ
    (:func:`~stickslip.model.kinematics.frame_for_sums`, :func:`bias_frame_for_sums`): its sums
    read its row lists (:func:`contact_velocity`, :func:`add_force_of`) and its stick systems W,
    and storing 2 n entries per contact at every right-hand side cost as much as a solve with the
    mass factor."""
    m = md.m
    for c in range(nc):
        G2 = G[2 * c:2 * c + 2]
        w2 = w[2 * c:2 * c + 2]
        if with_bias == 2 or (with_bias == 1 and is_stick(cst, c)):
            N[c] = bias_frame_for_sums(s, c, md, G2, w2, h[2 * c:2 * c + 2])
        else:
            N[c] = frame_for_sums(md.kin, s, c, m, G2, w2)
        N[c] = normal_in_mode(s, cst, md, n, c, N[c])  # a unilateral contact's: none while open
        v0, v1 = contact_velocity(md.kin, s, n, c, contact_dim(md.kin, m, n, c), G2, w2)
        v[2 * c] = v0
        v[2 * c + 1] = v1
