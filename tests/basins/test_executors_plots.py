"""The executors give the same labels; the figures draw every kind of study, partial ones too."""

import numpy as np
import pytest

from stickslip.basins import basin_stability, box, from_csv, grid
from stickslip.model.library import load_model
from stickslip.plot.basins import label_colors, plot_basins, plot_fractions, plot_parameter_study, save_basins_figure

BELT = load_model("belt")
STATES = box(BELT, {"x": (-2.0, 2.0), "dx": (-2.0, 2.0)}, n=60, seed=9)


@pytest.fixture(scope="module")
def serial():
    return basin_stability(BELT, STATES, executor="serial")


@pytest.mark.parametrize("executor", ["processes", "dask"])
def test_executors_give_the_serial_labels(serial, executor):
    res = basin_stability(BELT, STATES, executor=executor, workers=1, batch_size=7)
    assert np.array_equal(res.labels(), serial.labels())
    assert res.fractions == serial.fractions


def test_figures_of_every_layout(tmp_path, serial):
    g = basin_stability(BELT, grid(BELT, {"x": (-2.0, 2.0), "dx": (-2.0, 2.0)}, [6, 5]), executor="serial")
    one_axis = basin_stability(BELT, box(BELT, {"x": (-2.0, 2.0)}, n=10), executor="serial")
    (tmp_path / "ics.csv").write_text("x,dx\n2,2\n0.1,0.1\n")
    ics = basin_stability(BELT, from_csv(BELT, tmp_path / "ics.csv"), executor="serial")
    study = basin_stability(BELT, box(BELT, {"x": (-2.0, 2.0), "dx": (-2.0, 2.0)}, n=20), executor="serial",
                            param="contact.0.drive", values=[1.4, 1.6])
    for i, res in enumerate((serial, g, one_axis, ics, study)):
        path = save_basins_figure(res, tmp_path / f"f{i}.png")
        assert path.stat().st_size > 10_000
    ax = plot_basins(g)
    assert ax.get_xlabel() == "x" and ax.get_ylabel() == "dx"
    assert [t.get_text() for t in plot_fractions(serial).get_xticklabels()] == serial.names
    assert plot_parameter_study(study).get_xlabel() == "contact.0.drive"


def test_a_partial_study_draws_its_classified_states(serial, tmp_path):
    ds = serial.to_xarray().copy(deep=True)
    ds["label"].values[::2] = -1
    ds["done"].values[::2] = 0
    assert save_basins_figure(ds, tmp_path / "partial.png").stat().st_size > 10_000


def test_label_colours_are_fixed_per_name():
    a = label_colors(["equilibrium", "periodic", "periodic-2", "unsettled"])
    b = label_colors(["periodic-2", "unsettled", "equilibrium"])
    assert a[2] == b[0] and a[3] == b[1] and a[0] == b[2] and len(set(a)) == 4


def test_dask_waits_through_poll_timeouts(serial, monkeypatch):
    """Batches that outlast the polling interval (Ctrl-C is checked between polls) are waited for."""
    from stickslip import parallel

    monkeypatch.setattr(parallel, "POLL_S", 1e-4)
    res = basin_stability(BELT, STATES, executor="dask", workers=1, batch_size=20)
    assert np.array_equal(res.labels(), serial.labels())
