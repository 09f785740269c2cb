"""The sparse form of a model (stickslip.model.sparse_form) and sparse models (FrictionModel with
scipy.sparse matrices): the same numbers as the dense path on the library models, friction laws in
Python equal to the compiled ones, the checks of a sparse mass matrix against dense eigenvalues,
and a finite-element pad kept sparse and refused by the compiled tools in one line."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from numba import njit

from stickslip.errors import MemoryLimitError, ModelError
from stickslip.model.bundle import NORMAL_LAWS
from stickslip.model.friction import FrictionLaw, NoUserLaw, friction_coefficient
from stickslip.model.library import load_model, two_plates
from stickslip.model.library.laws import Stribeck
from stickslip.model.matrices import DENSE_DOFS, MAX_MASS_CONDITION, check_mass
from stickslip.model.sparse_form import NodeMap, friction_slope, friction_value
from stickslip.model.system_model import Contact, FrictionModel, NormalLaw

from .fe_models import pad_on_belt

FILE_MODELS = ("belt", "hoffmann", "impact-oscillator", "popp-stelter", "slider-belt", "sprag-slip")


@pytest.mark.parametrize("name", FILE_MODELS)
def test_the_sparse_form_holds_the_dense_models_numbers(name):
    model = load_model(name)
    form = model.sparse_form()
    n = model.n
    for key in ("mass", "damping", "stiffness"):
        matrix = getattr(form, key)
        assert isinstance(matrix, sp.csr_matrix) and np.array_equal(matrix.toarray(), getattr(model, key))
    assert np.array_equal(form.force, model.force) and np.array_equal(form.free, model.free)
    assert form.contact_names == model.contact_names and form.dofs == model.dofs
    for c, contact in enumerate(model.contacts):
        rows = form.rows(c)
        assert np.array_equal(form.tangent[rows].toarray(), contact.tangent)
        assert np.array_equal(form.drive[rows], contact.drive)
        # the compiled kernels' affine normal force (Contact.spec, packed by bundle.pack) is the
        # form's with each compliant contact closed
        spec = contact.spec(n)
        N0, n_q, n_v = form.closed_normal()
        assert N0[c] == spec["N0"]
        assert np.array_equal(n_q[c].toarray().ravel(), spec["n_q"])
        assert np.array_equal(n_v[c].toarray().ravel(), spec["n_v"])
        assert NORMAL_LAWS[form.normal_law[c] or "prescribed"] == spec.get("normal_law", NORMAL_LAWS["prescribed"])
        if contact.unilateral:
            assert form.gap[c] == spec["gap"] and np.array_equal(form.gap_gradient[c].toarray().ravel(), spec["W"])
            assert (form.contact_stiffness[c], form.contact_damping[c], form.restitution[c]) == (
                spec["k"], spec["c"], spec["e"])
        assert form.friction[c] is contact.friction


def test_the_plates_have_no_sparse_form():
    with pytest.raises(ModelError, match="constant tangent rows"):
        two_plates().sparse_form()


@njit(cache=False)
def _compiled(speed, row):
    """μ and dμ/d|v| of the compiled law (the complex step the Jacobians take), without a user law."""
    law = NoUserLaw()
    value = friction_coefficient(speed + 0j, row, law).real
    slope = friction_coefficient(speed + 1e-30j, row, law).imag / 1e-30
    return value, slope


LAWS = [FrictionLaw("coulomb", 0.3, 0.1), FrictionLaw("exponential", 0.3, 0.2, 4.0),
        FrictionLaw("exponential", 0.25, 0.5, 1.5, 0.05)]


@pytest.mark.parametrize("law", LAWS, ids=lambda law: law.law + (f"-mu_v{law.mu_v}" if law.mu_v else ""))
def test_python_friction_laws_equal_the_compiled_ones(law):
    speeds = np.array([0.0, 1e-6, 0.01, 0.3, 1.0, 7.5])
    for speed in speeds:
        value, slope = _compiled(speed, law.row())
        assert friction_value(law, speed) == pytest.approx(value, rel=1e-15, abs=0.0)
        assert friction_slope(law, speed) == pytest.approx(slope, rel=1e-14, abs=1e-300)


def test_a_user_laws_slope_is_its_derivative():
    stribeck = Stribeck(mu_c=0.5, mu_s=1.0, v_s=0.5, mu_v=0.05)
    law = FrictionLaw.from_user(stribeck)
    v = np.linspace(0.0, 3.0, 13)
    ratio = v / stribeck.v_s
    exact = -2.0 * ratio / stribeck.v_s * (stribeck.mu_s - stribeck.mu_c) * np.exp(-ratio ** 2) + stribeck.mu_v
    assert np.allclose(friction_slope(law, v), exact, rtol=1e-14, atol=1e-16)
    assert np.allclose(friction_value(law, v), stribeck.mu_c + (stribeck.mu_s - stribeck.mu_c) * np.exp(-ratio ** 2)
                       + stribeck.mu_v * v, rtol=1e-15)


# ----------------------------------------------------------------------------- sparse models
def pad_model(nx=10, ny=4, **changes) -> FrictionModel:
    """The generator's pad as a FrictionModel built in Python from its sparse matrices."""
    fe = pad_on_belt(nx, ny)
    n = fe.n
    unit = lambda i: sp.csr_matrix(([1.0], ([0], [i])), shape=(1, n))  # noqa: E731
    contacts = [Contact(dim=1, friction=FrictionLaw("coulomb", 0.3, 0.1), tangent=unit(fe.tangent_dof[c]),
                        drive=[fe.drive], normal=NormalLaw("compliant", 1e8), gap=fe.gap[c],
                        gap_gradient=unit(fe.normal_dof[c]), name=f"c{fe.node_ids[c]}")
                for c in range(len(fe.tangent_dof))]
    values = dict(name="pad", dofs=tuple(f"u{i}" for i in range(n)), mass=fe.mass, damping=fe.damping_matrix,
                  stiffness=fe.stiffness, force=None, contacts=contacts)
    values.update(changes)
    return FrictionModel(**values)


