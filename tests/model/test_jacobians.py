"""The derived Jacobian ∂f/∂s (complex step) against central differences of the right-hand side,
for every library model and the worked example of nonlinear kinematics, in slip and with each
contact in stick."""

import numpy as np
import pytest

from stickslip.model.bundle import CST, contact_state
from stickslip.model.derivatives import state_jacobian, state_jacobian_from_python
from stickslip.model.library import library, load_model
from stickslip.model.physics import MODE_SLIP_EXACT, MODE_STICK, project_velocities, rhs, slip_velocity
from stickslip.studies.models import belt_arm

#: The library's models and the worked example (G(θ) = H / cos²θ: a velocity bias in stick).
MODELS = {**{name: (lambda name=name: load_model(name)) for name in library()}, "belt-arm": belt_arm}

#: Relative step of the central differences: truncation ~ h² ≈ 1e-12, round-off ~ 1e-16 / h ≈ 1e-10.
FD_STEP = 1e-6


def central_differences(s, cst, md):
    """(2n × 2n) central differences of physics.rhs in the modes of ``cst``."""
    n2 = s.size
    J = np.empty((n2, n2))
    up, down = np.empty(n2), np.empty(n2)
    for j in range(n2):
        h = FD_STEP * max(1.0, abs(s[j]))
        sp, sm = s.copy(), s.copy()
        sp[j] += h
        sm[j] -= h
        rhs(sp, cst, md, up)
        rhs(sm, cst, md, down)
        J[:, j] = (up - down) / (2.0 * h)
    return J


def derived(s, cst, md):
    n2 = s.size
    J = np.empty((n2, n2))
    state_jacobian(s, cst, md, J, np.zeros(n2, dtype=complex), np.zeros(n2, dtype=complex))
    return J


def state_in(model, modes, seed):
    """A state of ``model`` with small random q and q̇, projected onto v_c = 0 for the sticking
    contacts, and its contact states (``modes``: one per contact)."""
    rng = np.random.default_rng(seed)
    n = model.n
    s = np.zeros(2 * n)
    scale = np.where(model.free, 1.0, 0.0)
    s[:n] = 0.01 * rng.standard_normal(n) * scale
    s[n:] = 0.05 * rng.standard_normal(n) * scale
    cst = contact_state(model.data.m)
    cst[0::CST] = modes
    project_velocities(s, cst, np.int64(-1), model.data)
    return s, cst


def assert_jacobians_agree(model, modes, seed=0):
    s, cst = state_in(model, modes, seed)
    for c, mode in enumerate(modes):
        speed = np.hypot(*slip_velocity(s, c, model.data))
        if mode == MODE_STICK:
            assert speed < 1e-12
        else:
            assert speed > 100 * model.slip_band  # exact slip direction, far from the band
    J = derived(s, cst, model.data)
    np.testing.assert_array_equal(state_jacobian_from_python(s, cst, model.data), J)  # the same steps from Python
    J_fd = central_differences(s, cst, model.data)
    assert np.all(np.isfinite(J))
    np.testing.assert_allclose(J, J_fd, rtol=1e-6, atol=1e-7 * np.max(np.abs(J)))
    return J


@pytest.mark.parametrize("name", list(MODELS))
def test_slip_jacobian_equals_central_differences(name):
    model = MODELS[name]()
    for seed in range(3):
        J = assert_jacobians_agree(model, [MODE_SLIP_EXACT] * model.n_contacts, seed)
    np.testing.assert_array_equal(J[:model.n, model.n:], np.eye(model.n))  # dq/dt = q̇, exactly


@pytest.mark.parametrize("name", list(MODELS))
def test_stick_jacobian_equals_central_differences(name):
    model = MODELS[name]()
    can_stick = [not contact.frictionless for contact in model.contacts]  # a contact without friction never sticks
    for c in np.flatnonzero(can_stick):
        modes = [MODE_SLIP_EXACT] * model.n_contacts
        modes[c] = MODE_STICK
        assert_jacobians_agree(model, modes, seed=int(c))
    assert_jacobians_agree(model, [MODE_STICK if stick else MODE_SLIP_EXACT for stick in can_stick], seed=7)
