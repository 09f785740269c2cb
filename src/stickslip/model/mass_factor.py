"""The sparse structure that the heap-flavour kernels of a large model take from its dense matrices.

A reduced finite-element model (Craig–Bampton, ``stickslip.reduction``) has dense M, C, K in
form only: the blocks that the reduction's theory makes zero (the fixed-interface modes are
orthonormal in M and orthogonal in K, and orthogonal in K to the constraint modes) come out of
its floating-point products as round-off, ~1e-15 of the diagonal. Read as data, they make every
right-hand side cost O(n²) memory traffic (M⁻¹ f, C q̇, K q) where the model has O(n nb)
numbers (nb the boundary DOFs).

* :func:`without_round_off` sets those entries to zero: |A_ij| ≤ :data:`ROUND_OFF` ·
  √|A_ii A_jj| (i ≠ j), four hundred times the round-off of a reduction, far below any coupling
  of a mechanical model (|A_ij| ≤ √(A_ii A_jj) for a positive semi-definite matrix); where a
  diagonal entry is zero the bound is zero and every nonzero entry stays;
* :func:`row_pattern` gives the row-compressed pattern of the entries that are not zero (the
  kernels sum over those only);
* :func:`mass_factor` gives the Cholesky factor of M on its free DOFs in an order that keeps it
  sparse: rows with fewest entries first (a reduced model's modes before its boundary DOFs: no
  fill at all), so that M⁻¹ f is two triangular solves over the factor's entries
  (:func:`~stickslip.model.model_data.inverse_mass_of`) instead of a product with the dense M⁻¹,
  reading each row's runs of consecutive DOFs (a boundary DOF's row over the modes) without their
  column indices;
* :func:`contact_rows` gives each contact's tangent rows G, normal-force gradients n_q, n_v and
  gap gradient ∂g/∂q over their nonzero entries (a reduced model's contact row is a unit vector on a boundary DOF),
  so that a frame costs their entries, not n;
* :func:`delassus` gives W = G M⁻¹ Gᵀ of all contact rows, constant where G is: the matrix of
  every stick system is a submatrix of it (:func:`~stickslip.model.stick.heap_stick_system`), where
  forming it costs one M⁻¹ product per stick row; and the rows M⁻¹ g_r, with which a stick
  system's right side and a projection of the velocities need no solve with the mass factor.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .bundle import C_G, contact_offsets, gap_offset, offsets

__all__ = ["ROUND_OFF", "without_round_off", "row_pattern", "mass_factor", "consecutive_runs", "contact_rows",
           "delassus"]

#: Relative size |A_ij| / √|A_ii A_jj| at or below which an off-diagonal entry of M, C or K of a
#: large model counts as round-off (module docstring).
ROUND_OFF = 1e-13


def without_round_off(matrix: np.ndarray) -> np.ndarray:
    """A copy of the dense (n, n) ``matrix`` with its off-diagonal entries at or below
    :data:`ROUND_OFF` of the geometric mean of their diagonal entries set to zero."""
    a = np.array(matrix, dtype=float)
    d = np.sqrt(np.abs(np.diag(a)))
    small = np.abs(a) <= ROUND_OFF * np.outer(d, d)
    np.fill_diagonal(small, False)
    a[small] = 0.0
    return a


def row_pattern(nonzero: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rows (n + 1,), columns) int64: the row-compressed pattern of the True entries of the
    (n, n) boolean ``nonzero``, columns ascending in each row."""
    rows = np.zeros(nonzero.shape[0] + 1, dtype=np.int64)
    np.cumsum(nonzero.sum(axis=1), out=rows[1:])
    return rows, np.nonzero(nonzero)[1].astype(np.int64)


def mass_factor(mass: np.ndarray, free: np.ndarray) -> tuple[np.ndarray, ...]:
    """The Cholesky factor L of M on its free DOFs, P M_ff Pᵀ = L Lᵀ, P the order of fewest
    entries per row first (stable).

    Returns (order, rows, columns, values, diagonal, segment_rows, segments): ``order`` (nf,)
    int64, the DOF of each factor row; the strictly lower part of L row-compressed over its
    nonzero entries, ``rows`` (nf + 1,) int64, ``columns`` int64 as the DOFs they stand for (not
    factor indices: the solve reads the vector there directly), ``values``; ``diagonal`` (nf,)
    the diagonal of L; each row's entries as runs of consecutive DOFs (:func:`consecutive_runs`:
    a reduced model's boundary row is two runs, over the modes and over the boundary DOFs before
    it), which the solve reads without their column indices. The factor's zeros are exact: the
    dense factorisation computes an entry outside the fill of P's order from products that are all
    exact zeros.
    """
    idx = np.flatnonzero(np.asarray(free, dtype=bool))
    sub = np.asarray(mass, dtype=float)[np.ix_(idx, idx)]
    order = np.argsort(np.count_nonzero(sub, axis=1), kind="stable")
    low = np.linalg.cholesky(sub[np.ix_(order, order)])
    strict = np.tril(low, -1)
    rows, columns = row_pattern(strict != 0.0)
    dofs = idx[order].astype(np.int64)
    columns = dofs[columns]
    return (dofs, rows, columns, strict[strict != 0.0].copy(), np.diag(low).copy(),
            *consecutive_runs(rows, columns))


