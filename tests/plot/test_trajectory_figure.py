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


def test_a_model_with_two_contacts_draws_each_contact_and_its_stick_limit():
    from stickslip import load_model, simulate

    traj = simulate(load_model("popp-stelter"), 20.0, sample_rate=50.0)
    fig = plot_trajectory(traj)
    coords, force, phase, spec = _panels(fig)
    assert [line.get_label() for line in force.get_lines()] == ["|F| mass 1", "μs N mass 1", "|F| mass 2",
                                                                "μs N mass 2"]
    assert [line.get_label() for line in coords.get_lines()] == ["x1", "x2"]
    assert "x1" in phase.get_xlabel() and "x1" in _title(spec)


def test_stick_limit_follows_a_normal_force_that_depends_on_the_state():
    import numpy as np

    from stickslip import load_model, simulate

    # hoffmann: N = N0 + k3 y (normal_gradient [0, 1]); the drawn limit is μs N(t), the closed form
    model = load_model("hoffmann")
    traj = simulate(model, 20.0, ic={"x": 0.1, "y": 0.2}, sample_rate=50.0)
    assert traj.normal_force[:, 0] == pytest.approx(1.0 + traj.states[:, 1], rel=1e-12)
    limit = plot_trajectory(traj).axes[1].get_lines()[1].get_ydata()
    mu_s = model.contacts[0].friction.mu_s
    shown = traj.t >= traj.t[-1] - 10.0
    assert limit == pytest.approx(mu_s * (1.0 + traj.states[shown, 1]), rel=1e-12)
    assert np.ptp(limit) > 0.01


def test_the_stick_limit_is_named_by_the_contact_s_normal_force():
    """μs N for a pressed contact; μs λ for a unilateral one (its contact force), and for a rigid
    one λ is named as the multiplier it is; the limit drawn is μs × that normal force."""
    from types import SimpleNamespace

    import numpy as np

    from stickslip import load_model
    from stickslip.plot.trajectory import friction_lines, stick_limit_label

    friction = np.array([[0.3, 0.0], [-0.2, 0.0], [0.0, 0.0]])
    normal = np.array([[1.0], [2.0], [0.0]])
    for name, words in (("belt", "μs N"), ("sprag-slip", "μs λ"), ("impact-oscillator", "μs λ (multiplier)")):
        model = load_model(name)
        assert stick_limit_label(model.contacts[0]) == words
        [drawn] = friction_lines(SimpleNamespace(system=model, friction=friction, normal_force=normal))
        assert drawn["label"] == "|F|" and drawn["limit_label"] == words
        assert drawn["force"] == pytest.approx([0.3, 0.2, 0.0], abs=0)
        assert drawn["limit"] == pytest.approx(model.contacts[0].friction.mu_s * normal[:, 0], abs=0)
