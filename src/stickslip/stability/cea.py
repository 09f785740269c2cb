"""Complex eigenvalue analysis (CEA) of steady sliding on sparse models: every eigenvalue of a band.

The linearisation M ẍ + C_t ẋ + K_t x = 0 about steady sliding (:mod:`.sparse_sliding`) has the
eigenvalues λ of the quadratic pencil P(λ) = λ² M + λ C_t + K_t, those of the first-order pencil

    A z = λ B z,   A = [[0, I], [−K_t, −C_t]],   B = [[I, 0], [0, M]],   z = [x, λ x].

**Direct CEA** (:func:`band_eigen`): shift-invert Arnoldi (ARPACK through scipy's ``eigs``) with
the shift at 0 works on T = A⁻¹ B, whose eigenvalues θ = 1/λ are largest for the λ of smallest
modulus. Applying T takes one solve with K_t (x₁ = −K_t⁻¹(M y₂ + C_t y₁), x₂ = y₁): real
arithmetic, and the LU factors of the steady-state solve are reused, so the whole band costs one
real sparse factorization. (A complex shift iω in the band would need a complex factorization of
P(iω), which SuperLU makes 25–40 times slower than the real one of the same matrix.)

**Nothing in the band is missed**: Arnoldi on T returns the k eigenvalues of largest |θ|, so
every eigenvalue of modulus below the largest modulus returned is among them. The band
{|Im λ| ≤ ω_max} up to the damping ratios a structure has lies inside the disc |λ| ≤ R,
R = ω_max √(1 + ρ²) (ρ = :data:`REAL_MARGIN`: at the band's top every eigenvalue with
|Re λ| ≤ ρ ω_max, lower down more); k grows (the factors reused) until the largest modulus
returned exceeds R, and each run must return the previous run's eigenvalues again (a check of
ARPACK's convergence). The frictionless count (the modes of (K_t − K_f, M) below R by Sylvester's
inertia of K_s − R² M) is reported beside the count found, a consistency check for small friction
and damping. Models of up to :data:`DENSE_STATES` states take every eigenvalue densely instead.

Every eigenpair is reported with its backward error ‖P(λ) x‖ / ((|λ|²‖M‖ + |λ|‖C_t‖ + ‖K_t‖)‖x‖)
on the full pencil (1-norms). Arnoldi's pairs are refined on the full pencil until it is below
:data:`REFINE_BELOW` (at most :data:`RITZ_STEPS` steps): Rayleigh–Ritz on the span of the
eigenvectors and their corrections K_t⁻¹ P(λ) x, with the same real LU factors — a projection
that also separates two nearly coalescing eigenvalues that Arnoldi left mixed.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import scipy.sparse as sp

from ..errors import EquilibriumError
from ..model.matrices import arpack_start
from .sparse_sliding import SlidingState, factorize

__all__ = ["BandEigen", "band_eigen", "dense_eigen", "backward_errors", "frictionless_count", "modes_below", "REAL_MARGIN",
           "DENSE_STATES", "REFINE_BELOW", "sorted_eigen"]

#: Half-width of the band's strip at its top, as a fraction of ω_max: every eigenvalue of
#: frequency ≤ ω_max with |Re λ| ≤ ρ ω_max there (damping ratio up to 0.24; more at lower
#: frequencies) lies in the disc that is searched.
REAL_MARGIN = 0.25

#: State counts (2n) up to which every eigenvalue is taken densely (LAPACK on B⁻¹A).
DENSE_STATES = 400

#: Backward error above which the band's eigenpairs are refined on the full pencil (Rayleigh–Ritz
#: steps, :func:`_ritz_step`). Arnoldi's pairs come out with backward errors up to ~1e-8; an
#: eigenvalue near a coalescence (two eigenvalues 1e-2 apart) then carried 3e-8 relative error,
#: which one step took to 1.5e-10 and a second to 1.5e-11 (docs/fe.md).
REFINE_BELOW = 1e-12

#: Rayleigh–Ritz steps at most.
RITZ_STEPS = 3

#: Relative distance within which a larger Arnoldi run must find each eigenvalue of the smaller
#: one again. Arnoldi's eigenvalues carry errors up to a few 1e-8 (above; on the test strip of
#: tests/fe/test_cea.py up to 3e-8 against the dense ones, which of its pairs depends on the
#: LAPACK build), so two correct runs differ by up to about twice that; a run that missed an
#: eigenvalue has only other eigenvalues near it, which lie orders of magnitude further apart
#: (the strip's closest pair: 1.4e-2 relative).
RUNS_AGREE = 1e-6

#: Largest number of eigenvalues one band may need before the search gives up (memory: 2k
#: Arnoldi vectors of 2n numbers).
MAX_EIGENVALUES = 2000


@dataclasses.dataclass(frozen=True, eq=False)
class BandEigen:
    """Eigenvalues of the linearisation inside a disc |λ| ≤ ``radius`` and their mode shapes.

    Attributes
    ----------
    eigenvalues : ndarray (m,) complex
        Every eigenvalue with |λ| ≤ radius, sorted by real part descending, then Im descending [1/s].
    vectors : ndarray (k, m) complex
        Displacement parts x on the free DOFs (unit 2-norm).
    radius : float
        The disc searched [rad/s].
    backward_error : ndarray (m,)
        Relative backward error of each pair on the full pencil.
    method : str
        ``dense`` or ``arnoldi``.
    arnoldi_runs : list of int
        The k of each Arnoldi run (the factors reused).
    frictionless_count : int or None
        Real modes of the frictionless structure below ``radius`` (:func:`frictionless_count`).
    """

    eigenvalues: np.ndarray
    vectors: np.ndarray
    radius: float
    backward_error: np.ndarray
    method: str
    arnoldi_runs: tuple = ()
    frictionless_count: int | None = None


def sorted_eigen(lam: np.ndarray, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues sorted by real part descending, then Im descending (the dense path's order)."""
    order = np.lexsort((-lam.imag, -lam.real))
    return lam[order], X[:, order]


