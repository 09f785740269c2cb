"""Kernels against the paper's component equations, written independently here."""

import math

import numpy as np
import pytest

from stickslip import Parameters
from stickslip.model import assemble, kernels, resolve_variant

RNG = np.random.default_rng(1)


def paper_relative_velocity(s, P):
    """Eq. (9), transcribed."""
    x1, y1, x2, y2, phi, psi, dx1, dy1, dx2, dy2, dphi, dpsi = s
    w = P.Omega + dpsi
    vx = dx1 - dx2 - P.r * dphi * math.sin(phi) + w * (y1 - y2 + P.r * math.sin(phi))
    vy = dy1 - dy2 + P.r * dphi * math.cos(phi) - w * (x1 - x2 + P.r * math.cos(phi))
    return vx, vy


def paper_forcing(s, F, P):
    """Right-hand sides of Eq. (1) with Eqs. (2), (7), (8)."""
    x1, y1, x2, y2, phi = s[:5]
    X = x1 - x2 + P.r * math.cos(phi)
    Y = y1 - y2 + P.r * math.sin(phi)
    R = math.hypot(X, Y)
    en1 = np.array([-math.sin(phi), math.cos(phi)])
    en2 = np.array([-Y / R, X / R])
    return np.array([F[0], F[1], -F[0], -F[1], P.r * F @ en1, -R * F @ en2])


def random_state(scale=0.05):
    return RNG.normal(size=12) * scale


