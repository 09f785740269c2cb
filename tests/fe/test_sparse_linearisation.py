"""The sparse steady sliding and linearisation against the dense path: the equilibrium of the compiled
Newton solver and the complex-step Jacobian of the simulator's own right-hand side (an independent
derivation: nothing of the sparse formulas is used there), on every library model with constant
kinematics and on small finite-element models."""

import numpy as np
import pytest

from stickslip.errors import EquilibriumError, ModelError
from stickslip.model import FrictionModel
from stickslip.model.friction import FrictionLaw
from stickslip.model.library import load_model
from stickslip.model.library.laws import Stribeck
from stickslip.model.system_model import Contact, NormalLaw
from stickslip.stability.analysis import linearization
from stickslip.stability.equilibrium import solve_steady
from stickslip.stability.sparse_sliding import sparse_steady_sliding

from .brake_models import pad_on_belt_2d, pad_on_surface_3d


def _compare(system, rtol=1e-13):
    """The sparse q, K_t and C_t against the dense solver's q and −M ∂q̈/∂q, −M ∂q̈/∂q̇."""
    q_dense, _, _ = solve_steady(system)
    _, K_L, C_L = linearization(system, q_dense)
    state = sparse_steady_sliding(system)
    scale_q = max(np.max(np.abs(q_dense)), 1e-300)
    assert np.max(np.abs(state.q - q_dense)) <= 1e-13 * scale_q
    K = state.stiffness.toarray()
    C = state.damping.toarray()
    assert np.max(np.abs(K - K_L)) <= rtol * np.max(np.abs(K_L))
    assert np.max(np.abs(C - C_L)) <= rtol * max(np.max(np.abs(C_L)), np.max(np.abs(K_L)) * 1e-3)
    assert state.residual < 1e-12
    return state, K_L, C_L


@pytest.mark.parametrize("name, changes", [
    ("belt", {}),
    ("hoffmann", {}),
    ("hoffmann", {"contact.0.friction.mu_k": 1.3}),
    ("popp-stelter", {}),
    ("slider-belt", {}),
    ("slider-belt", {"contact.0.normal.damping": 0.3}),
    ("sprag-slip", {"contact.0.friction.mu_k": 0.5}),
])
def test_library_models(name, changes):
    system = load_model(name).replace(**changes)
    _, K_L, C_L = _compare(system)
    # the friction and contact terms are there: the linearisation differs from K and C alone
    assert np.max(np.abs(K_L - system.stiffness)) + np.max(np.abs(C_L - system.damping)) > 0


def _two_d_model():
    """Three DOFs, one 2-D contact with a prescribed load depending on q and q̇, a 1-D compliant
    contact with damping and a user (Stribeck) law, a locked DOF and a full mass matrix."""
    M = np.array([[2.0, 0.3, 0.0, 0.1], [0.3, 1.5, 0.2, 0.0], [0.0, 0.2, 1.0, 0.0], [0.1, 0.0, 0.0, 1.0]])
    K = np.array([[5.0, -1.0, 0.5, 0.0], [-1.0, 4.0, 0.3, 0.0], [0.2, 0.3, 6.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    C = 0.02 * K + 0.01 * M
    exp_law = FrictionLaw("exponential", mu_k=0.3, delta_mu=0.2, alpha=1.5, mu_v=0.05)
    contacts = (
        Contact(dim=2, friction=exp_law, normal_force=2.0, tangent=np.array([[1.0, 0.2, 0.0, 0.0], [0.0, 1.0, -0.3, 0.0]]),
                drive=np.array([0.7, -0.4]), normal_gradient=np.array([0.3, -0.2, 0.5, 0.0]),
                normal_rate_gradient=np.array([0.05, 0.0, -0.02, 0.0]), name="plane"),
        Contact(dim=1, friction=FrictionLaw.from_user(Stribeck(0.2, 0.5, 0.3, 0.02)), tangent=np.array([[0.0, 0.5, 1.0, 0.0]]),
                drive=np.array([0.9]), normal=NormalLaw("compliant", stiffness=3.0, damping=0.4), gap=-0.2,
                gap_gradient=np.array([0.1, -0.4, -1.0, 0.0]), name="spring"),
    )
    return FrictionModel(name="mixed", dofs=("a", "b", "c", "d"), mass=M, damping=C, stiffness=K,
                         force=np.array([0.1, -0.2, 0.3, 0.0]), contacts=contacts,
                         free=np.array([True, True, True, False]))


def test_two_dimensional_contacts_user_law_locked_dof():
    state, K_L, C_L = _compare(_two_d_model())
    assert state.q[3] == 0.0 and state.n == 3
    # the 2-D direction's turn μ N/|v| (I − e eᵀ) is in C_t: not symmetric in general, not C + friction slope alone
    assert np.max(np.abs(C_L - C_L.T)) > 1e-3


@pytest.mark.parametrize("build", [
    lambda: pad_on_belt_2d(nx=3, ny=2, dense=True, law=FrictionLaw("exponential", 0.3, 0.2, 2.0, 0.01)),
    lambda: pad_on_surface_3d((2, 1, 1), dense=True, cc=50.0),
], ids=["2-D pad on belt", "3-D pad on a plane"])
def test_small_fe_model(build):
    """Plane-stress and 3-D pads on a moving surface, their bottom nodes on compliant contacts."""
    model = build()
    assert model.n <= 64
    _compare(model)


def test_open_and_stuck_contacts_named():
    hoffmann = load_model("hoffmann")
    with pytest.raises(EquilibriumError, match="contact 0 .*would be open"):
        sparse_steady_sliding(hoffmann.replace(N0=-1.0))
    with pytest.raises(EquilibriumError, match="contact 0 .*would stick"):
        sparse_steady_sliding(load_model("belt").replace(**{"contact.0.drive": 0.0}))
    with pytest.raises(ModelError, match="rigid"):
        sparse_steady_sliding(load_model("impact-oscillator"))