def dense_eigen(state: SlidingState) -> tuple[np.ndarray, np.ndarray]:
    """Every eigenvalue of the linearisation (LAPACK on B⁻¹A, M by Cholesky) and its displacement part."""
    from scipy.linalg import cho_factor, cho_solve

    n = state.n
    M = state.mass.toarray()
    factor = cho_factor(M)
    J = np.zeros((2 * n, 2 * n))
    J[:n, n:] = np.eye(n)
    J[n:, :n] = -cho_solve(factor, state.stiffness.toarray())
    J[n:, n:] = -cho_solve(factor, state.damping.toarray())
    lam, Z = np.linalg.eig(J)
    X = Z[:n]
    return lam, X / np.linalg.norm(X, axis=0)


def _operator(state: SlidingState):
    """T = A⁻¹ B (2n × 2n) through the LU factors of K_t."""
    from scipy.sparse.linalg import LinearOperator

    n, lu, M, C = state.n, state.stiffness_lu, state.mass, state.damping

    def apply(y):
        y = np.asarray(y).reshape(-1)
        y1, y2 = y[:n], y[n:]
        out = np.empty(2 * n, dtype=np.result_type(y.dtype, float))
        out[:n] = -lu.solve(np.asarray(M @ y2 + C @ y1))
        out[n:] = y1
        return out

    return LinearOperator((2 * n, 2 * n), matvec=apply, dtype=float)


