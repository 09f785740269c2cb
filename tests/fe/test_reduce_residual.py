"""Residual vectors of a reduction against dense numpy: their span, their M-orthonormality, and that
each method's reduced model keeps the full model's steady-sliding eigenvalues at least as well with them."""

import numpy as np
import pytest
import scipy.linalg as la

from stickslip.reduction import boundary_dofs, reduce_model, reduction_report
from stickslip.reduction.bases import _residual_vectors
from stickslip.stability.sparse_input import sparse_form

from .lined_pad import lined_pad


@pytest.fixture(scope="module")
def pad():
    fe = lined_pad(4, 4, lumped=False)  # consistent masses: M_ib ≠ 0 enters the first block
    return fe, fe.stiffness.toarray(), fe.mass.toarray()


def test_blocks_span_the_krylov_sequence_of_the_boundary_inertia(pad):
    fe, K, M = pad
    b = np.sort(np.concatenate([fe.tangent_dof, fe.normal_dof]))
    i = np.setdiff1d(np.arange(fe.n), b)
    Kii, Mii = K[np.ix_(i, i)], M[np.ix_(i, i)]
    Psi = -la.solve(Kii, K[np.ix_(i, b)])
    w2, V = la.eigh(Kii, Mii)
    Phi = V[:, :3]  # three fixed-interface modes, M-orthonormal
    load = Mii @ Psi + M[np.ix_(i, b)]
    X = _residual_vectors(Mii, lambda r: la.solve(Kii, r), load, Phi, 2)
    basis = np.hstack([Phi, X])
    np.testing.assert_allclose(basis.T @ Mii @ basis, np.eye(basis.shape[1]), atol=1e-10)
    first = la.solve(Kii, load)
    second = la.solve(Kii, Mii @ first)
    for target in (first, second):  # each block's span, with the modes', holds the sequence's vector
        coefficients = basis.T @ Mii @ target
        np.testing.assert_allclose(basis @ coefficients, target, atol=1e-9 * np.abs(target).max())
    assert X.shape[1] == 2 * b.size


def test_the_reduced_models_take_the_vectors(pad):
    fe, _, _ = pad
    form = sparse_form(_model(fe))
    nb = boundary_dofs(form).size
    for method in ("craig-bampton", "modal"):
        alone = reduce_model(form, method=method, modes=3)
        more = reduce_model(form, method=method, modes=3, residual=1)
        assert more.residual == nb and more.form.n == alone.form.n + nb
        mass = more.form.mass.toarray()[nb:, nb:]  # the η block: M-orthonormal coordinates
        np.testing.assert_allclose(mass, np.eye(mass.shape[0]), atol=1e-9)
        band = 2 * np.pi * 6e3
        assert reduction_report(form, more.form, band).max_error <= reduction_report(form, alone.form, band).max_error


def _model(fe):
    import tempfile
    from pathlib import Path

    from stickslip.model.library import load_model

    return load_model(str(fe.write(Path(tempfile.mkdtemp()) / "pad")))
