"""Contacts without friction (no tangent, no friction law): they open, close and take impacts and
never stick or slip, with no coordinate added; and steady sliding that leaves a contact open.

* A damped oscillator x'' + 2ζ x' + x = 0 from x0 = 1 against a rigid stop at x = −a (g = x + a ≥ 0,
  restitution e), against a separate event solver written here (scipy's solve_ivp with the
  landing as a terminal event, ẋ⁺ = −e ẋ⁻ applied by hand).
* ``clearance-oscillator``: the belt oscillator (x'' + 0.1 x' + x = μ(|v|) N, v = x' − 1.5 < 0,
  μ(|v|) = 0.5 + 0.5 exp(−2 |v|)) with a frictionless rigid stop at x = xs = 1.2. Steady sliding is
  x_e = μ(1.5) with the stop open; linearised by hand, ẍ = −x − 0.1 ẋ + μ'(|v|) d|v|/dẋ with
  μ'(|v|) = −exp(−2 |v|) and d|v|/dẋ = −1: J = [[0, 1], [−1, −0.1 + exp(−3)]].
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from typer.testing import CliRunner

import stickslip
from stickslip.cli import app
from stickslip.errors import ModelError
from stickslip.integrate.contacts import TRANSITION_IMPACT, TRANSITION_TO_SLIP, TRANSITION_TO_STICK
from stickslip.model import model_from_spec
from stickslip.model.system_model import Contact, FrictionModel, NormalLaw
from stickslip.stability import stability

ZETA, A, E = 0.02, 0.3, 0.8


def stop_spec(**contact):
    """The damped oscillator against a frictionless rigid stop at x = −A."""
    return {"name": "stop", "dofs": ["x"], "mass": [[1.0]], "damping": [[2.0 * ZETA]], "stiffness": [[1.0]],
            "force": [0.0],
            "contact": [{"name": "stop", "gap": A, "gap_gradient": [1.0],
                         "normal": {"law": "rigid", "restitution": E}, **contact}]}


def reference_impacts(t_end: float):
    """(instants, speeds before) of the landings by solve_ivp with a terminal event at g = 0."""
    def rhs(t, y):
        return [y[1], -2.0 * ZETA * y[1] - y[0]]

    def landing(t, y):
        return y[0] + A
    landing.terminal, landing.direction = True, -1.0
    t, y = 0.0, np.array([1.0, 0.0])
    times, speeds = [], []
    while t < t_end:
        sol = solve_ivp(rhs, (t, t_end), y, events=landing, rtol=1e-12, atol=1e-14)
        if sol.status != 1:
            break
        t = float(sol.t_events[0][0])
        y = sol.y_events[0][0].copy()
        times.append(t)
        speeds.append(y[1])
        y = np.array([-A, -E * y[1]])
    return np.array(times), np.array(speeds)


def test_a_frictionless_stop_bounces_as_an_independent_event_solver():
    model = model_from_spec(stop_spec())
    assert model.n == 1 and model.contacts[0].frictionless
    tr = stickslip.simulate(model, 20.0, ic=np.array([1.0, 0.0]), rtol=1e-12, atol=1e-14, sample_rate=50.0)
    times, speeds = reference_impacts(20.0)
    assert len(tr.impacts) == times.size >= 3
    np.testing.assert_allclose(tr.impacts.time, times, atol=1e-8)
    np.testing.assert_allclose(tr.impacts.speed_before, speeds, rtol=1e-8)
    np.testing.assert_allclose(tr.impacts.speed_after, -E * speeds, rtol=1e-8)
    kinds = tr.transitions.kind
    assert not np.isin(kinds, [TRANSITION_TO_STICK, TRANSITION_TO_SLIP]).any()
    assert not tr.stick.any() and np.isnan(tr.slip_velocity).all()
    np.testing.assert_array_equal(tr.friction, 0.0)
    assert tr.steady.stick_fraction == 0.0


def test_the_python_contact_without_friction_is_the_model_files():
    spec_model = model_from_spec(stop_spec())
    contact = Contact(name="stop", normal=NormalLaw("rigid", restitution=E), gap=A, gap_gradient=[1.0])
    model = FrictionModel(name="stop", dofs=("x",), mass=[[1.0]], damping=[[2.0 * ZETA]], stiffness=[[1.0]],
                          force=[0.0], contacts=(contact,))
    assert model.contacts[0].frictionless and model.rigid
    np.testing.assert_array_equal(model.data.m, spec_model.data.m)
    a = stickslip.simulate(model, 5.0, ic=np.array([1.0, 0.0]), sample_rate=20.0)
    b = stickslip.simulate(spec_model, 5.0, ic=np.array([1.0, 0.0]), sample_rate=20.0)
    np.testing.assert_array_equal(a.states, b.states)


@pytest.mark.parametrize(("contact", "words"), [
    ({"friction": {"law": "coulomb", "mu_k": 0.3, "delta_mu": 0.0}}, "tangent is missing"),
    ({"tangent": [[1.0]]}, "friction is missing"),
])
def test_half_a_tangential_part_is_refused_in_one_line(contact, words):
    with pytest.raises(ModelError, match=words):
        model_from_spec(stop_spec(**contact))


def test_a_pressed_contact_without_friction_is_refused():
    with pytest.raises(ModelError, match="acts through its gap only"):
        FrictionModel(name="p", dofs=("x",), mass=[[1.0]], damping=[[0.0]], stiffness=[[1.0]], force=[0.0],
                      contacts=(Contact(normal_force=1.0),))


def test_frictionless_runs_from_a_saved_file_rebuild_their_model(tmp_path):
    model = stickslip.load_model("clearance-oscillator")
    tr = stickslip.simulate(model, 2.0, ic=np.array([1.0, 0.0]), sample_rate=10.0)
    tr.to_netcdf(tmp_path / "r.nc")
    back = stickslip.load_trajectory(tmp_path / "r.nc")
    assert back.system.contacts[1].frictionless and np.array_equal(back.states, tr.states)


# --------------------------------------------------------------------------- steady sliding, stop open
X_E = 0.5 + 0.5 * math.exp(-3.0)
J_HAND = np.array([[0.0, 1.0], [-1.0, -0.1 + math.exp(-3.0)]])


def test_stability_with_the_stop_open_is_the_free_oscillators():
    res = stability("clearance-oscillator")
    assert res.open_contacts == ("stop",)
    assert abs(res.equilibrium[0] - X_E) < 1e-12
    np.testing.assert_allclose(res.jacobian, J_HAND, atol=1e-9)
    hand = np.linalg.eigvals(J_HAND)
    hand = hand[np.lexsort((-hand.imag, -hand.real))]
    np.testing.assert_allclose(res.eigenvalues, hand, atol=1e-9)
    assert res.stable


def test_stability_cli_reports_the_open_contact_and_the_eigenvalues():
    result = CliRunner().invoke(app, ["stability", "--model", "clearance-oscillator", "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["open_contacts"] == ["stop"]
    tr = -0.1 + math.exp(-3.0)
    assert abs(out["eigenvalues"][0][0] - tr / 2) < 1e-9
    assert abs(abs(out["eigenvalues"][0][1]) - math.sqrt(1.0 - tr * tr / 4)) < 1e-9


def test_a_stop_that_steady_sliding_would_press_through_is_closed_again():
    """The stop moved inside the equilibrium (xs = 0.3 < x_e): closed, it holds x at 0.3 with
    λ = μ(1.5) − 0.3 > 0, and steady sliding has no open contact."""
    res = stability(stickslip.load_model("clearance-oscillator").replace(xs=0.3))
    assert res.open_contacts == () and abs(res.equilibrium[0] - 0.3) < 1e-12
    assert res.eigenvalues.size == 0  # the stop fixes the one dof


def test_basins_run_with_the_stop_open_at_steady_sliding():
    from stickslip.basins import basin_stability, box

    model = stickslip.load_model("clearance-oscillator")
    res = basin_stability(model, box(model, {"x": (0.4, 0.6), "dx": (0.0, 0.1)}, n=2, seed=1), t_end=400.0,
                          executor="serial")
    summary = res.to_json()
    assert summary["n"] == 2 and summary["complete"]
    eq = [a for a in summary["attractors"] if a["name"] == "equilibrium"]
    assert eq and abs(eq[0]["state"]["x"] - X_E) < 1e-9
