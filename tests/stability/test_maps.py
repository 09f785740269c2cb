"""(N, Omega) stability maps and the boundary by root finding (paper Figs. 3, 4)."""

import json
import math

import numpy as np
import pytest
from conftest import measured_growth_rate

from stickslip import ParameterError, Parameters
from stickslip.model import two_plates
from stickslip.stability import load_stability_map, stability, stability_map
from stickslip.stability.maps import BOUNDARY_XTOL, max_real_part, parse_family

N_GRID = np.linspace(10.0, 190.0, 7)
W_GRID = np.linspace(0.5, 20.0, 40)


@pytest.fixture(scope="module")
def delta_mu_map():
    return stability_map(Parameters(), N_GRID, W_GRID, family=("delta_mu", [0.1, 0.2, 0.3]))


def test_map_equals_pointwise_stability(delta_mu_map):
    m = delta_mu_map
    for f, dmu in enumerate([0.1, 0.2, 0.3]):
        for a in (0, 3, 6):
            for b in (0, 10, 25, 39):
                value = m.max_real_part[f, a, b]
                try:
                    ref = stability(Parameters(delta_mu=dmu, N=m.N[a], Omega=m.Omega[b])).max_real_part
                except Exception:
                    assert math.isnan(value)
                    continue
                # same Jacobian, batched vs single LAPACK call: eigenvalue round-off ~1e-13 of |J|
                assert value == pytest.approx(ref, rel=1e-9, abs=1e-11)


def test_boundary_is_a_root_with_the_right_sign_on_both_sides(delta_mu_map):
    m = delta_mu_map
    count = 0
    for f, dmu in enumerate([0.1, 0.2, 0.3]):
        system = two_plates(Parameters(delta_mu=dmu))
        for a, N in enumerate(m.N):
            for c in range(m.boundary.shape[2]):
                w = m.boundary[f, a, c]
                if not np.isfinite(w):
                    continue
                count += 1
                assert not m.boundary_jump[f, a, c]
                d = m.boundary_direction[f, a, c]
                # 1e-6 rad/s is 1e4 × the brentq tolerance: outside its uncertainty, near enough
                # for the sign to be that of the crossing
                below = max_real_part(system, N, w - 1e-6)
                above = max_real_part(system, N, w + 1e-6)
                assert np.sign(above) == d and np.sign(below) == -d
    assert count >= 3 * len(m.N)


def test_boundary_matches_a_fine_scan():
    system = two_plates(Parameters())
    m = stability_map(Parameters(), [50.0], np.linspace(1.0, 15.0, 8))
    w_c = m.boundary[0, 0, 0]
    fine = np.linspace(w_c - 0.05, w_c + 0.05, 101)  # spacing 1e-3 rad/s
    values = np.array([max_real_part(system, 50.0, w) for w in fine])
    crossing = fine[np.flatnonzero(np.diff(np.sign(values)))[0]]
    assert abs(crossing - w_c) <= 1e-3 + BOUNDARY_XTOL


def test_paper_conclusions_hold(delta_mu_map):
    """Sect. 4.1: unstable at low Omega and large N; delta_mu widens, alpha narrows the
    unstable range; Model 1 unstable over a larger range than Model 4 (Figs. 3, 4)."""
    m = delta_mu_map
    lower = m.boundary[:, :, 0]  # first crossing above which sliding is stable
    assert np.all(m.boundary_direction[:, :, 0] == -1)
    assert np.all(np.diff(lower, axis=1) > 0), "Omega_c grows with N"
    assert np.all(np.diff(lower, axis=0) > 0), "Omega_c grows with delta_mu"
    alpha = stability_map(Parameters(), N_GRID, W_GRID, family=("alpha", [2.0, 5.0, 10.0]))
    assert np.all(np.diff(alpha.boundary[:, :, 0], axis=0) < 0), "Omega_c shrinks with alpha"
    models = stability_map(Parameters(), N_GRID, W_GRID, family=("model", ["full", "rotation"]))
    assert np.all(models.boundary[0, :, 0] > models.boundary[1, :, 0])


