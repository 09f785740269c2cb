"""The step-size study (Sect. 4.2.1): error measures, outputs, CLI."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.studies import PAPER_TABLE2, run_timestep_study
from stickslip.studies.timestep import period_waveform


def test_period_waveform_aligns_phase():
    t = np.linspace(0.0, 10.0, 20001)
    f = 2.0
    a = np.sin(2 * np.pi * f * t)
    b = np.sin(2 * np.pi * f * (t - 0.123))  # same orbit, shifted in time
    wa = period_waveform(t, a, a, 0.0, 1 / f)
    wb = period_waveform(t, b, b, 0.0, 1 / f)
    assert np.abs(wa - wb).max() < 1e-3  # linear interpolation of the 5e-4 s sampling
    # the waveform starts at the up-crossing: sin(2π τ)
    tau = np.arange(wa.size) / wa.size
    assert np.abs(wa - np.sin(2 * np.pi * tau)).max() < 1e-3
    assert period_waveform(t, np.zeros_like(t), np.zeros_like(t), 0.5, 1.0) is None


@pytest.fixture(scope="module")
def small_study():
    # 6 s, two steps, one event tolerance: structure and consistency, not the paper's numbers
    return run_timestep_study((1e-3, 1e-4), event_rtols=(1e-6,), t_end=6.0)


def test_study_rows_and_errors(small_study):
    s = small_study
    assert [r.dt for r in s.fixed("aeom")] == [1e-3, 1e-4]
    assert [r.dt for r in s.fixed("naeom")] == [1e-3, 1e-4]
    assert s.reference.errors == {"freq_error": 0.0, "phi_pp_error": 0.0, "phi_shape_error": 0.0, "F_shape_error": 0.0}
    for r in s.runs:
        assert r.wall_time_s > 0 and r.steps > 0 and r.stick_phases > 0
    # the smaller step is closer to the converged solution, for both methods
    for m in ("aeom", "naeom"):
        coarse, fine = s.fixed(m)
        assert fine.errors["phi_shape_error"] < coarse.errors["phi_shape_error"]
        assert fine.paper_time_s == PAPER_TABLE2[1e-4][("aeom", "naeom").index(m)]


def test_study_outputs(small_study, tmp_path):
    from stickslip.plot.timestep import save_timestep_figures

    files = small_study.save(tmp_path)
    figs = save_timestep_figures(small_study, tmp_path)
    data = json.loads(files["json"].read_text())
    assert len(data["runs"]) == 5 and data["reference"]["method"] == "event"
    md = files["markdown"].read_text()
    assert "| aeom | 0.0001 | 31.36 |" in md and "| naeom | 0.0001 | 9,581.69 |" in md
    for path in figs.values():
        assert path.stat().st_size > 10_000


def test_cli_quick(tmp_path):
    res = CliRunner().invoke(app, ["study", "timestep", "--quick", "--t-end", "4", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "timestep.json").read_text())
    assert sorted({r["dt"] for r in data["runs"] if r["dt"]}) == [1e-4, 1e-3, 0.01, 0.1]
    assert (tmp_path / "fig5_aeom.png").exists() and (tmp_path / "fig6_naeom.png").exists()
