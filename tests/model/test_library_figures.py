"""The model-library figures: the study computes, the plots draw, the script writes the PNGs."""

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from stickslip.studies import models as studies


def test_script_writes_the_three_figures(tmp_path, capsys):
    assert studies.main([str(tmp_path)]) == 0
    for name in ("belt.png", "hoffmann.png", "popp-stelter.png"):
        assert (tmp_path / name).stat().st_size > 20_000
    out = capsys.readouterr().out
    assert "flutter onset mu = 1.0000000000" in out and "flutter onset mu = 1.0200000000" in out
    assert studies.main([]) == 2  # no folder: usage, exit code 2


def test_hoffmann_sweep_agrees_with_its_characteristic_polynomial():
    sweep = studies.hoffmann_sweep(np.linspace(0.05, 1.95, 20), damping=(0.2, 0.02))
    for lam, poly in zip(sweep.eigenvalues, sweep.polynomial_eigenvalues):
        cost = np.abs(lam[:, None] - poly[None, :])
        assert cost[linear_sum_assignment(cost)].max() < 1e-9
    # Hurwitz: a3 a2 a1 − a1² − a3² (3 + μ) = 0 with a3 = 0.22, a2 = 4.004, a1 = 0.44 (test_library_hoffmann)
    assert sweep.onset == pytest.approx((0.22 * 4.004 * 0.44 - 0.44 ** 2 - 3 * 0.22 ** 2) / 0.22 ** 2, abs=1e-8)
    with pytest.raises(studies.OnsetError, match="widen the range"):
        studies.flutter_onset(lo=0.0, hi=0.5)


def test_belt_templates_are_classified_as_bstab_labels_them():
    belt = studies.belt_attractors(t_end=450.0, t_star=400.0, sample_rate=5.0)
    assert belt.feature["FP"] <= 0.2 < belt.feature["LC"]
    assert belt.breakaway == pytest.approx(0.85)


def test_popp_stelter_orbit_has_both_contacts_sticking():
    traj = studies.popp_stelter_orbit(t_end=60.0, sample_rate=50.0)
    late = traj.t > 40.0
    assert np.any(traj.mode[late] & 1) and np.any(traj.mode[late] & 2)