def test_a_large_model_stays_sparse_and_its_form_is_its_own():
    model = pad_model()
    assert model.n == 88 > DENSE_DOFS and not model.dense
    assert all(isinstance(getattr(model, k), sp.csr_matrix) for k in ("mass", "damping", "stiffness"))
    assert all(isinstance(c.tangent, sp.csr_matrix) and c.tangent.shape == (1, 88) for c in model.contacts)
    assert all(c.gap_gradient.shape == (1, 88) for c in model.contacts)
    form = model.sparse_form()
    fe = pad_on_belt(10, 4)
    assert abs(form.mass - fe.mass).max() == 0.0 and abs(form.stiffness - fe.stiffness).max() == 0.0
    assert form.tangent.shape == (11, 88) and form.tangent.nnz == 11
    assert np.array_equal(form.tangent.indices, fe.tangent_dof) and np.array_equal(form.row_start, np.arange(12))
    assert np.array_equal(form.gap_gradient.indices, fe.normal_dof)
    N0, n_q, _ = form.closed_normal()
    assert np.allclose(N0, 1e8 * 1e-6) and np.allclose(n_q.toarray(), -1e8 * form.gap_gradient.toarray())


def test_the_compiled_tools_take_a_large_model_packed_dense():
    """Above 64 dofs the kernels' data is the sparse model packed dense (its heap flavour:
    tests/fe/test_fe_transient.py), and the natural frequencies are those of scipy's sparse solver."""
    model = pad_model()
    fe = pad_on_belt(10, 4)
    n = model.n
    np.testing.assert_array_equal(model.data.m[8 + n * n:8 + 2 * n * n].reshape(n, n), fe.mass.toarray())
    lowest = np.sort(sla.eigsh(fe.stiffness.tocsc(), k=3, M=fe.mass.tocsc(), sigma=0.0, return_eigenvectors=False))
    np.testing.assert_allclose(model.natural_frequencies()[:3], np.sqrt(lowest) / (2 * np.pi), rtol=1e-9)


def test_the_compiled_form_of_a_model_too_large_for_memory_is_refused_up_front(monkeypatch):
    import stickslip.memory as memory
    monkeypatch.setattr(memory, "available_memory", lambda: 1e5)
    model = pad_model()
    with pytest.raises(MemoryLimitError) as info:
        model.data
    assert "dofs fit" in str(info.value) and "stickslip reduce" in str(info.value) and "\n" not in str(info.value)


