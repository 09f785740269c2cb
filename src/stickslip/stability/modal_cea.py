"""Modal CEA: the linearisation projected on the real modes of the frictionless structure, enriched
with the static response to the contact forces (residual vectors).

The field's everyday analysis of brake squeal (Nastran SOL 107, Abaqus *COMPLEX FREQUENCY,
ANSYS QRDAMP): the real modes Φ of (K_s, M) below a cutoff ω_c, with K_s the stiffness without
friction (symmetrised), by shift-invert Lanczos (ARPACK's ``eigsh`` at 0), then the small complex
problem of the projected system. The number of modes below ω_c is known beforehand by
Sylvester's law of inertia (:func:`~.cea.frictionless_count`), so the basis holds every mode
below the cutoff, checked.

Stiff contact springs put part of the motion of the coupled modes into modes far above any
practical cutoff, and a projection on modes alone stalls (1e-2 relative on the pad on a strip of
docs/fe.md, up to 4 ω_max). The friction forces and the contact springs act through the contact
rows only: K_t − K_s = Gᵀ(…) and C_t − C = Gᵀ(…) + Wᵀ(…), so (K symmetric) every eigenvector x satisfies

    (λ² M + λ C + K_s) x ∈ span(P),   P = [Gᵀ, Wᵀ, nᵀ, n_vᵀ]   (the contact rows' patterns)

and its part in the truncated modes is, to O(|λ|²/ω_c²), the static response K_s⁻¹ P y. The
*residual vectors* (Nastran's RESVEC, Abaqus' residual modes) are these static responses, M-
orthogonalised against the kept modes; with them the projection converges to the full model's
eigenvalues as modes are added (:func:`residual_vectors`). They are computed with the LU factors
of K_t that steady sliding made: span(K_t⁻¹ P) = span(K_s⁻¹ P), because K_t − K_s = K_f maps into
span(P) (one pair of triangular solves per contact row).

A projection is an approximation; its eigenvalues are never reported as the model's:
:func:`modal_cea` refines them on the full pencil (:func:`~.cea.band_eigen`, started from the
modal approximations) and reports the full eigenvalues with each approximation's distance from
them, and the convergence as modes are added (the eigenvalues of the projection on the first m
modes, with and without the residual vectors, for growing m).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import scipy.sparse as sp

from ..errors import EquilibriumError
from ..memory import check_memory, format_bytes
from ..model.matrices import arpack_start
from .cea import BandEigen, _frictionless_stiffness, band_eigen, modes_below
from .sparse_sliding import SlidingState, factorize

__all__ = ["ModalBasis", "ModalReport", "real_modes", "lowest_modes", "contact_patterns", "static_responses",
           "residual_vectors", "modal_cea", "CUTOFF_FACTOR"]

#: Default cutoff of the real modes as a multiple of the band's top (the rule of thumb of modal
#: CEA: modes up to 1.5–2 times the highest frequency of interest).
CUTOFF_FACTOR = 2.0

#: A residual vector is dropped when its M-norm after the orthogonalisation against the modes and
#: the other residual vectors is below this fraction of the largest (it adds nothing to the span).
RANK_TOLERANCE = 1e-10


@dataclasses.dataclass(frozen=True, eq=False)
class ModalBasis:
    """Real modes of (K_s, M) below a cutoff.

    Attributes
    ----------
    frequencies : ndarray (m,)
        Natural angular frequencies ascending [rad/s].
    vectors : ndarray (k, m)
        Mass-normalised modes (Φᵀ M Φ = I) on the free DOFs.
    cutoff : float
        ω_c [rad/s].
    count : int or None
        Modes below ω_c by Sylvester's inertia (None where it could not be taken).
    """

    frequencies: np.ndarray
    vectors: np.ndarray
    cutoff: float
    count: int | None


@dataclasses.dataclass(frozen=True, eq=False)
class ModalReport:
    """What the modal CEA did and how far its approximations were from the full eigenvalues.

    Attributes
    ----------
    modes : int
        Real modes in the basis.
    residual_vectors : int
        Residual vectors beside the modes (0 without them).
    cutoff : float
        ω_c [rad/s].
    approximations : ndarray (p,) complex
        The projection's eigenvalues in the band, with all modes (and the residual vectors).
    errors : ndarray (p,)
        |λ̃ − λ| / |λ| of each approximation from the nearest full eigenvalue.
    convergence : list of dict
        One row per number of modes: ``modes``, ``highest_mode`` [rad/s], ``residual_vectors``,
        ``max_relative_error`` over the band's full eigenvalues (each from its nearest
        approximation) of the basis (modes and residual vectors), ``found`` (eigenvalues of the
        band within 1e-2 relative), and ``modes_only_error``, ``modes_only_found``: the same of
        the modes alone.
    """

    modes: int
    residual_vectors: int
    cutoff: float
    approximations: np.ndarray
    errors: np.ndarray
    convergence: list


def real_modes(state: SlidingState, cutoff: float) -> ModalBasis:
    """Every real mode of (K_s, M) below ``cutoff`` [rad/s] (:func:`lowest_modes`).

    Raises
    ------
    EquilibriumError
        When there is no mode below the cutoff or Lanczos does not return the counted modes.
    """
    omega, V, count = lowest_modes(_frictionless_stiffness(state), state.mass, cutoff)
    return ModalBasis(frequencies=omega, vectors=V, cutoff=cutoff, count=count)


def lowest_modes(K, M, cutoff: float) -> tuple[np.ndarray, np.ndarray, int | None]:
    """Every mode of the symmetric pencil (K, M) below ``cutoff`` [rad/s]: angular frequencies (m,)
    ascending, M-orthonormal vectors (k, m) and Sylvester's count (checked against what Lanczos
    returns; shift-invert at 0, the LU of K with diagonal pivots).

    Raises
    ------
    EquilibriumError
        When there is no mode below the cutoff or Lanczos does not return the counted modes.
    """
    from scipy.sparse.linalg import LinearOperator, eigsh

    count = modes_below(K, M, cutoff)
    if count == 0:
        raise EquilibriumError(f"no real mode below the cutoff {cutoff:.6g} rad/s; give a larger cutoff")
    k = count if count is not None else 20
    n = K.shape[0]
    lu = factorize(K, pivot=0.0)
    op = LinearOperator((n, n), matvec=lambda x: lu.solve(np.asarray(x).reshape(-1)), dtype=float)
    while True:
        if k >= n - 1:  # a small model: every mode
            from scipy.linalg import eigh

            w2, V = eigh(K.toarray(), M.toarray())
        else:
            w2, V = eigsh(K, k=k, M=M, sigma=0.0, OPinv=op, which="LM", v0=arpack_start(n))
        order = np.argsort(w2)
        w2, V = w2[order], V[:, order]
        below = w2 < cutoff**2
        if count is not None or not below.all() or k >= n - 1:
            break
        k = int(math.ceil(k * 1.5))
    if count is not None and int(np.count_nonzero(below)) != count:
        raise EquilibriumError(f"Lanczos found {int(np.count_nonzero(below))} real modes below {cutoff:.6g} rad/s, "
                               f"Sylvester's inertia counts {count}; give another cutoff")
    return np.sqrt(np.maximum(w2[below], 0.0)), V[:, below], count


def contact_patterns(state: SlidingState) -> sp.csr_matrix:
    """P (p, k): the contact rows that carry the friction and contact forces on the free DOFs — the
    tangent rows G, the gap gradients W and the normal force's gradients n, n_v (module
    docstring) — each row that touches a free DOF once."""
    form = state.form
    rows = sp.vstack([sp.csr_matrix(A) for A in (form.tangent, form.gap_gradient, form.normal_gradient,
                                                   form.normal_rate_gradient)], format="csr")[:, state.free]
    rows = sp.csr_matrix(rows[np.flatnonzero(np.diff(rows.indptr) > 0)])
    rows.sum_duplicates()
    return rows


def residual_vectors(state: SlidingState, modes: np.ndarray, static: np.ndarray | None = None) -> np.ndarray:
    """The residual vectors of a modal basis (module docstring): the static responses K_t⁻¹ Pᵀ to
    the contact patterns (``static``, computed here when not given), M-orthogonalised against
    ``modes`` (k, m) and among themselves (M-orthonormal; directions already in the span dropped).

    Returns
    -------
    ndarray (k, r)
        r ≤ p vectors with Yᵀ M Y = I and Φᵀ M Y = 0.
    """
    M = state.mass
    Y = static_responses(state) if static is None else static.copy()
    for _ in range(2):  # twice is enough (Gram–Schmidt against the modes, Φᵀ M Φ = I)
        Y -= modes @ (modes.T @ (M @ Y))
    norm = np.sqrt(np.maximum(np.einsum("ij,ij->j", Y, M @ Y), 0.0))
    keep = norm > RANK_TOLERANCE * max(float(norm.max(initial=0.0)), 1e-300)
    Y = Y[:, keep] / norm[keep]
    if not Y.shape[1]:
        return Y
    w, U = np.linalg.eigh(Y.T @ (M @ Y))
    keep = w > RANK_TOLERANCE * w[-1]
    return Y @ (U[:, keep] / np.sqrt(w[keep]))


def static_responses(state: SlidingState) -> np.ndarray:
    """K_t⁻¹ Pᵀ (k, p): the static response to each contact pattern (:func:`contact_patterns`),
    with the LU factors of steady sliding.

    Raises
    ------
    MemoryLimitError
        When the p vectors of k numbers (and their orthogonalisation) do not fit in memory.
    """
    P = contact_patterns(state)
    check_memory(8.0 * 4 * state.n * P.shape[0], f"the {P.shape[0]} residual vectors of the contact rows "
                 f"({state.n} DOFs)",
                 lambda memory: f"use --method direct, or --no-residual-vectors (the vectors take 32 bytes per DOF "
                                f"and contact row; {format_bytes(memory)} available)")
    if not P.shape[0]:
        return np.zeros((state.n, 0))
    return state.stiffness_lu.solve(np.asfortranarray(P.T.toarray()))


def _companion_eigen(K: np.ndarray, C: np.ndarray, vectors: bool = True):
    """Eigenvalues (2r,) and displacement parts (r, 2r) of λ² I + λ C + K (r × r); the eigenvalues
    alone without ``vectors``."""
    r = K.shape[0]
    J = np.zeros((2 * r, 2 * r))
    J[:r, r:] = np.eye(r)
    J[r:, :r] = -K
    J[r:, r:] = -C
    if not vectors:
        return np.linalg.eigvals(J)
    lam, Z = np.linalg.eig(J)
    return lam, Z[:r]


class _Projection:
    """The linearisation projected once on B = [Φ, Q] (M-orthonormal: every mode, and the residual
    vectors against all of them) and the bases of the convergence table inside it.

    The first m modes and the residual vectors span [Φ_m, Y] with Y = K_t⁻¹ Pᵀ = Φ X + Q R: in
    B's coordinates, the unit columns of the m modes and an orthonormal basis of the columns of
    [X_{m+1…}; R] — exact coordinates, so nothing cancels however much of Y the modes hold.
    """

    def __init__(self, state: SlidingState, Phi: np.ndarray, static: np.ndarray | None) -> None:
        self.m = Phi.shape[1]
        if static is None:
            Q, self.X, self.R = np.zeros((Phi.shape[0], 0)), None, None
        else:
            Q = residual_vectors(state, Phi, static)
            MY = state.mass @ static
            self.X, self.R = Phi.T @ MY, Q.T @ MY
        self.B = np.hstack([Phi, Q])
        self.K = self.B.T @ (state.stiffness @ self.B)
        self.C = self.B.T @ (state.damping @ self.B)

    def coordinates(self, modes: int, residual: bool) -> np.ndarray:
        """T (dim B, r): the orthonormal coordinates of the first ``modes`` modes and, with
        ``residual``, of the residual vectors."""
        size = self.B.shape[1]
        T = np.eye(size)[:, :modes]
        if not residual or self.R is None or not self.R.size:
            return T
        W = np.vstack([self.X[modes:], self.R])
        W = W / np.maximum(np.linalg.norm(W, axis=0), 1e-300)
        U, sigma, _ = np.linalg.svd(W, full_matrices=False)
        U = U[:, sigma > RANK_TOLERANCE * max(float(sigma[0]), 1e-300)] if sigma.size else U[:, :0]
        extra = np.zeros((size, U.shape[1]))
        extra[modes:] = U
        return np.hstack([T, extra])

    def eigen(self, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The projection's eigenvalues (2r,) on the sub-basis T and their physical vectors (k, 2r)."""
        lam, Z = _companion_eigen(T.T @ self.K @ T, T.T @ self.C @ T)
        return lam, self.B @ (T @ Z)


