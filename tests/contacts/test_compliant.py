"""Compliant unilateral contacts against closed-form solutions.

A unit mass on a unit spring (y) bounces against a compliant stop (contact stiffness k, damping
c): open while y < 0 (g = −y > 0), closed while y > 0 and λ = k y + c ẏ > 0. Each phase is a
linear oscillator whose solution is written out here by hand, so the opening and closing
instants have closed forms; a second DOF x slides on a belt under the contact's friction only
while it is closed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import stickslip
from stickslip.analysis.signal import CLOSE, OPEN
from stickslip.integrate.contacts import hermite_dip
from stickslip.model import model_from_spec


def bouncer(k=3.0, c=0.0, mu=0.3, drive=0.5):
    """The bouncing mass with a sliding x (unit masses and springs)."""
    return model_from_spec({
        "name": "bouncer", "dofs": ["x", "y"], "observe": "y",
        "mass": [[1.0, 0.0], [0.0, 1.0]], "damping": [[0.0, 0.0], [0.0, 0.0]],
        "stiffness": [[1.0, 0.0], [0.0, 1.0]], "force": [0.0, 0.0],
        "contact": [{"tangent": [[1.0, 0.0]], "drive": [drive], "gap": 0.0, "gap_gradient": [0.0, -1.0],
                     "normal": {"law": "compliant", "stiffness": k, "damping": c},
                     "friction": {"law": "coulomb", "mu_k": mu, "delta_mu": 0.0}}]})


def events(traj):
    tr = traj.transitions
    return tr.time[tr.kind == CLOSE], tr.time[tr.kind == OPEN]


def test_undamped_stop_gives_the_piecewise_linear_period():
    """Open: y'' = −y (half period π); closed: y'' = −(1 + k) y (half period π/√(1+k))."""
    k = 3.0
    traj = stickslip.simulate(bouncer(k), 40.0, ic={"y": -0.5}, rtol=1e-11, atol=1e-13)
    close, opened = events(traj)
    assert traj.status == "success" and close.size >= 8
    assert close[0] == pytest.approx(math.pi / 2, abs=1e-9)  # y = −0.5 cos t reaches 0
    np.testing.assert_allclose(np.diff(close), math.pi + math.pi / math.sqrt(1 + k), rtol=0, atol=1e-8)
    np.testing.assert_allclose(opened - close[:opened.size], math.pi / math.sqrt(1 + k), rtol=0, atol=1e-8)
    # closed: the contact presses with λ = k y, its largest value k · 0.5 / √(1+k) (energy of the flight)
    closed = ~traj.open[:, 0]
    lam = traj.normal_force[:, 0]
    np.testing.assert_allclose(lam[closed], k * traj.states[closed, 1], rtol=1e-12, atol=1e-15)
    assert np.all(lam[~closed] == 0.0) and np.all(traj.gap[:, 0] == -traj.states[:, 1])
    assert lam.max() == pytest.approx(k * 0.5 / math.sqrt(1 + k), rel=1e-4)  # sampled at 100 Hz
    # the steady summary's open fraction: π of every π + π/2
    assert traj.steady.open_fraction == pytest.approx(math.pi / (math.pi + math.pi / 2), abs=0.02)


def test_the_open_fraction_of_a_periodic_run_is_the_cycle_s():
    """Periodic in y (flights of π, contacts of π/√(1+k)): the summary takes its fractions over the
    whole periods that end the window, so the open fraction is the cycle's π / (π + π/2) = 2/3
    (measured 5e-13 off); over the 60-s window itself, which holds 12.7 periods, it is not."""
    traj = stickslip.simulate(bouncer(3.0), 120.0, ic={"y": -0.5}, rtol=1e-11, atol=1e-13)
    steady = traj.steady
    assert steady.periodic and 1.0 / steady.fundamental_frequency_hz == pytest.approx(1.5 * math.pi, rel=1e-9)
    assert steady.open_fraction == pytest.approx(2.0 / 3.0, abs=1e-9)
    assert steady.contact_open_fractions[0] == steady.open_fraction
    close, opened = events(traj)
    flights = [(a, close[close > a][0] if np.any(close > a) else traj.t[-1]) for a in opened]
    window = sum(max(0.0, min(b, steady.t_to) - max(a, steady.t_from)) for a, b in flights)
    assert abs(window / (steady.t_to - steady.t_from) - 2.0 / 3.0) > 1e-3  # the part period's bias


def damped_cycle(k, c, v0):
    """One contact phase and flight of the damped stop, by hand: closing at y = 0 with ẏ = v0 > 0,
    y = (v0/ωd) e^(−a t) sin ωd t (a = c/2, ωd = √(1 + k − a²)) until λ = k y + c ẏ = 0, i.e.
    tan ωd t = −c ωd / (k − c a); then y'' = −y from there to the next upward zero of y.
    Returns (contact time, flight time, next closing speed)."""
    a = c / 2.0
    wd = math.sqrt(1.0 + k - a * a)
    t_c = (math.pi - math.atan(c * wd / (k - c * a))) / wd
    y1 = v0 / wd * math.exp(-a * t_c) * math.sin(wd * t_c)
    dy1 = v0 * math.exp(-a * t_c) * (math.cos(wd * t_c) - a / wd * math.sin(wd * t_c))
    # flight: y = y1 cos t + dy1 sin t = R cos(t − θ); next upward zero where t − θ = 3π/2 (mod 2π)
    R = math.hypot(y1, dy1)
    theta = math.atan2(dy1, y1)
    t_f = (1.5 * math.pi + theta) % (2.0 * math.pi)
    return t_c, t_f, R


def test_damped_stop_opens_before_the_gap_closes_at_the_closed_form_instants():
    """With contact damping the contact opens where λ = k y + c ẏ reaches 0, while still
    compressed (y > 0), and the force jumps to c ẏ at closing: every instant by hand."""
    k, c = 3.0, 0.4
    traj = stickslip.simulate(bouncer(k, c), 25.0, ic={"y": -0.5}, rtol=1e-11, atol=1e-13)
    close, opened = events(traj)
    assert close.size >= 4
    t, v = math.pi / 2, 0.5
    for i in range(4):
        t_c, t_f, v = damped_cycle(k, c, v)
        assert close[i] == pytest.approx(t, abs=1e-8)
        assert opened[i] == pytest.approx(t + t_c, abs=1e-8)
        t += t_c + t_f
    # opening happens with the mass still inside the stop (g < 0), as the law says
    tr = traj.transitions
    at_open = tr.state[tr.kind == OPEN]
    assert np.all(at_open[:, 1] > 1e-3)


def test_friction_acts_only_while_the_contact_is_closed():
    """x'' = −x + μ λ (the belt pulls x along +x while x slides slower than it): during a flight x
    swings freely, so its energy ½(ẋ² + x²) is constant while open, and the friction work grows
    only while closed."""
    traj = stickslip.simulate(bouncer(mu=0.3, drive=5.0), 20.0, ic={"y": -0.5}, rtol=1e-11, atol=1e-13)
    x, dx = traj.states[:, 0], traj.states[:, 2]
    energy = 0.5 * (x * x + dx * dx)
    is_open = traj.open[:, 0]
    tr = traj.transitions
    close, opened = events(traj)
    for t0, t1 in zip(opened, close[1:]):  # each flight
        inside = (traj.t > t0 + 1e-6) & (traj.t < t1 - 1e-6)
        assert is_open[inside].all()
        assert np.ptp(energy[inside]) < 1e-9
        assert np.all(traj.friction[inside] == 0.0)
    closed = ~is_open
    np.testing.assert_allclose(traj.friction[closed, 0], 0.3 * traj.normal_force[closed, 0], rtol=1e-12)
    assert tr.kind.size and set(np.unique(tr.kind)) <= {OPEN, CLOSE}


def test_a_flight_shorter_than_a_step_is_found():
    """A preload F presses the mass into the stop (closed: y'' = −(1 + k) y + F about y_e = F/(1+k));
    started at y_e with ẏ = −v_s it leaves at speed v0 = √(v_s² − (1+k) y_e²) and flies for
    t_f = 2 atan(v0/F) (y = F (1 − cos t) − v0 sin t), then stays closed for
    t_c = (2π − 2 atan(v0/(ω y_e)))/ω, ω = √(1+k). With v0 = 0.001 each flight lasts 2 ms, inside
    one step of the integrator (both of whose ends see the contact closed): every flight is found,
    at the closed-form instants. The gap crosses zero at speed v0, so a state error δ of the run
    moves an instant by δ/v0: 5e-8 s here (the error falls tenfold per tenfold tighter rtol)."""
    k, F, v0 = 3.0, 1.0, 0.001
    w, ye = math.sqrt(1.0 + k), F / (1.0 + k)
    vs = math.sqrt(v0 * v0 + (1.0 + k) * ye * ye)
    model = bouncer(k).replace(**{"force.y": F})
    traj = stickslip.simulate(model, 20.0, ic={"y": ye, "dy": -vs}, rtol=1e-11, atol=1e-13)
    close, opened = events(traj)
    t_open = math.asin(w * ye / vs) / w
    t_f = 2.0 * math.atan(v0 / F)
    t_c = (2.0 * math.pi - 2.0 * math.atan(v0 / (w * ye))) / w
    expected_open = t_open + np.arange(opened.size) * (t_f + t_c)
    assert traj.status == "success" and opened.size == math.floor((20.0 - t_open) / (t_f + t_c)) + 1
    assert close.size == opened.size or close.size == opened.size - 1
    np.testing.assert_allclose(opened, expected_open, rtol=0, atol=5e-8)
    np.testing.assert_allclose(close, expected_open[:close.size] + t_f, rtol=0, atol=5e-8)
    assert 20.0 / traj.stats.accepted_steps > 4.0 * t_f  # the flights are shorter than the steps


@settings(max_examples=300, deadline=None)
@given(st.floats(0.01, 1.0), st.floats(-8.0, 8.0), st.floats(0.01, 1.0), st.floats(-8.0, 8.0))
def test_the_hermite_dip_is_the_interior_minimum_of_the_cubic(g0, dg0, g1, dg1):
    """hermite_dip finds the interior minimum of the cubic Hermite interpolant (against the cubic on
    a grid of 20 001 points) where it falls to half the smaller end value, and nothing elsewhere."""
    th = np.linspace(0.0, 1.0, 20001)
    cubic = ((2 * th**3 - 3 * th**2 + 1) * g0 + (th**3 - 2 * th**2 + th) * dg0 + (-2 * th**3 + 3 * th**2) * g1
             + (th**3 - th**2) * dg1)
    i = int(np.argmin(cubic))
    got = hermite_dip(g0, dg0, g1, dg1)
    floor = 0.5 * min(g0, g1)
    if 0 < i < th.size - 1 and cubic[i] <= floor - 1e-9:
        assert got == pytest.approx(th[i], abs=2e-4)
    elif not (0 < i < th.size - 1) or cubic[i] > floor + 1e-9:
        assert got == -1.0
