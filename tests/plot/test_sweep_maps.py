"""Heat maps and line plots of sweep reductions: true cell edges, equilibria and failed runs in
their own colours, and a legend entry for every colour that is not on the colour scale."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import QuadMesh
from matplotlib.colors import to_rgba

from stickslip.plot.sweep import plot_reduction, save_sweep_figure

from .figdata import capture_saved_figures, legend_entries, make_sweep, mesh_edges, outcome_codes, top_cell_colours

N3 = [10.0, 20.0, 30.0]


def _meshes(ax):
    return [c for c in ax.collections if isinstance(c, QuadMesh)]


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _map(omega, frequency, outcomes=None, var="frequency", stick_fraction=0.2):
    """Heat map over (N, Ω) of a sweep whose every point is periodic stick-slip unless ``outcomes``
    (names) and ``stick_fraction`` say otherwise."""
    shape = (len(N3), len(omega))
    codes = np.full(shape, 1.0) if outcomes is None else outcome_codes(outcomes)
    ds = make_sweep({"N": N3, "Omega": omega}, attractor=codes, frequency=frequency,
                    stick_fraction=np.broadcast_to(stick_fraction, shape))
    return plot_reduction(ds, var)


def test_non_uniform_grid_is_drawn_with_its_true_cell_edges():
    """Ω = 0.5, 5, 8.5 rad/s: edges at the midpoints 2.75 and 6.75, the outer ones mirrored but not
    below Ω = 0 (no cell claims negative Ω that was never computed)."""
    ax = _map([0.5, 5.0, 8.5], np.arange(9.0).reshape(3, 3))
    (mesh,) = _meshes(ax)
    xe, ye = mesh_edges(mesh)
    np.testing.assert_allclose(xe, [5.0, 15.0, 25.0, 35.0])
    np.testing.assert_allclose(ye, [0.0, 2.75, 6.75, 10.25])
    assert ax.get_ylim() == pytest.approx((0.0, 10.25))
    assert ax.get_yscale() == "linear"


def test_few_grid_values_are_the_ticks_of_their_axis():
    ax = _map([0.5, 5.0, 8.5], np.ones((3, 3)))
    np.testing.assert_allclose(ax.get_yticks(), [0.5, 5.0, 8.5])
    np.testing.assert_allclose(ax.get_xticks(), N3)


def test_geometric_grid_is_drawn_on_a_log_axis_with_equal_cells():
    omega = [0.5, 1.0, 2.0, 4.0]
    ax = _map(omega, np.ones((3, 4)))
    (mesh,) = _meshes(ax)
    _, ye = mesh_edges(mesh)
    r = np.sqrt(2.0)
    np.testing.assert_allclose(ye, [0.5 / r, 0.5 * r, 1.0 * r, 2.0 * r, 4.0 * r])
    assert ax.get_yscale() == "log"


def test_unsorted_grid_puts_each_value_in_the_cell_around_its_own_coordinate():
    """A grid given as Ω = 5, 0.5, 8.5: the cell around 0.5 holds the value computed at 0.5."""
    freq = np.array([[1.0, 2.0, 3.0]] * 3)  # 1 Hz at Ω = 5, 2 Hz at 0.5, 3 Hz at 8.5
    ax = _map([5.0, 0.5, 8.5], freq)
    (mesh,) = _meshes(ax)
    _, ye = mesh_edges(mesh)
    np.testing.assert_allclose(ye, [0.0, 2.75, 6.75, 10.25])
    values = np.ma.getdata(mesh.get_array()).reshape(3, 3)  # rows: Ω cells bottom to top
    np.testing.assert_array_equal(values[:, 0], [2.0, 1.0, 3.0])


def test_equilibria_have_their_own_colour_and_legend_entry_not_a_frequency():
    """The sweep stores the decay frequency of a transient at an equilibrium (2.25 Hz); the map
    must not draw it as an oscillation at 2.25 Hz."""
    outcomes = np.array([["periodic", "periodic", "equilibrium"], ["chaotic", "periodic", "equilibrium"],
                         ["periodic", "equilibrium", "equilibrium"]], dtype=object)  # (N, Ω)
    freq = np.where(outcomes == "equilibrium", 2.25, np.array([[1.0, 1.1, 0], [1.2, 1.3, 0], [1.4, 0, 0]]))
    ax = _map([0.5, 5.0, 8.5], freq, outcomes)
    entries = legend_entries(ax)
    eq_label = next(label for label in entries if "equilibrium" in label)
    eq_colour = entries[eq_label].get_facecolor()
    cells = top_cell_colours(ax)  # (Ω, N)
    eq_cells = outcomes.T == "equilibrium"
    np.testing.assert_allclose(cells[eq_cells], np.tile(eq_colour, (eq_cells.sum(), 1)))
    scale = next(m for m in _meshes(ax) if m.colorbar is not None)
    assert scale.norm.vmax == pytest.approx(1.4)  # 2.25 Hz is not on the colour scale
    assert np.all(np.ma.getmaskarray(scale.get_array()).reshape(3, 3)[eq_cells])
    assert not np.any(np.all(np.isclose(cells[~eq_cells], eq_colour), axis=-1))


def test_failed_runs_and_missing_values_are_named_in_the_legend():
    outcomes = np.full((3, 3), "periodic", dtype=object)
    outcomes[0, 1] = "failed"
    freq = np.array([[1.0, np.nan, 1.2], [1.1, np.nan, 1.3], [1.2, 1.4, 1.5]])  # NaN at a failure and at (20 N, 5 rad/s)
    ax = _map([0.5, 5.0, 8.5], freq, outcomes)
    entries = legend_entries(ax)
    cells = top_cell_colours(ax)
    failed = next(label for label in entries if "failed" in label)
    np.testing.assert_allclose(cells[1, 0], entries[failed].get_facecolor())
    other = [label for label in entries if label != failed]
    assert other, "the NaN cell of a successful run needs its own legend entry"
    np.testing.assert_allclose(cells[1, 1], entries[other[0]].get_facecolor())


def test_every_outcome_and_the_stick_character_of_a_periodic_point_get_their_own_colour():
    """The map of ``attractor`` draws each outcome in a colour of its own, a periodic point with
    stick apart from one without, each named in the legend."""
    outcomes = np.array([["periodic", "unsettled", "equilibrium"], ["periodic", "chaotic", "quasiperiodic"],
                         ["unbounded", "contact-lost", "failed"]], dtype=object)
    stick = np.array([[0.2, 0.2, 0.0], [0.0, 0.2, 0.2], [0.0, 0.0, 0.0]])
    ax = _map([0.5, 5.0, 8.5], np.ones((3, 3)), outcomes, var="attractor", stick_fraction=stick)
    entries = legend_entries(ax)
    colours = {label: tuple(h.get_facecolor()) for label, h in entries.items()}
    assert len(set(colours.values())) == len(colours) == 9
    cells = top_cell_colours(ax)  # (Ω, N)
    np.testing.assert_allclose(cells[0, 0], colours["periodic stick-slip"])
    np.testing.assert_allclose(cells[0, 1], colours["periodic slip"])
    np.testing.assert_allclose(cells[1, 0], colours["unsettled"])
    np.testing.assert_allclose(cells[2, 2], colours["failed"])


def test_frequency_against_one_parameter_leaves_equilibria_off_the_curve():
    ds = make_sweep({"N": [10.0, 20.0, 30.0, 40.0]}, attractor=[1, 1, 0, 0], frequency=[1.0, 1.1, 2.25, 2.25],
                    stick_fraction=[0.2, 0.2, 0.0, 0.0])
    ax = plot_reduction(ds, "frequency")
    ys = np.concatenate([np.asarray(line.get_ydata(), float) for line in ax.get_lines()
                         if line.get_transform() == ax.transData])
    assert 2.25 not in ys
    entries = legend_entries(ax)
    marks = [h for label, h in entries.items() if "equilibrium" in label]
    assert marks and to_rgba(marks[0].get_color()) == pytest.approx(to_rgba("#7f7f7f"))


def test_dimensionless_quantity_says_so_on_its_colour_bar():
    ax = _map([0.5, 5.0, 8.5], np.ones((3, 3)), var="stick_fraction")
    labels = [a.get_ylabel() for a in ax.figure.axes if a is not ax]
    assert any(label.endswith("[-]") for label in labels)


def test_sweep_figure_title_gives_fixed_parameters_with_units(tmp_path, monkeypatch):
    saved = capture_saved_figures(monkeypatch)
    ds = make_sweep({"N": N3, "Omega": [0.5, 5.0, 8.5]}, attractor=np.full((3, 3), 1.0), frequency=np.ones((3, 3)),
                    stick_fraction=np.full((3, 3), 0.2))
    save_sweep_figure(ds, tmp_path / "s.png", var="frequency")
    title = saved[0].get_suptitle()
    assert "α = 5 s/m" in title and "steady window 100–200 s" in title


def test_title_names_the_value_of_a_grid_dimension_of_length_one(tmp_path, monkeypatch):
    saved = capture_saved_figures(monkeypatch)
    ds = make_sweep({"N": N3, "Omega": [8.5]}, attractor=np.full((3, 1), 1.0), frequency=np.ones((3, 1)),
                    stick_fraction=np.full((3, 1), 0.2))
    save_sweep_figure(ds, tmp_path / "s.png", var="frequency")
    assert "Ω = 8.5 rad/s" in saved[0].get_suptitle()
