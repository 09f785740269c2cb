"""The plates' linearisation through the generic derivation (complex step of the model's one
right-hand side) against the paper's own kernels, finite differences and the Appendix matrices."""

import numpy as np
import pytest

from stickslip import Parameters
from stickslip.model import MODELS, assemble, kernels
from stickslip.model.bundle import CST
from stickslip.model.derivatives import state_jacobian
from stickslip.model.physics import MODE_SLIP_EXACT, rhs
from stickslip.stability import equilibrium, linearization
from stickslip.stability.equilibrium import plates_model

from appendix import appendix_matrices

RNG = np.random.default_rng(7)


def slip_state(system, scale=0.05):
    """A random state with |v_r| well above the low-speed band (so the kernel uses v_r/|v_r|)."""
    while True:
        s = RNG.normal(size=12) * scale
        s[:6] *= system.minv > 0
        s[6:] *= system.minv > 0
        vx, vy = kernels.relative_velocity(s, system.p)
        if np.hypot(vx, vy) > 1e-3:
            return s


def _slip_modes():
    cst = np.zeros(CST)
    cst[0], cst[3] = MODE_SLIP_EXACT, np.inf
    return cst


def generic_rhs(s, system):
    """The model's right-hand side (the seam's physics) in exact slip."""
    ds = np.zeros(12)
    rhs(s, _slip_modes(), plates_model(system).data, ds)
    return ds


def generic_jacobian(s, system):
    J = np.empty((12, 12))
    state_jacobian(s, _slip_modes(), plates_model(system).data, J, np.zeros(12, complex), np.zeros(12, complex))
    return J


def kernel_rhs(s, system):
    ds = np.zeros(12)
    kernels.rhs(s, kernels.MODE_SLIP, 1.0, 0.0, system.minv, system.damp, system.stiff, system.p, ds)
    return ds


@pytest.mark.parametrize("model", list(MODELS))
@pytest.mark.parametrize("law", ["exponential", "coulomb"])
def test_generic_rhs_equals_the_plates_kernel(model, law):
    system = assemble(Parameters(friction_law=law, N=70.0, Omega=3.0), model)
    for _ in range(20):
        s = slip_state(system)
        ds = generic_rhs(s, system)
        ref = kernel_rhs(s, system)
        # the same floating-point operations as the kernel: only round-off (a few ulps) may differ
        assert np.max(np.abs(ds - ref)) <= 1e-14 * np.max(np.abs(ref))


def central_difference_jacobian(s, system, h=1e-6):
    """Central differences of the simulator's kernel; h = 1e-6 balances truncation (h² ≈ 1e-12)
    against round-off (eps/h ≈ 2e-10) for states of size 0.01–1."""
    J = np.zeros((12, 12))
    for j in range(12):
        e = np.zeros(12)
        e[j] = h
        J[:, j] = (kernel_rhs(s + e, system) - kernel_rhs(s - e, system)) / (2 * h)
    return J


@pytest.mark.parametrize("model", list(MODELS))
def test_jacobian_matches_central_differences(model):
    system = assemble(Parameters(N=60.0, Omega=2.5), model)
    q = equilibrium(system.params, model)
    states = [np.concatenate([q, np.zeros(6)])] + [slip_state(system) for _ in range(5)]
    for s in states:
        J = generic_jacobian(s, system)
        J_fd = central_difference_jacobian(s, system)
        # brief: agreement to 1e-6 relative (FD error is ~1e-9 here, see central_difference_jacobian)
        assert np.max(np.abs(J - J_fd)) <= 1e-6 * np.max(np.abs(J))
        # and column by column, so that small columns (psi, phi coupling) are checked too
        for j in range(12):
            col = np.max(np.abs(J[:, j]))
            if col > 0:
                assert np.max(np.abs(J[:, j] - J_fd[:, j])) <= 1e-6 * col, (model, j)


def test_reduced_jacobian_is_the_free_block_of_the_full_one():
    system = assemble(Parameters(), "x")
    q = equilibrium(system.params, "x")
    free = system.variant.free_indices
    idx = np.concatenate([free, 6 + free])
    full = generic_jacobian(np.concatenate([q, np.zeros(6)]), system)
    J, K_L, C_L = linearization(system, q)
    np.testing.assert_array_equal(J, full[np.ix_(idx, idx)])
    M = system.mass[free]
    # J = [[0, I], [-M⁻¹ K_L, -M⁻¹ C_L]] (Eq. 15); the same numbers, so exact up to one division
    np.testing.assert_allclose(J[free.size:, :free.size], -K_L / M[:, None], rtol=1e-15, atol=0)
    np.testing.assert_allclose(J[free.size:, free.size:], -C_L / M[:, None], rtol=1e-15, atol=0)


# entries of the printed Appendix that disagree with the linearisation (docs/stability.md);
# (row, column) in q order x1, y1, x2, y2, phi, psi
WRONG_C = {(5, 0), (5, 1), (5, 2), (5, 3), (0, 5), (1, 5), (2, 5), (3, 5), (4, 4)}
WRONG_K = {(4, 4)}


# Omega > 0 only: the Appendix writes |v_r| as v_re = Omega R, valid for Omega > 0
@pytest.mark.parametrize("N, Omega", [(80.0, 3.0), (30.0, 7.0), (150.0, 1.5), (50.0, 12.0)])
def test_appendix_matrices(N, Omega):
    P = Parameters(N=N, Omega=Omega)
    system = assemble(P, "full")
    q = equilibrium(P)
    _, K_L, C_L = linearization(system, q)
    C_p, K_p = appendix_matrices(q, P)
    C_c, K_c = appendix_matrices(q, P, corrected=True)
    # the Appendix's closed forms and complex-step derivatives agree to round-off of O(1e3) entries
    tol = 1e-10
    np.testing.assert_allclose(C_c, C_L, rtol=tol, atol=tol * np.max(np.abs(C_L)))
    np.testing.assert_allclose(K_c, K_L, rtol=tol, atol=tol * np.max(np.abs(K_L)))
    for (A, B, wrong) in ((C_p, C_L, WRONG_C), (K_p, K_L, WRONG_K)):
        for i in range(6):
            for j in range(6):
                close = abs(A[i, j] - B[i, j]) <= tol * max(abs(B[i, j]), 1e-3 * np.max(np.abs(B)))
                assert close != ((i, j) in wrong), (i, j, A[i, j], B[i, j])
    # C_L symmetric and K_L not, as stated under Eq. (A.2)
    np.testing.assert_allclose(C_L, C_L.T, rtol=0, atol=1e-12 * np.max(np.abs(C_L)))
    assert np.max(np.abs(K_L - K_L.T)) > 1e-3 * np.max(np.abs(K_L))