def test_netcdf_round_trip_and_attrs(tmp_path, delta_mu_map):
    path = delta_mu_map.to_netcdf(tmp_path / "map.nc")
    back = load_stability_map(path)
    np.testing.assert_array_equal(back.max_real_part, delta_mu_map.max_real_part)
    np.testing.assert_array_equal(back.boundary, delta_mu_map.boundary)
    assert back.family_values == [0.1, 0.2, 0.3]
    ds = delta_mu_map.to_xarray()
    assert ds["Omega"].attrs["units"] == "rad/s" and ds["N"].attrs["units"] == "N"
    assert ds["max_real_part"].attrs["units"] == "1/s"
    assert json.loads(ds.attrs["parameters"])["alpha"] == 5.0


def test_figure(tmp_path, delta_mu_map):
    from stickslip.plot.stability import save_stability_map_figure

    path = save_stability_map_figure(delta_mu_map, tmp_path / "map.png")
    assert path.stat().st_size > 10_000


def test_bad_input():
    with pytest.raises(ValueError, match="increasing"):
        stability_map(Parameters(), [50.0, 10.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="N = 0.0 must be > 0"):
        stability_map(Parameters(), [0.0, 10.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="Omega = 0"):
        stability_map(Parameters(), [10.0], [-1.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="already an axis"):
        stability_map(Parameters(), [10.0], [1.0, 2.0], family=("N", [1.0]))
    with pytest.raises(ParameterError, match="unknown family parameter"):
        stability_map(Parameters(), [10.0], [1.0, 2.0], family="foo=1,2")
    with pytest.raises(ParameterError):
        stability_map(Parameters(), [10.0], [1.0, 2.0], family="delta_mu=-1")
    with pytest.raises(ValueError, match="NAME=V1"):
        parse_family("delta_mu")
    assert parse_family("model=full,rotation") == ("model", ["full", "rotation"])


def test_no_equilibrium_region_is_nan():
    m = stability_map(Parameters(), [200.0], [0.5, 1.0], boundary=False)
    assert np.isnan(m.max_real_part[0, 0, 0])


@pytest.mark.parametrize("side", [-1, 1])
def test_boundary_matches_direct_simulation_on_both_sides(side):
    # 10 % below / above Omega_c(N = 50) the leading growth rate is ~ +0.02 / -0.003 1/s; a run
    # on the leading mode must grow / decay at that rate (5 %, as for the growth-rate test)
    m = stability_map(Parameters(), [50.0], np.linspace(1.0, 15.0, 8))
    w = m.boundary[0, 0, 0] * (1.0 + 0.1 * side)
    P = Parameters(Omega=w)
    predicted = stability(P).max_real_part
    assert np.sign(predicted) == side * -1
    measured, predicted, _ = measured_growth_rate(P, min(400.0, 3.0 / abs(predicted)), 1e-6, sample_rate=10.0,
                                                  t_from=20.0)
    assert np.sign(measured) == np.sign(predicted)
    assert measured == pytest.approx(predicted, rel=0.05)


@pytest.mark.parametrize("N", [10.0, 50.0, 150.0])
def test_reduced_model_boundary_is_the_closed_form(N):
    # Model 4: R = r always, so the friction torque is r mu(r (Omega + psi' - phi')) N. With
    # a = N r^2 alpha dmu exp(-alpha Omega r): C_L = [[c - a, a], [a, c - a]], and with equal
    # k/J of phi and psi (Table 1: 200 1/s^2) the mode (1, -1) has a purely imaginary eigenvalue
    # exactly when c = 2a, i.e. Omega_c = ln(2 N r^2 alpha dmu / c) / (alpha r)
    P = Parameters()
    expected = math.log(2 * N * P.r**2 * P.alpha * P.delta_mu / P.c_pphi) / (P.alpha * P.r)
    m = stability_map(two_plates(P, "rotation"), [N], np.linspace(0.2, 20.0, 30))
    # brentq to BOUNDARY_XTOL; 1e-9 allows for the round-off of max Re λ near the root
    assert m.boundary[0, 0, 0] == pytest.approx(expected, rel=1e-9)
    assert np.isnan(m.boundary[0, 0, 1:]).all()
