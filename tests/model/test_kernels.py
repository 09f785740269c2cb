"""The generic physics compiled for the two plates against the paper's component equations,
written independently here."""

import math

import numpy as np
import pytest

from stickslip import Parameters
from stickslip.model import physics as P
from stickslip.model import resolve_variant
from stickslip.model.bundle import contact_state
from stickslip.model.forces import rotated
from stickslip.model.library import two_plates

RNG = np.random.default_rng(1)
C0 = np.int64(0)  # contact 0, as an int64 so that no literal-typed version is compiled
NONE = np.int64(-1)
PASSIVE = ("c_px", "k_px", "c_py", "k_py", "c_dx", "k_dx", "c_dy", "k_dy", "c_pphi", "k_pphi", "c_dpsi", "k_dpsi")


def paper_relative_velocity(s, Pr):
    """Eq. (9), transcribed."""
    x1, y1, x2, y2, phi, psi, dx1, dy1, dx2, dy2, dphi, dpsi = s[:12]
    w = Pr.Omega + dpsi
    vx = dx1 - dx2 - Pr.r * dphi * math.sin(phi) + w * (y1 - y2 + Pr.r * math.sin(phi))
    vy = dy1 - dy2 + Pr.r * dphi * math.cos(phi) - w * (x1 - x2 + Pr.r * math.cos(phi))
    return vx, vy


def paper_contact_position(s, Pr):
    """(X, Y): the contact point relative to O2, Eq. (2) components."""
    x1, y1, x2, y2, phi = s[:5]
    return x1 - x2 + Pr.r * math.cos(phi), y1 - y2 + Pr.r * math.sin(phi)


def paper_jacobian(s, Pr):
    """G = ∂v_r/∂q̇ of Eq. (9) (2 × 6)."""
    X, Y = paper_contact_position(s, Pr)
    return np.array([[1, 0, -1, 0, -Pr.r * math.sin(s[4]), Y], [0, 1, 0, -1, Pr.r * math.cos(s[4]), -X]])


def paper_mu(speed, Pr):
    """Eq. (4), or μk for the Coulomb law."""
    if Pr.friction_law == "coulomb":
        return Pr.mu_k
    return Pr.mu_k + Pr.delta_mu * math.exp(-Pr.alpha * speed)


def paper_forcing(s, F, Pr):
    """Right-hand sides of Eq. (1) with Eqs. (2), (7), (8)."""
    X, Y = paper_contact_position(s, Pr)
    phi = s[4]
    R = math.hypot(X, Y)
    en1 = np.array([-math.sin(phi), math.cos(phi)])
    en2 = np.array([-Y / R, X / R])
    return np.array([F[0], F[1], -F[0], -F[1], Pr.r * F @ en1, -R * F @ en2])


def inverse_masses(Pr, variant):
    mass = np.array([Pr.m_p, Pr.m_p, Pr.m_d, Pr.m_d, Pr.J_p, Pr.J_d])
    return np.where(resolve_variant(variant).mask > 0, 1.0 / mass, 0.0)


def random_state(scale=0.05):
    """12 states and the two work accumulators (zero)."""
    s = np.zeros(14)
    s[:12] = RNG.normal(size=12) * scale
    return s


def contact_mode(md, mode):
    cst = contact_state(md.m)
    cst[0] = mode
    return cst