def _errors(full: np.ndarray, approx: np.ndarray) -> np.ndarray:
    """|λ − nearest of ``approx``| / |λ| for each λ of ``full``."""
    if approx.size == 0:
        return np.full(full.shape, np.inf)
    return np.min(np.abs(full[:, None] - approx[None, :]), axis=1) / np.abs(full)


def _row(projection: _Projection, frequencies: np.ndarray, size: int, full: np.ndarray) -> dict:
    """One row of the convergence table: the first ``size`` modes, alone and with the residual vectors."""
    T = projection.coordinates(size, False)
    alone = _errors(full, _companion_eigen(T.T @ projection.K @ T, T.T @ projection.C @ T, vectors=False))
    row = {"modes": size, "highest_mode": float(frequencies[size - 1]), "residual_vectors": 0,
           "max_relative_error": float(np.max(alone, initial=0.0)), "found": int(np.sum(alone < 1e-2)),
           "modes_only_error": float(np.max(alone, initial=0.0)), "modes_only_found": int(np.sum(alone < 1e-2))}
    if projection.R is not None:
        T = projection.coordinates(size, True)
        err = _errors(full, _companion_eigen(T.T @ projection.K @ T, T.T @ projection.C @ T, vectors=False))
        row.update(residual_vectors=int(T.shape[1] - size), max_relative_error=float(np.max(err, initial=0.0)),
                   found=int(np.sum(err < 1e-2)))
    return row


