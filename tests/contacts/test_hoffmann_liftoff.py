"""The hoffmann model past its flutter onset lifts off and settles on a cycle with flight phases;
checked against a separate event-driven solution written here with scipy.

Equations (unit mass, springs K = [[2, 1], [1, 1]], preload N0 = 1 on y, contact spring k3 = 1,
belt speed 1, damping c on both dofs, Coulomb friction μ = μs). While the contact is closed
(λ = 1 + y > 0) the friction force F acts along x, with the slip velocity v = x' − 1:

    x'' = −2x − y − c x' + F,   y'' = −x − 2y − c y',   F = −μ λ sign(v), or the stick force
    F = 2x + y + c (x' = 1, x'' = 0) while |F| ≤ μ λ;

while open, x'' = −2x − y − c x', y'' = −x − y + 1 − c y' (no contact force). The contact opens
where λ falls to 0 and closes where it rises through 0; slip reverses or sticks where v passes 0.
"""

from __future__ import annotations

import numpy as np
import pytest

import stickslip
from stickslip.analysis.signal import CLOSE, OPEN, SLIP, STICK
from stickslip.basins import basin_stability, box

from .event_reference import OPEN_MODE, STICK_MODE, event_driven

MU, C, T_END = 1.3, 0.1, 400.0


def _field(mode):
    """Right-hand side in ``mode``: ``open``, ``stick``, or slip with sign(v) = ``mode`` (±1)."""
    def f(t, s):
        x, y, dx, dy = s
        if mode == OPEN_MODE:
            return [dx, dy, -2 * x - y - C * dx, -x - y + 1 - C * dy]
        if mode == STICK_MODE:
            return [dx, dy, 0.0, -x - 2 * y - C * dy]
        return [dx, dy, -2 * x - y - C * dx - mode * MU * (1 + y), -x - 2 * y - C * dy]
    return f


def reference(t_eval, y0):
    """scipy DOP853 at rtol 1e-12, restarted at every located event (λ = 1 + y for the contact,
    v = x' − 1, the stick force 2x + y + c within μ λ). Returns the states at ``t_eval`` and the
    instants of each transition kind."""
    return event_driven(_field, phi=lambda s: 1.0 + s[1], slip_speed=lambda s: s[2] - 1.0,
                        stick_force=lambda s: 2 * s[0] + s[1] + C * 1.0, limit=lambda s: MU * (1 + s[1]),
                        t_eval=t_eval, y0=y0)


@pytest.fixture(scope="module")
def runs():
    model = stickslip.load_model("hoffmann").replace(
        **{"contact.0.friction.mu_k": MU, "damping.x.x": C, "damping.y.y": C})
    traj = stickslip.simulate(model, T_END, ic={"x": 0.01}, rtol=1e-11, atol=1e-13, sample_rate=20.0)
    ref, switches = reference(traj.t, traj.states[0])
    return traj, ref, switches


def test_past_the_onset_the_contact_lifts_off_and_the_run_goes_on(runs):
    traj, ref, switches = runs
    assert traj.status == "success" and traj.t[-1] == T_END
    tr = traj.transitions
    assert {OPEN, CLOSE} <= set(np.unique(tr.kind))
    assert traj.open.any() and (~traj.open).any()


def test_the_whole_run_matches_the_scipy_solution(runs):
    traj, ref, switches = runs
    tr = traj.transitions
    for kind in (OPEN, CLOSE, STICK, SLIP):
        np.testing.assert_allclose(tr.time[tr.kind == kind], switches[kind], rtol=0, atol=1e-6)
    np.testing.assert_allclose(traj.states, ref, rtol=0, atol=1e-6)


def test_the_lift_off_cycle_period_amplitude_and_open_fraction(runs):
    """On the settled cycle (the last 100 s): the period from successive closings, the open
    fraction from the flights and the amplitude of x agree with the reference to 1e-5."""
    traj, ref, switches = runs
    tr = traj.transitions
    late = tr.time > T_END - 100.0
    close = tr.time[late & (tr.kind == CLOSE)]
    opened = tr.time[late & (tr.kind == OPEN)]
    ref_close = switches[CLOSE][switches[CLOSE] > T_END - 100.0]
    ref_open = switches[OPEN][switches[OPEN] > T_END - 100.0]
    period, ref_period = np.diff(close)[-1], np.diff(ref_close)[-1]
    assert period == pytest.approx(ref_period, abs=1e-5)
    assert np.ptp(np.diff(close)) < 1e-6  # settled: one period
    flight = close[-1] - opened[opened < close[-1]][-1]
    ref_flight = ref_close[-1] - ref_open[ref_open < ref_close[-1]][-1]
    assert flight / period == pytest.approx(ref_flight / ref_period, abs=1e-5)
    window = traj.t >= T_END - 100.0
    assert np.ptp(traj.states[window, 0]) == pytest.approx(np.ptp(ref[window, 0]), abs=1e-5)
    steady = traj.steady_state(T_END - 100.0)
    assert steady.periodic and steady.period_multiplicity == 1
    assert 1.0 / steady.fundamental_frequency_hz == pytest.approx(ref_period, rel=1e-4)


