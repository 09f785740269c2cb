"""Sweeps over the parameter paths of models other than the plates."""

import json
import math

import numpy as np
import pytest

import stickslip
from stickslip.analysis.intensity import intensity
from stickslip.analysis.outcome import STOPPED, outcome_names
from stickslip.model.library import load_model
from stickslip.stability.equilibrium import steady_sliding
from stickslip.sweep import load_sweep, sweep
from stickslip.sweep.spec import SweepSpec

DRIVES = [0.6, 1.5, 2.4]
RUN = dict(t_end=60.0, t_from=30.0, sample_rate=100.0, ic="zero")


@pytest.fixture(scope="module")
def belt_sweep(tmp_path_factory):
    out = tmp_path_factory.mktemp("belt") / "belt.nc"
    return sweep({"contact.0.drive": DRIVES}, "belt", out=out, executor="serial", **RUN)


def test_belt_sweep_equals_single_runs(belt_sweep):
    ds = belt_sweep.to_xarray()
    assert ds["done"].dims == ("contact.0.drive.0",)  # the model's own name of the path is the coordinate
    np.testing.assert_array_equal(ds["contact.0.drive.0"].values, DRIVES)
    assert ds.attrs["observed"] == "x" and json.loads(ds.attrs["system"])["name"] == "belt"
    for i, v in enumerate(DRIVES):
        model = load_model("belt").replace(**{"contact.0.drive": v})
        traj = stickslip.simulate(model, RUN["t_end"], steady_from=RUN["t_from"], ic="zero",
                                  sample_rate=RUN["sample_rate"])
        sel = traj.t >= RUN["t_from"]
        x = traj.states[sel, 0]
        point = ds.isel({"contact.0.drive.0": i})
        assert float(point["x_min"]) == x.min() and float(point["x_max"]) == x.max()  # the model's own coordinate
        assert float(point["stick_fraction"]) == pytest.approx(traj.steady.stick_fraction, abs=0)
        assert float(point["t_reached"]) == traj.t[-1] and float(point["steps"]) == traj.stats.steps
        ref = intensity(traj.t, traj.states[:, 0], steady_sliding(model)[0], t_from=RUN["t_from"])
        assert float(point["intensity"]) == ref


def test_belt_sweep_sticks_below_the_stability_boundary_only(belt_sweep):
    # V_c = ln(α Δμ N / 2ξ) / α = ln(10) / 2 = 1.15 for the belt file: steady sliding is unstable
    # below it (from rest the run goes to stick-slip) and stable above (it decays to sliding)
    ds = belt_sweep.to_xarray()
    stick = ds["stick_fraction"].values
    assert stick[0] > 0.0 and stick[1] == 0.0 and stick[2] == 0.0
    assert list(ds["attractor"].values[1:]) == [0.0, 0.0]  # equilibrium (steady sliding)


def test_belt_sweep_resumes_without_recomputing(belt_sweep):
    again = sweep({"contact.0.drive": DRIVES}, "belt", out=belt_sweep.path, executor="serial", **RUN)
    assert again.timings["points_computed"] == 0 and again.timings["points_resumed"] == len(DRIVES)
    back = load_sweep(belt_sweep.path)
    np.testing.assert_array_equal(back["attractor"].values, belt_sweep.to_xarray()["attractor"].values)


def test_hoffmann_sweep_over_mu_k_runs(tmp_path):
    res = sweep({"contact.0.friction.mu_k": [0.3, 0.6]}, "hoffmann", out=tmp_path / "h.nc", executor="serial",
                t_end=20.0, sample_rate=50.0, ic="near")
    ds = res.to_xarray()
    assert ds["done"].dims == ("contact.0.friction.mu_k",) and int(ds.attrs["complete"]) == 1
    assert not np.any(np.isin(outcome_names(ds["attractor"].values), STOPPED))


def test_plates_specs_read_as_before():
    spec = SweepSpec.build({"N": [10.0, 20.0]}, stickslip.Parameters())
    assert "system" not in json.loads(spec.to_json()) and spec.system is None
    assert "intensity_r_phi" in [c[0] for c in spec.columns]


@pytest.mark.parametrize("grid, options, message", [
    ({"contact.0.drive": [1.0, 2.0]}, {"ic": "far"}, "unknown initial condition 'far' of model 'belt'"),
    ({"model": ["full"]}, {}, "cannot sweep 'model'"),
    ({"contact.0.nonsense": [1.0]}, {}, "cannot sweep 'contact.0.nonsense': give a parameter"),
    ({"contact.0.normal_force": [1.0, -1.0]}, {}, "must be > 0"),
    ({"perturb_phi": [0.1]}, {}, "cannot sweep 'perturb_phi'"),
])
def test_bad_model_sweeps_are_refused(grid, options, message):
    with pytest.raises(stickslip.StickSlipError, match=message):
        SweepSpec.build(grid, "belt", **options)


def test_perturbation_of_a_model_state(tmp_path):
    res = sweep({"perturb_dx": [0.0, 0.5]}, "belt", out=tmp_path / "p.nc", executor="serial", t_end=10.0,
                sample_rate=50.0, ic="equilibrium")
    ds = res.to_xarray()
    # from steady sliding exactly nothing moves; a kick of ẋ makes the observed x move
    amp = ds["amplitude"].values
    assert math.isfinite(amp[1]) and amp[1] > 10 * abs(amp[0])
