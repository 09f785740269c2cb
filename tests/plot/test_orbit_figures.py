"""Figures of continuation branches, Lyapunov spectra and the step-size study: legends name only
what is drawn, nothing drawn is left out silently, labels carry units."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from stickslip.model.parameters import Parameters
from stickslip.plot.continuation import plot_branch, save_branch_figure
from stickslip.plot.orbits import plot_lyapunov_spectrum
from stickslip.plot.timestep import plot_timestep_errors, plot_timestep_method

from .figdata import capture_saved_figures, legend_entries


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _branch(stable):
    """A branch in Ω (5 → 10 rad/s) at N = 50 N, stopped after its last point (max_points)."""
    n = len(stable)
    value = np.linspace(5.0, 10.0, n)
    ds = xr.Dataset({"value": ("point", value), "period": ("point", 0.37 - 0.001 * value),
                     "amplitude": ("point", 0.007 - 0.0004 * value), "stick_time": ("point", 0.06 - 0.003 * value),
                     "stable": ("point", np.asarray(stable, np.int8)),
                     "special_kind": ("special", np.array([], dtype=str)),
                     "special_index": ("special", np.array([], dtype=np.int32)),
                     "special_value": ("special", np.array([], dtype=float))})
    ds.attrs.update(param="Omega", model="full", param_N=50.0, param_Omega=5.0, stop_reason="max_points")
    return ds


def test_branch_legend_names_only_the_stabilities_drawn():
    ax = plot_branch(_branch([1, 1, 1, 1]))
    labels = list(legend_entries(ax))
    assert "stable" in labels and "unstable" not in labels
    ax = plot_branch(_branch([1, 1, 0, 0]))
    assert {"stable", "unstable"} <= set(legend_entries(ax))


def test_branch_figure_axis_and_title_use_symbols_units_and_say_why_it_ends(tmp_path, monkeypatch):
    saved = capture_saved_figures(monkeypatch)
    save_branch_figure(_branch([1, 1, 1]), tmp_path / "b.png")
    (fig,) = saved
    assert fig.axes[0].get_xlabel() == "Ω [rad/s]"
    title = fig.get_suptitle()
    assert "N = 50 N" in title and "max_points" in title


def _spectrum(exponents):
    from stickslip.model.library import two_plates
    from stickslip.orbits import LyapunovSpectrum

    exponents = np.asarray(exponents, float)
    time = np.linspace(1.0, 200.0, 50)
    estimate = exponents[None, :] + 1.0 / time[:, None]
    return LyapunovSpectrum(exponents=exponents, time=time, estimate=estimate, t_transient=50.0,
                            scale=np.ones(exponents.size), stick_phases=540, wall_time=1.0,
                            system=two_plates(Parameters(N=50.0), "full"), options={})


def test_lyapunov_spectrum_says_which_exponents_it_leaves_out():
    fig = plot_lyapunov_spectrum(_spectrum([0.002, -0.01, -50.0, -190.0]))
    ax = fig.axes[0]
    text = " ".join([ax.get_title()] + [t.get_text() for t in ax.texts] + list(legend_entries(ax)))
    assert "2 exponents below −10 1/s not shown" in text
    assert "model full" in ax.get_title() and "50 s" in ax.get_title()  # the transient left out before averaging


def _timestep_study(t_end=6.0):
    from stickslip.studies.timestep import TimestepRun, TimestepStudy

    t = np.linspace(0.0, 2.0, 401)
    phi = 0.02 + 0.003 * np.sin(2 * np.pi * 2.7 * t)
    force = 10.0 + 5.0 * (np.sin(2 * np.pi * 2.7 * t) > 0.9)

    def run(method, dt, rtol, err):
        errors = {"freq_error": err, "phi_pp_error": err, "phi_shape_error": err, "F_shape_error": err}
        return TimestepRun(method=method, dt=dt, rtol=rtol, wall_time_s=0.01, steps=100, rhs_calls=100, stick_phases=3,
                           frequency_hz=2.7, phi_min=0.017, phi_max=0.023, F_max=15.0, stick_fraction=0.1,
                           errors=errors, paper_time_s=None, window_t=t, window_phi=phi, window_F=force)

    runs = [run("aeom", 1e-3, None, 1e-4), run("naeom", 1e-3, None, 2e-4), run("event", None, 1e-6, 1e-6)]
    return TimestepStudy(params=Parameters(N=50.0, Omega=5.0), t_end=t_end, reference=run("event", None, 1e-10, 0.0),
                         runs=runs, machine={})


def test_timestep_panels_name_the_static_friction_level_and_relative_errors():
    fig = plot_timestep_method(_timestep_study(), "aeom")
    labels = {t.get_text() for legend in fig.legends for t in legend.get_texts()}
    for ax in fig.axes:
        labels |= set(legend_entries(ax))
    assert "μs N" in labels
    title = " ".join(ax.get_title(loc="left") for ax in fig.axes)
    assert "relative" in title


def test_timestep_cost_axis_names_the_simulated_time():
    fig = plot_timestep_errors(_timestep_study(t_end=6.0))
    assert fig.axes[0].get_xlabel() == "wall time for 0–6 s [s]"
