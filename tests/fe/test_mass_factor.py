"""The sparse structure of the heap flavour (model/mass_factor.py): round-off entries dropped, the
mass factor without fill, and the compiled M⁻¹ f, stick multipliers and memory estimate that use it,
against numpy and scipy on the model's own matrices."""

import numpy as np
import pytest
import scipy.linalg as sl

from stickslip.memory import (compiled_model_bytes, contact_rows_bytes, delassus_bytes, model_data_bytes, pattern_bytes,
                              work_array_bytes)
from stickslip.model import physics as P
from stickslip.model.bundle import CST, contact_state
from stickslip.model.kinematics import LARGE_KINEMATICS
from stickslip.model.library import load_model
from stickslip.model.linalg import solve_by_cholesky
from stickslip.model.mass_factor import ROUND_OFF, consecutive_runs, mass_factor, without_round_off
from stickslip.reduction import reduce_model, write_model_file

from .fe_models import pad_on_belt

PAD = dict(nx=8, ny=6, mu_k=0.3, delta_mu=0.2, preload=3e-5, E=1e7, contact_stiffness=1e6, rayleigh=(0.0, 2e-6),
           speed=0.05)


def arrow_mass(modes: int, boundary: int, seed: int = 0) -> np.ndarray:
    """A Craig–Bampton mass matrix: the boundary DOFs first, a dense coupling to the modes, the
    modes' block the identity."""
    rng = np.random.default_rng(seed)
    coupling = 0.1 * rng.standard_normal((boundary, modes))
    bb = coupling @ coupling.T + np.eye(boundary)
    return np.block([[bb, coupling], [coupling.T, np.eye(modes)]])


def test_round_off_entries_are_dropped_and_the_others_kept():
    a = np.array([[4.0, 1e-14, 2e-12, 0.5], [1e-14, 1.0, 0.0, 0.0], [2e-12, 0.0, 1.0, 3.0], [0.5, 0.0, 3.0, 0.0]])
    b = without_round_off(a)
    assert b[0, 1] == b[1, 0] == 0.0  # 1e-14 / √4 = 5e-15 ≤ ROUND_OFF
    assert b[0, 2] == 2e-12 and 2e-12 / 2.0 > ROUND_OFF  # kept: above the bound
    assert b[2, 3] == 3.0 and b[0, 3] == 0.5  # a zero diagonal entry bounds nothing away
    np.testing.assert_array_equal(np.diag(b), np.diag(a))
    assert a[0, 1] == 1e-14  # the input is not changed


def test_mass_factor_of_a_reduced_mass_has_no_fill_and_factors_it():
    modes, boundary = 30, 6
    mass = arrow_mass(modes, boundary)
    n = modes + boundary
    free = np.ones(n, bool)
    free[2] = False  # a locked boundary DOF: the factor covers the free ones
    order, rows, columns, values, diagonal, segment_rows, segments = mass_factor(mass, free)
    assert set(order[:modes]) == set(range(boundary, n))  # the modes first (fewest entries)
    nf = order.size
    assert rows[modes] == 0  # no fill: no entry between two modes (their block of L is diagonal)
    low = np.diag(diagonal)
    position = {dof: i for i, dof in enumerate(order)}
    for i in range(nf):
        for p in range(rows[i], rows[i + 1]):
            low[i, position[columns[p]]] = values[p]
    np.testing.assert_allclose(low @ low.T, mass[np.ix_(order, order)], rtol=0, atol=1e-14 * np.abs(mass).max())
    # a boundary row: one run over the modes (DOFs 6 … 35), one or two (the locked DOF 2 between)
    # over the boundary DOFs before it
    assert segment_rows[modes] == 0 and segment_rows[modes + 1] == 1  # the first boundary row: the modes only
    assert max(segment_rows[i + 1] - segment_rows[i] for i in range(nf)) == 3
    for start, end, first in segments:
        np.testing.assert_array_equal(columns[start:end], first + np.arange(end - start))


