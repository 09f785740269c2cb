"""The ``popp-stelter`` library model against an independent event-driven solution.

The reference below is written by hand with scipy's ``solve_ivp``, sharing nothing with the
package's kernels: two masses, each with its own 1-D contact on a belt moving at V,

    M x'' + C x' + K x = F,   F_c = −μ(|v_c|) N_c sgn(v_c) in slip (v_c = x_c' − V),

and in stick x_c' = V, x_c'' = 0, so (M diagonal, one contact per mass) the stick force is minus
the other forces on that mass, F_c = (C x' + K x)_c. Each contact is in one of three modes
(stick, slip with v < 0, slip with v > 0); events end a phase: v_c = 0 in slip (stick if the
stick force is within μs N_c, else slip on in the direction of the net force) and |F_c| = μs N_c
in stick (slip in the direction of the force).
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from stickslip import simulate
from stickslip.integrate.contacts import STICK_SPEED_TOL
from stickslip.model.library import load_model

# the model written out independently of popp_stelter.toml
MASS = np.array([1.0, 1.0])
DAMPING = np.diag([0.05, 0.05])
STIFFNESS = np.array([[2.0, -1.0], [-1.0, 3.0]])
V = 0.3
NORMAL = np.array([1.0, 1.0])
MU_K, DELTA_MU, ALPHA = 0.5, 0.5, 2.0
MU_S = MU_K + DELTA_MU
STICK = 0


def mu(speed):
    return MU_K + DELTA_MU * math.exp(-ALPHA * speed)


def other_forces(y):
    """−C x' − K x on each mass."""
    return -DAMPING @ y[2:] - STIFFNESS @ y[:2]


def rhs(modes):
    def f(t, y):
        force = other_forces(y)
        acc = np.empty(2)
        for c in range(2):
            if modes[c] == STICK:
                acc[c] = 0.0
            else:
                acc[c] = (force[c] - mu(abs(y[2 + c] - V)) * NORMAL[c] * modes[c]) / MASS[c]
        return np.concatenate([[V if modes[c] == STICK else y[2 + c] for c in range(2)], acc])
    return f


def events(modes):
    """One terminal event per contact: v_c = 0 (slip) or |stick force| = μs N_c (stick)."""
    out = []
    for c in range(2):
        if modes[c] == STICK:
            ev = (lambda t, y, c=c: abs(other_forces(y)[c]) - MU_S * NORMAL[c])
            ev.direction = 1.0
        else:
            ev = (lambda t, y, c=c: y[2 + c] - V)
            ev.direction = -modes[c]  # v < 0 rises to 0, v > 0 falls to 0
        ev.terminal = True
        out.append(ev)
    return out


def reference(y0, t_end):
    """Transitions and final state of the hand-written model.

    Returns a list of (time, kind: +1 slip→stick / −1 stick→slip, contact, state, |dv/dt| on
    arrival at stick (0 for breakaway)) and the state at ``t_end``.
    """
    y = np.array(y0, dtype=float)
    modes = [STICK if y[2 + c] == V else (1 if y[2 + c] > V else -1) for c in range(2)]
    t, found = 0.0, []
    while True:
        sol = solve_ivp(rhs(modes), (t, t_end), y, method="DOP853", rtol=1e-12, atol=1e-13, events=events(modes))
        if sol.status == 0:
            return found, sol.y[:, -1]
        c = next(i for i, te in enumerate(sol.t_events) if te.size)
        t, y = float(sol.t_events[c][0]), sol.y_events[c][0].copy()
        force = other_forces(y)[c]
        if modes[c] == STICK:  # breakaway: slip in the direction of the force
            modes[c] = 1 if force > 0.0 else -1
            found.append((t, -1, c, y.copy(), 0.0))
        elif abs(force) <= MU_S * NORMAL[c]:  # v = 0 and the stick force holds
            arrival = abs(force - MU_S * NORMAL[c] * modes[c]) / MASS[c]
            modes[c] = STICK
            y[2 + c] = V
            found.append((t, 1, c, y.copy(), arrival))
        else:  # passes through v = 0
            modes[c] = 1 if force > 0.0 else -1
            y[2 + c] = V


def run_both(y0, t_end=40.0):
    """The package's run and the reference over ten cycles of the orbit (period ≈ 3.7)."""
    ref, final = reference(y0, t_end)
    traj = simulate("popp-stelter", t_end, ic=np.array(y0), rtol=1e-11, atol=1e-13, sample_rate=10)
    assert traj.status == "success"
    return traj, ref, final


Y0 = [(0.1, 0.0, 0.0, 0.0), (-0.3, 0.4, 0.5, -0.2)]


@pytest.mark.parametrize("y0", Y0)
def test_transitions_and_states_match_the_hand_written_solution(y0):
    traj, ref, final = run_both(y0)
    tr = traj.transitions
    assert len(tr) == len(ref) >= 16
    np.testing.assert_array_equal(tr.kind, [r[1] for r in ref])
    np.testing.assert_array_equal(tr.contact, [r[2] for r in ref])
    assert {0, 1} <= set(tr.contact[tr.kind == 1].tolist())  # both contacts stick
    # breakaway instants and states to 1e-9; a contact may enter stick once |v| ≤ STICK_SPEED_TOL,
    # i.e. up to STICK_SPEED_TOL / |dv/dt| early (the integrator's stated bound; in fact ~1e-10, below)
    bound = np.array([STICK_SPEED_TOL / r[4] if r[1] == 1 else 0.0 for r in ref]) + 1e-9
    assert np.all(np.abs(tr.time - [r[0] for r in ref]) <= bound)
    away = tr.kind == -1
    np.testing.assert_allclose(tr.state[away], [r[3] for r in ref if r[1] == -1], rtol=0, atol=1e-9)
    np.testing.assert_allclose(traj.final_state, final, rtol=0, atol=1e-9)


@pytest.mark.parametrize("y0", Y0)
def test_stick_entries_are_located_as_accurately_as_breakaways(y0):
    traj, ref, _ = run_both(y0)
    np.testing.assert_allclose(traj.transitions.time, [r[0] for r in ref], rtol=0, atol=1e-8)


def test_mode_bits_say_which_contact_sticks():
    traj = simulate("popp-stelter", 60.0, ic={"x1": 0.1}, rtol=1e-10, atol=1e-12, sample_rate=100)
    model = load_model("popp-stelter")
    for c in range(2):
        stuck = (traj.mode >> c) & 1 == 1
        assert stuck.any()
        np.testing.assert_allclose(traj.states[stuck, 2 + c], model.contacts[c].drive[0], rtol=0, atol=1e-9)
        # the stick force stays within μs N, and the slip velocity of a slipping contact is not 0
        assert np.all(np.abs(traj.friction[stuck, 2 * c]) <= MU_S * NORMAL[c] * (1 + 1e-9))
        assert np.all(np.abs(traj.states[~stuck, 2 + c] - V) > 0.0)
