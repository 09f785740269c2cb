"""The overview figure of one run (`stickslip simulate` → run.png): it says which part of the run
each panel shows, names the frequency it marks for what it is, and hides no data under a legend."""

import matplotlib.pyplot as plt
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from stickslip.plot.trajectory import plot_trajectory, save_trajectory_figure

from .figdata import capture_saved_figures, make_trajectory


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _panels(fig):
    """(φ ψ panel, |F| panel, phase panel, spectrum panel)."""
    return tuple(fig.axes[:4])


def _title(ax):
    return " ".join(ax.get_title(loc=loc) for loc in ("left", "center", "right"))


def test_time_history_says_it_shows_the_last_seconds_of_the_run():
    fig = plot_trajectory(make_trajectory(t_end=100.0, steady_from=50.0))
    phi, force, phase, spec = _panels(fig)
    assert phi.get_xlim()[0] == pytest.approx(90.0, abs=1.0)  # what is drawn: the last 10 s
    assert "last 10 s" in _title(phi) and "90–100 s" in _title(phi) and "0–100 s" in _title(phi)
    for ax in (phase, spec):
        assert "50–100 s" in _title(ax)


def test_short_run_window_is_named_with_its_own_length():
    fig = plot_trajectory(make_trajectory(t_end=5.0, steady_from=2.5))
    assert "last 2.5 s" in _title(fig.axes[0]) and "2.5–5 s" in _title(fig.axes[0])


@pytest.mark.parametrize("periodic, word, not_word", [(True, "fundamental", "dominant"), (False, "dominant", "fundamental")])
def test_spectrum_marker_names_the_fundamental_only_of_a_periodic_response(periodic, word, not_word):
    fig = plot_trajectory(make_trajectory(periodic=periodic))
    spec = _panels(fig)[3]
    labels = " ".join(t.get_text() for t in spec.get_legend().get_texts())
    assert word in labels and not_word not in labels


def test_legends_of_the_time_histories_lie_outside_the_data(tmp_path, monkeypatch):
    saved = capture_saved_figures(monkeypatch)
    save_trajectory_figure(make_trajectory(), tmp_path / "run.png")
    (fig,) = saved
    FigureCanvasAgg(fig)  # the saved figure was closed; lay it out again as it was written
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in _panels(fig)[:2]:
        box, legend = ax.get_window_extent(renderer), ax.get_legend().get_window_extent(renderer)
        assert legend.y0 >= box.y1 - 1.0 or legend.x0 >= box.x1 - 1.0


def test_title_gives_every_parameter_with_its_unit():
    fig = plot_trajectory(make_trajectory())
    title = fig.get_suptitle()
    assert "N = 50 N" in title and "Ω = 5 rad/s" in title and "α = 5 s/m" in title
