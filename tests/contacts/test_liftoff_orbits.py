"""Periodic orbits with separation: the monodromy by variational equations and saltation matrices
at every opening and closing, against central differences of the flow map (independent runs of
the event integrator from perturbed states)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

import stickslip
from stickslip.orbits.linear_flow import flow_jacobian

from .test_compliant import bouncer


def central_differences(model, s0, T, h=1e-6):
    """∂Φ(s0, T)/∂s0 by central differences of event-integrated runs (rtol 1e-12)."""
    n2 = s0.size
    D = np.empty((n2, n2))
    for j in range(n2):
        e = np.zeros(n2)
        e[j] = h
        ends = [stickslip.simulate(model, T, ic=s0 + sign * e, rtol=1e-12, atol=1e-14, sample_rate=1.0 / T).final_state
                for sign in (1.0, -1.0)]
        D[:, j] = (ends[0] - ends[1]) / (2.0 * h)
    return D


@pytest.mark.parametrize("contact_damping", [0.0, 0.3])
def test_saltation_monodromy_of_the_lift_off_cycle_matches_the_flow_map(contact_damping):
    """hoffmann past its onset (μ = 1.3, c = 0.1): the cycle opens and closes once per period;
    with contact damping the normal force jumps at closing (f⁺ − f⁻ ≠ 0 there too)."""
    model = stickslip.load_model("hoffmann").replace(**{
        "contact.0.friction.mu_k": 1.3, "damping.x.x": 0.1, "damping.y.y": 0.1,
        "contact.0.normal.damping": contact_damping})
    run = stickslip.simulate(model, 400.0, ic={"x": 0.01}, rtol=1e-10, atol=1e-12)
    orbit = stickslip.periodic_orbit(model, run)
    tr = stickslip.simulate(model, orbit.period, ic=orbit.state, rtol=1e-10, atol=1e-12).transitions
    assert {2, 3} <= set(np.unique(tr.kind))  # the orbit opens and closes
    J = flow_jacobian(model, orbit.state, orbit.period, rtol=1e-11).matrix
    D = central_differences(model, orbit.state, orbit.period)
    np.testing.assert_allclose(J, D, rtol=0, atol=1e-6 * np.abs(D).max())
    # the trivial multiplier of an autonomous cycle, and the orbit's own multipliers from J
    assert np.min(np.abs(orbit.multipliers - 1.0)) < 1e-6
    np.testing.assert_allclose(np.sort(np.abs(np.linalg.eigvals(J))), np.sort(np.abs(orbit.multipliers)),
                               atol=1e-6)


#: A 2-DOF model whose compliant contact is open at rest (gap 0.1; M = diag(1, 2), C = diag(0.1, 0.2),
#: K = diag(10, 10)).
OPEN_AT_REST = Path(__file__).with_name("open_at_rest.toml")


def test_flow_map_from_an_open_contact():
    """A run that starts with its contact open: while it stays open the flow is that of the free
    linear system, exp(A t) in closed form; a run that flies onto the contact and closes on it
    matches central differences. (The re-integration used to start such a contact slipping.)"""
    model = stickslip.load_model(OPEN_AT_REST)
    M, C, K = np.diag([1.0, 2.0]), np.diag([0.1, 0.2]), np.diag([10.0, 10.0])
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    s0 = np.array([0.02, 0.0, 0.3, 0.1])  # stays open for 0.5 s (y reaches at most ~0.03 < 0.1)
    J = flow_jacobian(model, s0, 0.5, rtol=1e-11).matrix
    np.testing.assert_allclose(J, expm(0.5 * A), rtol=0, atol=1e-9)
    s0 = np.array([0.0, 0.0, 0.0, 1.2])  # reaches y = 0.1 and closes on the belt
    T = 0.4
    tr = stickslip.simulate(model, T, ic=s0, rtol=1e-10, atol=1e-12).transitions
    assert 3 in set(np.unique(tr.kind))  # it closes inside the window
    J = flow_jacobian(model, s0, T, rtol=1e-11).matrix
    D = central_differences(model, s0, T)
    np.testing.assert_allclose(J, D, rtol=0, atol=1e-6 * np.abs(D).max())


@pytest.mark.parametrize("v0", [1e-3, 3e-4, 1e-4])
def test_flow_map_across_a_flight_shorter_than_a_step(v0):
    """The preloaded stop of test_compliant leaves its contact at speed v0 for 2 atan(v0/F) (2 to
    0.2 ms), inside one step of the run; where the re-integration's steps miss it too (v0 ≤ 3e-4)
    the variations are carried to the run's recorded opening and closing. With c = 0 the vector field is continuous at both (λ = k y = 0 at y = 0), so the
    flow Jacobian of (y, ẏ) is exp(A_c (T − t2)) exp(A_f (t2 − t1)) exp(A_c t1) in closed form
    (A_c: ÿ = −(1 + k) y, A_f: ÿ = −y; t1, t2 the opening and closing by hand). Central
    differences cannot check it here: a change δ of ẏ changes the speed of lift-off by δ v_s/v0."""
    k, F = 3.0, 1.0
    w, ye = math.sqrt(1.0 + k), F / (1.0 + k)
    vs = math.sqrt(v0 * v0 + (1.0 + k) * ye * ye)
    model = bouncer(k).replace(**{"force.y": F})
    s0 = np.array([0.0, ye, 0.0, -vs])
    T = 0.9
    t1 = math.asin(w * ye / vs) / w  # 0.784 s
    t2 = t1 + 2.0 * math.atan(v0 / F)
    tr = stickslip.simulate(model, T, ic=s0, rtol=1e-11, atol=1e-13).transitions
    assert {2, 3} <= set(np.unique(tr.kind))
    J = flow_jacobian(model, s0, T, rtol=1e-11).matrix
    closed, free = np.array([[0.0, 1.0], [-(1.0 + k), 0.0]]), np.array([[0.0, 1.0], [-1.0, 0.0]])
    expected = expm(closed * (T - t2)) @ expm(free * (t2 - t1)) @ expm(closed * t1)
    np.testing.assert_allclose(J[np.ix_([1, 3], [1, 3])], expected, rtol=0, atol=1e-8)