def test_consecutive_runs_cover_each_row_in_order():
    rows = np.array([0, 3, 3, 7, 8])
    columns = np.array([5, 6, 7, 0, 1, 9, 10, 11])
    segment_rows, segments = consecutive_runs(rows, columns)
    np.testing.assert_array_equal(segment_rows, [0, 1, 1, 3, 4])
    np.testing.assert_array_equal(segments, [[0, 3, 5], [3, 5, 0], [5, 7, 9], [7, 8, 11]])  # 11 follows 10: a new row
    empty_rows, empty = consecutive_runs(np.zeros(3, np.int64), np.zeros(0, np.int64))
    assert empty.shape == (0, 3) and not empty_rows.any()


def test_cholesky_solves_what_is_full_rank_and_leaves_the_rest_to_jacobi():
    rng = np.random.default_rng(1)
    g = rng.standard_normal((5, 8))
    a = g @ g.T
    b = rng.standard_normal(5)
    x, v = np.zeros(5), np.zeros((5, 5))
    assert solve_by_cholesky(a.copy(), b, x, v, 5)
    np.testing.assert_allclose(x, np.linalg.solve(a, b), rtol=1e-12)
    singular = g[:, :3] @ g[:, :3].T  # rank 3 of 5
    x[:] = 7.0
    assert not solve_by_cholesky(singular, b, x, v, 5)
    assert np.all(x == 7.0)  # x not written: the caller's Jacobi solve takes it


@pytest.fixture(scope="module")
def reduced(tmp_path_factory):
    folder = tmp_path_factory.mktemp("factor")
    full = load_model(str(pad_on_belt(**PAD).write(folder / "pad")))
    red = reduce_model(full, method="craig-bampton", modes=60)
    write_model_file(red.form, folder / "cb.toml")
    model = load_model(str(folder / "cb.toml"))
    assert type(model.data.kin) is LARGE_KINEMATICS[type(model.kinematics)] and model.n == 78
    return model


def test_memory_estimate_counts_the_sparse_structure(reduced):
    n, nc = reduced.n, reduced.n_contacts
    assert compiled_model_bytes(n, nc) == (model_data_bytes(n, nc) + work_array_bytes(n, nc) + pattern_bytes(n)
                                           + contact_rows_bytes(n, nc))
    kin = reduced.data.kin
    held = sum(a.nbytes for a in kin if isinstance(a, np.ndarray))
    stick = kin.delassus.nbytes + kin.inverse_mass_rows.nbytes
    assert held - stick <= pattern_bytes(n) + contact_rows_bytes(n, nc)
    assert kin.delassus.shape == (2 * nc, 2 * nc) and kin.inverse_mass_rows.shape == (2 * nc, n)
    assert stick <= delassus_bytes(n, nc)


def matrices(model):
    form = model.sparse_form()
    return tuple(np.asarray(a.toarray() if hasattr(a, "toarray") else a, float)
                 for a in (form.mass, form.damping, form.stiffness))


def random_state(n, seed=2):
    rng = np.random.default_rng(seed)
    s = np.zeros(2 * n + 2)
    s[:n] = 1e-7 * rng.standard_normal(n)
    s[n:2 * n] = 1e-4 * rng.standard_normal(n)
    return s


def test_open_contacts_accelerate_by_the_model_matrices(reduced):
    """Every contact open: q̈ = M⁻¹ (f0 − C q̇ − K q), by scipy on the model's own M, C, K (with
    their round-off entries) against the kernels' factor solve."""
    n = reduced.n
    M, C, K = matrices(reduced)
    s = random_state(n)
    cst = contact_state(reduced.data.m)
    cst[0::CST] = P.MODE_OPEN
    ds = np.zeros_like(s)
    P.rhs(s, cst, reduced.data, ds)
    f = np.asarray(reduced.sparse_form().force, float) - C @ s[n:2 * n] - K @ s[:n]
    expected = sl.solve(M, f, assume_a="pos")
    np.testing.assert_allclose(ds[n:2 * n], expected, rtol=0, atol=1e-10 * np.abs(expected).max())


