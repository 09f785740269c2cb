"""The matrices of a model, dense or sparse: which form a model keeps, and the checks that scale.

A model the compiled kernels can take (at most :data:`DENSE_DOFS` coordinates, the kernels'
``MAX_DOFS``) keeps M, C, K as dense ``ndarray`` (n, n) and each contact's rows as dense arrays,
whatever form it was given in: every tool reads them as arrays, and the kernels' packed data is
built from them bit for bit as before. A larger model (a finite-element model, 10^3–10^6 dofs)
keeps them as ``scipy.sparse.csr_matrix`` — M, C, K (n, n), a contact's tangent rows (dim, n)
and its gradients n, n_v, W as one-row matrices (1, n) — and nothing here builds a dense n × n
array of it. The sparse numerics (steady sliding, complex eigenvalues, reduction) take such a
model through :meth:`~stickslip.model.system_model.FrictionModel.sparse_form`; the compiled tools
need it reduced first (``stickslip reduce``).

The checks of a sparse mass matrix (:func:`check_mass`), each one pass over its nonzeros
or one factorisation:

* symmetric: |M − Mᵀ| ≤ 1e-12 |Mᵀ| entry by entry, the dense check's rule, on the nonzeros;
* positive definite: a diagonal M by its diagonal; any other by an LDLᵀ factorisation without
  pivoting (SuperLU with a symmetric fill-reducing ordering and no off-diagonal pivots): by
  Sylvester's law of inertia M is positive definite exactly when every pivot is > 0;
* not singular to working precision: λmin by Lanczos in shift-invert mode through the same
  factorisation (``eigsh``, sigma 0), and λmax bounded by the largest absolute column sum
  (Gershgorin; within a few per cent of λmax for a consistent or lumped mass matrix, where
  Lanczos for λmax itself converges slowly on the clustered top of the spectrum), within
  :data:`MAX_MASS_CONDITION` of each other, as the dense check does with every eigenvalue.
  Should Lanczos not converge, the smallest pivot stands in for λmin (the pivots of an LDLᵀ
  factorisation lie between λmin and λmax).

A matrix that passed is remembered (by identity, while it lives), so that rebuilding a model with
other parameters (``replace``, ``--set``) does not factorise the same M again.
"""

from __future__ import annotations

import sys
import weakref

import numpy as np
# scipy.sparse is imported in the functions that use it: a dense model (the two plates, most model
# files) never needs it, and its import costs every command's start-up time.

from ..errors import ModelError
from .stack import MAX_DOFS

__all__ = ["DENSE_DOFS", "arpack_start", "is_sparse", "dense_array", "dense_spec", "square_matrix", "contact_rows",
           "has_nonzero", "mark_positive_definite", "check_mass", "MAX_MASS_CONDITION", "finite", "is_checked"]

#: Largest model kept dense: the compiled kernels' limit. Larger models keep their matrices sparse.
DENSE_DOFS = MAX_DOFS

#: Largest condition number λmax/λmin of the mass matrix (on the free dofs) accepted. eigvalsh
#: finds the eigenvalues of a dense M to an absolute error of about n·ε·λmax (ε = 2.2e-16), at
#: most 64·ε ≈ 1.4e-14·λmax for the kernels' MAX_DOFS = 64; an eigenvalue below 1e-13·λmax is
#: within ten times that of zero, so M is singular to working precision, and M⁻¹, formed once for
#: the kernels, would carry relative errors of cond(M)·ε ≈ 2e-3 or more. A sparse model's M is
#: held to the same bound.
MAX_MASS_CONDITION = 1e13

#: Symmetric tolerance of M, relative to each entry (the dense check's).
_SYMMETRY = 1e-12

#: Sparse mass matrices that passed :func:`check_mass`: id → weak reference.
_CHECKED: dict[int, weakref.ref] = {}


def arpack_start(n: int) -> np.ndarray:
    """ARPACK's start vector (n,): fixed, so that an eigen-solve gives the same result every run
    (ARPACK's own start is random, and a reduction's basis would differ in its last digits)."""
    return np.random.default_rng(0).standard_normal(n)