def test_a_sweep_over_mu_reports_the_open_fraction_and_openings(runs):
    """A sweep of hoffmann over μ: below the onset (μ = 0.5) the contact never opens; at μ = 1.3
    the point's run is the one above, and its open fraction over the whole periods that end the
    last 100 s is the reference's flights cut to them (pressed models keep their columns as before)."""
    traj, ref, switches = runs
    model = stickslip.load_model("hoffmann").replace(**{"damping.x.x": C, "damping.y.y": C})
    result = stickslip.sweep({"contact.0.friction.mu_k": [0.5, MU], "perturb_x": [0.01]}, model, executor="serial",
                             t_end=T_END, t_from=T_END - 100.0, ic="zero", rtol=1e-11, atol=1e-13, sample_rate=20.0)
    ds = result.dataset.squeeze("perturb_x")
    closed, lifting = ds.sel({"contact.0.friction.mu_k": 0.5}), ds.sel({"contact.0.friction.mu_k": MU})
    assert float(closed["open_fraction"]) == 0.0 and float(closed["openings"]) == 0.0
    t0, t1 = T_END - 100.0, traj.t[-1]
    steady = traj.steady_state(t0)  # periodic: the fractions are over the whole periods ending at t1
    assert steady.periodic
    period = 1.0 / steady.fundamental_frequency_hz
    whole = t1 - (t1 - steady.t_from) // period * period
    opens, closes = switches[OPEN], switches[CLOSE]
    flights = [(a, closes[closes > a][0] if np.any(closes > a) else t1) for a in opens]
    open_time = sum(max(0.0, min(b, t1) - max(a, whole)) for a, b in flights)
    assert float(lifting["open_fraction"]) == pytest.approx(open_time / (t1 - whole), abs=1e-5)
    assert float(lifting["openings"]) == np.sum((opens > t0) & (opens <= t1)) > 0
    belt = stickslip.sweep({"contact.0.drive": [1.0]}, "belt", executor="serial", t_end=2.0)
    assert "open_fraction" not in belt.dataset and "openings" not in belt.dataset


def test_basins_give_the_lift_off_cycle_its_open_fraction(runs):
    """Basins at μ = 1.3: every state reaches the lift-off cycle, whose open fraction (over the
    whole periods that end each state's window) is the reference's flight over its period, to
    the window's sample spacing (a window starts on a sample: ≤ one T_c / 64 of the window's
    16 or more periods, ~2e-3 relative); a pressed model's attractors have no open fraction."""
    traj, ref, switches = runs
    model = stickslip.load_model("hoffmann").replace(
        **{"contact.0.friction.mu_k": MU, "damping.x.x": C, "damping.y.y": C})
    states = box(model, {"x": (-0.5, 0.5), "dx": (-0.5, 0.5)}, n=4, seed=3)
    result = basin_stability(model, states, t_end=400.0, executor="serial")
    [cycle] = [a for a in result.attractors() if a["name"] == "periodic"]
    assert cycle["count"] == 4
    closes = switches[CLOSE]
    ref_period = np.diff(closes)[-1]
    ref_flight = closes[-1] - switches[OPEN][switches[OPEN] < closes[-1]][-1]
    assert cycle["period"] == pytest.approx(ref_period, rel=1e-4)
    assert cycle["open_fraction"] == pytest.approx(ref_flight / ref_period, rel=2e-3)
    belt = stickslip.load_model("belt")
    pressed = basin_stability(belt, box(belt, {"x": (-1.0, 1.0)}, n=2, seed=1), t_end=100.0, executor="serial")
    assert all("open_fraction" not in a for a in pressed.attractors())
    assert "open_fraction" not in pressed.dataset
