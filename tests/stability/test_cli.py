"""``stickslip stability`` and ``stickslip stability-map``."""

import json

import xarray as xr
from typer.testing import CliRunner

from stickslip.cli import app

runner = CliRunner()


def test_stability_json():
    result = runner.invoke(app, ["stability", "--N", "50", "--omega", "12", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert set(data) >= {"equilibrium", "eigenvalues", "max_real_part", "stable", "wall_time_s", "compile_time_s"}
    assert data["compile_time_s"] >= 0.0
    assert set(data["equilibrium"]) == {"x1", "y1", "x2", "y2", "phi", "psi"}
    assert len(data["eigenvalues"]) == 12 and len(data["eigenvalues"][0]) == 2
    assert data["stable"] is True


def test_stability_table_and_options(tmp_path):
    config = tmp_path / "p.toml"
    config.write_text("[parameters]\nk_px = 400.0\n")
    result = runner.invoke(app, ["stability", "--model", "rotation", "--mu-k", "0.3", "--delta-mu", "0.2",
                                 "--alpha", "3", "--set", "c_pphi=0.2", "--config", str(config)])
    assert result.exit_code == 0, result.output
    assert "growth rate" in result.stdout and "phi" in result.stdout


def test_stability_errors():
    result = runner.invoke(app, ["stability", "--omega", "0"])
    assert result.exit_code == 2
    assert "Omega = 0" in result.output
    result = runner.invoke(app, ["stability", "--model", "nonsense"])
    assert result.exit_code == 2 and "unknown model" in result.output
    result = runner.invoke(app, ["stability", "--set", "N=-1"])
    assert result.exit_code == 2 and "must be > 0" in result.output


def test_stability_map_writes_netcdf_and_figure(tmp_path):
    out = tmp_path / "m.nc"
    result = runner.invoke(app, ["stability-map", "--N-points", "6", "--omega-points", "12", "--family",
                                 "model=full,rotation", "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert len(data["members"]) == 2
    assert out.exists() and out.with_suffix(".png").exists()
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds["max_real_part"].shape == (2, 6, 12)
        assert ds["boundary_omega"].attrs["units"] == "rad/s"
        assert "param_mu_k" in ds.attrs


def test_stability_map_errors(tmp_path):
    result = runner.invoke(app, ["stability-map", "--family", "foo=1", "--out", str(tmp_path / "m.nc")])
    assert result.exit_code == 2 and "unknown family parameter" in result.output
    result = runner.invoke(app, ["stability-map", "--N-points", "1", "--out", str(tmp_path / "m.nc")])
    assert result.exit_code == 2 and "N-points" in result.output
    result = runner.invoke(app, ["stability-map", "--out", str(tmp_path / "m.txt")])
    assert result.exit_code == 2 and ".nc" in result.output
