"""Bifurcation diagrams: units in the title and on the axes, a legend entry per drawn class."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import to_rgba

from stickslip.plot.sweep import plot_bifurcation, save_bifurcation_figure

from .figdata import capture_saved_figures, handle_colour, legend_entries, make_sweep, outcome_codes

NPEAK = 4


def _diagram_data(control, values, outcomes, stick=None):
    """A sweep over one control parameter: oscillating points with peaks 0.02, 0.03 rad (sticking
    where ``stick``, default all), equilibria at rest at φ = 0.0197 rad, failed runs without values."""
    outcomes = np.asarray(outcomes, dtype=object)
    moving = np.isin(outcomes, ("periodic", "chaotic", "quasiperiodic", "unsettled"))
    peaks = np.full((len(values), NPEAK), np.nan)
    peaks[moving, :2] = [0.02, 0.03]
    phi_mean = np.where(outcomes == "equilibrium", 0.0197, 0.025)
    stick = np.ones(len(values), bool) if stick is None else np.asarray(stick, bool)
    return make_sweep({control: values}, attractor=outcome_codes(outcomes), peaks=peaks, phi_mean=phi_mean,
                      stick_fraction=np.where(moving & stick, 0.2, 0.0))


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.mark.parametrize("control, fixed", [("N", "Ω = 0.5 rad/s"), ("Omega", "N = 50 N")])
def test_title_gives_the_fixed_parameters_and_the_control_with_units(tmp_path, monkeypatch, control, fixed):
    saved = capture_saved_figures(monkeypatch)
    save_bifurcation_figure(_diagram_data(control, [1.0, 2.0, 3.0], ["periodic", "periodic", "equilibrium"]), tmp_path / "b.png")
    (fig,) = saved
    title = fig.get_suptitle()
    unit = {"N": "[N]", "Omega": "[rad/s]"}[control]
    assert fixed in title and "α = 5 s/m" in title
    assert unit in title.splitlines()[0]  # "... against Ω [rad/s]"
    assert fig.axes[0].get_xlabel().endswith(unit)
    assert fig.axes[0].get_ylabel() == "peak values of φ [rad]"


def test_legend_has_one_entry_per_drawn_class_in_its_colour():
    outcomes = ["periodic", "chaotic", "equilibrium", "failed", "periodic"]
    ax = plot_bifurcation(_diagram_data("N", [10.0, 20.0, 30.0, 40.0, 50.0], outcomes,
                                        stick=[True, True, False, False, False]))
    entries = legend_entries(ax)
    expected = {"periodic stick-slip": "#000000", "chaotic": "#ff7f0e", "periodic slip": "#1f77b4"}
    for label, colour in expected.items():
        assert handle_colour(entries[label]) == pytest.approx(to_rgba(colour))
    assert any("equilibrium" in label for label in entries) and any("failed" in label for label in entries)
    # every legend marker is drawn at one size: the legend does not magnify one class over another
    sizes = {h.get_markersize() for h in entries.values() if hasattr(h, "get_markersize")}
    assert len(sizes) == 1
