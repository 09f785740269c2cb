"""Modal CEA: the linearisation projected on the real modes of the frictionless structure.

The field's everyday analysis of brake squeal (Nastran SOL 107, Abaqus *COMPLEX FREQUENCY,
ANSYS QRDAMP): the real modes Φ of (K_s, M) below a cutoff ω_c, with K_s the stiffness without
friction (symmetrised), by shift-invert Lanczos (ARPACK's ``eigsh`` at 0), then the small complex
problem of the projected system Φᵀ M Φ = I, Φᵀ C_t Φ, Φᵀ K_t Φ. The number of modes below ω_c
is known beforehand by Sylvester's law of inertia (:func:`~.cea.frictionless_count`), so the
basis holds every mode below the cutoff, checked.

A projection is an approximation; its eigenvalues are never reported as the model's:
:func:`modal_cea` refines them on the full pencil (:func:`~.cea.band_eigen`, started from the
modal approximations) and reports the full eigenvalues with each approximation's distance from
them, and the convergence as modes are added (the eigenvalues of the projection on the first m
modes for growing m).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import EquilibriumError
from .cea import BandEigen, _frictionless_stiffness, band_eigen, modes_below
from .sparse_sliding import SlidingState, factorize

__all__ = ["ModalBasis", "ModalReport", "real_modes", "lowest_modes", "projected_eigen", "modal_cea", "CUTOFF_FACTOR"]

#: Default cutoff of the real modes as a multiple of the band's top (the rule of thumb of modal
#: CEA: modes up to 1.5–2 times the highest frequency of interest).
CUTOFF_FACTOR = 2.0


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
    cutoff : float
        ω_c [rad/s].
    approximations : ndarray (p,) complex
        The projection's eigenvalues in the band, with all modes.
    errors : ndarray (p,)
        |λ̃ − λ| / |λ| of each approximation from the nearest full eigenvalue.
    convergence : list of dict
        One row per basis size: ``modes``, ``highest_mode`` [rad/s], ``max_relative_error`` over the
        band's full eigenvalues (each from its nearest approximation), ``found`` (eigenvalues of
        the band within 1e-2 relative).
    """

    modes: int
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
            w2, V = eigsh(K, k=k, M=M, sigma=0.0, OPinv=op, which="LM")
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


def projected_eigen(state: SlidingState, basis: ModalBasis, modes: int | None = None):
    """Eigenvalues (2m,) and physical displacement vectors (k, 2m) of the projection on the first
    ``modes`` real modes."""
    Phi = basis.vectors[:, :modes]
    m = Phi.shape[1]
    K = Phi.T @ (state.stiffness @ Phi)
    C = Phi.T @ (state.damping @ Phi)
    J = np.zeros((2 * m, 2 * m))
    J[:m, m:] = np.eye(m)
    J[m:, :m] = -K
    J[m:, m:] = -C
    lam, Z = np.linalg.eig(J)
    return lam, Phi @ Z[:m]


def _errors(full: np.ndarray, approx: np.ndarray) -> np.ndarray:
    """|λ − nearest of ``approx``| / |λ| for each λ of ``full``."""
    if approx.size == 0:
        return np.full(full.shape, np.inf)
    return np.min(np.abs(full[:, None] - approx[None, :]), axis=1) / np.abs(full)


def modal_cea(state: SlidingState, max_frequency: float, *, cutoff: float | None = None,
              steps: int = 6) -> tuple[BandEigen, ModalReport]:
    """Modal CEA of the band |Im λ| ≤ ``max_frequency`` [rad/s], refined on the full pencil.

    Parameters
    ----------
    cutoff : float, optional
        ω_c of the real modes [rad/s] (default :data:`CUTOFF_FACTOR` × ``max_frequency``).
    steps : int
        Basis sizes of the convergence table (evenly spaced up to all modes).

    Returns
    -------
    band : BandEigen
        The full model's eigenvalues (as :func:`~.cea.band_eigen`).
    report : ModalReport
    """
    cutoff = CUTOFF_FACTOR * max_frequency if cutoff is None else cutoff
    if cutoff < max_frequency:
        raise EquilibriumError(f"the cutoff {cutoff:.6g} rad/s is below the band's top {max_frequency:.6g} rad/s; "
                               "give a cutoff above it (1.5 to 2 times)")
    basis = real_modes(state, cutoff)
    lam, Y = projected_eigen(state, basis)
    in_band = np.abs(lam.imag) <= max_frequency
    v0 = np.concatenate([Y[:, in_band].sum(axis=1), (Y[:, in_band] * lam[in_band]).sum(axis=1)]).real
    band = band_eigen(state, max_frequency, k=int(in_band.sum()) + 6, v0=v0 if np.any(v0) else None)
    full = band.eigenvalues[np.abs(band.eigenvalues.imag) <= max_frequency]
    m = basis.vectors.shape[1]
    sizes = sorted({max(1, int(round(m * (j + 1) / steps))) for j in range(steps)})
    rows = []
    for size in sizes:
        approx, _ = projected_eigen(state, basis, size)
        err = _errors(full, approx)
        rows.append({"modes": size, "highest_mode": float(basis.frequencies[size - 1]),
                     "max_relative_error": float(np.max(err, initial=0.0)), "found": int(np.sum(err < 1e-2))})
    report = ModalReport(modes=m, cutoff=cutoff, approximations=lam[in_band],
                         errors=_errors(lam[in_band], band.eigenvalues), convergence=rows)
    return band, report
