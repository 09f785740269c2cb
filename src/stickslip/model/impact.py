"""The impact of a rigid unilateral contact: Newton's restitution with a Coulomb impulse.

A rigid contact ``c`` that closes with normal speed ġ⁻ = W_c q̇⁻ < 0 receives an impulse that
changes the velocities at once, Δq̇ = M⁻¹ (W_cᵀ P_N + G_cᵀ P_T + Σ Jᵀ P), such that

* its normal speed after is ġ⁺ = −e ġ⁻ (Newton's law, e ∈ [0, 1] its restitution);
* the other constraints hold through the impact: closed rigid contacts keep ġ = 0 and sticking
  contacts keep v = 0 (their impulses P are multipliers, not bounded here);
* tangentially (Coulomb's impact law): a *sticking* impact, v_c⁺ = 0, where the impulse that
  needs is admissible, |P_T| ≤ μs P_N; else a *sliding* one, P_T = −μ(|v_c⁻|) P_N e⁻ against the
  slip before the impact, e⁻ = v_c⁻/|v_c⁻|.

The sticking trial is the symmetric positive semi-definite system J M⁻¹ Jᵀ P = Δ (minimal norm,
:func:`~stickslip.model.linalg.solve_psd`); the sliding one is not symmetric (the column of P_N is
M⁻¹ (W_cᵀ − μ G_cᵀ e⁻)) and is solved in order (:func:`~stickslip.model.linalg.solve_in_order`),
its first pivot W_c M⁻¹ (W_cᵀ − μ G_cᵀ e⁻) relative to W_c M⁻¹ W_cᵀ: where that is not positive,
or P_N comes out ≤ 0, no impulse satisfies the law (an impact Painlevé paradox) and the impact is
reported inconsistent instead of applied.

Before the impulse the positions are moved onto g_c = 0 along M⁻¹ W_cᵀ (the located root lies
within the event tolerance of it, ~1e-12 ġ⁻), so the contact starts its next phase exactly on the
constraint.
"""

from __future__ import annotations

import math

import numpy as np

from .bundle import C_GAP, C_RESTITUTION, contact_offsets, gap_offset
from .frames import frame_velocity
from .jit import kernel, standalone
from .kinematics import contact_dim, contact_frame, model_sizes
from .linalg import solve_in_order, solve_psd
from .model_data import apply_inverse_mass, is_stick, kinetic_coefficient, static_limit
from .normal import is_open, is_rigid
from .stack import DOFS, IMPULSE_ROWS, ONE, TWO, work_matrix

__all__ = ["IMPACT_SLIDING", "IMPACT_STICKING", "IMPACT_INCONSISTENT", "impact", "gap_rate", "restitution_of",
           "remove_gap_rate", "inverse_mass_product"]

#: Outcomes of :func:`impact`: the contact slides on after it, sticks after it, or no impulse
#: satisfies the law (nothing is changed).
IMPACT_SLIDING, IMPACT_STICKING, IMPACT_INCONSISTENT = 0, 1, -1


@kernel
def inverse_mass_product(m, n, diagonal, f, a):
    """a = M⁻¹ f (:func:`~stickslip.model.model_data.apply_inverse_mass`) as a kernel: the rigid
    contacts' code (the impacts, :func:`~stickslip.model.forces.rigid_normal_forces`) calls it at
    many sites, which then type and lower one call each instead of an inlined body each."""
    apply_inverse_mass(m, n, diagonal, f, a)


@kernel
def gap_rate(s, c, md):
    """ġ = W_c q̇ of rigid contact ``c`` [m/s] (its gap is affine in q)."""
    m = md.m
    n = model_sizes(md.kin, m)[0]
    og = gap_offset(n, c)
    rate = 0.0
    for j in range(n):
        rate += m[og + j] * s[n + j]
    return rate


@kernel
def restitution_of(c, md):
    """Newton's restitution coefficient e of rigid contact ``c``."""
    return md.m[contact_offsets(model_sizes(md.kin, md.m)[0], c)[0] + C_RESTITUTION]


