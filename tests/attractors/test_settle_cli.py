"""`stickslip simulate --t-end auto`: the run is extended until settled and says so."""

import json

import pytest
from typer.testing import CliRunner

from stickslip import load_trajectory
from stickslip.attractors import run_summary
from stickslip.cli import app

runner = CliRunner()


def test_auto_run_length_reports_the_settled_orbit(tmp_path):
    out = tmp_path / "auto.nc"
    res = runner.invoke(app, ["simulate", "--N", "50", "--omega", "0.5", "--t-end", "auto", "--sample-rate", "200",
                              "--no-plot", "--json", "--out", str(out)])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert (s["attractor"], s["settled"], s["period_count"]) == ("periodic", True, 1)
    assert s["fundamental_frequency_hz"] == pytest.approx(1.53810, rel=1e-4)   # the shot orbit, test_settle
    assert s["settle"]["cap_s"] == 2000.0 and s["settle_time_s"] == s["t_end_s"]
    traj = load_trajectory(out)
    assert traj.t[0] == 0.0 and traj.t[-1] == s["settle_time_s"]                # the whole run is kept
    assert traj.options["settle"]["settled"] and run_summary(traj)["attractor"] == "periodic"


def test_cap_stops_an_unsettled_run(tmp_path):
    res = runner.invoke(app, ["simulate", "--N", "50", "--omega", "0.5", "--t-end", "auto", "--cap", "300",
                              "--sample-rate", "100", "--no-plot", "--json", "--out", str(tmp_path / "c.nc")])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert (s["attractor"], s["settled"], s["t_end_s"], s["settle_time_s"]) == ("unsettled", False, 300.0, None)


@pytest.mark.parametrize("args, words", [
    (["--t-end", "soon"], "--t-end soon: give a time in seconds or auto"),
    (["--t-end", "auto", "--steady-from", "10"], "--steady-from and --t-end auto both set the steady window"),
    (["--t-end", "auto", "--cap", "-5"], "cap = -5.0 s must be a finite number > 0"),
])
def test_bad_run_length_is_one_line_and_exit_2(tmp_path, args, words):
    res = runner.invoke(app, ["simulate", *args, "--no-plot", "--out", str(tmp_path / "x.nc")])
    assert res.exit_code == 2
    assert words in res.output and "Traceback" not in res.output
    assert len(res.output.strip().splitlines()) == 1
