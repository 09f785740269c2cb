"""``stickslip sweep`` and ``stickslip bifurcation`` on models other than the plates."""

import json

from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.sweep import load_sweep

runner = CliRunner()
RUN = ["--t-end", "20", "--sample-rate", "50", "--executor", "serial", "--no-progress", "--json"]


def test_sweep_of_the_belt_over_its_drive_resumes(tmp_path):
    out = tmp_path / "belt.nc"
    args = ["sweep", "--model", "belt", "--grid", "contact.0.drive=0.6,2.4", "--plot", "intensity",
            "--out", str(out)] + RUN
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["points_computed"] == 2
    ds = load_sweep(out)
    assert ds["done"].dims == ("contact.0.drive.0",) and ds.attrs["observed"] == "x"
    assert out.with_suffix(".png").exists()
    again = runner.invoke(app, args)
    assert again.exit_code == 0 and json.loads(again.stdout)["points_computed"] == 0


def test_bifurcation_of_hoffmann_over_mu_k(tmp_path):
    out = tmp_path / "h.nc"
    result = runner.invoke(app, ["bifurcation", "--model", "hoffmann", "--param", "contact.0.friction.mu_k",
                                 "--range", "0.3,0.6", "--ic", "near", "--out", str(out)] + RUN)
    assert result.exit_code == 0, result.output
    assert load_sweep(out)["done"].dims == ("contact.0.friction.mu_k",)


def test_model_sweep_errors(tmp_path):
    out = str(tmp_path / "x.nc")
    result = runner.invoke(app, ["bifurcation", "--model", "belt", "--out", out] + RUN)  # --param N by default
    assert result.exit_code == 2 and "cannot sweep 'N'" in result.output
    result = runner.invoke(app, ["bifurcation", "--model", "belt", "--param", "contact.0.drive", "--range", "1,2",
                                 "--omega", "3", "--out", out] + RUN)
    assert result.exit_code == 2 and "--omega is a parameter of the two plates" in result.output
    result = runner.invoke(app, ["sweep", "--model", "belt", "--grid", "contact.0.drive=1,2", "--plot",
                                 "intensity_r_phi", "--out", out] + RUN)
    assert result.exit_code == 2 and "--plot intensity_r_phi" in result.output
    result = runner.invoke(app, ["sweep", "--model", "belt", "--grid", "contact.0.drive=1,2", "--set",
                                 "contact.0.drive=3", "--out", out] + RUN)
    assert result.exit_code == 2 and "contact.0.drive" in result.output
