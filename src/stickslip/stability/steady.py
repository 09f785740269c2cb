"""Compiled steady sliding of any friction model, and its Jacobian, at one point or over a grid.

Steady sliding is q̇ = 0 and f0 − K q + Σ_c G_cᵀ F_c(q, 0) = 0 with every contact slipping. The
residual is the simulator's own right-hand side (:func:`stickslip.model.physics.rhs`) at rest,
as forces Q = M q̈; its Jacobian is the complex step of the same right-hand side
(:func:`stickslip.model.derivatives.acceleration_jacobian`), so nothing is derived by hand and
nothing can drift from what the integrator sees.

Newton starts from q = 0. Close to a fold of the equilibrium branch it can stall although a
solution exists; then the normal forces N0 of all contacts are ramped from a fraction of their
value, each solution starting the next (step doubled on success, halved on failure, down to 1e-3).

Models arrive as :class:`~stickslip.model.bundle.ModelData`. Over a grid, each point's data array
is assembled inside the kernel from two axis tables (:func:`jacobian_points`), and its kinematics
data rebuilt from a row of numbers (:func:`kinematics_from`), so one compiled call serves a whole
map.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba.extending import overload

from ..model.bundle import C_DIM, C_N0, CST, H_BAND, H_DIAGONAL, H_N, H_NC, ModelData, contact_offsets, offsets
from ..model.compile_ahead import Split
from ..model.derivatives import acceleration_jacobian, state_jacobian
from ..model.stick import solve_stick_rows
from ..model.frame_pointers import is_pointer_class
from ..model.frames import _frame_bias_central
from ..model.jit import KERNEL_OPTIONS, inlined_kernel, inlined_loop, kernel, loop
from ..model.kinematics import model_sizes, sizes_at_run_time, unilateral_kernel
from ..model.model_data import kinetic_coefficient
from ..model.normal import contact_indicator, is_rigid, is_unilateral
from ..model.physics import MODE_SLIP_EXACT, rhs, slip_velocity

__all__ = ["NEWTON_OK", "NEWTON_MAX_ITER", "NEWTON_SINGULAR", "NEWTON_NOT_FINITE", "NEWTON_NO_DESCENT",
           "NEWTON_NOT_SLIDING", "NEWTON_TARGET", "CONTINUATION_ACCEPT", "STEADY_NONE", "STEADY_PRESSED",
           "STEADY_UNPRESSED", "steady_sliding_point",
           "steady_jacobian", "AxisTables", "jacobian_points", "kinematics_from", "kinematics_values"]

NEWTON_OK = 0
NEWTON_MAX_ITER = 1
NEWTON_SINGULAR = 2
NEWTON_NOT_FINITE = 3
NEWTON_NO_DESCENT = 4
#: Converged, but a contact does not slide (speed 0) or a 2-D contact slides inside the low-speed
#: band, where the simulator's slip direction is not v/|v|: no steady sliding of the simulated equations.
NEWTON_NOT_SLIDING = 5

#: Relative residual at which Newton stops (a few ulps above the round-off of the force balance).
NEWTON_TARGET = 1e-14

#: Relative residual below which a solve counts as converged for the load continuation.
CONTINUATION_ACCEPT = 1e-10

#: :func:`steady_jacobian`'s outcomes: no steady sliding with every contact closed (J NaN); steady
#: sliding with every unilateral contact pressed (g < 0, λ > 0), J its linearisation; steady
#: sliding held closed that leaves some unilateral contact unpressed (or holds a rigid one closed,
#: whose normal force is a multiplier: not decided here), J that of the closed contacts, which is
#: not the model's where that contact opens.
STEADY_NONE = 0
STEADY_PRESSED = 1
STEADY_UNPRESSED = 2


def kinematics_values(kin) -> np.ndarray:
    """The fields of a kinematics NamedTuple as floats (nf,), for :func:`kinematics_from`.

    Raises
    ------
    TypeError
        When a field is not a number (such kinematics cannot be varied over a grid).
    """
    fields = kin.values if is_pointer_class(type(kin)) else kin  # a frame compiled apart: the user's fields
    try:
        return np.array([float(v) for v in fields], dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"the kinematics data {type(kin).__name__} has fields that are not numbers") from None


def kinematics_from(kin, values):  # pragma: no cover - resolved by numba (overload below)
    """A kinematics NamedTuple of the class of ``kin`` with the fields ``values`` (nf,)."""
    raise NotImplementedError


@overload(kinematics_from, jit_options=KERNEL_OPTIONS)
def _kinematics_from(kin, values):
    cls = getattr(kin, "instance_class", None)
    types = getattr(kin, "types", ())
    pointers = is_pointer_class(cls)  # the addresses kept, the user's fields (the last one, a tuple) replaced
    fields = getattr(types[-1], "types", ()) if pointers else types
    if cls is None or not all(str(t) == "float64" for t in fields):
        def same(kin, values):  # fields that are not all floats are never varied
            return kin
        return same
    args = ", ".join(f"values[{i}]" for i in range(len(fields)))
    if pointers:
        args = ", ".join(f"kin[{i}]" for i in range(len(types) - 1)) + f", ({args},)"
    namespace = {"cls": cls}
    exec(f"def build(kin, values):\n    return cls({args})\n", namespace)  # noqa: S102 - fixed template
    return namespace["build"]


@kernel
def _sliding_modes(cst, nc):
    """Every contact slipping with the exact direction v/|v| (the modes of steady sliding)."""
    for c in range(nc):
        cst[c * CST] = MODE_SLIP_EXACT
        cst[c * CST + 1] = 1.0
        cst[c * CST + 2] = 0.0
        cst[c * CST + 3] = np.inf


@inlined_kernel
def _residual(q, cst, md, free, s, ds, Q):
    """Forces Q = M q̈ at rest (free DOFs) into ``Q``; returns max|Q| / max(|K q|, |f0|, |Σ Gᵀ F|)."""
    m = md.m
    n = q.shape[0]
    o_minv, o_mass, o_damp, o_stiff, o_force, o_free, o_c = offsets(n)
    for i in range(n):
        s[i] = q[i]
        s[n + i] = 0.0
    rhs(s, cst, md, ds)
    num = 0.0
    scale = 0.0
    for a in range(free.shape[0]):
        i = free[a]
        f = 0.0
        kq = 0.0
        for j in range(n):
            f += m[o_mass + i * n + j] * ds[n + j]
            kq += m[o_stiff + i * n + j] * q[j]
        Q[i] = f
        num = max(num, abs(f))
        scale = max(scale, abs(kq), abs(m[o_force + i]), abs(f + kq - m[o_force + i]))
    if num == 0.0:
        return 0.0
    if scale == 0.0 or not np.isfinite(num):
        return np.inf
    return num / scale


@kernel
def _solve_inplace(A, b):
    """Gaussian elimination with partial pivoting; returns False if A is singular (to round-off)."""
    n = A.shape[0]
    amax = 0.0
    for i in range(n):
        for j in range(n):
            amax = max(amax, abs(A[i, j]))
    if amax == 0.0:
        return False
    for c in range(n):
        piv = c
        for i in range(c + 1, n):
            if abs(A[i, c]) > abs(A[piv, c]):
                piv = i
        # a pivot below n·eps of the largest entry means the matrix is singular to round-off
        if abs(A[piv, c]) <= 1e-14 * amax:
            return False
        if piv != c:
            for j in range(n):
                A[c, j], A[piv, j] = A[piv, j], A[c, j]
            b[c], b[piv] = b[piv], b[c]
        for i in range(c + 1, n):
            f = A[i, c] / A[c, c]
            for j in range(c, n):
                A[i, j] -= f * A[c, j]
            b[i] -= f * b[c]
    for c in range(n - 1, -1, -1):
        acc = b[c]
        for j in range(c + 1, n):
            acc -= A[c, j] * b[j]
        b[c] = acc / A[c, c]
    return True


@inlined_loop
def _newton_from(q, cst, md, free, max_iter):
    """Damped Newton on the forces at rest from ``q`` (changed in place).

    The step solves (M ∂q̈/∂q) dx = −Q on the free DOFs and is halved until ‖Q‖² decreases
    (Armijo, c = 1e-4). Returns (status, relative residual, iterations).
    """
    m = md.m
    n = q.shape[0]
    k = free.shape[0]
    o_mass = offsets(n)[1]
    s = np.zeros(2 * n)
    ds = np.zeros(2 * n)
    Q = np.zeros(n)
    trial_Q = np.zeros(n)
    trial = np.zeros(n)
    Jqq = np.empty((n, n))
    acc = np.empty(n)
    z = np.zeros(2 * n, dtype=np.complex128)
    dz = np.zeros(2 * n, dtype=np.complex128)
    A = np.empty((k, k))
    dx = np.empty(k)
    rel = _residual(q, cst, md, free, s, ds, Q)
    for it in range(max_iter):
        if not np.isfinite(rel):
            return NEWTON_NOT_FINITE, rel, it
        if rel <= NEWTON_TARGET:
            return NEWTON_OK, rel, it
        acceleration_jacobian(q, cst, md, Jqq, acc, z, dz)
        norm0 = 0.0
        for a in range(k):
            i = free[a]
            dx[a] = -Q[i]
            norm0 += Q[i] ** 2
            for b in range(k):
                v = 0.0
                for j in range(n):
                    v += m[o_mass + i * n + j] * Jqq[j, free[b]]
                A[a, b] = v
        if not _solve_inplace(A, dx):
            return NEWTON_SINGULAR, rel, it
        t = 1.0
        accepted = False
        trial_rel = rel
        for _ in range(40):  # 2^-40 ≈ 1e-12: a shorter step cannot change q beyond round-off
            for i in range(n):
                trial[i] = q[i]
            for a in range(k):
                trial[free[a]] += t * dx[a]
            trial_rel = _residual(trial, cst, md, free, s, ds, trial_Q)
            norm1 = 0.0
            for a in range(k):
                norm1 += trial_Q[free[a]] ** 2
            if np.isfinite(norm1) and norm1 <= (1.0 - 1e-4 * t) * norm0:
                accepted = True
                break
            t *= 0.5
        if not accepted:
            # no decrease along the Newton direction: at round-off level this is convergence
            return NEWTON_NO_DESCENT, rel, it
        for i in range(n):
            q[i] = trial[i]
            Q[i] = trial_Q[i]
        rel = trial_rel
    if rel <= NEWTON_TARGET:
        return NEWTON_OK, rel, max_iter
    return NEWTON_MAX_ITER, rel, max_iter


@loop
def steady_sliding_point(md, free, max_iter):
    """Steady sliding of the model ``md``: Newton from q = 0, load continuation as a fallback.

    Parameters
    ----------
    md : ModelData
    free : ndarray (k,) int64
        Indices of the free DOFs.
    max_iter : int
        Newton iterations per solve.

    Returns
    -------
    q : ndarray (n,)
        Last iterate (locked DOFs 0).
    status : int
        ``NEWTON_*`` code (:data:`NEWTON_NOT_SLIDING` when converged but not sliding).
    rel : float
        Relative force residual of ``q``.
    iterations : int
        Newton iterations in all.
    """
    return _steady_sliding(md, free, max_iter)


@inlined_loop
def _steady_sliding(md, free, max_iter):
    """:func:`steady_sliding_point`'s body, inlined into it and into :func:`steady_jacobian` (a
    compiled call would link and optimise the complex-step physics below it once more)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    cst = np.zeros(CST * nc)
    _sliding_modes(cst, nc)
    q = np.zeros(n)
    # One call of the Newton, inlined: the first pass is the full load from q = 0, later passes
    # the load continuation, each from the previous load's solution.
    mw = m.copy()
    mdw = ModelData(mw, md.kin, md.law)
    qc = np.zeros(n)
    qt = np.zeros(n)
    status = NEWTON_MAX_ITER
    rel = np.inf
    iterations = 0
    full_load = True
    lam = 0.0
    step = 0.125
    while full_load or lam < 1.0:
        trial = 1.0 if full_load else min(1.0, lam + step)
        for c in range(nc):
            o = contact_offsets(n, c)[0]
            mw[o + C_N0] = trial * m[o + C_N0]
        for i in range(n):
            qt[i] = qc[i]
        # from the previous load's solution Newton converges in a few steps or not at all
        st, rt, it = _newton_from(qt, cst, mdw, free, max_iter if full_load else min(max_iter, 20))
        iterations += it
        if full_load:
            full_load = False
            for i in range(n):
                q[i] = qt[i]
            status, rel = st, rt
            if rel <= CONTINUATION_ACCEPT:
                break
        elif rt <= CONTINUATION_ACCEPT:
            lam = trial
            for i in range(n):
                qc[i] = qt[i]
                q[i] = qt[i]
            status, rel = st, rt
            step = min(2.0 * step, 0.25)
        else:
            step *= 0.5
            if step < 1e-3:  # the equilibrium branch from N0 = 0 ends (fold) before the full load
                for i in range(n):
                    q[i] = qt[i]
                return q, st, rt, iterations
    if rel <= CONTINUATION_ACCEPT:
        s = np.zeros(2 * n)
        for i in range(n):
            s[i] = q[i]
        for c in range(nc):
            v0, v1 = slip_velocity(s, c, md)
            speed = np.sqrt(v0 * v0 + v1 * v1)
            o = contact_offsets(n, c)[0]
            if speed == 0.0 or (m[o + C_DIM] == 2.0 and speed <= m[H_BAND]):
                return q, NEWTON_NOT_SLIDING, rel, iterations
    return q, status, rel, iterations


