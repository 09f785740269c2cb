"""Region maps (Figs. 8, 9) on the true cells of their grid."""

import json

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr
from matplotlib.collections import QuadMesh

from stickslip.plot.regions import REGION_STYLE, plot_regions

from .figdata import capture_saved_figures, legend_entries, mesh_edges, top_cell_colours


def _region_map(omega):
    """Two models over N = 10, 20, 30 N and the given Ω: region I below Ω = 3, III above."""
    N = np.array([10.0, 20.0, 30.0])
    W = np.asarray(omega, float)
    region = np.broadcast_to(np.where(W < 3.0, 1, 3), (2, 3, W.size)).astype(np.int8)
    omax = np.full((2, 3), W[W < 3.0].max())
    ds = xr.Dataset({"region": (("model", "N", "Omega"), region),
                     "stick_slip_omega_max": (("model", "N"), omax)},
                    coords={"model": ["full", "rotation"], "N": N, "Omega": W})
    ds.attrs.update(parameters=json.dumps({"mu_k": 0.2, "delta_mu": 0.1, "alpha": 5.0}), t_end=300.0, t_from=200.0)
    return ds


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def test_region_cells_span_their_true_edges_and_no_negative_omega():
    ax = plot_regions(_region_map([0.5, 2.0, 5.0, 8.5, 12.0]))
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    xe, ye = mesh_edges(mesh)
    np.testing.assert_allclose(xe, [5.0, 15.0, 25.0, 35.0])
    np.testing.assert_allclose(ye, [0.0, 1.25, 3.5, 6.75, 10.25, 13.75])
    assert ax.get_ylim()[0] == 0.0


def test_region_map_of_an_unsorted_grid_keeps_each_region_at_its_omega():
    ax = plot_regions(_region_map([5.0, 0.5, 2.0]))
    cells = top_cell_colours(ax)  # rows: Ω cells from the bottom
    entries = legend_entries(ax)
    np.testing.assert_allclose(cells[0, 0], entries[REGION_STYLE[1][1]].get_facecolor())  # Ω = 0.5: region I
    np.testing.assert_allclose(cells[2, 0], entries[REGION_STYLE[3][1]].get_facecolor())  # Ω = 5: region III


def test_regions_figure_title_gives_alpha_with_its_unit(tmp_path, monkeypatch):
    from stickslip.plot.regions import save_regions_figure

    saved = capture_saved_figures(monkeypatch)
    save_regions_figure(_region_map([0.5, 2.0, 5.0]), tmp_path / "r.png")
    assert "α = 5 s/m" in saved[0].get_suptitle()
