"""Steady sliding and its linearisation for sparse models with constant contact kinematics.

With constant tangent rows G and drives w, every contact slides at rest with v = −w, so its speed
|v| = |w| and its direction e = −w/|w| do not depend on q. The friction force F_c = −μ(|w|) N_c e_c
is then affine in q (N_c is), and steady sliding

    f0 − K q + Σ_c G_cᵀ F_c(q) + Σ_u W_uᵀ λ_u(q) = 0

is one sparse linear solve, K_t q = b on the free DOFs, with the stiffness of the linearisation

    K_t = K + Σ_u k_u W_uᵀ W_u + Σ_c μ_c G_cᵀ e_c n_cᵀ                  (K_f, not symmetric)

(n_c = ∂N_c/∂q; a compliant contact has n = −k W) and its damping

    C_t = C + Σ_u c_u W_uᵀ W_u + Σ_c G_cᵀ [μ_c e_c n_v,cᵀ + N_c (μ'_c e_c e_cᵀ + μ_c/|w_c| (I − e_c e_cᵀ)) G_c]

(μ' = dμ/d|v| along the slip direction; the 2-D direction's turn (I − e eᵀ) μ N/|v|, zero for a
1-D contact). Every matrix is assembled from the stacked contact tables as sparse products; nothing
is dense. The linearisation is checked against the complex-step Jacobian of the simulator's own
right-hand side on the library's models and on small finite-element models (tests/stability).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import scipy.sparse as sp

from ..errors import EquilibriumError
from .sparse_input import normal_rows, sparse_form

__all__ = ["SlidingState", "sparse_steady_sliding", "factorize"]

@dataclasses.dataclass(frozen=True, eq=False)
class SlidingState:
    """Steady sliding of a sparse model and the matrices of its linearisation.

    Attributes
    ----------
    form : object
        The model's sparse form (:func:`~stickslip.stability.sparse_input.sparse_form`).
    q : ndarray (n,)
        Steady-sliding coordinates, locked DOFs 0 [units of the dofs].
    free : ndarray (k,) of int
        Indices of the free DOFs.
    mass, damping, stiffness : csr_matrix (k, k)
        M, C_t, K_t of the linearisation on the free DOFs (module docstring).
    normal_force : ndarray (nc,)
        Each contact's normal force at steady sliding [N].
    speed : ndarray (nc,)
        Each contact's sliding speed |w| [m/s].
    residual : float
        Relative force residual of the steady state, by the friction forces themselves (not K_t).
    stiffness_lu : SuperLU
        The LU factors of ``stiffness`` (the solve of the steady state; the shift-invert at 0 reuses them).
    friction_stiffness : csr_matrix (k, k)
        K_f, the friction's unsymmetric part of K_t (K_t − K_f is the frictionless stiffness).
    """

    form: object
    q: np.ndarray
    free: np.ndarray
    mass: sp.csr_matrix
    damping: sp.csr_matrix
    stiffness: sp.csr_matrix
    normal_force: np.ndarray
    speed: np.ndarray
    residual: float
    stiffness_lu: object = None
    friction_stiffness: sp.csr_matrix = None

    @property
    def n(self) -> int:
        """Number of free DOFs."""
        return int(self.free.size)


def factorize(A, *, pivot: float = 0.1):
    """Sparse LU of a square matrix with the structure of a finite-element matrix (SuperLU).

    The minimum-degree ordering of Aᵀ + A with pivots preferred on the diagonal keeps the fill of
    a structurally symmetric matrix low: 51 M entries for K_t of a 99,260-DOF pad on a disc, 8 s,
    against 2.5 times the fill and the time with scipy's default column ordering.
    ``pivot`` = 0 takes every pivot on the diagonal (the inertia count of a symmetric matrix).

    Raises
    ------
    RuntimeError
        SuperLU's "Factor is exactly singular".
    """
    from scipy.sparse.linalg import splu  # imported on use: scipy's sparse solvers cost start-up time

    return splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=pivot,
                options={"SymmetricMode": True})


def _directions(form):
    """(μ, μ', |w|, E): per contact the coefficient and its slope at |w|, the speed, and E (R, nc)
    with E[r, c] the component of the slip direction e_c = −w_c/|w_c| on tangent row r."""
    start = np.asarray(form.row_start)
    w = np.asarray(form.drive, float)
    nc = start.size - 1
    speed = np.sqrt(np.add.reduceat(w * w, start[:-1])) if w.size else np.zeros(0)
    band = form.slip_band
    dims = np.diff(start)
    names = form.contact_names
    for c in range(nc):
        if speed[c] == 0.0:
            raise EquilibriumError(f"no steady sliding: contact {c} ({names[c]}) would stick (its drive w is 0, so it "
                                   "does not slide at rest); give it a non-zero drive")
        if dims[c] == 2 and speed[c] <= band:
            raise EquilibriumError(f"the sliding speed of contact {c} ({names[c]}), {speed[c]:.3g} m/s, is inside the "
                                   f"low-speed band ({band:g} m/s), where its slip direction is not v/|v|; increase "
                                   "the drive")
    rows = np.repeat(np.arange(nc), dims)
    E = sp.csr_matrix((-w / speed[rows], (np.arange(w.size), rows)), shape=(w.size, nc))
    mu = np.array([float(form.mu(c, speed[c])) for c in range(nc)])
    slope = np.array([float(form.dmu(c, speed[c])) for c in range(nc)])
    return mu, slope, speed, E, rows


def _stiffness(form, normal, mu, E) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """K_t = K + Wᵀ diag(k) W + K_f and the friction's part K_f = Gᵀ E diag(μ) n_q (n, n)."""
    G = sp.csr_matrix(form.tangent)
    K = sp.csr_matrix(form.stiffness) + normal.W.T @ sp.diags(normal.k) @ normal.W
    K_f = sp.csr_matrix(G.T @ (E @ sp.diags(mu) @ normal.n_q))
    return sp.csr_matrix(K + K_f), K_f


def _damping(form, normal, mu, slope, speed, E, rows, N) -> sp.csr_matrix:
    """C_t (module docstring) at the normal forces N (nc,)."""
    G = sp.csr_matrix(form.tangent)
    # per contact D_c = N (μ' e eᵀ + μ/|w| (I − e eᵀ)): a block diagonal of 1×1 and 2×2 blocks
    a = N * slope
    b = N * mu / speed
    outer = sp.csr_matrix(E @ sp.diags(a - b) @ E.T)
    D = outer + sp.diags(b[rows])
    C = sp.csr_matrix(form.damping) + normal.W.T @ sp.diags(normal.c) @ normal.W
    return sp.csr_matrix(C + G.T @ (E @ sp.diags(mu) @ normal.n_v) + G.T @ D @ G)


def _closed_check(form, normal, N, gap_values) -> None:
    """Steady sliding needs every contact pressed: N > 0 (a compliant one: λ > 0, g < 0)."""
    bad = np.flatnonzero(~(N > 0.0))
    if bad.size:
        c = int(bad[0])
        what = (f"gap {gap_values[c]:.6g}, normal force {N[c]:.6g} with it closed" if form.unilateral[c]
                else f"normal force {N[c]:.6g}")
        raise EquilibriumError(f"no steady sliding: contact {c} ({form.contact_names[c]}) would be open ({what}); "
                               "press it (a force towards the contact, a negative gap)")


def sparse_steady_sliding(model) -> SlidingState:
    """Steady sliding of a model with constant contact kinematics, by one sparse solve, and its
    linearisation (module docstring).

    Parameters
    ----------
    model : FrictionModel or sparse form
        Any model with constant tangent rows and drives, pressed or compliant contacts.

    Returns
    -------
    SlidingState

    Raises
    ------
    EquilibriumError
        A contact that would stick (drive 0), slide inside the low-speed band (2-D), or be open
        (normal force ≤ 0) at the steady state; a singular K_t.
    ModelError
        For a rigid contact or kinematics that are not constant.
    """
    form = sparse_form(model)
    normal = normal_rows(form)
    mu, slope, speed, E, rows = _directions(form)
    free = np.flatnonzero(np.asarray(form.free, bool))
    n = int(form.stiffness.shape[0])
    G = sp.csr_matrix(form.tangent)
    K_t, K_f = _stiffness(form, normal, mu, E)
    # f0 − Σ μ N0 Gᵀ e (+ the compliant contacts' −k g0 Wᵀ, inside N0 through λ = N0 + n·q)
    b = np.asarray(form.force, float) + G.T @ (E @ (-mu * normal.N0)) + normal.W.T @ normal.N0
    K_free = sp.csc_matrix(K_t[free][:, free])
    q = np.zeros(n)
    try:
        lu = factorize(K_free)
        q[free] = lu.solve(b[free])
    except RuntimeError:  # SuperLU: "Factor is exactly singular"
        raise EquilibriumError("no steady sliding: the stiffness of steady sliding K_t is singular on the free DOFs "
                               "(a free part held by nothing: fix it, or add contact stiffness)") from None
    if not np.all(np.isfinite(q)):
        raise EquilibriumError("no steady sliding: the solve of K_t q = b gave non-finite values (K_t singular to "
                               "working precision)")
    N = normal.N0 + normal.n_q @ q
    gaps = np.asarray(form.gap, float) + sp.csr_matrix(form.gap_gradient) @ q
    _closed_check(form, normal, N, gaps)
    residual = _force_residual(form, normal, q, N, mu, E, free)
    C_t = _damping(form, normal, mu, slope, speed, E, rows, N)
    return SlidingState(form=form, q=q, free=free, mass=sp.csr_matrix(form.mass[free][:, free]),
                        damping=sp.csr_matrix(C_t[free][:, free]), stiffness=sp.csr_matrix(K_free),
                        normal_force=N, speed=speed, residual=residual, stiffness_lu=lu,
                        friction_stiffness=sp.csr_matrix(K_f[free][:, free]))


def _force_residual(form, normal, q, N, mu, E, free) -> float:
    """max |f0 − K q + Gᵀ F + Wᵀ λ| / max(|K q|, |f0|, |Gᵀ F + Wᵀ λ|) on the free DOFs, with the
    friction forces F = −μ N e evaluated as forces (an independent check of the solve)."""
    Kq = (sp.csr_matrix(form.stiffness) @ q)[free]
    contact = (sp.csr_matrix(form.tangent).T @ (E @ (-mu * N)) + normal.W.T @ N)[free]
    f0 = np.asarray(form.force, float)[free]
    num = float(np.max(np.abs(f0 - Kq + contact), initial=0.0))
    scale = max(float(np.max(np.abs(Kq), initial=0.0)), float(np.max(np.abs(f0), initial=0.0)),
                float(np.max(np.abs(contact), initial=0.0)))
    return 0.0 if num == 0.0 else (num / scale if scale > 0.0 else math.inf)

