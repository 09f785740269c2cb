"""Normal contact of unilateral contacts: gap, compliant normal force, and the open/closed test.

A contact either carries a prescribed normal load N = N0 + n·q + n_v·q̇ (always pressed; the
model's K and f0 hold its effect on the coordinates) or states a gap

    g(q) = g0 + W·q        (closed while g ≤ 0, open while g > 0)

whose normal force λ ≥ 0 acts on the coordinates as Wᵀλ and bounds the friction, |F| ≤ μ λ, as N
does for a pressed contact. The *compliant* law (Kelvin–Voigt with max(0, ·)):

    λ = max(0, λ̃),   λ̃ = −k g − c ġ   while g < 0,   λ = 0 while g ≥ 0.

A closed contact (mode not ``MODE_OPEN``) has g < 0 and λ̃ > 0, so its force is λ̃ itself: affine
in the state, smooth until an event. The contact is closed exactly where

    φ(s) = min(−g, λ̃) > 0,

one continuous function whose zero is both events: opening (λ̃ reaches 0 while g < 0, which with
c > 0 happens before g reaches 0; or g reaches 0 with c = 0) and closing (g reaches 0 from above
with ġ < 0, or λ̃ turns positive again while g < 0). :func:`contact_indicator` gives φ for a
closed contact and −φ for an open one, so an event is always "the indicator falls to 0".

A *rigid* contact (g ≥ 0, λ ≥ 0, g λ = 0) has no force law: while closed its λ is the multiplier
that keeps g̈ = 0, solved with the stick multipliers (:func:`stickslip.model.forces.rigid_normal_forces`);
it opens where that λ falls through 0 and closes where g does, with an impact
(:mod:`stickslip.model.impact`). Here it contributes its gap (the open contact's indicator is g) and
nothing else: :func:`normal_in_mode` gives 0 for it, and the multiplier replaces that.

Kernels are complex-safe (polynomial in the state; comparisons on real parts) for the Jacobians.

What the generic kernels call (:func:`normal_in_mode`, :func:`add_normal_forces`,
:func:`starts_open`) is chosen at compile time by the kinematics class: for a class registered
without unilateral contacts (the plates, :class:`~stickslip.model.kinematics.ConstantKinematics`)
it is the identity or nothing, so their kernels compile and run as if unilateral contacts did not
exist.
"""

from __future__ import annotations

import numpy as np
from numba.extending import overload

from . import csmath as csm
from .bundle import (C_GAP, C_NORMAL_C, C_NORMAL_K, C_NORMAL_LAW, CST, H_CONSTANT, H_RIGID, NORMAL_PRESCRIBED,
                     NORMAL_RIGID, contact_offsets, gap_offset)
from .jit import KERNEL_OPTIONS, inlined_kernel, kernel
from .kinematics import contact_gap, gap_computed, has_unilateral, model_sizes, rigid_kernel, unilateral_kernel
from .model_data import for_kinematics
from .stack import work_vectors

__all__ = ["MODE_OPEN", "is_open", "is_unilateral", "is_rigid", "any_rigid_closed", "gap_sums", "add_gap_force",
           "gap_and_rate", "gap_with_rate", "compliant_force", "contact_indicator", "add_normal_force",
           "add_normal_forces", "normal_in_mode", "starts_open", "open_in_mode"]

#: Mode of an open unilateral contact: no normal force, no friction (the stick and slip modes
#: are in :mod:`stickslip.model.model_data`).
MODE_OPEN = 4


@kernel
def is_open(cst, c):
    return np.int64(cst[CST * c]) == MODE_OPEN


@kernel
def is_unilateral(md, n, c):
    """Whether contact ``c`` has a gap instead of a prescribed load (False at compile time for
    kinematics registered without unilateral contacts)."""
    if not has_unilateral(md.kin, md.m):
        return False
    return md.m[contact_offsets(n, c)[0] + C_NORMAL_LAW] != NORMAL_PRESCRIBED


