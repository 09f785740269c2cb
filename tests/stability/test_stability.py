"""Eigen analysis of steady sliding (paper Sect. 4.1, Eq. 15)."""

import json
import math

import numpy as np
import pytest

from stickslip import Parameters
from stickslip.model import MODELS, two_plates
from stickslip.stability import EquilibriumError, StabilityResult, stability

from conftest import measured_growth_rate


def oscillator_eigenvalues(m, c, k):
    """λ = −c/2m ± i √(k/m − (c/2m)²) of an isolated damped oscillator [1/s]."""
    return np.roots([m, c, k])


def uncoupled_eigenvalues(P, dofs):
    table = {
        "x1": (P.m_p, P.c_px, P.k_px), "y1": (P.m_p, P.c_py, P.k_py),
        "x2": (P.m_d, P.c_dx, P.k_dx), "y2": (P.m_d, P.c_dy, P.k_dy),
        "phi": (P.J_p, P.c_pphi, P.k_pphi), "psi": (P.J_d, P.c_dpsi, P.k_dpsi),
    }
    lam = np.concatenate([oscillator_eigenvalues(*table[d]) for d in dofs])
    return lam[np.lexsort((-lam.imag, -lam.real))]


@pytest.mark.parametrize("model", list(MODELS))
def test_without_friction_eigenvalues_are_the_uncoupled_oscillators(model):
    # mu_k = delta_mu = 0: no friction, nothing couples the six oscillators of Eq. (1)
    P = Parameters(mu_k=0.0, delta_mu=0.0, c_px=0.3, c_dy=2.0)  # distinct damping: no ties
    res = stability(two_plates(P, model))
    expected = uncoupled_eigenvalues(P, res.dofs)
    # eigenvalues of a 12×12 matrix with entries up to k/m = 300: LAPACK round-off ~1e-13
    np.testing.assert_allclose(res.eigenvalues, expected, rtol=1e-12, atol=1e-12)
    assert np.all(res.equilibrium == 0.0)


@pytest.mark.parametrize("mu_k", [0.2, 0.5])
def test_constant_friction_does_not_couple_the_reduced_model(mu_k):
    # Model 4 with delta_mu = 0: F = mu_k N along e_n1 whatever the rotation, a constant torque
    # on phi and psi, so the linearisation is again two isolated oscillators
    P = Parameters(mu_k=mu_k, delta_mu=0.0, N=80.0)
    res = stability(two_plates(P, "rotation"))
    expected = uncoupled_eigenvalues(P, ("phi", "psi"))
    np.testing.assert_allclose(res.eigenvalues, expected, rtol=1e-12, atol=1e-12)
    # and the equilibrium is the static deflection by that torque, r mu_k N / k
    assert res.equilibrium[4] == pytest.approx(P.r * mu_k * P.N / P.k_pphi, rel=1e-12)


def test_result_is_typed_and_sorted():
    res = stability(Parameters())
    assert isinstance(res, StabilityResult)
    assert res.jacobian.shape == (12, 12) and res.eigenvalues.shape == (12,)
    assert np.all(np.diff(res.eigenvalues.real) <= 0)
    assert res.max_real_part == res.eigenvalues.real.max()
    assert res.stable == (res.max_real_part < 0)
    np.testing.assert_allclose(res.frequencies_hz, np.abs(res.eigenvalues.imag) / (2 * math.pi))
    # mode shapes: eigenvectors of J (displacement part), largest entry 1
    for j in range(12):
        assert np.max(np.abs(res.mode_shapes[j])) == pytest.approx(1.0, rel=1e-14)
    lam = res.eigenvalues[0]
    v = np.concatenate([res.mode_shapes[0], lam * res.mode_shapes[0]])
    # J v = λ v to round-off of |J| ~ 3e3
    assert np.max(np.abs(res.jacobian @ v - lam * v)) < 1e-9 * np.max(np.abs(res.jacobian))
    summary = res.summary()
    assert set(summary) >= {"equilibrium", "eigenvalues", "max_real_part", "stable"}
    json.dumps(summary)
    assert len(res.modes()) == 6


@pytest.mark.parametrize("model, size", [("full", 12), ("x", 8), ("y", 8), ("rotation", 4), ("phi", 2)])
def test_jacobian_is_reduced_to_the_free_dofs(model, size):
    res = stability(two_plates(Parameters(), model))
    assert res.jacobian.shape == (size, size)
    assert len(res.dofs) == size // 2


def test_to_xarray(tmp_path):
    res = stability(two_plates(Parameters(N=70.0), "rotation"))
    ds = res.to_xarray()
    assert ds["eigenvalue_real"].attrs["units"] == "1/s"
    assert ds.attrs["param_N"] == 70.0 and ds.attrs["param_N_units"] == "N"
    assert json.loads(ds.attrs["parameters"])["N"] == 70.0
    np.testing.assert_array_equal(ds["eigenvalue_real"].values, res.eigenvalues.real)
    ds.to_netcdf(tmp_path / "s.nc", engine="h5netcdf")


def test_paper_operating_points():
    # Sect. 4.2.2 (Fig. 7): N = 50 N; at 12 rad/s both initial conditions settle on the equilibrium
    # (stable), at 5 rad/s both go to stick-slip (we find the equilibrium unstable there)
    assert stability(Parameters(Omega=12.0)).stable
    assert not stability(Parameters(Omega=5.0)).stable


@pytest.mark.parametrize("N, Omega", [(50.0, 3.0), (100.0, 4.0)])
def test_growth_rate_matches_simulation(N, Omega):
    # start 1e-6 along the leading mode; ~7 s of growth keep the motion linear (amplitude < 1e-4)
    P = Parameters(N=N, Omega=Omega)
    predicted = stability(P).max_real_part
    t_end = math.log(100.0) / predicted
    measured, predicted, _ = measured_growth_rate(P, t_end, 1e-6)
    # brief: within 5 %
    assert measured == pytest.approx(predicted, rel=0.05)


def test_growth_rate_matches_simulation_reduced_model():
    P = Parameters(N=100.0, Omega=1.5)
    predicted = stability(two_plates(P, "rotation")).max_real_part
    assert predicted > 0
    measured, predicted, _ = measured_growth_rate(P, math.log(100.0) / predicted, 1e-6, model="rotation")
    assert measured == pytest.approx(predicted, rel=0.05)


def test_errors():
    with pytest.raises(EquilibriumError, match="Omega = 0"):
        stability(Parameters(Omega=0.0))
    with pytest.raises(EquilibriumError, match="low-speed band"):
        stability(Parameters(Omega=1e-7))
    with pytest.raises(TypeError):
        stability(object())  # neither Parameters nor a model (None means the default plates)
