"""Monodromy from the variational equations with saltation matrices, on the plates.

Evidence: the band-phase Jacobian against central differences of the simulator's own vector field;
the linearised flow of a linear oscillator against its closed form; the monodromy of the belt
oscillator against a closed form derived from the stick collapse; Model 1 multipliers and the
linearised flow over transients against the finite-difference (perturbed-shooting) monodromy.
The same machinery on the model-file models: tests/orbits/test_generic_models.py.
"""

import math

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from stickslip import Parameters
from stickslip.model import physics as PH
from stickslip.model.library import two_plates
from stickslip.orbits import OrbitError, periodic_orbit
from stickslip.orbits.layout import free_states
from stickslip.orbits.linear_flow import flow_jacobian
from stickslip.orbits.problem import Monodromy, central_differences, monodromy
from stickslip.orbits.saltation import field, saltation_matrix, with_mode
from stickslip.orbits.section import flow
from stickslip.orbits import var_kernels as V


def matched_distance(a, b):
    """Largest |a_i − b_π(i)| over the best pairing π of two multiplier sets."""
    C = np.abs(a[:, None] - b[None, :])
    r, c = linear_sum_assignment(C)
    return float(C[r, c].max())


def fd_flow_jacobian(system, s0, T, h):
    """Central differences of the event integrator's flow map on the free states, steps h (2 n_free,)."""
    free = free_states(system)
    return central_differences(lambda s: flow(system, s, T, rtol=1e-10, atol=1e-13)[0], s0, free, h)


def kinds(events):
    return [k for _, k, _ in events]


@pytest.mark.parametrize("band", [True, False])
def test_band_jacobian_turns_with_the_quasi_static_direction(band):
    """Right after a breakaway (|v_r| = 3e-6 m/s, inside the low-speed band) the slip direction is
    the quasi-static one, a function of the state found by a Newton iteration on real numbers. The
    variational Jacobian (complex step + the direction's turn, band=True) against central
    differences of the simulator's own right-hand side with steps far below |v_r| (1e-3 of the
    orbit's ranges); the complex step alone (band=False) misses the turn and is refused here."""
    from stickslip import simulate

    o = periodic_orbit(Parameters(N=50.0, Omega=0.5), "equilibrium", search_time=30.0,
                       monodromy="finite-difference")
    system = o.system
    traj = simulate(system, 0.634, ic=o.state, rtol=1e-10, atol=1e-13, sample_rate=1 / 0.634)
    s = traj.final_state
    t_b = traj.transitions
    assert t_b.kind[-1] == -1 and 0.634 - t_b.time[-1] < 1e-3       # 0.5 ms after the breakaway
    Fs = np.empty(2)
    PH.stick_forces(t_b.state[-1], with_mode(np.zeros(4), 0, PH.MODE_STICK), -1, system.data, Fs, np.empty(1))
    e = -Fs / np.hypot(*Fs)
    cst = with_mode(np.zeros(4), 0, PH.MODE_SLIP_QUASI_STATIC, e)
    y = np.concatenate([s, np.eye(12).ravel()])         # Φ = I: the variational rhs is J itself
    dy = np.empty(y.size)
    V.variational_rhs(y, cst, system.data, 12, band, dy, np.empty(12), np.empty(12, complex), np.empty(12, complex),
                      np.empty(12))
    J = dy[12:].reshape(12, 12)
    h = np.zeros(12)
    h[free_states(system)] = 1e-8 * o.scale
    Jfd = np.zeros((12, 12))
    for j in range(12):
        sp, sm = s.copy(), s.copy()
        sp[j] += h[j]
        sm[j] -= h[j]
        Jfd[:, j] = (field(system, sp, cst) - field(system, sm, cst)) / (2 * h[j])
    error = np.max(np.abs(J - Jfd)) / np.max(np.abs(Jfd))
    if band:
        assert error < 1e-6       # measured 1e-7 (the differences' own truncation and round-off)
    else:
        assert error > 1e-4       # measured 1.6e-3: the direction's turn is not in the complex step


def test_saltation_matrix_maps_the_field_across_the_event():
    rng = np.random.default_rng(2)
    fm, fp, g = rng.normal(size=12), rng.normal(size=12), rng.normal(size=12)
    S = saltation_matrix(fm, fp, g)
    assert np.allclose(S @ fm, fp, rtol=1e-13, atol=1e-13)         # S f⁻ = f⁺
    v = rng.normal(size=12)
    v -= (g @ v) / (g @ g) * g                                        # tangent to the surface
    assert np.allclose(S @ v, v, rtol=1e-13, atol=1e-13)
    with pytest.raises(OrbitError, match="grazing"):
        saltation_matrix(np.zeros(12), fp, g)


