"""The event method finishes, without NaN, across parameters, models and initial conditions."""

import numpy as np
import pytest

from stickslip import MODELS, Parameters, simulate
from stickslip.model import resolve_variant

RNG = np.random.default_rng(20261122)
IC_SCALE = np.array([0.002] * 4 + [0.3, 0.05] + [0.3] * 6)  # m, rad, m/s, rad/s
CASES = [
    (float(RNG.uniform(10, 150)), float(RNG.uniform(0.3, 15)), model, law, RNG.normal(size=12) * IC_SCALE)
    for model in list(MODELS) + ["phi"] for law in ("exponential", "coulomb") for _ in range(3)
]


@pytest.mark.parametrize("N, Omega, model, law, ic", CASES)
def test_random_cases_finish(N, Omega, model, law, ic):
    mask = np.tile(resolve_variant(model).mask, 2)
    traj = simulate(Parameters(N=N, Omega=Omega, friction_law=law), 40.0, model=model,
                    ic=np.where(mask, ic, 0.0), sample_rate=100, max_steps=2_000_000)
    assert traj.status == "success", traj.status
    assert np.isfinite(traj.states).all() and np.isfinite(traj.friction).all()
    stick = traj.mode == 1
    muN = traj.params.mu_s * traj.params.N
    assert (traj.friction_magnitude[stick] <= muN * (1 + 1e-9)).all()


def test_near_singular_contact_metric_model_3():
    # Model 3 near φ = 0: G M⁻¹ Gᵀ has eigenvalues ~1e-3 and 1.2 1/kg and |v_r| creeps along the
    # edge of the low-speed band; this case used to run into max_steps at t ≈ 3.6 s
    ic = np.zeros(12)
    ic[7] = 0.6  # ẏ1 [m/s]
    traj = simulate(Parameters(N=70, Omega=3), 20.0, model="y", ic=ic, sample_rate=100, max_steps=500_000)
    assert traj.status == "success", traj.status
    assert traj.stats.slip_to_stick > 0  # it reaches stick-slip
    assert np.isfinite(traj.states).all()