def _arnoldi(state: SlidingState, radius: float, k: int, v0) -> tuple[np.ndarray, np.ndarray, tuple]:
    """Shift-invert Arnoldi at 0 with k grown until the largest modulus returned exceeds ``radius``."""
    from scipy.sparse.linalg import ArpackNoConvergence, eigs

    T = _operator(state)
    n2 = 2 * state.n
    if v0 is None:  # a fixed start: the same run every time (ARPACK's own start is random)
        v0 = arpack_start(n2)
    runs, previous = [], None
    while True:
        k = int(min(k, n2 - 2))
        try:
            theta, Z = eigs(T, k=k, which="LM", ncv=min(n2, max(2 * k + 1, k + 20)), v0=v0, maxiter=max(1000, n2))
        except ArpackNoConvergence:
            raise EquilibriumError(f"the Arnoldi iteration did not converge for {k} eigenvalues; give a lower "
                                   "--max-frequency or use --method modal") from None
        runs.append(k)
        lam = 1.0 / theta
        found = float(np.max(np.abs(lam)))
        if previous is not None:
            _check_again(previous, lam)
        if found > radius or k >= n2 - 2:
            inside = np.abs(lam) <= radius
            return lam[inside], Z[:state.n, inside], tuple(runs)
        if k >= MAX_EIGENVALUES:
            raise EquilibriumError(f"the band needs more than {MAX_EIGENVALUES} eigenvalues (|λ| up to {found:.6g} "
                                   f"after {k}); give a lower --max-frequency")
        previous = lam
        k = int(math.ceil(k * max(1.5, 1.2 * (radius / found) ** 2)))


def _check_again(previous: np.ndarray, lam: np.ndarray) -> None:
    """A larger run must find every eigenvalue of the smaller one again (to :data:`RUNS_AGREE` relative)."""
    inner = previous[np.abs(previous) < 0.999 * np.max(np.abs(previous))]
    for value in inner:
        if np.min(np.abs(lam - value)) > RUNS_AGREE * max(abs(value), 1e-300):
            raise EquilibriumError(f"the Arnoldi runs disagree on the eigenvalue {value:.6g} (ARPACK missed or did "
                                   "not converge); give a lower --max-frequency")


def band_eigen(state: SlidingState, max_frequency: float, *, margin: float = REAL_MARGIN, k: int | None = None,
               v0=None) -> BandEigen:
    """Every eigenvalue with |λ| ≤ ω_max √(1 + margin²) and its mode shape (module docstring).

    Parameters
    ----------
    state : SlidingState
    max_frequency : float
        ω_max, the band's top [rad/s, the model's angular-frequency unit].
    k : int, optional
        Eigenvalues asked of the first Arnoldi run (default from the frictionless count).
    v0 : ndarray (2n,), optional
        Start vector of Arnoldi (the modal CEA gives its approximations).

    Raises
    ------
    EquilibriumError
        When Arnoldi does not converge or its runs disagree.
    """
    radius = max_frequency * math.sqrt(1.0 + margin**2)
    count = frictionless_count(state, radius)
    if 2 * state.n <= DENSE_STATES:
        lam, X = dense_eigen(state)
        inside = np.abs(lam) <= radius
        lam, X, method, runs = lam[inside], X[:, inside], "dense", ()
    else:
        if k is None:
            k = 2 * count + 6 if count is not None else 40
        lam, X, runs = _arnoldi(state, radius, max(k, 6), v0)
        X = X / np.linalg.norm(X, axis=0)
        method = "arnoldi"
    lam, X = sorted_eigen(lam, X)
    eta = backward_errors(state, lam, X)
    for _ in range(RITZ_STEPS):
        if method == "dense" or not eta.size or np.max(eta) <= REFINE_BELOW:
            break
        lam, X = sorted_eigen(*_ritz_step(state, lam, X))
        eta = backward_errors(state, lam, X)
    return BandEigen(eigenvalues=lam, vectors=X, radius=radius, backward_error=eta, method=method,
                     arnoldi_runs=runs, frictionless_count=count)


def _norms(state: SlidingState) -> tuple[float, float, float]:
    from scipy.sparse.linalg import norm

    return norm(state.mass, 1), norm(state.damping, 1), norm(state.stiffness, 1)