def is_sparse(value) -> bool:
    """Whether ``value`` is a scipy.sparse matrix or array (none is where scipy.sparse was never
    imported: this asks without importing it)."""
    sparse = sys.modules.get("scipy.sparse")
    return sparse is not None and sparse.issparse(value)


def dense_array(value) -> np.ndarray:
    """``value`` as a dense float array (a sparse matrix's ``toarray()``): for the compiled kernels'
    packed data of a large model, whose size the memory estimate checked first."""
    return value.toarray() if is_sparse(value) else np.asarray(value, dtype=float)


def dense_spec(spec: dict) -> dict:
    """A contact's spec (``Contact.spec``) with its rows dense (tangent rows G (dim, n), gradients
    n, n_v, W (n,)), as :func:`stickslip.model.bundle.pack` takes it."""
    out = dict(spec)
    for key in ("G", "n_q", "n_v", "W"):
        if key in out and is_sparse(out[key]):
            value = out[key].toarray()
            out[key] = value if key == "G" else value.reshape(-1)
    return out


def _csr(value) -> sp.csr_matrix:
    """``value`` as a canonical float64 CSR matrix (duplicates summed, indices sorted, no stored
    zeros); one that already is a canonical float64 CSR matrix is kept as it is (not copied: a
    model's matrices are never changed in place, and a checked mass stays known as checked)."""
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    if type(value) is sp.csr_matrix and value.dtype == np.float64 and value.has_canonical_format:
        return value
    out = sp.csr_matrix(value, dtype=float, copy=True)
    out.sum_duplicates()
    out.eliminate_zeros()
    return out


def square_matrix(value, n: int, dense: bool, where: str):
    """``value`` as the model keeps an n × n matrix: a dense ``ndarray`` when ``dense``, else CSR.

    Raises
    ------
    ModelError
        ``{where} must be n×n (...)`` or ``{where} has a non-finite entry``.
    """
    if is_sparse(value):
        out = value.toarray().astype(float) if dense else _csr(value)
        finite = np.isfinite(out).all() if dense else np.isfinite(out.data).all()
    else:
        out = np.array(value, dtype=float)
        finite = None
    if out.shape != (n, n):
        raise ModelError(f"{where} must be {n}×{n} (one row and column per dof), got shape {out.shape}")
    if finite is None:
        finite = np.isfinite(out).all()
        if not dense:
            out = _csr(out)
    if not finite:
        raise ModelError(f"{where} has a non-finite entry; give finite numbers")
    return out


def contact_rows(value, rows: int | None, n: int, dense: bool):
    """A contact's rows (tangent G: ``rows`` None, any count) or one vector (``rows`` 1: n, n_v, W).

    Dense: an ndarray (rows, n), or (n,) for a vector, as given (the caller checks its shape).
    Sparse: a CSR matrix (rows, n), a vector as (1, n). Returns None for None.
    """
    if value is None:
        return None
    if dense:
        out = value.toarray() if is_sparse(value) else np.array(value, dtype=float)
        out = np.asarray(out, dtype=float)
        return out.reshape(-1) if rows == 1 else out
    if is_sparse(value):
        return _csr(value)
    out = np.array(value, dtype=float)
    return _csr(out.reshape(1, -1) if rows == 1 or out.ndim == 1 else out)


def finite(value) -> bool:
    """Whether every entry of a dense or sparse array is finite."""
    return bool(np.isfinite(value.data if is_sparse(value) else value).all())


def has_nonzero(value, columns: np.ndarray) -> bool:
    """Whether ``value`` (dense or sparse rows) has a nonzero in one of ``columns`` (a bool mask)."""
    if is_sparse(value):
        return bool(np.any(value.data[columns[value.indices]] != 0.0))
    return bool(np.any(np.atleast_2d(value)[:, columns]))


def mark_positive_definite(mass: sp.spmatrix) -> None:
    """Remember ``mass`` as checked (a positive multiple of a checked matrix is as definite and as
    well conditioned)."""
    _CHECKED[id(mass)] = weakref.ref(mass, lambda _ref, key=id(mass): _CHECKED.pop(key, None))


def is_checked(mass) -> bool:
    """Whether ``mass`` passed :func:`check_mass` (and is still that object)."""
    ref = _CHECKED.get(id(mass))
    return ref is not None and ref() is mass


