"""`stickslip simulate`: defaults, JSON, files, and one-line errors for bad input."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from stickslip import load_trajectory
from stickslip.cli import app

runner = CliRunner()

JSON_KEYS = {"settled", "attractor", "period_count", "fundamental_frequency_hz", "dominant_frequency_hz",
             "settle_time_s", "evidence", "status", "model", "parameters", "t_end_s", "steady_from_s",
             "stick_fraction", "n_transitions", "phi_min", "phi_max", "steps", "wall_time_s", "method"}


def run(*args):
    return runner.invoke(app, ["simulate", *args])


def test_json_summary_and_netcdf_round_trip(tmp_path):
    out = tmp_path / "a.nc"
    res = run("--t-end", "5", "--json", "--out", str(out))
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout.strip().splitlines()[-1])
    assert set(summary) == JSON_KEYS
    assert summary["method"] == "event" and summary["steps"] > 0
    assert (tmp_path / "a.png").stat().st_size > 10_000
    traj = load_trajectory(out)
    assert traj.params.N == 50.0 and traj.params.Omega == 5.0
    assert traj.steady.n_transitions == summary["n_transitions"]
    assert np.isclose(traj.steady.phi_max, summary["phi_max"])


def test_human_summary_and_options(tmp_path):
    res = run("--t-end", "3", "--N", "30", "--omega", "0.5", "--set", "k_px=400", "--model", "x",
              "--no-plot", "--out", str(tmp_path / "b.nc"))
    assert res.exit_code == 0, res.output
    assert "fundamental frequency" in res.output
    traj = load_trajectory(tmp_path / "b.nc")
    assert (traj.params.N, traj.params.Omega, traj.params.k_px, traj.model) == (30.0, 0.5, 400.0, "x")
    assert not (tmp_path / "b.png").exists()


def test_config_file_and_continuation(tmp_path):
    cfg = tmp_path / "p.toml"
    cfg.write_text("[parameters]\nN = 70\nalpha = 2\n")
    first = tmp_path / "first.nc"
    assert run("--t-end", "2", "--config", str(cfg), "--no-plot", "--out", str(first)).exit_code == 0
    second = tmp_path / "second.nc"
    res = run("--t-end", "1", "--config", str(cfg), "--ic", str(first), "--no-plot", "--out", str(second))
    assert res.exit_code == 0, res.output
    a, b = load_trajectory(first), load_trajectory(second)
    assert np.allclose(b.states[0], a.states[-1])
    assert b.params.alpha == 2.0


@pytest.mark.parametrize(
    "args, words",
    [
        (["--N", "-5"], "must be > 0"),
        (["--N", "0"], "must be > 0"),
        (["--set", "m_p=-1"], "m_p"),
        (["--set", "alpha=nan"], "not finite"),
        (["--set", "bogus=1"], "unknown parameter"),
        (["--set", "N"], "NAME=VALUE"),
        (["--model", "z"], "unknown model"),
        (["--method", "euler"], "unknown method"),
        (["--t-end", "-1"], "t_end"),
        (["--rtol", "0"], "rtol"),
        (["--rtol", "1e-20"], "rtol"),
        (["--dt", "-0.1"], "dt"),
        (["--ic", "somewhere"], "unknown initial condition"),
        (["--ic", "1,2,3"], "12 entries"),
        (["--ic", "missing.nc"], "does not exist"),
        (["--config", "missing.toml"], "does not exist"),
        (["--out", "run.txt"], ".nc"),
    ],
)
def test_bad_input_gives_one_line_error(args, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = run("--t-end", "1", "--no-plot", *args)
    assert res.exit_code != 0
    text = res.output
    assert words in text, text
    assert "Traceback" not in text


def test_file_that_is_not_ours(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "junk.nc").write_text("not a netcdf file")
    res = run("--t-end", "1", "--no-plot", "--ic", "junk.nc")
    assert res.exit_code != 0 and "not a stickslip NetCDF file" in res.output
    import xarray as xr

    xr.Dataset({"a": ("x", [1.0, 2.0])}).to_netcdf(tmp_path / "other.nc", engine="h5netcdf")
    res = run("--t-end", "1", "--no-plot", "--ic", "other.nc")
    assert res.exit_code != 0 and "not a stickslip trajectory" in res.output


def test_locked_dof_in_initial_state_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = run("--t-end", "1", "--no-plot", "--model", "rotation", "--ic", ",".join(["0.001"] + ["0"] * 11))
    assert res.exit_code != 0 and "locked" in res.output
