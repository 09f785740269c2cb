"""The orbit tools, continuation, Lyapunov exponents and basin stability on a model above the
kernels' stack maxima: the belt with 69 modal coordinates that nothing forces (70 DOFs,
``fe_models.belt_with_modes``). Its motions are the belt's with the modes at rest, so each tool's
answer is the 1-DOF belt's, and its Floquet multipliers add the modes' closed-form exp(λ_r T).
"""

import numpy as np
import pytest

from stickslip import basin_stability, continue_orbit, load_model, lyapunov_exponent, periodic_orbit
from stickslip.basins.states import box
from stickslip.model.kinematics import LARGE_KINEMATICS

from .fe_models import belt_with_modes

MODES, ZETA = 69, 0.05


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    fe = belt_with_modes(MODES, zeta=ZETA)
    model = load_model(str(fe.write(tmp_path_factory.mktemp("belt") / "belt", contacts="tables", nodes=False)))
    assert model.n == 70 and type(model.data.kin) is LARGE_KINEMATICS[type(model.kinematics)]
    return model


@pytest.fixture(scope="module")
def orbit(model):
    return periodic_orbit(model, {"u0": 0.0, "du0": 1.5}, search_time=60.0)


def test_orbit_is_the_belts_with_the_modes_multipliers(orbit):
    belt = periodic_orbit("belt", {"x": 0.0, "dx": 1.5}, search_time=60.0)
    assert orbit.period == pytest.approx(belt.period, rel=1e-8)
    assert orbit.stick_phases == belt.stick_phases == 1
    np.testing.assert_allclose(orbit.state[1:70], 0.0, atol=1e-12)
    omega = np.linspace(2.0, 9.0, MODES)
    lam = -ZETA * omega + 1j * omega * np.sqrt(1.0 - ZETA**2)
    expected = np.concatenate([belt.multipliers, np.exp(lam * orbit.period), np.exp(np.conj(lam) * orbit.period)])
    got = orbit.multipliers
    assert got.size == expected.size == 140
    # the modes' multipliers: matched one by one (each closed-form value has one computed within 1e-7)
    for mu in np.exp(lam * orbit.period):
        assert np.abs(got - mu).min() < 1e-7 and np.abs(got - np.conj(mu)).min() < 1e-7
    assert np.abs(got[0] - 1.0) < 1e-6  # the orbit's own


def test_continuation_follows_the_belts_branch(model, orbit):
    branch = continue_orbit(model, "contact.0.drive", start=orbit, bounds=(1.5, 1.6), step=0.02, max_step=0.05,
                            max_points=4, amplitude=False)
    assert len(branch) >= 3 and branch.values.max() > 1.52
    for V, T in zip(branch.values[:3], branch.periods[:3]):
        single = periodic_orbit(load_model("belt").replace(**{"contact.0.drive": V}), {"x": 0.0, "dx": V},
                                search_time=60.0)
        assert T == pytest.approx(single.period, rel=1e-7)


def test_lyapunov_exponent_of_the_stable_cycle(orbit):
    """The cycle attracts: its largest exponent is the neutral one along the orbit, 0 (the belt's
    other multiplier is 0 and the modes decay at −ζ ω_r ≤ −0.1). The finite-time estimate is the
    log of the perturbation's growth over the time: once its components off the orbit have
    decayed, that log stays put, so the estimate falls as 1/t."""
    T = orbit.period
    short, long = (lyapunov_exponent(ic=orbit, t_transient=T, t_average=k * T, chunk=T) for k in (20, 100))
    assert long.exponent * 100 == pytest.approx(short.exponent * 20, rel=1e-4)
    assert abs(long.exponent) < 0.01


def test_basins_state_by_state_as_the_belt(model):
    ranges = {"u0": (0.5, 2.5), "du0": (-2.0, 0.0)}
    res = basin_stability(model, box(model, ranges, n=6, seed=1), t_end=300.0, executor="serial")
    belt = load_model("belt")
    ref = basin_stability(belt, box(belt, {"x": ranges["u0"], "dx": ranges["du0"]}, n=6, seed=1), t_end=300.0,
                          executor="serial")
    states, ref_states = res.to_xarray()["initial_state"].values, ref.to_xarray()["initial_state"].values
    np.testing.assert_array_equal(states[:, [0, 70]], ref_states)
    np.testing.assert_array_equal(res.labels(), ref.labels())
    assert set(ref.labels()) == {"equilibrium", "periodic"}
