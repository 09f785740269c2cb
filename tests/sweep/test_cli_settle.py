"""``stickslip sweep`` and ``stickslip bifurcation`` with --settle / --cap."""

import json

from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.sweep import load_sweep

runner = CliRunner()


def test_cap_needs_settle(tmp_path):
    result = runner.invoke(app, ["sweep", "--grid", "N=30,50", "--cap", "100", "--out", str(tmp_path / "s.nc")])
    assert result.exit_code == 2 and "give --settle" in result.output
    result = runner.invoke(app, ["bifurcation", "--range", "30,50", "--settle", "--cap", "5", "--t-end", "10",
                                 "--out", str(tmp_path / "b.nc")])
    assert result.exit_code == 2 and "cap = 5.0 s must be a finite number ≥ t_end = 10.0 s" in result.output


def test_settle_runs_each_point_until_settled(tmp_path):
    out = tmp_path / "s.nc"
    result = runner.invoke(app, ["sweep", "--grid", "Omega=12,5", "--settle", "--t-end", "20", "--t-from", "10",
                                 "--cap", "60", "--executor", "serial", "--no-plot", "--no-progress", "--json",
                                 "--out", str(out)])
    assert result.exit_code == 0, result.output
    ds = load_sweep(out)
    spec = json.loads(ds.attrs["spec"])
    assert spec["settle"] is True and spec["cap"] == 60.0
    # each run went on past the first 20 s only as long as it needed, and never past the cap
    assert all(20.0 <= t <= 60.0 for t in ds["t_reached"].values)
    assert ds["settle_time"].notnull().any()