def test_every_contact_sticking_holds_its_slip_velocity(reduced):
    """All nine contacts sticking (nine stick rows: the Cholesky solve): their slip accelerations
    G q̈ vanish to round-off of the terms that make them up."""
    n, nc = reduced.n, reduced.n_contacts
    s = random_state(n, 3)
    cst = contact_state(reduced.data.m)
    cst[0::CST] = P.MODE_STICK
    ds = np.zeros_like(s)
    P.rhs(s, cst, reduced.data, ds)
    rows = reduced.sparse_form().tangent.toarray()
    assert rows.shape[0] == nc  # one tangent row each: nine stick rows
    acc = rows @ ds[n:2 * n]
    scale = np.abs(rows).max() * np.abs(ds[n:2 * n]).max()
    assert np.abs(acc).max() <= 1e-11 * scale


def test_contact_rows_and_their_delassus_matrix_are_the_models(reduced):
    """The heap class's contact rows over their nonzero entries rebuild the model's tangent rows,
    and W = G M⁻¹ Gᵀ and G M⁻¹ are those of scipy's solve with the model's own M (round-off entries and all)."""
    n, nc = reduced.n, reduced.n_contacts
    kin = reduced.data.kin
    G = np.zeros((2 * nc, n))
    for r in range(2 * nc):
        p = slice(kin.row_starts[r], kin.row_starts[r + 1])
        G[r, kin.row_columns[p]] = kin.row_values[p]
    tangent = reduced.sparse_form().tangent.toarray()
    dims = reduced.sparse_form().dim
    used = np.concatenate([[2 * c, 2 * c + 1][:d] for c, d in enumerate(dims)])
    np.testing.assert_array_equal(G[used], tangent)
    assert not G[np.setdiff1d(np.arange(2 * nc), used)].any()
    M = matrices(reduced)[0]
    expected = G @ sl.solve(M, G.T, assume_a="pos")
    np.testing.assert_allclose(kin.delassus, expected, rtol=0, atol=1e-10 * np.abs(expected).max())
    response = sl.solve(M, G.T, assume_a="pos").T  # row r: M⁻¹ g_r
    np.testing.assert_allclose(kin.inverse_mass_rows, response, rtol=0, atol=1e-10 * np.abs(response).max())


def test_stick_without_the_delassus_matrix_forms_the_same_system(reduced):
    """Where W does not fit (an empty ``delassus``) the stick systems are formed row by row: the
    same accelerations, each stick row's sum the same as W's entry."""
    n = reduced.n
    md = reduced.data
    row_by_row = md._replace(kin=md.kin._replace(delassus=np.zeros((0, 0)), inverse_mass_rows=np.zeros((0, 0))))
    s = random_state(n, 4)
    cst = contact_state(md.m)
    for sticking in (slice(None), slice(0, 2), slice(5, 6)):  # stick systems of nine rows, two and one
        cst[0::CST] = P.MODE_SLIP_EXACT
        cst[0::CST][sticking] = P.MODE_STICK
        with_w, without = np.zeros_like(s), np.zeros_like(s)
        P.rhs(s, cst, md, with_w)
        P.rhs(s, cst, row_by_row, without)
        np.testing.assert_allclose(with_w, without, rtol=1e-12, atol=1e-12 * np.abs(without).max())


