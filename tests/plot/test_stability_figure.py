"""Stability maps (Figs. 3, 4): every shaded colour is a legend entry, every line style is
explained, the cells are the grid's true cells."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import QuadMesh

from stickslip.plot.stability import plot_stability_map, save_stability_map_figure

from .figdata import (capture_saved_figures, filled_colours, legend_entries, legend_patch_colours, make_stability_map,
                      mesh_edges, top_cell_colours)

N = np.linspace(10.0, 100.0, 10)
OMEGA = np.linspace(1.0, 10.0, 10)


def _family():
    """Δμ = 0.1, 0.2, 0.3: unstable below Ω_c = 3, 4, 5 rad/s + N/50; the last one also above
    9 rad/s (dashed boundary); no steady sliding at the three lowest Ω of the largest N for 0.3."""
    missing = np.zeros((N.size, OMEGA.size), bool)
    missing[-1, :3] = True
    return make_stability_map(N, OMEGA, [lambda n, c=c: c + n / 50.0 for c in (3.0, 4.0, 5.0)],
                              missing=[None, None, missing], upper=[None, None, lambda n: np.full(n.shape, 9.0)],
                              labels=("Δμ = 0.1", "Δμ = 0.2", "Δμ = 0.3"))


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture
def family_figure(tmp_path, monkeypatch):
    saved = capture_saved_figures(monkeypatch)
    save_stability_map_figure(_family(), tmp_path / "fig3a.png")
    (fig,) = saved
    return fig


def test_every_shaded_colour_is_a_legend_entry(family_figure):
    """The figure the CLI and `reproduce` save: no shaded area in a colour the legend does not
    name (translucent layers stacked over each other make such colours)."""
    for ax in family_figure.axes:
        if ax.get_label() == "<colorbar>":
            continue
        shaded = filled_colours(ax)
        assert shaded <= legend_patch_colours(ax), ax.get_title()
        assert all(c[3] == 1.0 for c in shaded), "translucent shading mixes into unnamed colours"


def test_dashed_boundary_is_explained_in_the_legend(family_figure):
    for ax in family_figure.axes:
        styles = {line.get_linestyle() for line in ax.get_lines()}
        handle_styles = {h.get_linestyle() for h in legend_entries(ax).values() if hasattr(h, "get_linestyle")}
        assert styles <= handle_styles, ax.get_title()
    assert any("--" in {line.get_linestyle() for line in ax.get_lines()} for ax in family_figure.axes)


def test_each_member_is_shown_with_its_own_stable_unstable_and_missing_cells(family_figure):
    smap = _family()
    titled = {ax.get_title(): ax for ax in family_figure.axes}
    for f, label in enumerate(smap.family_labels):
        ax = next(a for t, a in titled.items() if label in t)
        entries = legend_entries(ax)
        colour = {key: next(h.get_facecolor() for t, h in entries.items() if key in t)
                  for key in ("unstable", "stable")}
        cells = top_cell_colours(ax).transpose(1, 0, 2)  # (N, Ω)
        mrp = smap.max_real_part[f]
        np.testing.assert_allclose(cells[mrp > 0], np.tile(colour["unstable"], ((mrp > 0).sum(), 1)))
        np.testing.assert_allclose(cells[mrp < 0], np.tile(colour["stable"], ((mrp < 0).sum(), 1)))
        if np.isnan(mrp).any():
            none = next(h.get_facecolor() for t, h in entries.items() if "no steady sliding" in t)
            np.testing.assert_allclose(cells[np.isnan(mrp)], np.tile(none, (np.isnan(mrp).sum(), 1)))


def test_cells_span_the_true_edges_of_the_grid():
    omega = np.array([0.2, 1.0, 5.0, 20.0])
    smap = make_stability_map(N, omega, [lambda n: 3.0 + 0 * n])
    ax = plot_stability_map(smap)
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    xe, ye = mesh_edges(mesh)
    np.testing.assert_allclose(xe, np.linspace(5.0, 105.0, 11))
    np.testing.assert_allclose(ye, [0.0, 0.6, 3.0, 12.5, 27.5])


def test_title_gives_the_fixed_parameters_with_units(family_figure):
    text = family_figure.get_suptitle() + " ".join(ax.get_title() for ax in family_figure.axes)
    assert "α = 5 s/m" in text