def test_linear_oscillator_flow():
    """Belt model, Coulomb, no damping, pure slip: φ̈ = −ω² (φ − φk); the linearised flow is
    [[cos ωt, sin ωt / ω], [−ω sin ωt, cos ωt]]."""
    P = Parameters(c_pphi=0.0, Omega=5.0, friction_law="coulomb")
    omega = math.sqrt(P.k_pphi / P.J_p)
    s0 = np.zeros(12)
    s0[4] = P.mu_k * P.N * P.r / P.k_pphi + 0.01
    t = 0.3
    fj = flow_jacobian(two_plates(P, "phi"), s0, t)
    M = fj.matrix[np.ix_([4, 10], [4, 10])]
    c, s = math.cos(omega * t), math.sin(omega * t)
    exact = np.array([[c, s / omega], [-omega * s, c]])
    assert np.allclose(M, exact, rtol=0, atol=1e-8)   # variational rtol 1e-10 over 0.7 periods
    assert fj.events == ()


def belt_coulomb():
    P = Parameters(c_pphi=0.0, Omega=0.5, friction_law="coulomb")
    ic = np.zeros(12)
    ic[10] = P.Omega
    return P, periodic_orbit(two_plates(P, "phi"), ic, search_time=3.0)


def test_belt_coulomb_monodromy_closed_form():
    """Undamped belt oscillator with Coulomb friction, section φ̇ = 0 (φ maximum).

    After the stick phase the perturbed motion is the nominal one delayed by δ, so
    M = −f(s0) ∇δᵀ. Slip from (φ0, φ̇0): φ = φk + a cos ωt + (b/ω) sin ωt (a = φ0 − φk,
    b = φ̇0); stick starts where φ̇ = Ω and ends at the fixed breakaway angle, so
    δ = −(cos ωts δa + sin ωts δb / ω)/Ω. With f(s0) = (0, −ω² a), −aω sin ωts = Ω and
    (aω)² = (ωD)² + Ω² (D = Δμ N r / k), M = [[0, 0], [ω² D / Ω, 1]]: multipliers {1, 0}.
    """
    P, orbit = belt_coulomb()
    assert orbit.options["monodromy"] == "saltation"            # the default
    omega2 = P.k_pphi / P.J_p
    D = P.delta_mu * P.N * P.r / P.k_pphi
    exact = np.array([[0.0, 0.0], [omega2 * D / P.Omega, 1.0]])
    M = orbit.monodromy
    assert orbit.free_states == ("phi", "dphi")
    # the orbit itself is exact to ~1e-11 (test_shooting); 1e-8 leaves room for the
    # variational integration (rtol 1e-10)
    assert np.allclose(M, exact, rtol=0, atol=1e-8 * np.abs(exact).max())
    assert matched_distance(orbit.multipliers, np.array([1.0, 0.0])) < 1e-8


def test_belt_exponential_law_rank_one_collapse():
    """Belt with the exponential law and damping (Table 1): the stick phase still collapses
    the state, so M = f(s0) wᵀ with wᵀ f(s0) = 1 (the same argument as above, any friction
    law): the φ row is zero (f(s0) = (0, φ̈0) on the section) and the trace is 1."""
    P = Parameters(Omega=0.5)
    ic = np.zeros(12)
    ic[10] = P.Omega
    orbit = periodic_orbit(two_plates(P, "phi"), ic, search_time=10.0)
    m = monodromy(orbit)
    M = m.matrix
    scale = np.abs(M).max()
    assert np.abs(M[0]).max() < 1e-5 * scale      # measured 2e-7 relative
    assert abs(np.trace(M) - 1.0) < 1e-5          # measured 3e-7
    assert matched_distance(m.multipliers, np.array([1.0, 0.0])) < 1e-5
    assert kinds(m.events) == ["stick", "breakaway", "band"]


@pytest.fixture(scope="module")
def orbit50():
    """Model 1, N = 50 N, Ω = 0.5 rad/s (Fig. 10(b)), FD monodromy as the reference."""
    return periodic_orbit(Parameters(N=50.0, Omega=0.5), "equilibrium", search_time=30.0,
                          monodromy="finite-difference")


def test_model1_saltation_matches_finite_differences(orbit50):
    o = orbit50
    assert o.period == pytest.approx(0.6501543, abs=1e-7)
    assert o.options["monodromy"] == "finite-difference"
    m = monodromy(o, "saltation")
    assert isinstance(m, Monodromy) and m.matrix.shape == (12, 12)
    assert kinds(m.events) == ["stick", "breakaway", "band"]
    # measured: 2.8e-8 between the two sets; the FD matrix is good to ~1e-8 (trivial multiplier)
    assert matched_distance(m.multipliers, o.multipliers) < 1e-5
    assert abs(m.trivial_multiplier - 1.0) < 1e-5                 # measured 2.7e-8
    # v_r = 0 is two conditions: stick collapses two directions exactly
    assert np.sum(np.abs(m.multipliers) < 1e-10) == 2
    assert m.stable == o.stable
    ds = m.to_xarray()
    assert ds.attrs["method"] == "saltation" and ds["multiplier_abs"].size == 12


