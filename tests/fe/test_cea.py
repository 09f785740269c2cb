"""Complex eigenvalue analysis of sparse models: the direct (shift-invert Arnoldi), modal and dense
paths against each other, against the closed form of Hoffmann's model, and the refusals."""

import math

import numpy as np
import pytest
import scipy.linalg

from stickslip import memory
from stickslip.errors import EquilibriumError, MemoryLimitError
from stickslip.model.library import load_model
from stickslip.stability.band import BandError, band_stability
from stickslip.stability.cea import _check_again, band_eigen, dense_eigen, frictionless_count
from stickslip.stability.modal_cea import real_modes, residual_vectors
from stickslip.stability.sparse_sliding import sparse_steady_sliding

from .brake_models import pad_on_strip_2d


@pytest.fixture(scope="module")
def strip():
    """A pad on a flexible strip (495 DOFs, 17 contacts) past its flutter onset, light stiffness damping."""
    return pad_on_strip_2d(strip=(48, 3), pad=(16, 3), mu=0.6, beta=2e-7)


@pytest.fixture(scope="module")
def strip_dense(strip):
    state = sparse_steady_sliding(strip)
    return state, dense_eigen(state)[0]


def _nearest_errors(found, reference):
    return np.array([np.min(np.abs(reference - x)) / abs(x) for x in found])


def _band(lam, omega):
    """The band of the sparse path: |Im λ| ≤ ω_max inside the disc |λ| ≤ ω_max √(1 + 0.25²)."""
    return lam[(np.abs(lam.imag) <= omega) & (np.abs(lam) <= omega * math.sqrt(1 + 0.25**2))]


def _same(a, b, rtol=1e-9):
    """The same eigenvalues (as sets, to ``rtol``)."""
    assert a.size == b.size
    assert max(np.max(_nearest_errors(a, b)), np.max(_nearest_errors(b, a))) < rtol


@pytest.mark.parametrize("mu", [0.5, 1.0 - 1e-3, 1.4])
def test_hoffmann_closed_form(mu):
    """Hoffmann's 2-DOF model: λ² = −(2 ± √(1 − μ)) (docs/models/hoffmann.md), complex past μ = 1."""
    result = band_stability(load_model("hoffmann").replace(**{"contact.0.friction.mu_k": mu}), 3.0)
    root = np.sqrt(complex(1.0 - mu))
    exact = np.array([s * np.sqrt(-(2.0 + sign * root)) for sign in (1, -1) for s in (1, -1)])
    assert result.eigenvalues.size == 4
    assert np.max(_nearest_errors(result.eigenvalues, exact)) < 1e-13
    assert result.stable == (mu < 1.0) or abs(result.max_real_part) < 1e-12


def test_direct_matches_dense_to_1e_8(strip, strip_dense):
    state, lam = strip_dense
    omega = 2 * np.pi * 30e3
    result = band_stability(strip, omega)
    assert result.method == "direct" and state.n == 495
    reference = _band(lam, omega)
    # the same eigenvalues: each found one is a dense one, and as many
    assert result.eigenvalues.size == reference.size > 20
    assert np.max(_nearest_errors(result.eigenvalues, reference)) < 1e-8
    assert np.max(_nearest_errors(reference, result.eigenvalues)) < 1e-8
    assert result.max_real_part > 0.0 and not result.stable  # the pad flutters at μ = 0.6
    assert np.max(result.backward_error) < 1e-10
    # the disc searched covers the band and the frictionless count is consistent with it
    assert result.radius > omega
    assert abs(2 * result.frictionless_count - np.sum(np.abs(lam) <= result.radius)) <= 4


def test_modal_refined_and_converging(strip, strip_dense):
    _, lam = strip_dense
    omega = 2 * np.pi * 30e3
    modal = band_stability(strip, omega, method="modal")
    direct = band_stability(strip, omega)
    _same(modal.eigenvalues, direct.eigenvalues)
    # the reported eigenvalues are the full model's, not the projection's
    assert np.max(_nearest_errors(modal.eigenvalues, lam)) < 1e-8
    assert np.max(modal.modal.errors) > 1e-8
    rows = modal.modal.convergence
    assert rows[-1]["modes"] == modal.modal.modes == frictionless_count(sparse_steady_sliding(strip), 2 * omega)
    assert all(row["residual_vectors"] == modal.modal.residual_vectors > 0 for row in rows)
    errors = [row["max_relative_error"] for row in rows]
    # with the residual vectors the approximations converge to the full eigenvalues as modes are
    # added; the modes alone stall where the stiff contacts put motion into high modes (docs/fe.md)
    assert errors[-1] < 1e-4 and errors[-1] < 1e-3 * errors[0]
    assert errors[-1] < 1e-2 * rows[-1]["modes_only_error"]
    assert rows[-1]["found"] == modal.eigenvalues.size > rows[-1]["modes_only_found"]
    alone = band_stability(strip, omega, method="modal", residual=False)
    assert alone.modal.residual_vectors == 0
    assert alone.modal.convergence[-1]["max_relative_error"] == pytest.approx(rows[-1]["modes_only_error"], rel=1e-9)
    _same(alone.eigenvalues, direct.eigenvalues)


