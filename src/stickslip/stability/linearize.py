"""Linearisation of the slip equations by complex-step (forward-mode) differentiation.

The slip right-hand side is written **once**, in :func:`slip_forces`, as a numba function that is
generic in the number type of the state: compiled for ``float64`` it is the simulator's slip
right-hand side (the test suite checks it against ``kernels.dynamics(contact_force(...))`` to
round-off); compiled for ``complex128`` it differentiates itself. With a perturbation i h along
state j and h = :data:`STEP` = 1e-150, every product of two perturbations is of order h² = 1e-300
relative and vanishes against the values, so complex arithmetic *is* dual-number arithmetic
(f + f' ε, ε² = 0) and Im f(s + i h e_j) / h = ∂f/∂s_j exactly up to round-off — no truncation
error, no subtractive cancellation, nothing derived or copied by hand (Squire & Trapp 1998;
Martins, Sturdza & Alonso 2003, "The complex-step derivative approximation").
Requirements that keep this exact: only analytic operations on the state (``np.sqrt`` of a sum
of squares, never ``abs``), and branches decided by real parts only.

Notation (DESIGN.md §1): q = [x1, y1, x2, y2, φ, ψ], s = [q, q̇],

    M q̈ = Q(q, q̇),   Q = Gᵀ F − C q̇ − K q,   F = −μ(|v_r|) N v_r / |v_r|   (Eqs. 1, 3, 4, 9)

The linearisation about a state (paper Eq. 15) is M_L = M, C_L = −∂Q/∂q̇, K_L = −∂Q/∂q, and the
first-order Jacobian of s is J = [[0, I], [M⁻¹ ∂Q/∂q, M⁻¹ ∂Q/∂q̇]].
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..model.kernels import LAW_COULOMB, P_ALPHA, P_DELTA_MU, P_LAW, P_MU_K, P_N, P_OMEGA, P_R, P_SLIP_BAND

__all__ = ["slip_forces", "slip_rhs", "force_jacobian", "state_jacobian", "newton_from", "newton_equilibrium",
           "reduced_jacobian", "equilibrium_jacobian", "jacobian_grid", "STEP"]

#: Complex step h. Any h with h² far below round-off of the values and h·|∂f| far above the
#: smallest normal double (2.2e-308) gives ∂f exactly; 1e-150 sits in the middle of that range.
STEP = 1e-150

# Newton status codes (newton_equilibrium)
NEWTON_OK = 0
NEWTON_MAX_ITER = 1
NEWTON_SINGULAR = 2
NEWTON_NOT_FINITE = 3
NEWTON_NO_DESCENT = 4

#: Relative residual at which Newton stops iterating: a few ulps above the ~1e-16 round-off of
#: |K x| and |b|; the caller accepts anything ≤ its own (looser) tolerance.
NEWTON_TARGET = 1e-14


@njit(cache=True)
def slip_forces(s, damp, stiff, p, out):
    """Generalised forces Q = Gᵀ F − C q̇ − K q in slip (Eqs. 1, 3, 4, 9) [N, N m].

    Generic in the number type: ``s`` and ``out`` are both float64 or both complex128 (the latter
    for complex-step differentiation). Locked DOFs need no special case here: their rows are
    multiplied by a zero inverse mass in :func:`slip_rhs` and dropped by :func:`reduced_jacobian`.

    Parameters
    ----------
    s : ndarray, shape (≥12,)
        State [q, q̇] (extra entries ignored).
    damp, stiff : ndarray, shape (6,)
        Diagonals of C and K.
    p : ndarray, shape (8,)
        Contact and friction data, ``kernels.P_*``.
    out : ndarray, shape (6,)
        Receives Q.
    """
    r = p[P_R]
    sphi = np.sin(s[4])
    cphi = np.cos(s[4])
    X = s[0] - s[2] + r * cphi
    Y = s[1] - s[3] + r * sphi
    w = p[P_OMEGA] + s[11]
    # relative velocity, Eq. (9)
    vx = s[6] - s[8] - r * sphi * s[10] + w * Y
    vy = s[7] - s[9] + r * cphi * s[10] - w * X
    speed = np.sqrt(vx * vx + vy * vy)  # analytic: no abs(), so the complex step stays exact
    # friction coefficient, Eq. (4) (or constant μk for the Coulomb law)
    if p[P_LAW] == LAW_COULOMB:
        mu = p[P_MU_K] + 0.0 * speed
    else:
        mu = p[P_MU_K] + p[P_DELTA_MU] * np.exp(-p[P_ALPHA] * speed)
    # slip force, Eq. (3)
    scale = -mu * p[P_N] / speed
    Fx = scale * vx
    Fy = scale * vy
    # generalised friction Gᵀ F (DESIGN.md §1)
    out[0] = Fx - damp[0] * s[6] - stiff[0] * s[0]
    out[1] = Fy - damp[1] * s[7] - stiff[1] * s[1]
    out[2] = -Fx - damp[2] * s[8] - stiff[2] * s[2]
    out[3] = -Fy - damp[3] * s[9] - stiff[3] * s[3]
    out[4] = r * (-sphi * Fx + cphi * Fy) - damp[4] * s[10] - stiff[4] * s[4]
    out[5] = Y * Fx - X * Fy - damp[5] * s[11] - stiff[5] * s[5]


@njit(cache=True)
def slip_rhs(s, minv, damp, stiff, p, ds):
    """Slip right-hand side ds/dt = [q̇, M⁻¹ Q] (12,), from :func:`slip_forces`."""
    Q = np.empty(6, dtype=ds.dtype)
    slip_forces(s, damp, stiff, p, Q)
    for i in range(6):
        ds[i] = s[6 + i]
        ds[6 + i] = minv[i] * Q[i]


@njit(cache=True)
def force_jacobian(s, damp, stiff, p, columns, out):
    """∂Q/∂s_j for the state indices j in ``columns``, by complex step (exact to round-off).

    Parameters
    ----------
    s : ndarray, shape (12,), float64
    columns : ndarray of int64
        State indices to differentiate along.
    out : ndarray, shape (6, len(columns)), float64
        Receives ∂Q_i/∂s_columns[k] [N/m, N s/m, ...].
    """
    z = np.empty(12, dtype=np.complex128)
    Q = np.empty(6, dtype=np.complex128)
    for i in range(12):
        z[i] = s[i]
    for k in range(columns.shape[0]):
        j = columns[k]
        z[j] = s[j] + 1j * STEP
        slip_forces(z, damp, stiff, p, Q)
        for i in range(6):
            out[i, k] = Q[i].imag / STEP
        z[j] = s[j]


@njit(cache=True)
def state_jacobian(s, minv, damp, stiff, p):
    """Full 12×12 Jacobian ∂(ds/dt)/∂s of the slip equations at state ``s`` [1/s, 1/s²]."""
    cols = np.arange(12)
    dQ = np.empty((6, 12))
    force_jacobian(s, damp, stiff, p, cols, dQ)
    J = np.zeros((12, 12))
    for i in range(6):
        J[i, 6 + i] = 1.0
        for j in range(12):
            J[6 + i, j] = minv[i] * dQ[i, j]
    return J


@njit(cache=True)
def reduced_jacobian(q, free, minv, damp, stiff, p):
    """Jacobian of the slip equations about the rest state (q, q̇ = 0), reduced to the free DOFs.

    Rows and columns are [q_free, q̇_free] (2k×2k); locked DOFs (zero inverse mass, zero state)
    carry only zero rows and would add spurious zero eigenvalues, so they are left out.
    """
    k = free.shape[0]
    s = np.zeros(12)
    for i in range(6):
        s[i] = q[i]
    cols = np.empty(2 * k, dtype=np.int64)
    for a in range(k):
        cols[a] = free[a]
        cols[k + a] = 6 + free[a]
    dQ = np.empty((6, 2 * k))
    force_jacobian(s, damp, stiff, p, cols, dQ)
    J = np.zeros((2 * k, 2 * k))
    for a in range(k):
        J[a, k + a] = 1.0
        i = free[a]
        for b in range(2 * k):
            J[k + a, b] = minv[i] * dQ[i, b]
    return J


@njit(cache=True)
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


@njit(cache=True)
def _relative_residual(q, free, damp, stiff, p, Q):
    """max |Q_free| / max(|K q|, |b|) at rest; Q = b − K q is filled in as a side effect."""
    s = np.zeros(12)
    for i in range(6):
        s[i] = q[i]
    slip_forces(s, damp, stiff, p, Q)
    num = 0.0
    scale = 0.0
    for a in range(free.shape[0]):
        i = free[a]
        kq = stiff[i] * q[i]
        num = max(num, abs(Q[i]))
        scale = max(scale, abs(kq), abs(Q[i] + kq))
    if num == 0.0:
        return 0.0
    if scale == 0.0 or not np.isfinite(num):
        return np.inf
    return num / scale


@njit(cache=True)
def newton_from(q0, free, damp, stiff, p, max_iter):
    """Steady sliding K x = b(x) (Eq. 14) by damped Newton from ``q0`` with the exact Jacobian.

    The residual is Q(q, q̇ = 0) = b(q) − K q on the free DOFs; its Jacobian is ∂Q/∂q = −K_L
    (complex step). Steps are halved until the residual norm decreases (Armijo, c = 1e-4).

    Returns
    -------
    q : ndarray (6,)
        Last iterate (locked DOFs 0) [m, rad].
    status : int
        ``NEWTON_*`` code.
    rel : float
        Relative residual max|b − K q| / max(|K q|, |b|) of ``q``.
    iterations : int
    """
    k = free.shape[0]
    q = q0.copy()
    Q = np.empty(6)
    trial_Q = np.empty(6)
    dQ = np.empty((6, k))
    A = np.empty((k, k))
    dx = np.empty(k)
    trial = np.empty(6)
    s = np.zeros(12)
    rel = _relative_residual(q, free, damp, stiff, p, Q)
    for it in range(max_iter):
        if not np.isfinite(rel):
            return q, NEWTON_NOT_FINITE, rel, it
        if rel <= NEWTON_TARGET:
            return q, NEWTON_OK, rel, it
        for i in range(6):
            s[i] = q[i]
        force_jacobian(s, damp, stiff, p, free, dQ)
        norm0 = 0.0
        for a in range(k):
            dx[a] = -Q[free[a]]
            norm0 += Q[free[a]] ** 2
            for b in range(k):
                A[a, b] = dQ[free[a], b]
        if not _solve_inplace(A, dx):
            return q, NEWTON_SINGULAR, rel, it
        t = 1.0
        accepted = False
        for _ in range(40):  # 2^-40 ≈ 1e-12: a shorter step cannot change q beyond round-off
            for i in range(6):
                trial[i] = q[i]
            for a in range(k):
                trial[free[a]] += t * dx[a]
            trial_rel = _relative_residual(trial, free, damp, stiff, p, trial_Q)
            norm1 = 0.0
            for a in range(k):
                norm1 += trial_Q[free[a]] ** 2
            if np.isfinite(norm1) and norm1 <= (1.0 - 1e-4 * t) * norm0:
                accepted = True
                break
            t *= 0.5
        if not accepted:
            # no decrease along the Newton direction: at round-off level this is convergence
            return q, NEWTON_NO_DESCENT, rel, it
        for i in range(6):
            q[i] = trial[i]
            Q[i] = trial_Q[i]
        rel = trial_rel
    if rel <= NEWTON_TARGET:
        return q, NEWTON_OK, rel, max_iter
    return q, NEWTON_MAX_ITER, rel, max_iter


#: Relative residual below which a Newton solve counts as converged for the load continuation
#: (the same as ``equilibrium.RESIDUAL_TOL``).
CONTINUATION_ACCEPT = 1e-10


@njit(cache=True)
def newton_equilibrium(free, damp, stiff, p, max_iter):
    """Steady sliding (Eq. 14): Newton from x = 0, with continuation in the load N as fallback.

    Newton from x = 0 converges in 3–8 iterations for moderate deflections. Close to the load
    where the equilibrium ceases to exist (a fold, where the contact point is dragged towards
    the centre O2) it can stall although a solution exists; then the load is ramped up from a
    fraction of N with each solution as the next start (step doubled on success, halved on
    failure, down to 1e-3 of N). Returns as :func:`newton_from`, with the total iterations.
    """
    q, status, rel, iterations = newton_from(np.zeros(6), free, damp, stiff, p, max_iter)
    if rel <= CONTINUATION_ACCEPT:
        return q, status, rel, iterations
    pp = p.copy()
    n_target = p[P_N]
    lam = 0.0
    step = 0.125
    qc = np.zeros(6)
    while lam < 1.0:
        trial = min(1.0, lam + step)
        pp[P_N] = trial * n_target
        # from the previous load's solution Newton converges in a few steps or not at all
        qt, st, rt, it = newton_from(qc, free, damp, stiff, pp, min(max_iter, 20))
        iterations += it
        if rt <= CONTINUATION_ACCEPT:
            lam = trial
            qc = qt
            q, status, rel = qt, st, rt
            step = min(2.0 * step, 0.25)
        else:
            step *= 0.5
            if step < 1e-3:  # the equilibrium branch from N = 0 ends (fold) before the target load
                return qt, st, rt, iterations
    return q, status, rel, iterations


@njit(cache=True)
def equilibrium_jacobian(free, minv, damp, stiff, p, max_iter, tol, J):
    """Newton equilibrium, then the reduced Jacobian there written into ``J`` (2k×2k).

    Returns True when Newton reached the relative residual ``tol`` at a sliding speed above the
    simulator's low-speed band; otherwise ``J`` is NaN (no steady sliding of the simulated equations).
    """
    q, status, rel, _ = newton_equilibrium(free, damp, stiff, p, max_iter)
    r = p[P_R]
    X = q[0] - q[2] + r * np.cos(q[4])
    Y = q[1] - q[3] + r * np.sin(q[4])
    speed = abs(p[P_OMEGA]) * np.sqrt(X * X + Y * Y)
    # inside the low-speed band the simulator's slip direction is not v_r/|v_r| (kernels.py)
    if not (rel <= tol) or speed <= p[P_SLIP_BAND]:
        J[:, :] = np.nan
        return False
    Jq = reduced_jacobian(q, free, minv, damp, stiff, p)
    for i in range(J.shape[0]):  # element loop: a slice copy compiles numba's shape-error formatting
        for j in range(J.shape[1]):
            J[i, j] = Jq[i, j]
    return True


@njit(cache=True)
def jacobian_grid(free, minv, damp, stiff, p, N_values, Omega_values, max_iter, tol, out):
    """:func:`equilibrium_jacobian` over the grid N_values × Omega_values into ``out`` (nN, nΩ, 2k, 2k).

    The eigenvalues are taken outside numba by NumPy's batched LAPACK dgeev, which is several
    times faster than numba's complex-only path for real matrices with complex spectra.
    """
    pp = p.copy()
    for a in range(N_values.shape[0]):
        pp[P_N] = N_values[a]
        for b in range(Omega_values.shape[0]):
            pp[P_OMEGA] = Omega_values[b]
            equilibrium_jacobian(free, minv, damp, stiff, pp, max_iter, tol, out[a, b])
