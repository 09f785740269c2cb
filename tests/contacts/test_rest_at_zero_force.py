"""A rigid contact at rest at zero normal force is a state: closed with λ = 0, kept while nothing
pulls it off, left where its normal force turns negative (the free gap acceleration positive).

The ``impact-oscillator`` (m = 1, kx = 1, ky = 4π², g = y) with d = 0 puts the normal spring's rest
position on the stop: a mass at rest on the stop is pressed by nothing (λ = ky (y + d) = 0), so it
stays there, and x, free of friction (μ λ = 0), oscillates as x0 cos t (kx/m = 1). With a coupling
stiffness kxy between x and y the closed contact carries λ = kxy x = kxy x0 cos t and leaves the stop
where that turns negative, at t = π/2 (closed forms written here, not taken from the package).
"""

from __future__ import annotations

import json
import math

import numpy as np
from typer.testing import CliRunner

import stickslip
from stickslip.cli import app
from stickslip.integrate.contacts import TRANSITION_IMPACT, TRANSITION_OPEN
from stickslip.integrate.status import Status

X0 = 0.1


def test_cli_simulate_at_rest_on_the_stop_runs_to_the_end_without_impacts(tmp_path):
    result = CliRunner().invoke(app, ["simulate", "--model", "impact-oscillator", "--set", "d=0", "--t-end", "20",
                                      "--json", "--out", str(tmp_path / "r.nc")])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
    assert out["status"] == "success" and out["t_end_s"] == 20.0
    assert out["impacts"] == 0 and out["open_fraction"] == 0.0


def test_sliding_along_the_stop_at_zero_force_keeps_it_closed():
    """The gap runs along the motion: x oscillates freely while y rests on the stop at λ = 0."""
    model = stickslip.load_model("impact-oscillator").replace(d=0.0)
    tr = stickslip.simulate(model, 10.0, ic=np.array([X0, 0.0, 0.0, 0.0]), sample_rate=50.0, rtol=1e-10, atol=1e-12)
    assert tr.status_code is Status.SUCCESS and tr.t[-1] == 10.0
    assert len(tr.impacts) == 0 and not np.any(tr.transitions.kind == TRANSITION_IMPACT)
    assert not tr.open.any()
    np.testing.assert_array_equal(tr.states[:, 1], 0.0)  # y
    np.testing.assert_allclose(tr.normal_force[:, 0], 0.0, atol=1e-12)
    np.testing.assert_allclose(tr.states[:, 0], X0 * np.cos(tr.t), atol=1e-8)


def test_a_contact_resting_at_zero_force_leaves_where_its_force_turns_negative():
    kxy = 2.0
    base = stickslip.load_model("impact-oscillator").replace(d=0.0)
    model = base.replace(**{"stiffness.0.1": kxy, "stiffness.1.0": kxy, "contact.0.friction.mu_k": 0.0})
    tr = stickslip.simulate(model, 2.0, ic=np.array([X0, 0.0, 0.0, 0.0]), sample_rate=100.0, rtol=1e-10,
                            atol=1e-12)
    opened = tr.transitions.time[tr.transitions.kind == TRANSITION_OPEN]
    assert opened.size >= 1 and abs(opened[0] - math.pi / 2) < 1e-8
    before = tr.t < math.pi / 2 - 1e-6
    np.testing.assert_allclose(tr.normal_force[before, 0], kxy * X0 * np.cos(tr.t[before]), atol=1e-8)