def test_a_small_model_given_sparse_is_the_dense_model():
    dense = load_model("popp-stelter")
    sparse = FrictionModel(name=dense.name, dofs=dense.dofs, mass=sp.csr_matrix(dense.mass),
                           damping=sp.coo_matrix(dense.damping), stiffness=sp.csc_matrix(dense.stiffness),
                           force=dense.force, contacts=tuple(
                               Contact(dim=c.dim, friction=c.friction, normal_force=c.normal_force,
                                       tangent=sp.csr_matrix(c.tangent), drive=c.drive, name=c.name)
                               for c in dense.contacts))
    assert sparse.dense and isinstance(sparse.mass, np.ndarray)
    assert sparse.data.m.tobytes() == dense.data.m.tobytes()


# ----------------------------------------------------------------------------- the mass checks
def _spd(n, seed, condition=1e3):
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    lam = np.geomspace(1.0, condition, n)
    return (Q * lam) @ Q.T


@pytest.mark.parametrize("seed", range(4))
def test_the_sparse_mass_checks_agree_with_the_dense_ones(seed):
    n = 80
    free = np.ones(n, dtype=bool)
    good = _spd(n, seed)
    good = 0.5 * (good + good.T)
    check_mass(sp.csr_matrix(good), free, "m")  # accepted, as dense
    check_mass(good, free, "m")
    shift = np.linalg.eigvalsh(good)[2] * 1.01  # two eigenvalues pushed below zero: indefinite
    bad = good - shift * np.eye(n)
    for matrix in (bad, sp.csr_matrix(bad)):
        with pytest.raises(ModelError, match="not positive definite"):
            check_mass(matrix, free, "m")
    ill = _spd(n, seed, condition=1e15)
    ill = 0.5 * (ill + ill.T)
    for matrix in (ill, sp.csr_matrix(ill)):
        with pytest.raises(ModelError, match=f"within a factor {MAX_MASS_CONDITION:.0e}|not positive definite"):
            check_mass(matrix, free, "m")
    skew = good.copy()
    skew[0, 1] += 1e-6 * abs(skew[0, 1]) + 1e-9
    with pytest.raises(ModelError, match="symmetric"):
        check_mass(sp.csr_matrix(skew), free, "m")


def test_a_sparse_mass_with_a_zero_or_negative_diagonal_is_refused():
    n = 70
    free = np.ones(n, dtype=bool)
    diagonal = np.ones(n)
    diagonal[5] = 0.0
    with pytest.raises(ModelError, match="not positive definite"):
        check_mass(sp.diags(diagonal).tocsr(), free, "m")
    tridiagonal = sp.diags([np.full(n - 1, 0.5), np.ones(n), np.full(n - 1, 0.5)], [-1, 0, 1]).tolil()
    tridiagonal[10, 10] = 0.0
    with pytest.raises(ModelError, match="not positive definite"):
        check_mass(tridiagonal.tocsr(), free, "m")
    assert np.linalg.eigvalsh(tridiagonal.toarray()).min() < 0.0  # the dense truth


def test_the_mass_is_checked_on_the_free_dofs_only():
    model = pad_model()
    assert model.free.all()
    M = model.mass.tolil()
    M[0, :] = 0.0
    M[:, 0] = 0.0
    free = np.ones(model.n, dtype=bool)
    free[0] = False
    check_mass(M.tocsr(), free, "m")
    with pytest.raises(ModelError, match="not positive definite"):
        check_mass(M.tocsr(), np.ones(model.n, dtype=bool), "m")


def test_node_maps_give_displacements():
    nodes = NodeMap(ids=[10, 20], coordinates=[[0, 0, 0], [1, 0, 0]], node=[0, 0, 1, -1], component=[0, 1, 1, -1])
    assert np.array_equal(nodes.displacement(np.array([1.0, 2.0, 3.0, 4.0])), [[1, 2, 0], [0, 3, 0]])
    with pytest.raises(ModelError, match="unique"):
        NodeMap(ids=[1, 1], coordinates=np.zeros((2, 3)), node=[0], component=[0])