@pytest.mark.parametrize("trial", range(5))
def test_relative_velocity_is_eq_9(trial):
    P = Parameters()
    sys_ = assemble(P)
    s = random_state()
    assert np.allclose(kernels.relative_velocity(s, sys_.p), paper_relative_velocity(s, P), rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("trial", range(5))
def test_generalised_friction_is_eq_1(trial):
    P = Parameters()
    sys_ = assemble(P)
    s = random_state()
    F = RNG.normal(size=2) * 10
    ds = np.zeros(12)
    kernels.dynamics(s, F[0], F[1], sys_.minv, np.zeros(6), np.zeros(6), sys_.p, ds)
    mass = np.array([P.m_p, P.m_p, P.m_d, P.m_d, P.J_p, P.J_d])
    assert np.allclose(ds[6:] * mass, paper_forcing(s, F, P), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("model", ["full", "x", "y", "rotation", "phi"])
def test_stick_force_keeps_relative_velocity_zero(model):
    """Along the stick flow, dv_r/dt = 0: checked by a central difference of Eq. (9)."""
    P = Parameters()
    sys_ = assemble(P, model)
    s = random_state() * np.concatenate([sys_.variant.mask] * 2)
    kernels.project_velocity(s, sys_.minv, sys_.p)
    assert np.hypot(*kernels.relative_velocity(s, sys_.p)) < 1e-14
    Fx, Fy, rank = kernels.stick_force(s, sys_.minv, sys_.damp, sys_.stiff, sys_.p)
    assert rank == (1 if model in ("rotation", "phi") else 2)
    ds = np.zeros(12)
    kernels.dynamics(s, Fx, Fy, sys_.minv, sys_.damp, sys_.stiff, sys_.p, ds)
    h = 1e-6
    vp = np.array(kernels.relative_velocity(s + h * ds, sys_.p))
    vm = np.array(kernels.relative_velocity(s - h * ds, sys_.p))
    dv = (vp - vm) / (2 * h)
    scale = np.abs(ds).max()
    assert np.abs(dv).max() < 1e-7 * scale


def test_rank_one_solution_is_minimal_norm():
    # A = u uᵀ with u = (3, 4)/5: the solution of A x = b for b in range(A) lies along u
    u = np.array([0.6, 0.8])
    A = np.outer(u, u) * 2.0
    b = A @ np.array([1.0, -2.0])
    x1, x2, rank = kernels.solve_psd_2x2(A[0, 0], A[0, 1], A[1, 1], b[0], b[1])
    assert rank == 1
    assert np.allclose(A @ [x1, x2], b)
    assert abs(x1 * u[1] - x2 * u[0]) < 1e-15
    assert np.allclose([x1, x2], np.linalg.pinv(A) @ b)


@pytest.mark.parametrize("ratio", [1.0, 1e-3, 1e-9, 1.01e-10, 0.99e-10, 1e-14])
def test_rank_decision_follows_eigenvalue_ratio(ratio):
    # eigenvalues (1, ratio) in a rotated frame: full rank exactly when λ2 > RANK_TOL λ1, whether
    # the cheap determinant test or the eigenvalue path decides it; full rank is the inverse
    c, s_ = math.cos(0.3), math.sin(0.3)
    R = np.array([[c, -s_], [s_, c]])
    A = R @ np.diag([1.0, ratio]) @ R.T
    b = A @ np.array([0.7, -0.2])
    x1, x2, rank = kernels.solve_psd_2x2(A[0, 0], A[0, 1], A[1, 1], b[0], b[1])
    assert rank == (2 if ratio > kernels.RANK_TOL else 1)
    if ratio >= 1e-3:
        assert np.allclose([x1, x2], np.linalg.solve(A, b), rtol=1e-12)
    assert np.allclose(A @ [x1, x2], b, atol=1e-12)


def test_projection_is_minimal_kinetic_energy_change():
    P = Parameters()
    sys_ = assemble(P)
    s = random_state()
    s2 = s.copy()
    kernels.project_velocity(s2, sys_.minv, sys_.p)
    dq = s2[6:] - s[6:]
    # Δq̇ = −M⁻¹ Gᵀ λ: M Δq̇ lies in the row space of G
    X, Y = kernels.contact_position(s, sys_.p)
    G = np.array([[1, 0, -1, 0, -P.r * math.sin(s[4]), Y], [0, 1, 0, -1, P.r * math.cos(s[4]), -X]])
    lam, *_ = np.linalg.lstsq(G.T, dq / sys_.minv, rcond=None)
    assert np.allclose(G.T @ lam, dq / sys_.minv, atol=1e-12)


def test_variants():
    assert resolve_variant("rotation").free == ("phi", "psi")
    assert resolve_variant("phi,psi").name == "rotation"
    assert resolve_variant(["phi"]).name == "custom:phi"
    with pytest.raises(ValueError, match="unknown model"):
        resolve_variant("z")


@pytest.mark.parametrize("angle", [0.0, 1e-9, -3e-4, 2.0**-9, -0.0019532, 0.05, -0.1, 0.1000001, -0.7, 2.5, -40.0])
def test_rotated_is_the_angle_sum(angle):
    """(cos, sin) turned by an angle, Taylor series or library: the angle-sum formulas to round-off."""
    for theta in (0.0, 0.3, -2.0, 3.1):
        c, s_ = kernels.rotated(math.cos(theta), math.sin(theta), angle)
        assert abs(c - math.cos(theta + angle)) < 5e-16 * (1 + abs(theta + angle))
        assert abs(s_ - math.sin(theta + angle)) < 5e-16 * (1 + abs(theta + angle))


def _direction_function(s, sys_, theta):
    """g(θ) = e × A (μ N e + F_s) with e = (cos θ, sin θ), A = G M⁻¹ Gᵀ (docstring of
    kernels.quasi_static_direction), from the matrices written out here."""
    P_r = sys_.p[kernels.P_R]
    X, Y = kernels.contact_position(s, sys_.p)
    G = np.array([[1, 0, -1, 0, -P_r * math.sin(s[4]), Y], [0, 1, 0, -1, P_r * math.cos(s[4]), -X]])
    A = G @ np.diag(sys_.minv) @ G.T
    Fs = np.array(kernels.stick_force(s, sys_.minv, sys_.damp, sys_.stiff, sys_.p)[:2])
    speed = math.hypot(*kernels.relative_velocity(s, sys_.p))
    muN = kernels.friction_coefficient(speed, sys_.p) * sys_.p[kernels.P_N]
    e = np.array([np.cos(theta), np.sin(theta)])
    w = A @ (muN * e + Fs[:, None])
    return e[0] * w[1] - e[1] * w[0]


@pytest.mark.parametrize("trial", range(4))
def test_quasi_static_direction_is_the_nearest_stable_root(trial):
    """Against a scan of g(θ): the stable root (g rising through 0) nearest the start direction."""
    sys_ = assemble(Parameters())
    s = random_state()
    kernels.project_velocity(s, sys_.minv, sys_.p)
    s[6] += 1e-5  # a small slip velocity, inside the low-speed band
    grid = np.linspace(-math.pi, math.pi, 20001)
    g = _direction_function(s, sys_, grid)
    rising = np.flatnonzero((g[:-1] < 0) & (g[1:] >= 0))
    roots = grid[rising] - g[rising] * (grid[1] - grid[0]) / (g[rising + 1] - g[rising])
    start = roots[trial % roots.size] + 0.05  # near one of them
    ex, ey = kernels.quasi_static_direction(s, math.cos(start), math.sin(start), sys_.minv, sys_.damp,
                                            sys_.stiff, sys_.p)
    assert abs(math.hypot(ex, ey) - 1.0) < 1e-14
    nearest = roots[np.argmin(np.abs(np.angle(np.exp(1j * (roots - start)))))]
    assert abs(np.angle(np.exp(1j * (math.atan2(ey, ex) - nearest)))) < 1e-6
    assert abs(_direction_function(s, sys_, np.array([math.atan2(ey, ex)]))[0]) < 1e-9 * np.abs(g).max()
