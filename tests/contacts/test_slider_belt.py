"""The ``slider-belt`` library model from its default start: stick, slip, separation and
reattachment within 100 s, checked against a separate event-driven solution written here with
scipy (``event_reference``), with and without contact damping.

Equations (its defaults, written out by hand: unit mass, tangential and normal springs 1, a spring
3 inclined at 150° to the belt, so K = [[13/4, −3√3/4], [−3√3/4, 7/4]]; dampers 0.05 on x and
0.2 on y; preload 0.5 towards the belt; contact stiffness 5 and contact damping c; belt speed
0.5; exponential friction μ(|v|) = 0.3 + 0.6 exp(−2 |v|), μs = 0.9). y points away from the
belt, g = y − 0.1, and while closed λ̃ = 0.5 − 5 y − c y' > 0:

    x'' = −13/4 x + 3√3/4 y − 0.05 x' + F,      y'' = 3√3/4 x − 7/4 y − 0.2 y' − 0.5 + λ,
    slip: F = −μ(|v|) λ sign(v), v = x' − 0.5;  stick: x' = 0.5, x'' = 0, F = 13/4 x − 3√3/4 y
    + 0.05 · 0.5 while |F| ≤ 0.9 λ;  open: F = 0, λ = 0.

The contact is closed while φ = min(−g, λ̃/5) > 0 (docs/contacts.md): it opens where φ falls to 0
and closes where it rises through 0.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

import stickslip
from stickslip.analysis.signal import CLOSE, OPEN, SLIP, STICK
from stickslip.cli import app

from .event_reference import OPEN_MODE, STICK_MODE, event_driven

T_END, STEADY_FROM = 100.0, 50.0
K11, K12, K22 = 13 / 4, -3 * math.sqrt(3) / 4, 7 / 4
CX, CY, P, KC, V = 0.05, 0.2, 0.5, 5.0, 0.5
MU_K, DELTA_MU, ALPHA = 0.3, 0.6, 2.0
#: Contact dampings of the two runs: the file's (none), and one where λ jumps at closing.
CONTACT_DAMPINGS = (0.0, 0.5)


def equations(cc, V=V, CX=CX, ALPHA=ALPHA):
    """``field``, ``phi``, ``slip_speed``, ``stick_force``, ``limit`` of the model with contact
    damping ``cc`` (and the belt speed, x damping and friction decay given), for :func:`event_driven`."""
    def lam(s):
        return P - KC * s[1] - cc * s[3]

    def stick_force(s):
        return K11 * s[0] + K12 * s[1] + CX * V

    def field(mode):
        def f(t, s):
            x, y, dx, dy = s.tolist()  # Python floats: the same arithmetic, faster than numpy scalars
            spring_x, spring_y = -K11 * x - K12 * y, -K12 * x - K22 * y - P
            if mode == OPEN_MODE:
                return [dx, dy, spring_x - CX * dx, spring_y - CY * dy]
            pressed = P - KC * y - cc * dy  # lam(s)
            if mode == STICK_MODE:
                return [dx, dy, 0.0, spring_y - CY * dy + pressed]
            mu = MU_K + DELTA_MU * math.exp(-ALPHA * abs(dx - V))
            return [dx, dy, spring_x - CX * dx - mode * mu * pressed, spring_y - CY * dy + pressed]
        return f

    return dict(field=field, phi=lambda s: min(P / KC - s[1], lam(s) / KC), slip_speed=lambda s: s[2] - V,
                stick_force=stick_force, limit=lambda s: (MU_K + DELTA_MU) * lam(s))


@pytest.fixture(scope="module", params=CONTACT_DAMPINGS, ids=lambda c: f"contact damping {c}")
def runs(request):
    model = stickslip.load_model("slider-belt").replace(**{"contact.0.normal.damping": request.param})
    traj = stickslip.simulate(model, T_END, rtol=1e-11, atol=1e-13, sample_rate=20.0)
    ref, switches = event_driven(**equations(request.param), t_eval=traj.t, y0=np.zeros(4))
    return traj, ref, switches


def test_the_file_states_the_equations_written_here():
    model = stickslip.load_model("slider-belt")
    np.testing.assert_allclose(model.stiffness, [[K11, K12], [K12, K22]], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(model.damping, [[CX, 0.0], [0.0, CY]])
    np.testing.assert_array_equal(model.force, [0.0, -P])
    assert model.parameters["contact.0.normal.damping"] == CONTACT_DAMPINGS[0]


def test_steady_sliding_is_unstable_as_its_linearisation_by_hand_says():
    """Why the slip from rest grows: at steady sliding (v = −V, contact closed) the falling
    friction law puts c_x − λ0 μ'(V) < 0 on x, and the friction's share μ(V) kc y of the contact
    force couples y into x; the eigenvalues of that linearisation are stability()'s (growth
    0.105487 1/s at 0.309127 Hz)."""
    mu = MU_K + DELTA_MU * math.exp(-ALPHA * V)
    slope = ALPHA * DELTA_MU * math.exp(-ALPHA * V)  # dμ/dx' at x' = 0, where |v| = V − x'
    K = np.array([[K11, K12 + mu * KC], [K12, K22 + KC]])
    q = np.linalg.solve(K, [mu * P, 0.0])
    C = np.array([[CX - (P - KC * q[1]) * slope, 0.0], [0.0, CY]])
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-K, -C]])
    result = stickslip.stability("slider-belt")
    np.testing.assert_allclose(result.equilibrium, q, rtol=0, atol=1e-12)
    by_hand = sorted(np.linalg.eigvals(A), key=lambda z: (-z.real, -z.imag))
    np.testing.assert_allclose(result.eigenvalues, by_hand, rtol=0, atol=1e-10)
    assert result.eigenvalues[0].real == pytest.approx(0.105487, abs=1e-6)


def test_the_whole_run_matches_the_scipy_solution(runs):
    """Every transition of each kind at the reference's instant, and every sample's state (20 a
    second), to 1e-9 (measured: 1.1e-10 in time and in state, with and without contact damping)."""
    traj, ref, switches = runs
    assert traj.status == "success" and traj.t[-1] == T_END
    tr = traj.transitions
    for kind in (OPEN, CLOSE, STICK, SLIP):
        np.testing.assert_allclose(tr.time[tr.kind == kind], switches[kind], rtol=0, atol=1e-9)
    np.testing.assert_allclose(traj.states, ref, rtol=0, atol=1e-9)


def test_the_default_start_sticks_slips_separates_and_reattaches(runs):
    """All four kinds of transition happen, and keep happening in the second half of the run
    (the settled cycle), where the contact is open a nonzero fraction of the time: the
    reference's flights cut to the window (to its whole periods where the run is periodic)."""
    traj, ref, switches = runs
    tr = traj.transitions
    late = tr.time > STEADY_FROM
    for kind in (OPEN, CLOSE, STICK, SLIP):
        assert np.sum(late & (tr.kind == kind)) >= 10
    assert traj.open.any() and (~traj.open).any()
    opens, closes = switches[OPEN], switches[CLOSE]
    flights = [(a, closes[closes > a][0] if np.any(closes > a) else T_END) for a in opens]
    steady = traj.steady_state(STEADY_FROM)
    start = STEADY_FROM  # a periodic run's fractions are over the whole periods that end the window
    if steady.periodic:
        period = 1.0 / steady.fundamental_frequency_hz
        start = T_END - (T_END - STEADY_FROM) // period * period
    open_time = sum(max(0.0, min(b, T_END) - max(a, start)) for a, b in flights)
    assert steady.open_fraction > 0.3
    assert steady.open_fraction == pytest.approx(open_time / (T_END - start), abs=1e-9)


