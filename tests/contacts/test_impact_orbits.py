"""A cycle with impacts: the flow Jacobian by variational equations with the impact's saltation
matrix (and those of opening, stick and breakaway), against central differences of the flow map
(independent event-integrated runs from perturbed states)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import stickslip
from stickslip.integrate.contacts import TRANSITION_IMPACT, TRANSITION_OPEN
from stickslip.orbits.linear_flow import flow_jacobian

from .test_liftoff_orbits import central_differences

RIGID_SLIDER = Path(__file__).with_name("rigid_slider.toml")


@pytest.fixture(scope="module")
def cycle():
    """The settled cycle's state a quarter of a flight after an opening, and its period [s]."""
    model = stickslip.load_model(RIGID_SLIDER)
    run = stickslip.simulate(model, 150.0, rtol=1e-11, atol=1e-13, sample_rate=10.0)
    tr = run.transitions
    impacts = tr.time[tr.kind == TRANSITION_IMPACT]
    period = float(np.diff(impacts[-6:]).mean())
    assert np.ptp(np.diff(impacts[-6:])) < 1e-8  # settled: the impacts repeat
    i_open = np.flatnonzero((tr.kind == TRANSITION_OPEN) & (tr.time > 100.0))[0]
    t_land = impacts[impacts > tr.time[i_open]][0]
    t0 = tr.time[i_open] + 0.25 * (t_land - tr.time[i_open])
    s0 = stickslip.simulate(model, t0, rtol=1e-11, atol=1e-13, sample_rate=1.0 / t0).final_state
    return model, s0, period


@pytest.fixture(scope="module")
def flow_map_differences(cycle):
    model, s0, period = cycle
    return central_differences(model, s0, period)


def test_saltation_flow_jacobian_of_a_cycle_with_an_impact_matches_central_differences(cycle,
                                                                                       flow_map_differences):
    model, s0, period = cycle
    fj = flow_jacobian(model, s0, period, rtol=1e-11)
    kinds = [kind for _, kind, _ in fj.events]
    assert kinds.count("impact") == 1 and "stick" in kinds and "breakaway" in kinds and "open" in kinds
    D = flow_map_differences
    np.testing.assert_allclose(fj.matrix, D, rtol=0, atol=1e-6 * np.abs(D).max())
    # one period from a point of the cycle: the trivial multiplier 1 of an autonomous cycle
    assert np.min(np.abs(np.linalg.eigvals(fj.matrix) - 1.0)) < 1e-5


def test_lyapunov_spectrum_across_impacts(cycle, flow_map_differences):
    """The cycle keeps one direction per period (the flow's own): the plastic impact and the
    closed contact hold y and y', stick holds x'. The flow map's central differences have rank 1
    (singular values below 1e-6 of the largest otherwise), so the exponents are 0 and three that
    diverge to −∞; the variational spectrum gives ~0 and three strongly negative ones."""
    model, s0, period = cycle
    singular = np.linalg.svd(flow_map_differences, compute_uv=False)
    assert singular[1] < 1e-6 * singular[0]
    # over whole periods the flow direction ends as long as it started (the frame has turned onto it)
    spectrum = stickslip.lyapunov_spectrum(model, ic=s0, t_transient=10.0, t_average=round(100.0 / period) * period,
                                           rtol=1e-10)
    exponents = np.sort(spectrum.exponents)[::-1]
    assert abs(exponents[0]) < 2e-3
    assert (exponents[1:] < -10.0).all()