def test_model1_second_case_n40():
    """Model 1, N = 40 N, Ω = 0.5 rad/s: the default (saltation) orbit against FD."""
    o = periodic_orbit(Parameters(N=40.0, Omega=0.5), "equilibrium", search_time=30.0)
    assert o.options["monodromy"] == "saltation" and o.stick_phases == 1
    fd = monodromy(o, "finite-difference")
    assert matched_distance(o.multipliers, fd.multipliers) < 1e-5
    assert abs(o.trivial_multiplier - 1.0) < 1e-5


def test_bad_method(orbit50):
    with pytest.raises(OrbitError, match="unknown monodromy"):
        monodromy(orbit50, "nonsense")
    with pytest.raises(OrbitError, match="unknown monodromy"):
        periodic_orbit(Parameters(), np.zeros(12), monodromy="nonsense")


@pytest.mark.parametrize("model, N, duration", [("x", 50.0, 1.0), ("full", 120.0, 3.0)])
def test_flow_jacobian_of_a_transient_against_finite_differences(model, N, duration):
    """Not an orbit: the linearised flow over a stretch of a transient with several stick
    phases (Model 2: 3 stick + 3 breakaway, Model 1 at N = 120 N: 3 + 2) against central
    differences of the flow map (step 1e-5 σ)."""
    from stickslip import simulate

    P = Parameters(N=N, Omega=0.5)
    system = two_plates(P, model)
    free = free_states(system)
    tr = simulate(system, 30.0, ic="equilibrium", perturbation=1e-3, rtol=1e-10, atol=1e-13,
                  sample_rate=100)
    sigma = np.ptp(tr.states[tr.t >= 15.0], axis=0)[free]
    sigma = np.maximum(sigma, 1e-4 * sigma.max())
    fj = flow_jacobian(system, tr.final_state, duration, scale=sigma)
    assert kinds(fj.events).count("stick") == 3
    M = fj.matrix[np.ix_(free, free)]
    # Step 1e-5 σ: the adaptive flow map carries round-off-level noise (rtol 1e-10) that central
    # differences divide by the step. Measured for Model 1 against the variational matrix: step
    # 1e-7 σ 1.2e-4, 1e-6 σ 1.1e-5 to 1.5e-5 (it depends on the start state's last bits), 1e-5 σ
    # 1.1e-6, where the variational matrices of two code versions agree to 1e-8.
    Mfd = fd_flow_jacobian(system.with_slip_band(1e-4), tr.final_state, duration, 1e-5 * sigma)
    assert np.max(np.abs(M - Mfd)) < 1e-5 * np.max(np.abs(Mfd))


def test_newton_with_the_saltation_jacobian_converges_to_the_same_orbit(orbit50):
    """periodic_orbit's default Newton Jacobian (saltation) against the FD Newton: same period and
    section state. Both are solved to 1e-11 σ: at the default tol 1e-8 an iterate may stop at a
    residual of ~1e-9 σ (measured: the saltation Newton's last one, 1.1e-9), whose period is then
    only good to ~1e-9 relative."""
    kw = dict(search_time=30.0, monodromy="finite-difference", tol=1e-11)
    o = periodic_orbit(Parameters(N=50.0, Omega=0.5), "equilibrium", newton_jacobian="finite-difference",
                       **kw)
    s = periodic_orbit(Parameters(N=50.0, Omega=0.5), "equilibrium", **kw)
    assert s.options["newton_jacobian"] == "saltation"
    assert o.options["newton_jacobian"] == "finite-difference"
    assert o.period == pytest.approx(s.period, rel=1e-10)
    assert np.allclose(o.state, s.state, rtol=0, atol=1e-9 * np.abs(s.state).max())
    ds = flow_jacobian(o.system, o.state, o.period, scale=o.scale).to_xarray()
    assert ds["flow_jacobian"].shape == (12, 12) and ds.attrs["duration"] == o.period


@pytest.mark.parametrize("law", ["coulomb", "exponential"])
def test_velocity_reversals_against_finite_differences(law):
    """Belt oscillator started at φ = 0.3 rad (10× the stick limit μs N r / k): v_r passes
    through zero where the stick force is inadmissible (the integrator projects and slips on,
    recording no transition). The reversal jump (saltation with f⁺ the departing slip field,
    no projection) against central differences of the flow map over 1 s (4 reversals)."""
    P = Parameters(Omega=0.5, friction_law=law)
    s0 = np.zeros(12)
    s0[4] = 0.3
    sigma = np.array([0.6, 8.0])   # φ and φ̇ ranges of the motion [rad, rad/s]
    system = two_plates(P, "phi")
    fj = flow_jacobian(system, s0, 1.0, scale=sigma)
    assert kinds(fj.events).count("reversal") == 4
    M = fj.matrix[np.ix_([4, 10], [4, 10])]
    Mfd = fd_flow_jacobian(system, s0, 1.0, 1e-6 * sigma)
    # measured 5e-8 (Coulomb) and 7e-8 (exponential) relative; the same with FD step 1e-5 σ
    assert np.max(np.abs(M - Mfd)) < 1e-5 * np.max(np.abs(Mfd))