def test_the_command_line_runs_it_and_sets_its_parameters():
    """``simulate --model slider-belt`` shows openings and stick; ``--set P=1`` (twice the
    preload) keeps the contact closed over the same 100 s; a path into an expression of the file
    is refused in one line that names the parameter to set."""
    runner = CliRunner()
    res = runner.invoke(app, ["simulate", "--model", "slider-belt", "--t-end", "100", "--json"])
    assert res.exit_code == 0, res.output
    default = json.loads(res.stdout.strip().splitlines()[-1])
    belt = default["contacts"]["belt"]
    assert default["model"] == "slider-belt" and default["status"] == "success"
    assert belt["openings"] > 0 and belt["stick_fraction"] > 0 and belt["n_transitions"] > 0
    res = runner.invoke(app, ["simulate", "--model", "slider-belt", "--set", "P=1", "--set",
                              "contact.0.normal.damping=0.5", "--t-end", "100", "--json"])
    assert res.exit_code == 0, res.output
    pressed = json.loads(res.stdout.strip().splitlines()[-1])
    assert pressed["parameters"]["P"] == 1.0 and pressed["parameters"]["contact.0.normal.damping"] == 0.5
    assert pressed["open_fraction"] == 0.0 and pressed["contacts"]["belt"]["openings"] == 0
    assert pressed["stick_fraction"] > 0
    res = runner.invoke(app, ["simulate", "--model", "slider-belt", "--set", "contact.0.normal.stiffness=10"])
    lines = res.output.strip().splitlines()
    assert res.exit_code == 2 and len(lines) == 1 and "kc" in lines[0], res.output
