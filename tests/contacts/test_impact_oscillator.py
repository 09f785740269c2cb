"""The ``impact-oscillator`` library model: a mass bouncing on a rigid moving stop, against its
closed form, written here independently of the package.

Its equations (the file's numbers): m = 1, x along the stop with a spring kx = 1 (ωx = 1), y
normal to it with a spring ky = 4π² (ω = 2π) whose rest position lies d = 0.1 inside the stop,
g = y ≥ 0, restitution e = 0.8, Coulomb friction μ = 0.3 on the slip v = x' − V, V = 0.2.

* y, dropped from rest at y0: first landing at t1 = acos(d/(y0 + d))/ω with speed
  u1 = ω √((y0 + d)² − d²); the k-th bounce leaves with e^k u1 and, under the spring, lands again
  after T = (2/ω) atan(e^k u1/(ω d)) with the same speed (tan(ωT/2) = u/(ω d)); the landings
  accumulate at the rest time t1 + Σ T_k, after which λ = ky d.
* x: free oscillation x(τ) = x0 cos τ + v0 sin τ in flight; at a landing with speed u the normal
  impulse is P_N = m (1 + e) u and the tangential one sticks, x'⁺ = V, where m |V − x'⁻| ≤ μ P_N,
  else slides, x'⁺ = x'⁻ − μ P_N sign(x'⁻ − V) / m; at rest it slides, x'' = −x + μ λ, until
  x' = V, where it sticks (|x| ≤ μ λ / kx).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.optimize import brentq
from typer.testing import CliRunner

import stickslip
from stickslip.cli import app
from stickslip.errors import ModelError, SimulationError
from stickslip.integrate.contacts import TRANSITION_CLOSE, TRANSITION_IMPACT, TRANSITION_OPEN, TRANSITION_TO_STICK
from stickslip.integrate.result import Impact, Impacts
from stickslip.integrate.status import Status
from stickslip.model import model_from_spec
from stickslip.model.system_model import NormalLaw

E, MU, V, D, Y0 = 0.8, 0.3, 0.2, 0.1, 0.5
OMEGA = 2.0 * math.pi
KY = OMEGA ** 2
#: Tolerances of the runs compared with the closed form (its error is the integrator's).
RTOL, ATOL = 1e-12, 1e-14


def closed_form(n_bounces: int = 400, MU: float = MU):
    """Landing instants, landing speeds, the state (x, x') before each landing, the rest time and
    x, x' there (the closed form of the module docstring; friction coefficient ``MU``)."""
    t = math.acos(D / (Y0 + D)) / OMEGA
    u = OMEGA * math.sqrt((Y0 + D) ** 2 - D ** 2)
    x, dx = math.cos(t) * 0.0, 0.0  # at rest at x = 0 until the first landing
    times, speeds, before = [], [], []
    for _ in range(n_bounces):
        times.append(t)
        speeds.append(u)
        before.append((x, dx))
        impulse = (1.0 + E) * u
        if abs(V - dx) <= MU * impulse:
            dx = V
        else:
            dx -= MU * impulse * math.copysign(1.0, dx - V)
        u *= E
        flight = 2.0 / OMEGA * math.atan(u / (OMEGA * D))
        x, dx = x * math.cos(flight) + dx * math.sin(flight), -x * math.sin(flight) + dx * math.cos(flight)
        t += flight
    return np.array(times), np.array(speeds), np.array(before), t, (x, dx)


def after_rest(t_rest, x, dx, t, MU=MU):
    """(stick instant or None, x at ``t``) after the rest time: at rest on the stop λ = ky d; with
    x' = V there the contact sticks at once (|kx x| ≤ μ λ here), else it slides, x'' = −x + μ λ
    (x' < V), x = c + (x_r − c) cos τ + x'_r sin τ with c = μ λ / kx, until x' reaches V. Stuck,
    the mass rides with the stop, x' = V, while kx x ≤ μ λ (checked to hold until ``t``)."""
    c = MU * KY * D
    if abs(dx - V) < 1e-9:
        assert x + V * (t - t_rest) <= c
        return t_rest, x + V * (t - t_rest)

    def rate(tau):
        return -(x - c) * math.sin(tau) + dx * math.cos(tau) - V
    taus = np.linspace(0.0, t - t_rest, 20001)
    values = [rate(tau) for tau in taus]
    i = next((i for i in range(1, len(taus)) if values[i - 1] < 0.0 <= values[i]), None)
    if i is None:
        return None, c + (x - c) * math.cos(t - t_rest) + dx * math.sin(t - t_rest)
    tau = brentq(rate, taus[i - 1], taus[i], xtol=1e-15)
    x_stick = c + (x - c) * math.cos(tau) + dx * math.sin(tau)
    assert x_stick + V * (t - t_rest - tau) <= c
    return t_rest + tau, x_stick + V * (t - t_rest - tau)


@pytest.fixture(scope="module")
def run():
    model = stickslip.load_model("impact-oscillator")
    return stickslip.simulate(model, 6.0, ic=np.array([0.0, Y0, 0.0, 0.0]), rtol=RTOL, atol=ATOL,
                              sample_rate=100.0, steady_from=0.0)


def test_impact_times_and_rest_time_match_the_closed_form(run):
    times, speeds, before, t_rest, _ = closed_form()
    impacts = run.impacts
    k = len(impacts)
    # the bounces that land later than ZENO_TIME before the rest time are all followed; the rest
    # accumulate at the last one
    assert 60 < k < len(times)
    assert np.max(np.abs(impacts.time - times[:k])) < 1e-8
    closes = run.transitions.time[run.transitions.kind == TRANSITION_CLOSE]
    assert closes.size == 1 and abs(closes[0] - t_rest) < 1e-8
    assert t_rest - impacts.time[-1] < 1e-8


def test_landing_speeds_impulses_and_rebounds(run):
    _, speeds, _, _, _ = closed_form()
    imp = run.impacts
    k = len(imp)
    # relative 1e-8, and an absolute floor for the last, micrometre-per-second landings: the
    # integrator's velocity error (~1e-11 m/s at these tolerances) carried through the bounces
    np.testing.assert_allclose(-imp.speed_before, speeds[:k], rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(imp.speed_after[:-1], E * speeds[:k - 1], rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(imp.impulse[:-1], (1.0 + E) * speeds[:k - 1], rtol=1e-8, atol=1e-10)
    assert imp.speed_after[-1] == 0.0  # the accumulation point: at rest on the stop
    assert (run.transitions.kind == TRANSITION_OPEN).sum() == k - 1


def test_impacts_are_a_sequence_of_typed_records(run):
    """``run.impacts[i]`` is impact i of the closed form: its instant, contact, speeds and impulse."""
    times, speeds, _, _, _ = closed_form()
    imp = run.impacts
    first = imp[0]
    assert isinstance(first, Impact) and first.contact == 0
    assert abs(first.time - times[0]) < 1e-8
    assert abs(first.speed_before + speeds[0]) < 1e-8 * speeds[0]
    assert abs(first.speed_after - E * speeds[0]) < 1e-8 * speeds[0]
    assert abs(first.impulse - (1.0 + E) * speeds[0]) < 1e-8 * speeds[0]
    assert imp[-1].time == imp.time[-1] and imp[-1].speed_after == 0.0
    assert [i.time for i in imp] == list(imp.time) and len(list(imp)) == len(imp)
    assert isinstance(imp[1:3], Impacts) and len(imp[1:3]) == 2 and imp[1:3][0] == imp[1]
    with pytest.raises(IndexError):
        imp[len(imp)]


@pytest.mark.parametrize("mu", [MU, 0.02])
def test_coulomb_impulses_stick_or_slide_as_the_closed_form(run, mu):
    """μ = 0.3 (the file's): every landing's tangential impulse is admissible, x'⁺ = V; μ = 0.02:
    most landings slide (the impulse μ P_N cannot stop the slip), a few stick."""
    if mu != MU:
        model = stickslip.load_model("impact-oscillator").replace(**{"contact.0.friction.mu_k": mu})
        run = stickslip.simulate(model, 6.0, ic=np.array([0.0, Y0, 0.0, 0.0]), rtol=RTOL, atol=ATOL,
                                 sample_rate=100.0)
    _, speeds, before, t_rest, after_rest_state = closed_form(MU=mu)
    tr = run.transitions
    at = np.flatnonzero(tr.kind == TRANSITION_IMPACT)
    states = tr.state[at]
    np.testing.assert_allclose(states[:, 0], before[:len(at), 0], atol=1e-8)
    np.testing.assert_allclose(states[:, 2], before[:len(at), 1], atol=1e-8)
    sticking = np.abs(V - before[:len(at), 1]) <= mu * (1.0 + E) * speeds[:len(at)]
    if mu == MU:
        assert sticking.all()
    else:
        assert not sticking[0] and sticking.any() and (~sticking).sum() > 10
    stick_at = tr.time[tr.kind == TRANSITION_TO_STICK]
    t_stick, x_end = after_rest(t_rest, *after_rest_state, t=run.t[-1], MU=mu)
    if t_stick is None:  # μ = 0.02: it slides on, never as fast as the stop
        assert stick_at.size == 0 or stick_at[-1] < t_rest
    else:
        assert abs(stick_at[-1] - t_stick) < 1e-7
    assert abs(run.states[-1, 0] - x_end) < 1e-7


def test_at_rest_the_stop_carries_the_preload(run):
    late = run.t > 4.3
    assert not run.open[late].any()
    np.testing.assert_allclose(run.normal_force[late, 0], KY * D, rtol=1e-9)
    np.testing.assert_allclose(run.gap[late, 0], 0.0, atol=1e-12)


def test_summary_counts_impacts(run):
    s = run.steady
    _, speeds, _, _, _ = closed_form()
    assert s.impacts == len(run.impacts)
    assert abs(s.max_impact_speed - speeds[0]) < 1e-8 * speeds[0]
    ds = run.to_xarray()
    assert "impact" in ds["transition_kind"].attrs["flag_meanings"]


def test_cli_simulate_json_reports_impacts(tmp_path):
    result = CliRunner().invoke(app, ["simulate", "--model", "impact-oscillator", "--ic", "y=0.5", "--t-end", "6",
                                      "--steady-from", "0", "--json", "--out", str(tmp_path / "r.nc")])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["impacts"] > 60 and abs(out["max_impact_speed"] - OMEGA * math.sqrt((Y0 + D) ** 2 - D ** 2)) < 1e-6


def test_restitution_on_the_command_line_changes_the_bounces(tmp_path):
    model = stickslip.load_model("impact-oscillator").replace(**{"contact.0.normal.restitution": 0.0})
    tr = stickslip.simulate(model, 2.0, ic=np.array([0.0, Y0, 0.0, 0.0]), sample_rate=100.0)
    assert len(tr.impacts) == 1 and tr.impacts.speed_after[0] == 0.0
    assert abs(tr.impacts.time[0] - math.acos(D / (Y0 + D)) / OMEGA) < 1e-7


def test_bad_rigid_numbers_are_refused_in_one_line():
    model = stickslip.load_model("impact-oscillator")
    with pytest.raises(ModelError, match=r"restitution = 1.5 must lie in \[0, 1\]"):
        model.replace(**{"contact.0.normal.restitution": 1.5})
    with pytest.raises(ModelError, match="a rigid contact has no stiffness or damping"):
        NormalLaw("rigid", stiffness=10.0).check("contact 0: normal")
    with pytest.raises(ModelError, match="restitution is a rigid contact's"):
        NormalLaw("compliant", stiffness=10.0, restitution=0.5).check("contact 0: normal")


@pytest.mark.parametrize(("state", "words"), [
    ([0.0, -0.01, 0.0, 0.0], "starts inside its stop"),
    ([0.0, 0.0, 0.0, -1.0], "starts at its stop moving into it"),
])
def test_starts_a_rigid_contact_cannot_take_are_refused(state, words):
    model = stickslip.load_model("impact-oscillator")
    with pytest.raises(SimulationError, match=words):
        stickslip.simulate(model, 1.0, ic=np.array(state))


def painleve_slider(mu: float):
    """A rigid contact with W = [0, 1], G = [1, 1], M = I, sliding forward, friction coefficient ``mu``."""
    return model_from_spec({
        "name": "painleve", "dofs": ["x", "y"], "mass": [[1.0, 0.0], [0.0, 1.0]],
        "damping": [[0.0, 0.0], [0.0, 0.0]], "stiffness": [[0.0, 0.0], [0.0, 1.0]], "force": [0.0, -1.0],
        "contact": [{"tangent": [[1.0, 1.0]], "drive": [-1.0], "gap": 0.0, "gap_gradient": [0.0, 1.0],
                     "normal": {"law": "rigid", "restitution": 0.0},
                     "friction": {"law": "coulomb", "mu_k": mu, "delta_mu": 0.0}}]})


def test_painleve_sliding_without_a_consistent_normal_force_stops_with_its_status():
    """W = [0, 1] and G = [1, 1] with M = I: sliding forward (e = +1), D = W·(W − μ G e) = 1 − μ,
    negative for μ = 1.5: no normal force keeps the contact closed consistently (Painlevé)."""
    model = painleve_slider(1.5)
    tr = stickslip.simulate(model, 1.0, sample_rate=100.0)
    assert tr.status_code is Status.INCONSISTENT
    assert "Painlevé" in tr.status and "\n" not in tr.status
    # the one sample, at the start, has no normal force: undefined, not the multiplier solved there
    assert tr.t.size == 1 and np.isnan(tr.normal_force[0, 0])


def test_a_consistent_rigid_normal_force_is_sampled_as_it_is():
    """The model above with μ = 0.5 (D = 1 − μ > 0): closed and sliding forward, y'' = −y − 1 +
    (1 − μ) λ = 0 at y = 0, so λ = 1 / (1 − μ) = 2 N from the first sample on."""
    model = painleve_slider(0.5)
    tr = stickslip.simulate(model, 0.2, sample_rate=100.0)
    assert tr.status_code is Status.SUCCESS
    np.testing.assert_allclose(tr.normal_force[:, 0], 2.0, rtol=1e-12)


def _refuse_constant(name):
    raise ValueError(f"{name} is not strict JSON")


def test_max_impact_speed_is_exact_beyond_the_kept_transition_states(tmp_path):
    """With e = 1 from rest at y0 every landing has the speed u = ω √((y0 + d)² − d²) (energy is
    conserved in flight and at the impacts); from y0 = 1e-8 the flights last ~0.14 ms, so 30 s
    hold some 2·10⁵ impacts, more transitions in the steady window than the run keeps states of.
    The window's largest landing speed is still u, and every --json value strict JSON."""
    y0 = 1e-8
    u = OMEGA * math.sqrt((y0 + D) ** 2 - D ** 2)
    result = CliRunner().invoke(app, ["simulate", "--model", "impact-oscillator", "--set",
                                      "contact.0.normal.restitution=1", "--ic", f"y={y0}", "--t-end", "30",
                                      "--sample-rate", "10", "--json", "--out", str(tmp_path / "r.nc")])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout, parse_constant=_refuse_constant)
    assert out["impacts"] > 100_000 and "max_impact_speed_reason" not in out
    assert abs(out["max_impact_speed"] - u) < 1e-6 * u
    tr = stickslip.load_trajectory(tmp_path / "r.nc")
    assert np.isnan(tr.transitions.state[0]).all()  # states dropped: the speed comes from the tally
    assert tr.steady.impacts == out["impacts"] and tr.steady.max_impact_speed == out["max_impact_speed"]