def backward_errors(state: SlidingState, lam: np.ndarray, X: np.ndarray) -> np.ndarray:
    """‖P(λ) x‖₂ / ((|λ|²‖M‖₁ + |λ|‖C_t‖₁ + ‖K_t‖₁)‖x‖₂) of each pair (columns of X)."""
    if lam.size == 0:
        return np.zeros(0)
    m, c, k = _norms(state)
    R = (state.mass @ X) * lam**2 + (state.damping @ X) * lam + state.stiffness @ X
    a = np.abs(lam)
    return np.linalg.norm(R, axis=0) / ((a * a * m + a * c + k) * np.linalg.norm(X, axis=0))


def _ritz_step(state: SlidingState, lam: np.ndarray, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One Rayleigh–Ritz step on the full pencil: the quadratic problem projected on the real span
    of the eigenvectors X and their residual corrections K_t⁻¹ P(λ) x (the LU factors of K_t; two
    real solves per pair), each eigenvalue replaced by the Ritz value assigned to it (least total
    distance). Only the members with Im λ ≥ 0 are refined; their conjugates follow."""
    from scipy.optimize import linear_sum_assignment

    up = lam.imag >= 0.0
    L, Y = lam[up], X[:, up]
    R = (state.mass @ Y) * L**2 + (state.damping @ Y) * L + state.stiffness @ Y
    D = np.column_stack([state.stiffness_lu.solve(np.ascontiguousarray(r.real))
                         + 1j * state.stiffness_lu.solve(np.ascontiguousarray(r.imag)) for r in R.T])
    V, _ = np.linalg.qr(np.hstack([Y.real, Y.imag, D.real, D.imag]))
    k = V.shape[1]
    Mr, Cr, Kr = (V.T @ (A @ V) for A in (state.mass, state.damping, state.stiffness))
    J = np.zeros((2 * k, 2 * k))
    J[:k, k:] = np.eye(k)
    J[k:, :k] = -np.linalg.solve(Mr, Kr)
    J[k:, k:] = -np.linalg.solve(Mr, Cr)
    mu, Z = np.linalg.eig(J)
    rows, cols = linear_sum_assignment(np.abs(L[:, None] - mu[None, :]))
    L, Y = mu[cols[np.argsort(rows)]], V @ Z[:k, cols[np.argsort(rows)]]
    L = np.where(np.abs(L.imag) < 1e-14 * np.abs(L), L.real + 0j, L)
    Y = Y / np.linalg.norm(Y, axis=0)
    pair = L.imag > 0.0
    return np.concatenate([L, L[pair].conj()]), np.hstack([Y, Y[:, pair].conj()])


def frictionless_count(state: SlidingState, omega: float) -> int | None:
    """Number of modes of (K_s, M) below ``omega`` [rad/s], K_s the symmetric part of K_t − K_f
    (:func:`modes_below`)."""
    return modes_below(_frictionless_stiffness(state), state.mass, omega)


def modes_below(K, M, omega: float) -> int | None:
    """Number of eigenvalues of the symmetric pencil (K, M) below ω² (M positive definite), by
    Sylvester's law of inertia: the negative pivots of an LU of K − ω² M with diagonal pivots
    (None where SuperLU had to pivot off the diagonal)."""
    try:
        lu = factorize(K - omega**2 * M, pivot=0.0)
    except RuntimeError:  # ω² is an eigenvalue: count it with those below
        lu = factorize(K - (omega * (1 + 1e-12)) ** 2 * M, pivot=0.0)
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return None
    return int(np.count_nonzero(lu.U.diagonal() < 0.0))


def _frictionless_stiffness(state: SlidingState) -> sp.csr_matrix:
    """K_s = sym(K_t − K_f): the stiffness without friction, symmetrised (the real modes' stiffness)."""
    K0 = state.stiffness if state.friction_stiffness is None else state.stiffness - state.friction_stiffness
    return sp.csr_matrix(0.5 * (K0 + K0.T))