@kernel
def remove_gap_rate(s, c, md):
    """q̇ −= M⁻¹ W_cᵀ ġ / (W_c M⁻¹ W_cᵀ): the smallest (kinetic-energy) velocity change that ends
    contact ``c``'s normal motion; returns the ġ removed [m/s]."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    WMW = work_matrix(md.kin, TWO, DOFS, s)
    og = gap_offset(n, c)
    for j in range(n):
        WMW[0, j] = m[og + j]
    inverse_mass_product(m, n, diagonal, WMW[0], WMW[1])
    wmw = 0.0
    rate = 0.0
    for j in range(n):
        wmw += WMW[0, j] * WMW[1, j]
        rate += WMW[0, j] * s[n + j]
    for j in range(n):
        s[n + j] -= WMW[1, j] * rate / wmw
    return rate


@kernel
def impulse_rows(s, cst, c, md, restitution, J, target, with_tangent):
    """Fill the impulse rows J (k, n) and the velocity changes Δ they must make, in this order:
    contact ``c``'s normal row (Δ = −(1 + e) ġ⁻), its tangent rows if ``with_tangent``
    (Δ = −v_c), the other closed rigid contacts' normal rows and the sticking contacts' tangent
    rows (Δ = minus their velocity, which stays 0). Returns k."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G2 = work_matrix(md.kin, TWO, DOFS, s)
    w2 = work_matrix(md.kin, ONE, TWO, s)[0]
    k = _normal_row(s, c, md, J, target, np.int64(0), 1.0 + restitution)
    if with_tangent:
        k = _tangent_rows(s, c, md, J, target, k, G2, w2)
    for r in range(nc):
        if r != c and is_rigid(md, n, r) and not is_open(cst, r):
            k = _normal_row(s, r, md, J, target, k, 1.0)
    for r in range(nc):
        if r != c and is_stick(cst, r):
            k = _tangent_rows(s, r, md, J, target, k, G2, w2)
    return k


@kernel
def _normal_row(s, r, md, J, target, k, factor):
    """Row k: contact ``r``'s gap gradient W_r, its target −factor · ġ_r. Returns k + 1."""
    m = md.m
    n = model_sizes(md.kin, m)[0]
    og = gap_offset(n, r)
    rate = 0.0
    for j in range(n):
        J[k, j] = m[og + j]
        rate += m[og + j] * s[n + j]
    target[k] = -factor * rate
    return k + 1


@kernel
def _tangent_rows(s, r, md, J, target, k, G2, w2):
    """Rows k…: contact ``r``'s tangent rows G_r, their targets −v_r. Returns the next row."""
    m = md.m
    n = model_sizes(md.kin, m)[0]
    contact_frame(md.kin, s, r, m, G2, w2)
    dim = contact_dim(md.kin, m, n, r)
    v0, v1 = frame_velocity(s, n, dim, G2, w2)
    for i in range(dim):
        for j in range(n):
            J[k, j] = G2[i, j]
        target[k] = -(v0 if i == 0 else v1)
        k += 1
    return k