@kernel
def is_rigid(md, n, c):
    """Whether contact ``c`` is a rigid unilateral contact (False at compile time for kinematics
    registered without unilateral contacts; a header flag skips the look-up for models without any)."""
    if not has_unilateral(md.kin, md.m) or md.m[H_RIGID] == 0.0:
        return False
    return md.m[contact_offsets(n, c)[0] + C_NORMAL_LAW] == NORMAL_RIGID


@rigid_kernel(lambda cst, md, n, nc: False, inline="always")
def any_rigid_closed(cst, md, n, nc):  # pragma: no cover - compiled only
    """Whether some rigid contact is closed in ``cst`` (its normal force is then a multiplier)."""
    if md.m[H_RIGID] == 0.0:
        return False
    for c in range(nc):
        if is_rigid(md, n, c) and not is_open(cst, c):
            return True
    return False


def gap_sums(kin, m, n, c, s, d, g, rate):  # pragma: no cover - resolved by numba (overload below)
    """(g + W·q, rate + W·d[n:2n]) with contact ``c``'s gap gradient W from the data array ``m``;
    for a heap kinematics class over its nonzero entries (``kin.gap_*``)."""
    raise NotImplementedError


def _gap_sums_dense(kin, m, n, c, s, d, g, rate):
    og = gap_offset(n, c)
    for j in range(n):
        g += m[og + j] * s[j]
        rate += m[og + j] * d[n + j]
    return g, rate


def _gap_sums_by_rows(kin, m, n, c, s, d, g, rate):
    for p in range(kin.gap_starts[c], kin.gap_starts[c + 1]):
        j = kin.gap_columns[p]
        g += kin.gap_values[p] * s[j]
        rate += kin.gap_values[p] * d[n + j]
    return g, rate


@overload(gap_sums, jit_options=KERNEL_OPTIONS, inline="always")
def _gap_sums(kin, m, n, c, s, d, g, rate):
    return for_kinematics(kin, _gap_sums_dense, _gap_sums_by_rows)


def add_gap_force(kin, m, n, c, lam, f):  # pragma: no cover - resolved by numba (overload below)
    """f += Wᵀ λ with contact ``c``'s gap gradient W from the data array ``m`` (:func:`gap_sums`)."""
    raise NotImplementedError


def _gap_force_dense(kin, m, n, c, lam, f):
    og = gap_offset(n, c)
    for j in range(n):
        f[j] += m[og + j] * lam


def _gap_force_by_rows(kin, m, n, c, lam, f):
    for p in range(kin.gap_starts[c], kin.gap_starts[c + 1]):
        f[kin.gap_columns[p]] += kin.gap_values[p] * lam


@overload(add_gap_force, jit_options=KERNEL_OPTIONS, inline="always")
def _add_gap_force(kin, m, n, c, lam, f):
    return for_kinematics(kin, _gap_force_dense, _gap_force_by_rows)


@kernel
def gap_with_rate(s, d, md, n, c):
    """(g(q), W(q)·d[n:2n]) of contact ``c`` at ``s`` = [q, …] (W = ∂g/∂q) [m, m/s for d = s]:
    the gap and its rate along the velocities held in ``d`` (``s`` itself, or a derivative
    [q̇, q̈] for W·q̈). The kinematics' gap function where it registered one, else g0 + W·q from
    the data array (the other branch is a compile-time constant's dead code)."""
    m = md.m
    rate = csm.zero(s[0])
    if gap_computed(md.kin):
        W = work_vectors(md.kin, 1, s)[0]
        g = contact_gap(md.kin, s, c, m, W)
        for j in range(n):
            rate += W[j] * d[n + j]
        return g, rate
    o = contact_offsets(n, c)[0]
    return gap_sums(md.kin, m, n, c, s, d, m[o + C_GAP] + csm.zero(s[0]), rate)


@kernel
def gap_and_rate(s, md, n, c):
    """(g, ġ) = (g(q), W(q)·q̇) of contact ``c`` [m, m/s]: g0 + W·q for a gap the kinematics does
    not compute (:func:`~stickslip.model.kinematics.contact_gap`)."""
    return gap_with_rate(s, s, md, n, c)


