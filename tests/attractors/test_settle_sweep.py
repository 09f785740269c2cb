"""Sweeps that settle every point: verdict, settle time and cap recorded in the file."""

import numpy as np
import pytest

import stickslip
from stickslip import OUTCOMES
from stickslip.attractors import simulate_until_settled
from stickslip.sweep import load_sweep, sweep


def test_settling_sweep_records_verdicts_settle_times_and_the_cap(tmp_path):
    out = tmp_path / "s.nc"
    base = stickslip.Parameters(Omega=0.5)
    r = sweep({"N": [50.0, 110.0]}, base, out=out, executor="serial", settle=True, cap=1500.0)
    ds = load_sweep(out)
    assert ds.attrs["settle"] == 1 and ds.attrs["cap"] == 1500.0
    assert [OUTCOMES[int(c)] for c in ds["attractor"].values] == ["periodic", "periodic"]
    assert ds["period_count"].values.tolist() == [1.0, 2.0] and np.all(ds["settled"].values == 1)
    st = ds["settle_time"].values
    assert np.all((st > 200.0) & (st <= 1500.0)) and np.array_equal(st, ds["t_reached"].values)
    # N = 50 N: the shot orbit's frequency (test_settle); N = 110 N: the direct settled run's
    assert ds["fundamental_frequency"].values[0] == pytest.approx(1.53810, rel=1e-4)
    direct = simulate_until_settled(base.replace(N=110.0), sample_rate=200.0, keep="window")
    assert ds["fundamental_frequency"].values[1] == direct.attractor.fundamental_frequency_hz
    assert r.outcomes().tolist() == ["periodic", "periodic"] and np.all(ds["stick_fraction"].values > 0)


def test_fixed_length_sweep_says_unsettled():
    r = sweep({"N": [50.0, 70.0]}, stickslip.Parameters(Omega=0.5), executor="serial")
    ds = r.dataset
    assert ds.attrs["settle"] == 0 and "cap" not in ds.attrs
    assert [OUTCOMES[int(c)] for c in ds["attractor"].values] == ["unsettled", "unsettled"]
    assert np.all(np.isnan(ds["fundamental_frequency"].values)) and np.all(np.isnan(ds["settle_time"].values))
    assert np.all(np.isfinite(ds["dominant_frequency"].values))
    assert r.outcomes().tolist() == ["unsettled", "unsettled"]


def test_cap_below_the_first_run_is_refused():
    with pytest.raises(stickslip.SweepError, match="cap"):
        sweep({"N": [50.0]}, settle=True, cap=100.0, t_end=200.0, executor="serial")