@standalone
@kernel
def impact(s, cst, c, md, restitution):
    """Apply the impact of rigid contact ``c`` with restitution e = ``restitution`` to the state
    ``s`` (in place; module docstring).

    Returns
    -------
    outcome : int
        ``IMPACT_STICKING``, ``IMPACT_SLIDING`` (also for a touch with ġ⁻ ≥ 0: no impulse) or
        ``IMPACT_INCONSISTENT`` (velocities unchanged).
    impulse : float
        The normal impulse P_N [N s].
    before, after : float
        ġ⁻ and ġ⁺ [m/s].
    """
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    J = work_matrix(md.kin, IMPULSE_ROWS, DOFS, s)
    MJ = work_matrix(md.kin, IMPULSE_ROWS, DOFS, s)
    A = work_matrix(md.kin, IMPULSE_ROWS, IMPULSE_ROWS, s)
    V = work_matrix(md.kin, IMPULSE_ROWS, IMPULSE_ROWS, s)
    target = work_matrix(md.kin, ONE, IMPULSE_ROWS, s)[0]
    x = work_matrix(md.kin, ONE, IMPULSE_ROWS, s)[0]
    G2 = work_matrix(md.kin, TWO, DOFS, s)
    w2 = work_matrix(md.kin, ONE, TWO, s)[0]
    WMW = work_matrix(md.kin, TWO, DOFS, s)
    W = WMW[0]
    MW = WMW[1]
    og = gap_offset(n, c)
    g = m[contact_offsets(n, c)[0] + C_GAP]
    for j in range(n):
        W[j] = m[og + j]
        g += W[j] * s[j]
    inverse_mass_product(m, n, diagonal, W, MW)
    wmw = 0.0
    for j in range(n):
        wmw += W[j] * MW[j]
    for j in range(n):  # onto g = 0
        s[j] -= MW[j] * g / wmw
    before = gap_rate(s, c, md)
    if before >= 0.0:
        return IMPACT_SLIDING, 0.0, before, before
    contact_frame(md.kin, s, c, m, G2, w2)
    dim = contact_dim(md.kin, m, n, c)
    v0, v1 = frame_velocity(s, n, dim, G2, w2)

    # a sticking impact: every row an equality
    k = impulse_rows(s, cst, c, md, restitution, J, target, np.bool_(True))
    for r in range(k):
        inverse_mass_product(m, n, diagonal, J[r], MJ[r])
    for r in range(k):
        for r2 in range(k):
            acc = 0.0
            for j in range(n):
                acc += J[r, j] * MJ[r2, j]
            A[r, r2] = acc
    solve_psd(A, target, x, V, k)
    PN = x[0]
    PT = math.sqrt(x[1] * x[1] + (x[2] * x[2] if dim == 2 else 0.0))
    if PN > 0.0 and PT <= static_limit(m, n, c, PN):
        _add_impulses(s, n, MJ, x, k)
        return IMPACT_STICKING, PN, before, gap_rate(s, c, md)

    # a sliding impact: P_T = −μ P_N e⁻ (e⁻ against the slip before; from v = 0, against the
    # sticking trial's impulse)
    speed = math.sqrt(v0 * v0 + v1 * v1)
    if speed > 0.0:
        e0 = v0 / speed
        e1 = v1 / speed
    elif PT > 0.0:
        e0 = -x[1] / PT
        e1 = -x[2] / PT if dim == 2 else 0.0
    else:
        e0 = 0.0
        e1 = 0.0
    mu = kinetic_coefficient(md, n, c, speed)
    k = impulse_rows(s, cst, c, md, restitution, J, target, np.bool_(False))
    for j in range(n):
        MW[j] = W[j] - mu * (G2[0, j] * e0 + (G2[1, j] * e1 if dim == 2 else 0.0))
    inverse_mass_product(m, n, diagonal, MW, MJ[0])
    for r in range(1, k):
        inverse_mass_product(m, n, diagonal, J[r], MJ[r])
    for r in range(k):  # each row scaled by its frictionless diagonal: relative pivots
        inverse_mass_product(m, n, diagonal, J[r], MW)
        scale = 0.0
        for j in range(n):
            scale += J[r, j] * MW[j]
        for r2 in range(k):
            acc = 0.0
            for j in range(n):
                acc += J[r, j] * MJ[r2, j]
            A[r, r2] = acc / scale
        target[r] /= scale
    pivot = solve_in_order(A, target, x, k)
    if not (pivot > 0.0 and x[0] > 0.0):
        return IMPACT_INCONSISTENT, x[0], before, before
    _add_impulses(s, n, MJ, x, k)
    return IMPACT_SLIDING, x[0], before, gap_rate(s, c, md)


@kernel
def _add_impulses(s, n, MJ, x, k):
    """q̇ += Σ_r x_r MJ_r (the impulses' velocity change)."""
    for r in range(k):
        for j in range(n):
            s[n + j] += MJ[r, j] * x[r]