def modal_cea(state: SlidingState, max_frequency: float, *, cutoff: float | None = None, residual: bool = True,
              steps: int = 6) -> tuple[BandEigen, ModalReport]:
    """Modal CEA of the band |Im λ| ≤ ``max_frequency`` [rad/s], refined on the full pencil.

    Parameters
    ----------
    cutoff : float, optional
        ω_c of the real modes [rad/s] (default :data:`CUTOFF_FACTOR` × ``max_frequency``).
    residual : bool
        Enrich the modes with the residual vectors of the contact rows (module docstring).
    steps : int
        Numbers of modes of the convergence table (evenly spaced up to all modes).

    Returns
    -------
    band : BandEigen
        The full model's eigenvalues (as :func:`~.cea.band_eigen`).
    report : ModalReport

    Raises
    ------
    EquilibriumError
        A cutoff below the band, or no real mode below it.
    MemoryLimitError
        When the residual vectors do not fit in memory.
    """
    cutoff = CUTOFF_FACTOR * max_frequency if cutoff is None else cutoff
    if cutoff < max_frequency:
        raise EquilibriumError(f"the cutoff {cutoff:.6g} rad/s is below the band's top {max_frequency:.6g} rad/s; "
                               "give a cutoff above it (1.5 to 2 times)")
    basis = real_modes(state, cutoff)
    projection = _Projection(state, basis.vectors, static_responses(state) if residual else None)
    m = basis.vectors.shape[1]
    T = projection.coordinates(m, residual)
    lam, Y = projection.eigen(T)
    in_band = np.abs(lam.imag) <= max_frequency
    v0 = np.concatenate([Y[:, in_band].sum(axis=1), (Y[:, in_band] * lam[in_band]).sum(axis=1)]).real
    band = band_eigen(state, max_frequency, k=int(in_band.sum()) + 6, v0=v0 if np.any(v0) else None)
    full = band.eigenvalues[np.abs(band.eigenvalues.imag) <= max_frequency]
    sizes = sorted({max(1, int(round(m * (j + 1) / steps))) for j in range(steps)})
    rows = [_row(projection, basis.frequencies, size, full) for size in sizes]
    report = ModalReport(modes=m, residual_vectors=T.shape[1] - m, cutoff=cutoff, approximations=lam[in_band],
                         errors=_errors(lam[in_band], band.eigenvalues), convergence=rows)
    return band, report