def _steady_calls(md) -> dict:
    """The arguments with which steady sliding's Newton calls the kernels of :data:`STEADY`, for
    the model data ``md`` (complex-step physics: complex states and work arrays)."""
    m = md.m
    n, nc, diagonal = int(m[H_N]), int(m[H_NC]), bool(m[H_DIAGONAL] != 0.0)
    s = np.zeros(2 * n, dtype=complex)
    cst = np.zeros(CST * nc)
    G = np.zeros((2 * nc, n), dtype=complex)
    rows = np.zeros(2 * nc, dtype=complex)
    return {solve_stick_rows: (s, md, n, nc, diagonal, cst, -1, G, rows, np.zeros(n, dtype=complex), rows,
                               np.zeros((2 * nc, 2 * nc), dtype=complex)),
            kinetic_coefficient: (md, n, 0, 0j),
            _frame_bias_central: (s, 0, md, G[0:2], rows[0:2], rows[0:2]),
            _solve_inplace: (np.zeros((n, n)), np.zeros(n))}


#: A cold start's steady-sliding kernels in two processes (:mod:`stickslip.model.compile_ahead`),
#: for kinematics whose sizes are run-time data (model files; fixed sizes are compile-time constants
#: in these signatures): the complex-step stick solve (the deepest level of the chain under the
#: Newton) in the helper; the friction coefficient, the frame's central-difference bias (complex)
#: and the Newton's linear solve here; :func:`steady_sliding_point` then loads both.
STEADY = Split(helper=(solve_stick_rows,), own=(kinetic_coefficient, _frame_bias_central, _solve_inplace),
               caller=steady_sliding_point, calls=_steady_calls, applies=lambda md: sizes_at_run_time(md.kin))


