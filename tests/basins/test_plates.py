"""The plates' Region II (N = 50 N, Ω = 8.5 rad/s): steady sliding and a stick-slip cycle coexist
(docs/sweeps.md); the basin study finds both, each label confirmed by a direct long run."""

import numpy as np
import pytest

import stickslip
from stickslip.attractors import attractor
from stickslip.basins import basin_stability, grid
from stickslip.model.library import load_model

PLATES = load_model("two-plates").replace(N=50.0, Omega=8.5)
#: The plates' `far` state (docs/sweeps.md): q = 0 with the upper plate carried by the disc,
#: ẏ1 = Ω r = 1.7 m/s.
FAR_DY1 = 8.5 * 0.2
#: docs/settling.md: from `far` the run settles on a period-1 stick-slip orbit of 2.743527 Hz.
FAR_FREQUENCY_HZ = 2.743527


@pytest.fixture(scope="module")
def region_two():
    """A 5 × 5 grid of (φ, φ̇) around the far state."""
    states = grid(PLATES, {"phi": (-0.2, 0.2), "dphi": (-5.0, 5.0)}, 5, base="zero", fixed={"dy1": FAR_DY1})
    return basin_stability(PLATES, states, t_end=600.0, executor="serial")


def direct(s0, t_end=1000.0):
    """The verdict of a plain run from s0, on its last 100 s."""
    return attractor(stickslip.simulate(PLATES, t_end, ic=s0, sample_rate=200), t_end - 100.0)


def test_both_attractors_are_found(region_two):
    assert region_two.complete
    assert set(region_two.names) == {"equilibrium", "periodic"}
    table = {a["name"]: a for a in region_two.attractors()}
    cycle = table["periodic"]
    assert cycle["frequency"] == pytest.approx(FAR_FREQUENCY_HZ, rel=1e-5)
    assert cycle["multiplicity"] == 1 and cycle["stick_fraction"] > 0.0
    eq = table["equilibrium"]
    assert float(region_two.to_xarray()["steady_sliding_stable"]) == 1
    assert eq["state"]["phi"] == pytest.approx(float(region_two.to_xarray()["steady_sliding"].sel(state_name="phi")))
    assert 0.0 < region_two.fractions["periodic"] < 1.0


def test_the_far_state_reaches_the_cycle(region_two):
    ds = region_two.to_xarray()
    s = ds["initial_state"].values
    far = np.flatnonzero((s[:, 4] == 0.0) & (s[:, 10] == 0.0))
    assert far.size == 1 and region_two.labels()[far[0]] == "periodic"


@pytest.mark.parametrize("name", ["equilibrium", "periodic"])
def test_labels_are_confirmed_by_direct_long_runs(region_two, name):
    ds = region_two.to_xarray()
    labels = region_two.labels()
    picked = np.flatnonzero(labels == name)[[0, -1]]
    for i in picked:
        verdict = direct(ds["initial_state"].values[i])
        assert verdict.attractor == name, (i, verdict.attractor, verdict.evidence.get("reason"))
        if name == "periodic":
            assert verdict.fundamental_frequency_hz == pytest.approx(FAR_FREQUENCY_HZ, rel=1e-5)