def test_sliding_contacts_act_through_their_rows(reduced):
    """Every contact closed and sliding: the slip velocities are G q̇ − w of the model's own tangent
    rows and drives, and q̈ = M⁻¹ (f0 − C q̇ − K q + Gᵀ F + Wᵀ λ) with the contacts' friction and
    normal forces, by scipy on the model's own matrices (the kernels sum over the rows' nonzero
    entries only)."""
    n, nc = reduced.n, reduced.n_contacts
    form = reduced.sparse_form()
    M, C, K = matrices(reduced)
    s = random_state(n, 5)
    cst = contact_state(reduced.data.m)
    cst[0::CST] = P.MODE_SLIP_EXACT
    ds, F, N, v = np.zeros_like(s), np.zeros(2 * nc), np.zeros(nc), np.zeros(2 * nc)
    P.rhs(s, cst, reduced.data, ds)
    P.contact_forces(s, cst, reduced.data, F, N, v)
    used = np.concatenate([[2 * c, 2 * c + 1][:d] for c, d in enumerate(form.dim)])
    G = np.zeros((2 * nc, n))
    G[used] = form.tangent.toarray()
    w = np.zeros(2 * nc)
    w[used] = form.drive
    qd = s[n:2 * n]
    np.testing.assert_allclose(v, G @ qd - w, rtol=0, atol=1e-13 * np.abs(G).max() * np.abs(qd).max())
    assert np.all(np.abs(v[used]) > 0.0) and np.all(F[used] != 0.0)  # every contact slides with a force
    gaps = np.array([P.gap(s, c, reduced.data) for c in range(nc)])  # (g, ġ) summed over W's nonzero entries
    W = form.gap_gradient.toarray()
    np.testing.assert_allclose(gaps[:, 0], form.gap + W @ s[:n], rtol=1e-13, atol=1e-13 * np.abs(W @ s[:n]).max())
    np.testing.assert_allclose(gaps[:, 1], W @ qd, rtol=1e-13, atol=1e-13 * np.abs(W @ qd).max())
    f = np.asarray(form.force, float) - C @ qd - K @ s[:n] + G.T @ F + form.gap_gradient.T @ N
    expected = sl.solve(M, f, assume_a="pos")
    np.testing.assert_allclose(ds[n:2 * n], expected, rtol=0, atol=1e-10 * np.abs(expected).max())


@pytest.mark.parametrize("sticking", [slice(None), slice(2, 4), slice(7, 8)], ids=["all", "two", "one"])
def test_projection_onto_stick_is_the_mass_metric_one(reduced, sticking):
    """The heap class projects q̇ onto v_S = 0 with W and the rows M⁻¹ g_r it carries: the same
    change as Δq̇ = −M⁻¹ G_Sᵀ (G_S M⁻¹ G_Sᵀ)⁻¹ v_S by scipy on the model's own M, and the kinetic
    energy change booked (in closed form) equal to the difference of ½ q̇ᵀ M q̇ before and after."""
    n, nc = reduced.n, reduced.n_contacts
    form = reduced.sparse_form()
    M = matrices(reduced)[0]
    s = random_state(n, 6)
    s[2 * n] = 0.25  # the work of friction so far
    cst = contact_state(reduced.data.m)
    cst[0::CST] = P.MODE_SLIP_EXACT
    cst[0::CST][sticking] = P.MODE_STICK
    stick = np.arange(nc)[sticking]
    G = form.tangent.toarray()[stick]  # one tangent row per contact
    w = np.asarray(form.drive, float)[stick]
    qd = s[n:2 * n].copy()
    y = s.copy()
    delta = P.project_velocities(y, cst, np.int64(-1), reduced.data)
    MG = sl.solve(M, G.T, assume_a="pos")
    change = -MG @ np.linalg.solve(G @ MG, G @ qd - w)
    np.testing.assert_allclose(y[n:2 * n] - qd, change, rtol=0, atol=1e-10 * np.abs(change).max())
    scale = np.abs(G @ qd).max() + np.abs(w).max()  # of the terms that make up v_S
    np.testing.assert_allclose(G @ y[n:2 * n] - w, 0.0, atol=1e-12 * scale)
    energy = 0.5 * y[n:2 * n] @ M @ y[n:2 * n] - 0.5 * qd @ M @ qd
    assert abs(energy) > 1e-3 * abs(0.5 * qd @ M @ qd)  # a change to measure: the contacts take the belt's speed
    assert delta == pytest.approx(energy, rel=1e-9) and y[2 * n] == pytest.approx(0.25 + energy, rel=1e-12)
    np.testing.assert_array_equal(y[:n], s[:n])