def check_mass(mass, free: np.ndarray, where: str) -> None:
    """Refuse an M (dense or sparse) that is not symmetric positive definite on the free dofs, or
    is singular to working precision (:data:`MAX_MASS_CONDITION`).

    Dense: every eigenvalue (``eigvalsh``). Sparse: the checks of the module docstring.

    Raises
    ------
    ModelError
        One line: ``{where}: mass must be symmetric ...`` or ``... is not positive definite ...``.
    """
    if is_sparse(mass):
        if is_checked(mass):
            return
        low, high = _sparse_range(mass if free.all() else mass[free][:, free], where)
    else:
        idx = np.flatnonzero(free)
        M = mass[np.ix_(idx, idx)]
        if not (np.abs(M - M.T) <= _SYMMETRY * np.abs(M.T)).all():  # M = Mᵀ to 1e-12 relative
            raise ModelError(f"{where}: mass must be symmetric; give M with M[i][j] = M[j][i]")
        lam = np.linalg.eigvalsh(0.5 * (M + M.T)) if M.size else np.ones(1)
        low, high = _positive_range(lam.min(), lam.max(), where)
    if low < np.finfo(float).tiny or not np.isfinite(high) or high > low * MAX_MASS_CONDITION:
        raise ModelError(f"{where}: mass is singular or not positive definite to working precision "
                         f"(eigenvalues from {low:.3g} to {high:.3g}); masses and inertias must be normal floats "
                         f"(>= {np.finfo(float).tiny:.3g}) within a factor {MAX_MASS_CONDITION:.0e} of each other")
    if is_sparse(mass):
        mark_positive_definite(mass)


def _sparse_range(M: sp.csr_matrix, where: str) -> tuple[float, float]:
    """(λmin, λmax) of a sparse M, after checking it symmetric and positive definite."""
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    asym = abs(M - M.T) - _SYMMETRY * abs(M.T)
    if asym.nnz and asym.max() > 0.0:
        raise ModelError(f"{where}: mass must be symmetric; give M with M[i][j] = M[j][i]")
    off = M - sp.diags(M.diagonal())
    off.eliminate_zeros()
    if off.nnz == 0:
        diagonal = M.diagonal()
        return _positive_range(diagonal.min(), diagonal.max(), where)
    return _factored_range(M, where)


def _positive_range(low: float, high: float, where: str) -> tuple[float, float]:
    if not low > 0.0:
        raise ModelError(f"{where}: mass is not positive definite (smallest eigenvalue {low:.3g}); masses and "
                         "inertias must be > 0")
    return float(low), float(high)


def _factored_range(M: sp.csr_matrix, where: str) -> tuple[float, float]:
    """(λmin, λmax) of a symmetric sparse M after an LDLᵀ factorisation shows it positive definite."""
    from scipy.sparse.linalg import ArpackNoConvergence, LinearOperator, eigsh, splu  # noqa: PLC0415 - scipy's
    # solvers cost start-up time; a model of this size needs them only here

    A = M.tocsc()
    try:
        lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    except RuntimeError:  # SuperLU: "Factor is exactly singular"
        raise ModelError(f"{where}: mass is not positive definite (it is singular: a zero pivot in its "
                         "factorisation); masses and inertias must be > 0") from None
    pivots = lu.U.diagonal()
    if not np.array_equal(lu.perm_r, lu.perm_c) or not pivots.min() > 0.0:
        low = float(pivots.min())
        raise ModelError(f"{where}: mass is not positive definite (its LDLᵀ factorisation has the pivot {low:.3g}"
                         " <= 0); masses and inertias must be > 0")
    n = A.shape[0]
    high = float(abs(A).sum(axis=0).max())  # Gershgorin: λmax ≤ the largest absolute column sum
    try:
        inverse = LinearOperator((n, n), matvec=lu.solve, dtype=float)
        low = float(eigsh(A, k=1, sigma=0.0, which="LM", OPinv=inverse, return_eigenvectors=False, tol=1e-6,
                        v0=arpack_start(n))[0])
    except ArpackNoConvergence:  # the pivots lie in [λmin, λmax]: the smallest is what can be said
        low = float(pivots.min())
    return low, high