@inlined_kernel
def compliant_force(s, md, n, c):
    """λ̃ = −k g − c ġ [N] of compliant contact ``c`` (its normal force while closed)."""
    o = contact_offsets(n, c)[0]
    g, rate = gap_and_rate(s, md, n, c)
    return -md.m[o + C_NORMAL_K] * g - md.m[o + C_NORMAL_C] * rate


@kernel
def contact_indicator(s, cst, md, n, c):
    """φ = min(−g, λ̃) for a closed contact, −φ for an open one: > 0 while the contact stays in its
    state, its fall through 0 is the opening or closing event [m or N; only the sign matters].
    A rigid contact: g while open (−g while closed, which is not its event:
    :func:`stickslip.model.physics.indicator` gives its λ instead)."""
    m = md.m
    o = contact_offsets(n, c)[0]
    g, rate = gap_and_rate(s, md, n, c)
    if is_rigid(md, n, c):  # open: g; closed: −g ≡ 0 (its event, λ through 0, needs the forces)
        return g if is_open(cst, c) else -g
    lam = -m[o + C_NORMAL_K] * g - m[o + C_NORMAL_C] * rate
    # φ in the same unit: λ̃ / k is a length (k > 0 for a compliant contact)
    phi = -g if (-g).real < (lam / m[o + C_NORMAL_K]).real else lam / m[o + C_NORMAL_K]
    return -phi if is_open(cst, c) else phi


@inlined_kernel
def add_normal_force(s, md, n, c, lam, f):
    """f += W(q)ᵀ λ: the normal force λ of contact ``c`` on the coordinates (W from the kinematics'
    gap function where it registered one, else the data array's)."""
    if gap_computed(md.kin):
        W = work_vectors(md.kin, 1, s)[0]
        contact_gap(md.kin, s, c, md.m, W)
        for j in range(n):
            f[j] += W[j] * lam
        return
    add_gap_force(md.kin, md.m, n, c, lam, f)


@unilateral_kernel(lambda s, cst, md, n, nc, N, f: None, inline="always")
def add_normal_forces(s, cst, md, n, nc, N, f):  # pragma: no cover - compiled only
    """f += Wᵀ λ for every closed compliant contact (λ = N[c], its normal force; a rigid one's is
    added with its multiplier)."""
    if has_unilateral(md.kin, md.m):
        for c in range(nc):
            if is_unilateral(md, n, c) and not is_open(cst, c) and not is_rigid(md, n, c):
                add_normal_force(s, md, n, c, N[c], f)


@unilateral_kernel(lambda s, cst, md, n, c, normal: normal, inline="always")
def normal_in_mode(s, cst, md, n, c, normal):  # pragma: no cover - compiled only
    """Normal force of contact ``c`` in its mode, given ``normal`` as its frame returned it: the
    frame's for a pressed contact; 0 for an open unilateral one; for a closed compliant one λ̃
    (which constant kinematics return from the frame already); 0 for a rigid one (its multiplier
    replaces it)."""
    if not is_unilateral(md, n, c):
        return normal
    if is_open(cst, c) or is_rigid(md, n, c):
        return csm.zero(normal)
    if md.m[H_CONSTANT] != 0.0:
        return normal
    return compliant_force(s, md, n, c) + csm.zero(normal)


@unilateral_kernel(lambda cst, md, c: False, inline="always")
def open_in_mode(cst, md, c):  # pragma: no cover - compiled only
    """Whether contact ``c`` is open in ``cst`` (False at compile time for pressed-only kinematics)."""
    return is_open(cst, c)


@unilateral_kernel(lambda y, cst, c, md: False)
def starts_open(y, cst, c, md):  # pragma: no cover - compiled only
    """Whether unilateral contact ``c`` is open at the state ``y`` (its indicator ≤ 0 when closed);
    False for a pressed contact. A rigid contact is open where g > 0 or ġ > 0 (whether a closed
    one is pressed, λ > 0, takes the forces: :func:`stickslip.integrate.contacts.initial_modes`)."""
    n = model_sizes(md.kin, md.m)[0]
    if is_rigid(md, n, c):
        g, rate = gap_and_rate(y, md, n, c)
        return g > 0.0 or rate > 0.0
    return is_unilateral(md, n, c) and contact_indicator(y, cst, md, n, c) <= 0.0
