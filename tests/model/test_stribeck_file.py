"""The Stribeck law in a model file against its closed form.

μ(v) = μk + Δμ exp(−(v/v_s)²) + μv v. On a mass on a spring over a belt of speed V (m x'' + c x'
+ k x = F, v = x' − V), steady sliding has x' = 0 and the friction μ(V) N along the belt:
x_e = μ(V) N / k. In slip the friction force is F = −μ(|v|) N sign(v) at every sample.
"""

import math

import numpy as np
import pytest

from stickslip import simulate
from stickslip.model.friction import FrictionLaw, FrictionLawError
from stickslip.model.model_file import ModelFileError, load_model_file
from stickslip.model.sparse_form import friction_slope
from stickslip.stability import equilibrium

MU_K, DELTA_MU, V_S, MU_V, N, K = 0.3, 0.2, 0.4, 0.05, 2.0, 5.0

TOML = f"""
name = "stribeck-belt"
dofs = ["x"]
mass = [[1.0]]
damping = [[0.05]]
stiffness = [[{K}]]
[parameters]
V = 0.5
[[contact]]
tangent = [[1.0]]
drive = ["V"]
normal_force = {N}
[contact.friction]
law = "stribeck"
mu_k = {MU_K}
delta_mu = {DELTA_MU}
v_s = {V_S}
mu_v = {MU_V}
"""


def mu(v):
    """The Stribeck curve, written here independently of the package."""
    v = np.abs(v)
    return MU_K + DELTA_MU * np.exp(-(v / V_S) ** 2) + MU_V * v


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    path = tmp_path_factory.mktemp("stribeck") / "stribeck.toml"
    path.write_text(TOML)
    return load_model_file(path)


def test_the_law_of_the_file(model):
    law = model.contacts[0].friction
    assert law.law == "stribeck" and law.v_s == V_S and law.mu_s == MU_K + DELTA_MU
    speeds = np.array([0.0, 0.05, 0.4, 1.3, 7.0])
    np.testing.assert_allclose(law.coefficient(speeds), mu(speeds), rtol=1e-15)
    assert law.to_dict() == {"law": "stribeck", "mu_k": MU_K, "delta_mu": DELTA_MU, "v_s": V_S, "mu_v": MU_V}
    # dμ/dv by its closed form against a central difference
    v, h = np.array([0.1, 0.4, 1.0]), 1e-6
    np.testing.assert_allclose(friction_slope(law, v), (mu(v + h) - mu(v - h)) / (2 * h), rtol=1e-8)


@pytest.mark.parametrize("speed", [0.02, 0.2, 0.4, 0.9, 3.0])
def test_steady_sliding_friction_is_the_closed_form(model, speed):
    q = equilibrium(model.replace(V=speed))
    assert math.isclose(K * q[0], mu(speed) * N, rel_tol=1e-12, abs_tol=1e-15)


def test_slip_samples_carry_the_formula(model):
    run = simulate(model, 20.0, ic={"x": 2.0, "dx": 0.0}, rtol=1e-10, atol=1e-12, sample_rate=50)
    assert run.status == "success"
    slip = ~run.stick[:, 0]
    v = run.slip_velocity[slip, 0]
    moving = np.abs(v) > 1e-3  # away from the low-speed band at v = 0
    assert moving.sum() > 100
    F = run.friction[slip, 0][moving]
    np.testing.assert_allclose(F, -mu(v[moving]) * N * np.sign(v[moving]), rtol=1e-12, atol=0)


def test_set_reaches_the_stribeck_speed(model):
    changed = model.replace(**{"contact.0.friction.v_s": 0.8})
    assert changed.contacts[0].friction.v_s == 0.8


@pytest.mark.parametrize("edit, message", [
    (("v_s = 0.4", ""), "v_s is missing; the Stribeck law needs its Stribeck speed"),
    (("v_s = 0.4", "v_s = 0.0"), "v_s = 0.0 must be > 0"),
    (("v_s = 0.4", "v_s = 0.4\nalpha = 2.0"), "alpha belongs to the exponential law, not the stribeck law"),
])
def test_bad_stribeck_tables_are_one_line(tmp_path, edit, message):
    path = tmp_path / "bad.toml"
    path.write_text(TOML.replace(*edit))
    with pytest.raises(ModelFileError, match=message):
        load_model_file(path)


def test_the_law_object_refuses_a_missing_speed():
    with pytest.raises(FrictionLawError, match="v_s"):
        FrictionLaw("stribeck", 0.3, 0.2)
    with pytest.raises(FrictionLawError, match="v_s"):
        FrictionLaw("exponential", 0.3, 0.2, 5.0, 0.0, None, 0.4)