@loop
def steady_jacobian(md, free, max_iter, tol, J):
    """Steady sliding with every contact closed, then the Jacobian of the slip equations there,
    reduced to the free DOFs.

    Writes J (2k × 2k) = ∂(ds/dt)/∂s on [q_free, q̇_free] and returns :data:`STEADY_PRESSED` or
    :data:`STEADY_UNPRESSED` when Newton reached the relative residual ``tol`` with every contact
    sliding (whether each unilateral contact is pressed there: :func:`_pressed`); otherwise
    :data:`STEADY_NONE` and ``J`` NaN.
    """
    n, nc, diagonal = model_sizes(md.kin, md.m)
    k = free.shape[0]
    q, status, rel, _ = _steady_sliding(md, free, max_iter)
    if not (rel <= tol) or status == NEWTON_NOT_SLIDING:
        for i in range(2 * k):
            for j in range(2 * k):
                J[i, j] = np.nan
        return STEADY_NONE
    s = np.zeros(2 * n)
    for i in range(n):
        s[i] = q[i]
    cst = np.zeros(CST * nc)
    _sliding_modes(cst, nc)
    full = np.empty((2 * n, 2 * n))
    state_jacobian(s, cst, md, full, np.zeros(2 * n, dtype=np.complex128), np.zeros(2 * n, dtype=np.complex128))
    for a in range(k):
        for b in range(k):
            J[a, b] = full[free[a], free[b]]
            J[a, k + b] = full[free[a], n + free[b]]
            J[k + a, b] = full[n + free[a], free[b]]
            J[k + a, k + b] = full[n + free[a], n + free[b]]
    return STEADY_PRESSED if _pressed(s, cst, md, n, nc) else STEADY_UNPRESSED