def consecutive_runs(rows: np.ndarray, columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows of the row-compressed pattern (``rows`` (r + 1,), ``columns``) as runs of consecutive
    columns: (segment_rows (r + 1,), segments (k, 3)) int64, row i's runs at segment_rows[i] …
    segment_rows[i + 1] − 1, each [start, end, first]: the entries p in [start, end) stand for
    columns first, first + 1, …, in the pattern's order."""
    breaks = np.ones(columns.size, dtype=bool)
    breaks[1:] = columns[1:] != columns[:-1] + 1
    breaks[rows[:-1][rows[:-1] < columns.size]] = True  # every row starts a run
    starts = np.flatnonzero(breaks)
    ends = np.append(starts[1:], columns.size)[:starts.size]  # the next run's start (rows start runs)
    segments = np.stack([starts, ends, columns[starts]], axis=1).astype(np.int64)
    segment_rows = np.searchsorted(starts, rows).astype(np.int64)
    return segment_rows, segments.reshape(-1, 3)


def _packed_rows(m: np.ndarray, n: int, nc: int) -> tuple[np.ndarray, ...]:
    """(G (2 nc, n), n_q (nc, n), n_v (nc, n), ∂g/∂q (nc, n)) copied from the packed data ``m``:
    contact c's tangent rows are rows 2c, 2c + 1 of G, its gap gradient row c of ∂g/∂q."""
    blocks = [contact_offsets(n, c) for c in range(nc)]
    G = np.array([m[o + C_G:o + C_G + 2 * n] for o, _, _, _ in blocks]).reshape(2 * nc, n)
    nq = np.array([m[onq:onq + n] for _, _, onq, _ in blocks]).reshape(nc, n)
    nv = np.array([m[onv:onv + n] for _, _, _, onv in blocks]).reshape(nc, n)
    gap = np.array([m[gap_offset(n, c):gap_offset(n, c) + n] for c in range(nc)]).reshape(nc, n)
    return G, nq, nv, gap


def contact_rows(m: np.ndarray, n: int, nc: int) -> tuple[np.ndarray, ...]:
    """Each contact's tangent rows and normal-force gradients over their nonzero entries, from the
    packed data ``m`` (float64) of a model of n DOFs and nc contacts with constant frames.

    Returns (row_starts (2 nc + 1,), row_columns, row_values): the rows of G (contact c's at 2c,
    2c + 1) row-compressed, columns ascending; (normal_starts (nc + 1,), normal_columns, normal_q,
    normal_v): per contact the DOFs j where n_q or n_v is not zero, ascending, and both there
    (the normal force N0 + n_q·q + n_v·q̇ sums over those only, in the same order);
    (gap_starts (nc + 1,), gap_columns, gap_values): the gap gradients ∂g/∂q row-compressed (empty
    for a contact without a gap), over which the gaps, their rates and the normal forces on the
    coordinates are summed.
    """
    G, nq, nv, gap = _packed_rows(m, n, nc)
    row_starts, row_columns = row_pattern(G != 0.0)
    starts, columns = row_pattern((nq != 0.0) | (nv != 0.0))
    rows = np.repeat(np.arange(nc), np.diff(starts))
    gap_starts, gap_columns = row_pattern(gap != 0.0)
    return (row_starts, row_columns, G[G != 0.0].copy(), starts, columns, nq[rows, columns].copy(),
            nv[rows, columns].copy(), gap_starts, gap_columns, gap[gap != 0.0].copy())


def delassus(m: np.ndarray, n: int, nc: int,
             rows: tuple[np.ndarray, np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(W, R): W = G M⁻¹ Gᵀ (2 nc, 2 nc) of all contact rows of the packed data ``m`` (float64),
    with G as ``rows`` = (row_starts, row_columns, row_values) of :func:`contact_rows` and M⁻¹ the
    packed one, and R = G M⁻¹ (2 nc, n), whose row r is M⁻¹ g_r (M⁻¹ symmetric): the acceleration
    of a unit force on contact row r, from which a stick system's right side g_r·M⁻¹ f is one dot
    product R_r·f instead of a solve with the mass factor.

    Each entry is the sum the stick solve formed: (M⁻¹ g_s)_i = Σ_j g_s,j (M⁻¹)_ji over the nonzero
    g_s,j in order, then W_rs = Σ_i g_r,i (M⁻¹ g_s)_i likewise (a sparse-times-dense product sums
    in that order), so a stick system read from W is the one formed row by row.
    """
    G = sp.csr_matrix((rows[2], rows[1], rows[0]), shape=(2 * nc, n))
    o = offsets(n)[0]
    inverse = m[o:o + n * n].reshape(n, n)
    response = np.ascontiguousarray(np.asarray(G @ inverse))
    return np.ascontiguousarray(G @ response.T), response