def test_residual_vectors_span_the_static_response(strip):
    """The residual vectors (from K_t's factors) with the modes span the static response of the
    frictionless structure K_s⁻¹ Pᵀ to every contact row, M-orthonormal and M-orthogonal to the modes."""
    state = sparse_steady_sliding(strip)
    basis = real_modes(state, 2 * np.pi * 30e3)
    Phi = basis.vectors
    Y = residual_vectors(state, Phi)
    M = state.mass.toarray()
    assert np.abs(Y.T @ M @ Y - np.eye(Y.shape[1])).max() < 1e-10 and np.abs(Phi.T @ M @ Y).max() < 1e-10
    K0 = (state.stiffness - state.friction_stiffness).toarray()
    form = state.form
    rows = np.vstack([form.tangent.toarray(), form.gap_gradient.toarray()])[:, state.free]
    rows = rows[np.abs(rows).sum(axis=1) > 0]
    X = np.linalg.solve(0.5 * (K0 + K0.T), rows.T)
    V = np.hstack([Phi, Y])
    inside = V @ (V.T @ (M @ X))  # the M-orthogonal projection on the span
    assert np.linalg.norm(X - inside) < 1e-8 * np.linalg.norm(X)
    assert Y.shape[1] == np.linalg.matrix_rank(rows)


def test_frictionless_count_is_sylvester(strip):
    state = sparse_steady_sliding(strip)
    K0 = (state.stiffness - state.friction_stiffness).toarray()
    w2 = scipy.linalg.eigh(0.5 * (K0 + K0.T), state.mass.toarray(), eigvals_only=True)
    for omega in (2 * np.pi * 5e3, 2 * np.pi * 40e3):
        assert frictionless_count(state, omega) == int(np.sum(w2 < omega**2))


def test_arnoldi_grows_until_the_disc_is_covered(strip, strip_dense):
    state, lam = strip_dense
    band = band_eigen(state, 2 * np.pi * 30e3, k=6)
    assert len(band.arnoldi_runs) > 1
    assert band.eigenvalues.size == np.sum(np.abs(lam) <= band.radius)


def test_arnoldi_runs_may_differ_by_arnoldis_error_but_not_miss_an_eigenvalue(strip_dense):
    """Arnoldi's eigenvalues carry errors of a few 1e-8 relative (which pairs depends on the LAPACK
    build): a smaller run 5e-8 off the larger one's is accepted; a larger run without one of the
    smaller run's eigenvalues is refused."""
    _, lam = strip_dense
    lam = lam[np.argsort(np.abs(lam))][:12]
    smaller = lam[:6] * (1.0 + 5e-8)
    _check_again(smaller, lam)
    with pytest.raises(EquilibriumError, match="the Arnoldi runs disagree on the eigenvalue"):
        _check_again(smaller, np.delete(lam, 2))


def test_refusals(strip, monkeypatch):
    with pytest.raises(BandError, match="no eigenvalue with frequency below 10 rad/s; the lowest lies near"):
        band_stability(strip, 10.0)
    with pytest.raises(BandError, match="choose one of direct, modal, dense"):
        band_stability(strip, 1e5, method="qr")
    monkeypatch.setattr(memory, "available_memory", lambda: 1e6)
    with pytest.raises(MemoryLimitError, match=r"use --method direct .*fits up to \d+ DOFs"):
        band_stability(strip, 1e5, method="dense")


def test_dense_method_of_band():
    small = pad_on_strip_2d(strip=(24, 2), pad=(8, 2), mu=0.6, beta=2e-7)  # the dense path's own check: 135 DOFs
    lam = dense_eigen(sparse_steady_sliding(small))[0]
    omega = 2 * math.pi * 60e3
    dense = band_stability(small, omega, method="dense")
    assert dense.eigenvalues.size == _band(lam, omega).size > 10
    assert np.max(_nearest_errors(dense.eigenvalues, lam)) < 1e-13
