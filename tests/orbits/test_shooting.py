"""Shooting on a Poincaré section: analytic orbits of the belt oscillator, and a 6-DOF orbit
that a long simulation also settles on."""

import math

import numpy as np
import pytest

from stickslip import Parameters, simulate
from stickslip.model.library import two_plates
from stickslip.orbits import OrbitError, PeriodicOrbit, periodic_orbit
from stickslip.orbits.section import section_crossings


def belt(Omega=0.5):
    """1-DOF belt oscillator (model ``phi``, Coulomb, no damping): closed-form period and φ max."""
    P = Parameters(c_pphi=0.0, Omega=Omega, friction_law="coulomb")
    omega = math.sqrt(P.k_pphi / P.J_p)
    D = P.delta_mu * P.N * P.r / P.k_pphi          # φs − φk
    beta = math.atan2(Omega / omega, D)
    period = 2 * D / Omega + (math.pi + 2 * beta) / omega
    phi_max = P.mu_k * P.N * P.r / P.k_pphi + math.hypot(D, Omega / omega)
    return P, period, phi_max


def test_belt_stick_slip_orbit_analytic():
    P, period, phi_max = belt()
    # start stuck to the belt at φ = 0 (from rest at φ = 0 the oscillation never reaches the belt)
    ic = np.zeros(12)
    ic[10] = P.Omega
    orbit = periodic_orbit(two_plates(P, "phi"), ic, search_time=3.0)
    assert isinstance(orbit, PeriodicOrbit)
    # the flow map is integrated at rtol 1e-10; 1e-9 relative leaves room for the event location
    assert orbit.period == pytest.approx(period, rel=1e-9)
    assert orbit.state[4] == pytest.approx(phi_max, rel=1e-9)
    assert orbit.state[10] == 0.0                      # on the section φ̇ = 0 exactly
    assert orbit.stick_phases == 1
    assert orbit.residual <= orbit.options["tol"]
    # stick collapses φ̇: multipliers {1, 0}; FD accuracy measured ~2e-10 (1e-6 is the claim)
    assert abs(orbit.trivial_multiplier - 1.0) < 1e-6
    assert np.abs(orbit.nontrivial_multipliers).max() < 1e-6
    assert orbit.stable


def test_belt_pure_slip_orbit_analytic():
    """Pure slip: without damping and with Coulomb friction, a small oscillation about
    φk = μk N r / k never reaches the belt speed; its period is 2π/ω and both multipliers are 1
    (a neutral family: Newton's least-squares step converges onto the member through the guess)."""
    P = Parameters(c_pphi=0.0, Omega=5.0, friction_law="coulomb")
    omega = math.sqrt(P.k_pphi / P.J_p)
    phi_k = P.mu_k * P.N * P.r / P.k_pphi
    ic = np.zeros(12)
    ic[4] = phi_k + 0.01  # amplitude 0.01 rad: max φ̇ = 0.14 rad/s < Ω = 5 rad/s, no stick
    orbit = periodic_orbit(two_plates(P, "phi"), ic, search_time=1.0)
    assert orbit.stick_phases == 0
    assert orbit.period == pytest.approx(2 * math.pi / omega, rel=1e-9)   # integration at rtol 1e-10
    assert orbit.state[4] == pytest.approx(phi_k + 0.01, rel=1e-8)
    assert np.allclose(orbit.multipliers, 1.0, atol=1e-6)                # FD accuracy (see above)


def test_period_multiplicity_two_doubles_the_period():
    P, period, _ = belt()
    ic = np.zeros(12)
    ic[10] = P.Omega
    orbit = periodic_orbit(two_plates(P, "phi"), ic, search_time=3.0, period_multiplicity=2)
    assert orbit.period == pytest.approx(2 * period, rel=1e-9)
    assert orbit.stick_phases == 2


