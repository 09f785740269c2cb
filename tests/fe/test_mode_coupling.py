"""The mode-coupling diagram: Hoffmann's closed form (onset at μ = 1, ω = √2), branches, the command."""

import json
import math

import numpy as np
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.model.library import load_model
from stickslip.stability.mode_coupling import mode_coupling


def test_hoffmann_onset_and_branches():
    result = mode_coupling(load_model("hoffmann"), np.linspace(0.05, 1.45, 15), 3.0)
    assert len(result.onsets) == 1
    onset = result.onsets[0]
    assert abs(onset["mu"] - 1.0) < 1e-8
    # at the exceptional point ω² = 2 ± √(1 − μ): μ within 1e-10 of 1 moves ω by up to √1e-10 / (2√2) ≈ 3.5e-6
    assert abs(onset["angular_frequency"] - math.sqrt(2.0)) < 1e-5
    # below the onset two branches ω² = 2 ± √(1 − μ), each followed as one branch
    below = result.mu < 1.0
    for sign in (1, -1):
        exact = np.sqrt(2.0 + sign * np.sqrt(1.0 - result.mu[below]))
        assert any(np.allclose(result.eigenvalues[below, j].imag, exact, rtol=1e-12) for j in range(2))
    assert not result.unstable[below].any() and result.unstable[~below].sum() == (~below).sum()
    ds = result.to_xarray()
    assert ds["growth_rate"].shape == (15, 2) and json.loads(ds.attrs["onsets"])[0]["partner"] is not None


def test_command(tmp_path):
    out = tmp_path / "mc.nc"
    result = CliRunner().invoke(app, ["mode-coupling", "--model", "hoffmann", "--mu", "0.1:1.3:7", "--max-frequency",
                                      "3", "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output)
    assert abs(summary["critical_mu"] - 1.0) < 1e-8 and (tmp_path / "mc.png").exists()
    bad = CliRunner().invoke(app, ["mode-coupling", "--model", "hoffmann", "--mu", "1,0.5", "--max-frequency", "3",
                                   "--out", str(tmp_path / "b.nc")])
    assert bad.exit_code == 2 and "increasing" in bad.output


def test_onset_labels_one_per_mu_and_apart():
    import matplotlib

    matplotlib.use("Agg")
    from stickslip.plot.fe import plot_mode_coupling
    from stickslip.stability.mode_coupling import ModeCoupling

    mu = np.linspace(0.0, 1.0, 5)
    lam = np.tile(np.array([-0.1 + 1j, -0.1 + 2j, -0.1 + 3j]), (5, 1))
    onsets = [{"mu": 0.5, "angular_frequency": 1.0, "branch": 0, "partner": 1},
              {"mu": 0.5, "angular_frequency": 2.0, "branch": 1, "partner": 0},
              {"mu": 0.52, "angular_frequency": 3.0, "branch": 2, "partner": None}]
    fig = plot_mode_coupling(ModeCoupling("m", mu, lam, 4.0, onsets))
    texts = [(t.get_text(), t.xyann) for t in fig.axes[1].texts]
    # the first two onsets print as one μ: one label; the third a label of its own, raised above it
    assert [t for t, _ in texts] == ["μ = 0.5", "μ = 0.52"]
    assert texts[0][1][1] < texts[1][1][1]
