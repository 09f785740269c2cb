"""Steady-sliding equilibrium, Eq. (14)."""

import numpy as np
import pytest
from plates import plate_arrays

import stickslip
from stickslip import Parameters
from stickslip.model import MODELS, two_plates
from stickslip.stability import EquilibriumError, equilibrium, equilibrium_residual, stability
from stickslip.stability.equilibrium import RESIDUAL_TOL, solve_steady


@pytest.mark.parametrize("model", list(MODELS))
@pytest.mark.parametrize("N, Omega", [(50.0, 5.0), (10.0, 0.5), (150.0, 3.0), (80.0, -2.0), (200.0, 20.0)])
def test_residual_is_below_tolerance(model, N, Omega):
    P = Parameters(N=N, Omega=Omega)
    system = plate_arrays(P, model)
    q = equilibrium(two_plates(P, model))
    res = equilibrium_residual(system.model, q)  # the simulator's kernel, not the differentiated copy
    Kq = system.stiff * q
    # brief: relative residual ≤ 1e-10 (Newton reaches round-off, ~1e-16)
    assert np.max(np.abs(res)) <= RESIDUAL_TOL * np.max(np.abs(Kq))
    assert np.all(q[system.minv == 0] == 0.0)
    _, rel, iterations = solve_steady(system.model)
    assert rel <= RESIDUAL_TOL and iterations <= 12


def test_equilibrium_is_the_long_time_state_of_a_stable_simulation():
    # Table 1 damping decays the heavy lower plate at only c/(2 m_d) = 0.005 1/s; with damping
    # raised to c = m (0.5 1/s per DOF) 80 s shrink any transient by e^-40, so the end state is
    # the attractor to round-off. Omega = 12, N = 50 is in the stable region (paper Fig. 7(e)).
    P = Parameters(Omega=12.0, c_px=1.0, c_py=1.0, c_dx=10.0, c_dy=10.0, c_pphi=0.5, c_dpsi=5.0)
    res = stability(P)
    assert res.max_real_part < -0.4
    q = equilibrium(P)
    # start from rest with undeformed springs: the simulator has to find the state by itself
    traj = stickslip.simulate(P, 80.0, ic="zero", rtol=1e-11, atol=1e-14, sample_rate=10.0)
    assert traj.status == "success"
    # equal to 1e-9 of the deflection: far below the ~1e-3 a wrong b(x) or sign would give,
    # limited by the integrator tolerance (rtol 1e-11 over ~1e4 steps)
    np.testing.assert_allclose(traj.final_state[:6], q, rtol=0, atol=1e-9 * np.max(np.abs(q)))
    assert np.max(np.abs(traj.final_state[6:])) < 1e-9


def test_equilibrium_from_perturbed_start_returns():
    P = Parameters(Omega=12.0, c_px=1.0, c_py=1.0, c_dx=10.0, c_dy=10.0, c_pphi=0.5, c_dpsi=5.0)
    traj = stickslip.simulate(P, 60.0, ic="equilibrium", perturbation=1e-4, rtol=1e-11, atol=1e-14, sample_rate=10.0)
    q = equilibrium(P)
    # 1e-4 rad decays by e^-29 over 60 s; what is left is integration error (see above)
    np.testing.assert_allclose(traj.final_state[:6], q, rtol=0, atol=1e-9 * np.max(np.abs(q)))


def test_no_friction_gives_zero_equilibrium():
    q = equilibrium(Parameters(mu_k=0.0, delta_mu=0.0))
    assert np.all(q == 0.0)


def test_omega_zero_is_a_clear_error():
    with pytest.raises(EquilibriumError, match="Omega = 0"):
        equilibrium(Parameters(Omega=0.0))


def test_no_steady_sliding_at_large_load_is_a_clear_error():
    # at N = 200 N, Omega = 0.5 rad/s the contact point is dragged onto the centre of the lower
    # plate; Newton stalls and no equilibrium exists (docs/stability.md)
    with pytest.raises(EquilibriumError, match="no steady-sliding equilibrium found.*N = 200"):
        equilibrium(Parameters(N=200.0, Omega=0.5))


def test_missing_stiffness_is_reported():
    # no springs along x: moving both plates together along x changes nothing, K_L is singular
    with pytest.raises(EquilibriumError, match="singular"):
        equilibrium(Parameters(k_px=0.0, k_dx=0.0))


def test_bad_params_type():
    with pytest.raises(TypeError, match="Parameters"):
        equilibrium({"N": 50})
    with pytest.raises(stickslip.StickSlipError, match="unknown model 'nonsense'"):
        equilibrium("nonsense")


def test_continuation_finds_the_equilibrium_near_the_fold():
    # N = 178 N, Omega = 0.5 rad/s: an equilibrium exists (the branch from N = 0 folds at
    # N ≈ 184.5 N) but Newton from x = 0 stalls; the load continuation reaches it
    P = Parameters(N=178.0, Omega=0.5)
    system = plate_arrays(P)
    q = equilibrium(P)
    res = equilibrium_residual(system.model, q)
    assert np.max(np.abs(res)) <= RESIDUAL_TOL * np.max(np.abs(system.stiff * q))
    # the neighbours on the same branch, found by plain Newton, bracket it smoothly
    q_lo, q_hi = equilibrium(Parameters(N=177.0, Omega=0.5)), equilibrium(Parameters(N=179.0, Omega=0.5))
    assert np.all(np.abs(q - 0.5 * (q_lo + q_hi)) < 0.05 * np.abs(q_hi - q_lo) + 1e-12)