def test_level_section():
    P, period, _ = belt()
    # stick spans φk − D … φk + D; the level φk + 1.2 D is crossed upwards in slip, after breakaway
    D = P.delta_mu * P.N * P.r / P.k_pphi
    level = P.mu_k * P.N * P.r / P.k_pphi + 1.2 * D
    ic = np.zeros(12)
    ic[10] = P.Omega
    orbit = periodic_orbit(two_plates(P, "phi"), ic, search_time=3.0, section=("phi", level))
    assert orbit.state[4] == level and orbit.state[10] > 0
    assert orbit.period == pytest.approx(period, rel=1e-9)


@pytest.fixture(scope="module")
def full_orbit():
    """Model 1 at N = 50 N, Ω = 0.5 rad/s (Fig. 10(b)): a stick-slip orbit."""
    return periodic_orbit(Parameters(N=50.0, Omega=0.5), "equilibrium", search_time=30.0)


def test_full_model_orbit(full_orbit):
    o = full_orbit
    assert o.model == "full" and o.monodromy.shape == (12, 12)
    assert o.stick_phases == 1
    assert o.iterations >= 2                  # the 30 s run is not yet on the orbit: Newton works
    assert o.residual <= 1e-8
    # measured |μ − 1| ~ 3e-8 for the trivial multiplier (central FD, step 1e-5 σ, rtol 1e-10)
    assert abs(o.trivial_multiplier - 1.0) < 1e-6
    assert o.stable
    # fundamental of Fig. 10(b) region: docs/numerics.md measures 1.538 Hz for the long run
    assert o.frequency == pytest.approx(1.538, abs=2e-3)


def test_long_simulation_settles_on_the_shooting_orbit(full_orbit):
    """Start on the shooting orbit perturbed by 1e-4 rad in φ; after 600 s (the slowest
    translational multiplier 0.994 per 0.65 s period decays by e^-5.5 ≈ 4e-3) the section
    states of the run agree with the orbit's to the decayed perturbation."""
    o = full_orbit
    t_end = 600.0
    traj = simulate(o.params, t_end, ic=o.state, perturbation=1e-4, rtol=1e-10,
                    atol=1e-13, sample_rate=2000)
    times, idx = section_crossings(o.system, o.section, traj.t, traj.states, traj.mode)
    last = traj.states[idx[-1]]   # sample before the last crossing; compare peak value and period
    peaks = np.diff(times[-20:])
    assert np.allclose(peaks, o.period, rtol=1e-5)          # 1e-4 · 4e-3 decayed perturbation, relative
    from stickslip.analysis.peaks import hermite_value
    phi_peak = hermite_value(traj.t, traj.states[:, 4], traj.states[:, 10], idx[-5:], times[-5:])
    assert np.allclose(phi_peak, o.state[4], rtol=1e-5)
    assert last.shape == (12,)


def test_bad_inputs():
    P, _, _ = belt()
    with pytest.raises(OrbitError, match="section"):
        periodic_orbit(two_plates(P, "phi"), np.zeros(12), section="nonsense")
    with pytest.raises(OrbitError, match="locked"):
        periodic_orbit(two_plates(P, "phi"), np.zeros(12), section=("x1", 0.0))
    with pytest.raises(OrbitError, match="crosses section"):
        # a run at the stable equilibrium of Model 1 at Ω = 8 rad/s never crosses φ̇ = 0
        periodic_orbit(Parameters(N=40.0, Omega=6.0), "equilibrium", search_time=1.0)
    with pytest.raises(OrbitError, match="did not converge"):
        periodic_orbit(Parameters(N=50.0, Omega=0.5), "equilibrium", search_time=30.0, max_iter=1)


def test_to_xarray(full_orbit):
    ds = full_orbit.to_xarray()
    assert ds.attrs["period_units"] == "s"
    assert ds.attrs["period"] == full_orbit.period
    assert ds["multiplier_abs"].size == 12
    assert ds["state_on_section"].sel(state="dphi").item() == 0.0
    assert ds.attrs["param_N"] == 50.0
