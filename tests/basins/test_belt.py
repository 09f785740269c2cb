"""Known answers on the belt (bSTAB's friction case): its two templates, fractions against an
independent classification of the same states by long runs, and bSTAB's published fractions."""

import math

import numpy as np
import pytest

import stickslip
from stickslip.attractors import attractor
from stickslip.basins import basin_stability, box
from stickslip.basins.context import make_context
from stickslip.basins.early import Options, classify_state
from stickslip.model.library import load_model

BELT = load_model("belt")

#: bSTAB's feature (features_friction.m): max |x'| after t* = t_end − 100 above 0.2 is the cycle.
FEATURE_THRESHOLD = 0.2

#: bSTAB's published case (setup_friction.m: x ∈ [−2, 2], x' ∈ [0, 2], N = 5000 uniform, 500 time
#: units): FP 0.304 ± 0.0065, LC 0.696 (bSTAB-M results as reproduced by pyBasin,
#: tests/integration/friction/main_friction_case1.json), and its driving-velocity study
#: (main_friction_v_study.json) at two of its values.
BSTAB_CASE1_FP = (0.304, 0.0065051364320819587)
BSTAB_V_STUDY_FP = {1.4: (0.213, 0.0057901813443103833), 1.7: (0.4922, 0.007070207351980563)}


def long_run_label(s0, t_end=1000.0):
    """Independent classification: one plain `simulate` of 1000 time units, bSTAB's feature over
    its last 100."""
    traj = stickslip.simulate(BELT, t_end, ic=s0, sample_rate=10)
    feature = np.max(np.abs(traj.states[traj.t >= t_end - 100.0, 1]))
    return "periodic" if feature > FEATURE_THRESHOLD else "equilibrium"


def test_bstab_templates_reach_steady_sliding_and_the_stick_slip_cycle():
    ctx = make_context(BELT)
    fp = classify_state(ctx, BELT, np.array([0.1, 0.1]), [], Options())
    assert fp.verdict == "equilibrium" and fp.decided_by == "linear" and fp.t_decided < 200.0
    lc = classify_state(ctx, BELT, np.array([2.0, 2.0]), [], Options())
    assert lc.verdict == "periodic" and lc.decided_by == "period-rule"
    # the cycle against the verdict on a plain 500-unit run from the same state
    ref = attractor(stickslip.simulate(BELT, 500.0, ic=[2.0, 2.0], sample_rate=20), 300.0)
    assert ref.attractor == "periodic" and ref.period_count == 1
    assert lc.cycle.period == pytest.approx(ref.period_s, rel=1e-5)
    assert lc.cycle.multiplicity == 1 and lc.cycle.stick_fraction > 0.0
    # stick phases end at breakaway x_b = μs − 2ξV = 0.85 (docs/models/belt.md): the cycle passes there
    assert lc.cycle.peaks[0] > 0.85


def test_labels_equal_long_runs_state_by_state():
    res = basin_stability(BELT, box(BELT, {"x": (0.5, 2.5), "dx": (-2.0, 0.0)}, n=300, seed=1), t_end=500.0,
                          executor="serial")
    labels = res.labels()
    states = res.to_xarray()["initial_state"].values
    truth = np.array([long_run_label(s) for s in states])
    assert set(truth) == {"equilibrium", "periodic"}
    assert np.array_equal(labels, truth)
    p = np.mean(truth == "equilibrium")
    assert res.fractions["equilibrium"] == p
    assert res.standard_errors["equilibrium"] == pytest.approx(math.sqrt(p * (1 - p) / 300), rel=1e-12)
    # every state stopped early: none needed the whole 500 time units
    assert float(res.to_xarray()["t_decided"].max()) < 500.0


def _within(p, se, ref, ref_se, k=3.0):
    return abs(p - ref) <= k * math.hypot(se, ref_se)


def test_fractions_agree_with_bstab_published_case():
    res = basin_stability(BELT, box(BELT, {"x": (-2.0, 2.0), "dx": (0.0, 2.0)}, n=5000, seed=0), t_end=500.0)
    p, se = res.fractions["equilibrium"], res.standard_errors["equilibrium"]
    assert set(res.names) == {"equilibrium", "periodic"}
    assert _within(p, se, *BSTAB_CASE1_FP), (p, se)


@pytest.mark.slow
def test_driving_velocity_study_agrees_with_bstab():
    values = sorted(BSTAB_V_STUDY_FP)
    res = basin_stability(BELT, box(BELT, {"x": (-2.0, 2.0), "dx": (0.0, 2.0)}, n=5000), param="contact.0.drive",
                          values=values, t_end=500.0)
    for i, v in enumerate(values):
        p, se = res.fractions["equilibrium"][i], res.standard_errors["equilibrium"][i]
        assert _within(p, se, *BSTAB_V_STUDY_FP[v]), (v, p, se)
