"""Period and chaos confirmations (attractors/confirm.py) on a model file: the belt's stick-slip cycle."""

import pytest

from stickslip import simulate
from stickslip.attractors.confirm import confirm_period, lyapunov_sign

#: The belt's stick-slip cycle [s] (tests/orbits/test_generic_models.py: closed-form stick phase and a
#: DOP853 slip phase, to 3e-12).
BELT_PERIOD = 6.3163063578913965


@pytest.fixture(scope="module")
def belt_run():
    return simulate("belt", 120.0, ic={"x": 0.0, "dx": 1.5}, rtol=1e-10, atol=1e-12, sample_rate=200)


def test_period_of_a_model_file_run_is_confirmed_by_shooting(belt_run):
    out = confirm_period(belt_run, 1, BELT_PERIOD, dof="x")
    assert out["confirmed"], out
    assert out["period_s"] == pytest.approx(BELT_PERIOD, rel=1e-9)
    assert out["stick_phases"] == 1 and out["stable"] and out["max_multiplier"] < 1e-8


def test_lyapunov_sign_of_a_model_file_run(belt_run):
    out = lyapunov_sign(belt_run, averaging=200.0)
    assert out["sign"] == "zero", out