@pytest.mark.parametrize("trial", range(5))
def test_relative_velocity_is_eq_9(trial):
    Pr = Parameters()
    md = two_plates(Pr).data
    s = random_state()
    assert np.allclose(P.slip_velocity(s, C0, md), paper_relative_velocity(s, Pr), rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("trial", range(5))
def test_generalised_friction_is_eq_1(trial):
    """Without damping and stiffness M q̈ is the friction's generalised force alone; in exact slip the
    force is Eq. (3) with Eq. (4) and e = v_r/|v_r|."""
    Pr = Parameters().replace(**dict.fromkeys(PASSIVE, 0.0))
    md = two_plates(Pr).data
    s = random_state()
    v = np.array(paper_relative_velocity(s, Pr))
    speed = np.hypot(*v)
    F = -paper_mu(speed, Pr) * Pr.N * v / speed
    ds = np.zeros(14)
    P.rhs(s, contact_mode(md, P.MODE_SLIP_EXACT), md, ds)
    mass = np.array([Pr.m_p, Pr.m_p, Pr.m_d, Pr.m_d, Pr.J_p, Pr.J_d])
    assert np.allclose(ds[6:12] * mass, paper_forcing(s, F, Pr), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("model", ["full", "x", "y", "rotation", "phi"])
def test_stick_force_keeps_relative_velocity_zero(model):
    """Along the stick flow, dv_r/dt = 0: checked by a central difference of Eq. (9)."""
    Pr = Parameters()
    md = two_plates(Pr, model).data
    minv = inverse_masses(Pr, model)
    cst = contact_mode(md, P.MODE_STICK)
    s = random_state() * np.concatenate([minv > 0, minv > 0, [1, 1]])
    P.project_velocities(s, cst, C0, md)
    assert np.hypot(*paper_relative_velocity(s, Pr)) < 1e-14
    # G M⁻¹ Gᵀ of Eq. (9): rank 1 when only the rotations are free (Model 4)
    G = paper_jacobian(s, Pr)
    A = G @ np.diag(minv) @ G.T
    rank = P.solve_psd_2x2(A[0, 0], A[0, 1], A[1, 1], 1.0, 0.0)[2]
    assert rank == (1 if model in ("rotation", "phi") else 2)
    ds = np.zeros(14)
    P.rhs(s, cst, md, ds)
    ds[12:] = 0.0  # move along the states only
    h = 1e-6
    vp = np.array(paper_relative_velocity(s + h * ds, Pr))
    vm = np.array(paper_relative_velocity(s - h * ds, Pr))
    dv = (vp - vm) / (2 * h)
    scale = np.abs(ds).max()
    assert np.abs(dv).max() < 1e-7 * scale


def test_rank_one_solution_is_minimal_norm():
    # A = u uᵀ with u = (3, 4)/5: the solution of A x = b for b in range(A) lies along u
    u = np.array([0.6, 0.8])
    A = np.outer(u, u) * 2.0
    b = A @ np.array([1.0, -2.0])
    x1, x2, rank = P.solve_psd_2x2(A[0, 0], A[0, 1], A[1, 1], b[0], b[1])
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
    x1, x2, rank = P.solve_psd_2x2(A[0, 0], A[0, 1], A[1, 1], b[0], b[1])
    assert rank == (2 if ratio > P.RANK_TOL else 1)
    if ratio >= 1e-3:
        assert np.allclose([x1, x2], np.linalg.solve(A, b), rtol=1e-12)
    assert np.allclose(A @ [x1, x2], b, atol=1e-12)


def test_projection_is_minimal_kinetic_energy_change():
    Pr = Parameters()
    md = two_plates(Pr).data
    minv = inverse_masses(Pr, "full")
    s = random_state()
    s2 = s.copy()
    P.project_velocities(s2, contact_mode(md, P.MODE_STICK), C0, md)
    dq = s2[6:12] - s[6:12]
    # Δq̇ = −M⁻¹ Gᵀ λ: M Δq̇ lies in the row space of G
    G = paper_jacobian(s, Pr)
    lam, *_ = np.linalg.lstsq(G.T, dq / minv, rcond=None)
    assert np.allclose(G.T @ lam, dq / minv, atol=1e-12)


def test_variants():
    assert resolve_variant("rotation").free == ("phi", "psi")
    assert resolve_variant("phi,psi").name == "rotation"
    assert resolve_variant(["phi"]).name == "custom:phi"
    with pytest.raises(ValueError, match="unknown model"):
        resolve_variant("z")


@pytest.mark.parametrize("angle", [0.0, 1e-9, -3e-4, 2.0**-9, -0.0019532, 0.05, -0.1, 0.1000001, -0.7, 2.5, -40.0])
def test_rotated_is_the_angle_sum(angle):
    """(cos, sin) turned by an angle: the angle-sum formulas to round-off."""
    for theta in (0.0, 0.3, -2.0, 3.1):
        c, s_ = rotated(math.cos(theta), math.sin(theta), angle)
        assert abs(c - math.cos(theta + angle)) < 5e-16 * (1 + abs(theta + angle))
        assert abs(s_ - math.sin(theta + angle)) < 5e-16 * (1 + abs(theta + angle))


def _direction_function(s, Pr, md, theta):
    """g(θ) = e × A (μ N e + F_s) with e = (cos θ, sin θ), A = G M⁻¹ Gᵀ (docstring of
    forces.quasi_static_direction), from the matrices and the friction law written out here."""
    G = paper_jacobian(s, Pr)
    A = G @ np.diag(inverse_masses(Pr, "full")) @ G.T
    Fs, N = np.zeros(2), np.zeros(1)
    P.stick_forces(s, contact_mode(md, P.MODE_STICK), NONE, md, Fs, N)
    speed = math.hypot(*paper_relative_velocity(s, Pr))
    muN = paper_mu(speed, Pr) * Pr.N
    e = np.array([np.cos(theta), np.sin(theta)])
    w = A @ (muN * e + Fs[:, None])
    return e[0] * w[1] - e[1] * w[0]


@pytest.mark.parametrize("trial", range(4))
def test_quasi_static_direction_is_the_nearest_stable_root(trial):
    """Against a scan of g(θ): the stable root (g rising through 0) nearest the start direction."""
    Pr = Parameters()
    md = two_plates(Pr).data
    s = random_state()
    P.project_velocities(s, contact_mode(md, P.MODE_STICK), C0, md)
    s[6] += 1e-5  # a small slip velocity, inside the low-speed band
    grid = np.linspace(-math.pi, math.pi, 20001)
    g = _direction_function(s, Pr, md, grid)
    rising = np.flatnonzero((g[:-1] < 0) & (g[1:] >= 0))
    roots = grid[rising] - g[rising] * (grid[1] - grid[0]) / (g[rising + 1] - g[rising])
    start = roots[trial % roots.size] + 0.05  # near one of them
    cst = contact_mode(md, P.MODE_SLIP)
    cst[1], cst[2] = math.cos(start), math.sin(start)
    vx, vy = paper_relative_velocity(s, Pr)
    ex, ey = P.slip_direction(s, cst, C0, md, vx, vy)
    assert abs(math.hypot(ex, ey) - 1.0) < 1e-14
    nearest = roots[np.argmin(np.abs(np.angle(np.exp(1j * (roots - start)))))]
    assert abs(np.angle(np.exp(1j * (math.atan2(ey, ex) - nearest)))) < 1e-6
    assert abs(_direction_function(s, Pr, md, np.array([math.atan2(ey, ex)]))[0]) < 1e-9 * np.abs(g).max()