@unilateral_kernel(lambda s, cst, md, n, nc: True, inline="always")
def _pressed(s, cst, md, n, nc):  # pragma: no cover - compiled only
    """Whether every unilateral contact is pressed at ``s`` in the modes ``cst`` (all closed): a
    compliant one with g < 0 and λ̃ = −k g − c ġ > 0 (its indicator min(−g, λ̃/k) > 0), as
    :func:`stickslip.stability.equilibrium.solve_steady_modes` asks; False where a rigid one is
    closed (its normal force, a multiplier, is not computed here). Kinematics without unilateral
    contacts compile the constant True instead."""
    for c in range(nc):
        if is_unilateral(md, n, c) and (is_rigid(md, n, c) or not contact_indicator(s, cst, md, n, c) > 0.0):
            return False
    return True


class AxisTables(NamedTuple):
    """The points of a grid over two parameters, as two tables of model numbers (:func:`jacobian_points`).

    Point p has the data array ``m_a[ia[p]]`` with the entries flagged in ``mask_b`` taken from
    ``m_b[ib[p]]``, and the kinematics fields ``kv_a[ia[p]]`` with those flagged in ``kmask_b``
    from ``kv_b[ib[p]]``. A map whose two parameters touch disjoint entries is thus nA + nB rows
    instead of nA × nB models.

    Attributes
    ----------
    m_a, m_b : ndarray (nA, L), (nB, L)
        Data arrays along each axis.
    mask_b : ndarray (L,) bool
        Entries of ``m`` taken from ``m_b``.
    kv_a, kv_b : ndarray (nA, nf), (nB, nf)
        Kinematics fields along each axis (:func:`kinematics_values`).
    kmask_b : ndarray (nf,) bool
        Fields taken from ``kv_b``.
    ia, ib : ndarray (P,) int64
        Each point's rows.
    """

    m_a: np.ndarray
    m_b: np.ndarray
    mask_b: np.ndarray
    kv_a: np.ndarray
    kv_b: np.ndarray
    kmask_b: np.ndarray
    ia: np.ndarray
    ib: np.ndarray


@loop
def jacobian_points(tables, kin0, law, free, max_iter, tol, out, found):
    """:func:`steady_jacobian` at the points of the :class:`AxisTables` ``tables``, into ``out``
    (P, 2k, 2k) and its outcome into ``found`` (P,) int8 (``STEADY_*``); the kinematics of a point
    are ``kinematics_from(kin0, kv)``, its user friction law ``law``
    (:class:`~stickslip.model.friction.NoUserLaw` if none). NaN where no steady sliding exists."""
    m_a, m_b, mask_b, kv_a, kv_b, kmask_b, ia, ib = tables
    mw = np.empty(m_a.shape[1])
    kv = np.empty(kv_a.shape[1])
    for p in range(ia.shape[0]):
        a = ia[p]
        b = ib[p]
        for i in range(mw.shape[0]):
            mw[i] = m_b[b, i] if mask_b[i] else m_a[a, i]
        for i in range(kv.shape[0]):
            kv[i] = kv_b[b, i] if kmask_b[i] else kv_a[a, i]
        found[p] = steady_jacobian(ModelData(mw, kinematics_from(kin0, kv), law), free, max_iter, tol, out[p])
