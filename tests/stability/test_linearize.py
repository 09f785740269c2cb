"""The plates' linearisation through the generic derivation (complex step of the model's one
right-hand side) against the paper's equations written out here, finite differences and the
Appendix matrices."""

import numpy as np
import pytest
from appendix import appendix_matrices
from plates import plate_arrays

from stickslip import Parameters
from stickslip.model import MODELS, two_plates
from stickslip.model.bundle import CST
from stickslip.model.derivatives import state_jacobian
from stickslip.model.physics import MODE_SLIP, MODE_SLIP_EXACT, rhs, slip_velocity
from stickslip.stability import equilibrium, linearization

RNG = np.random.default_rng(7)


def slip_state(system, scale=0.05):
    """A random state with |v_r| well above the low-speed band (so slip takes the direction v_r/|v_r|)."""
    while True:
        s = RNG.normal(size=12) * scale
        s[:6] *= system.minv > 0
        s[6:] *= system.minv > 0
        vx, vy = paper_relative_velocity(s, system.params)
        if np.hypot(vx, vy) > 1e-3:
            return s


def paper_basis(q, P):
    """e_n1 (Eq. 7), e_n2 (Eq. 8) and R (Eq. 2) at the positions q."""
    X = q[0] - q[2] + P.r * np.cos(q[4])
    Y = q[1] - q[3] + P.r * np.sin(q[4])
    R = np.hypot(X, Y)
    return np.array([-np.sin(q[4]), np.cos(q[4])]), np.array([-Y / R, X / R]), R


def paper_relative_velocity(s, P):
    """v_r = v_c^p − v_c^d, the contact-point velocities of both plates, Eqs. (5)–(9)."""
    q, qd = s[:6], s[6:12]
    en1, en2, R = paper_basis(q, P)
    return tuple(qd[0:2] + qd[4] * P.r * en1 - qd[2:4] - (P.Omega + qd[5]) * R * en2)


def paper_rhs(s, system):
    """Eq. (1) in slip with Eqs. (2)–(4), (7)–(9): [q̇, M⁻¹ (−C q̇ − K q + Q(F))], F = −μ(|v_r|) N v_r/|v_r|."""
    P = system.params
    q, qd = s[:6], s[6:12]
    free = system.minv > 0
    v = np.array(paper_relative_velocity(s, P))
    speed = np.hypot(*v)
    mu = P.mu_k if P.friction_law == "coulomb" else P.mu_k + P.delta_mu * np.exp(-P.alpha * speed)
    F = -mu * P.N * v / speed
    en1, en2, R = paper_basis(q, P)
    Q = np.array([F[0], F[1], -F[0], -F[1], P.r * F @ en1, -R * F @ en2])
    mass = np.array([P.m_p, P.m_p, P.m_d, P.m_d, P.J_p, P.J_d])
    c = np.array([P.c_px, P.c_py, P.c_dx, P.c_dy, P.c_pphi, P.c_dpsi])
    k = np.array([P.k_px, P.k_py, P.k_dx, P.k_dy, P.k_pphi, P.k_dpsi])
    acc = np.where(free, (Q - c * qd - k * q) / mass, 0.0)
    return np.concatenate([np.where(free, qd, 0.0), acc])


def _slip_modes(mode=MODE_SLIP_EXACT):
    cst = np.zeros(CST)
    cst[0], cst[1], cst[3] = mode, 1.0, np.inf
    return cst


def generic_rhs(s, system):
    """The model's right-hand side (the seam's physics) in exact slip."""
    ds = np.zeros(12)
    rhs(s, _slip_modes(), system.model.data, ds)
    return ds


def generic_jacobian(s, system):
    J = np.empty((12, 12))
    state_jacobian(s, _slip_modes(), system.model.data, J, np.zeros(12, complex), np.zeros(12, complex))
    return J


def simulator_rhs(s, system):
    """The right-hand side in the simulator's slip mode (v_r/|v_r| above the low-speed band)."""
    ds = np.zeros(12)
    rhs(s, _slip_modes(MODE_SLIP), system.model.data, ds)
    return ds


@pytest.mark.parametrize("model", list(MODELS))
@pytest.mark.parametrize("law", ["exponential", "coulomb"])
def test_generic_rhs_equals_the_paper_equations(model, law):
    system = plate_arrays(Parameters(friction_law=law, N=70.0, Omega=3.0), model)
    md = system.model.data
    for _ in range(20):
        s = slip_state(system)
        ds = generic_rhs(s, system)
        ref = paper_rhs(s, system)
        # the same equations in another order of operations: only round-off (a few ulps) may differ
        assert np.max(np.abs(ds - ref)) <= 1e-14 * np.max(np.abs(ref))
        assert np.max(np.abs(simulator_rhs(s, system) - ref)) <= 1e-14 * np.max(np.abs(ref))
        assert np.allclose(slip_velocity(s, np.int64(0), md), paper_relative_velocity(s, system.params),
                           rtol=1e-13, atol=1e-15)


def central_difference_jacobian(s, system, h=1e-6):
    """Central differences of the simulator's right-hand side; h = 1e-6 balances truncation (h² ≈ 1e-12)
    against round-off (eps/h ≈ 2e-10) for states of size 0.01–1."""
    J = np.zeros((12, 12))
    for j in range(12):
        e = np.zeros(12)
        e[j] = h
        J[:, j] = (simulator_rhs(s + e, system) - simulator_rhs(s - e, system)) / (2 * h)
    return J


@pytest.mark.parametrize("model", list(MODELS))
def test_jacobian_matches_central_differences(model):
    system = plate_arrays(Parameters(N=60.0, Omega=2.5), model)
    q = equilibrium(two_plates(system.params, model))
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
    system = plate_arrays(Parameters(), "x")
    q = equilibrium(two_plates(system.params, "x"))
    free = system.variant.free_indices
    idx = np.concatenate([free, 6 + free])
    full = generic_jacobian(np.concatenate([q, np.zeros(6)]), system)
    J, K_L, C_L = linearization(system.model, q)
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
    system = plate_arrays(P, "full")
    q = equilibrium(P)
    _, K_L, C_L = linearization(system.model, q)
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
