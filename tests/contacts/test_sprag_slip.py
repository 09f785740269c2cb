"""The sprag-slip library model: steady sliding in closed form below the friction threshold μ*,
none above it (the stability command says so in one line), and the motion above it checked
against a separate event-driven scipy solution written here.

Equations (unit mass, damping c on x and y, the beam's stiffness K = R diag(ka, kb) Rᵀ tilted
by α, preload P, contact stiffness kc, belt speed V; s = sin α, co = cos α):

    K11 = ka co² + kb s²,   K12 = (kb − ka) s co,   K22 = ka s² + kb co²
    x'' = −c x' − K11 x − K12 y + F,   y'' = −c y' − K12 x − K22 y + P − λ

closed (λ = P + kc y > 0): slip F = −μ λ sign(x' − V), stick x' = V with the force
F = c V + K11 x + K12 y while |F| ≤ μ λ; open: λ = F = 0. Steady sliding (x' = 0, F = μ λ):

    D(μ) = ka kb + kc K11 + μ kc K12,   μ* = (ka kb + kc K11) / (−kc K12)
    x = μ P (K22 + kc) / D,   y = −μ P K12 / D,   λ = P (ka kb + kc K11) / D = P / (1 − μ/μ*)

so λ ≤ 0 (no steady sliding with the contact closed) for μ ≥ μ*.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from typer.testing import CliRunner

import stickslip
from stickslip.analysis.signal import CLOSE, OPEN, SLIP, STICK
from stickslip.cli import app

ALPHA, KA, KB, KC, P, V, C, MU = 60.0, 100.0, 1.0, 100.0, 1.0, 1.0, 0.02, 0.7
S, CO = math.sin(math.radians(ALPHA)), math.cos(math.radians(ALPHA))
K11, K12, K22 = KA * CO**2 + KB * S**2, (KB - KA) * S * CO, KA * S**2 + KB * CO**2
MU_STAR = (KA * KB + KC * K11) / (-KC * K12)
LIFTED_Y, LIFTED_T = -0.3, 30.0  # released 0.29 above the belt with the beam bent up

runner = CliRunner()


def steady(mu):
    """Closed-form steady sliding: (x, y), λ."""
    d = KA * KB + KC * K11 + mu * KC * K12
    return np.array([mu * P * (K22 + KC) / d, -mu * P * K12 / d]), P * (KA * KB + KC * K11) / d


def slip_matrix(mu):
    """First-order matrix of the slip equations linearised at steady sliding."""
    k = np.array([[K11, K12 - mu * KC], [K12, K22 + KC]])
    return np.block([[np.zeros((2, 2)), np.eye(2)], [-k, -C * np.eye(2)]])


def mu_k(mu):
    return f"contact.0.friction.mu_k={mu!r}"


def test_the_file_states_the_values_the_closed_form_uses():
    model = stickslip.load_model("sprag-slip")
    assert {k: model.parameters[k] for k in ("alpha", "ka", "kb", "kc", "P", "V", "c")} == dict(
        alpha=ALPHA, ka=KA, kb=KB, kc=KC, P=P, V=V, c=C)
    assert model.parameters["contact.0.friction.mu_k"] == MU > MU_STAR
    np.testing.assert_allclose(model.stiffness, [[K11, K12], [K12, K22]], rtol=1e-15)
    assert MU_STAR == pytest.approx(0.6240048363968684, abs=1e-15)


def test_the_rigid_limit_is_spurrs_strut():
    """kb → 0, kc → ∞: μ* → cot α and λ = P / (1 − μ tan α), through the package."""
    model = stickslip.load_model("sprag-slip").replace(kb=1e-6, kc=1e6)
    tan = math.tan(math.radians(ALPHA))
    for mu in (0.5 / tan, 0.99 / tan):
        q = stickslip.stability(model.replace(**{"contact.0.friction.mu_k": mu})).equilibrium
        assert P + 1e6 * q[1] == pytest.approx(P / (1 - mu * tan), rel=1e-5)
    with pytest.raises(stickslip.EquilibriumError, match="would be open"):
        stickslip.stability(model.replace(**{"contact.0.friction.mu_k": 1.01 / tan}))


@pytest.mark.parametrize("mu", [0.0, 0.3, 0.6, 0.98 * MU_STAR])
def test_steady_sliding_below_mu_star_is_the_closed_form(mu):
    model = stickslip.load_model("sprag-slip").replace(**{"contact.0.friction.mu_k": mu})
    result = stickslip.stability(model)
    q, lam = steady(mu)
    np.testing.assert_allclose(result.equilibrium, q, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(np.sort_complex(result.eigenvalues), np.sort_complex(np.linalg.eigvals(slip_matrix(mu))),
                               rtol=0, atol=1e-10)
    assert result.stable and result.max_real_part == pytest.approx(-C / 2, abs=1e-10)
    traj = stickslip.simulate(model, 1.0, ic="equilibrium", rtol=1e-11, atol=1e-13, sample_rate=10.0)
    assert lam == pytest.approx(P / (1 - mu / MU_STAR), rel=1e-13)
    np.testing.assert_allclose(traj.normal_force[:, 0], lam, rtol=1e-10)
    np.testing.assert_allclose(traj.states[:, :2], np.broadcast_to(q, (traj.t.size, 2)), rtol=1e-10, atol=1e-14)


def test_stability_reports_steady_sliding_below_mu_star_and_none_above_it():
    below = runner.invoke(app, ["stability", "--model", "sprag-slip", "--set", mu_k(0.98 * MU_STAR), "--json"])
    assert below.exit_code == 0, below.output
    data = json.loads(below.stdout)
    q, _ = steady(0.98 * MU_STAR)
    assert data["equilibrium"]["x"] == pytest.approx(q[0], rel=1e-10)
    assert data["equilibrium"]["y"] == pytest.approx(q[1], rel=1e-10)
    got = np.sort_complex(np.array([complex(re, im) for re, im in data["eigenvalues"]]))
    np.testing.assert_allclose(got, np.sort_complex(np.linalg.eigvals(slip_matrix(0.98 * MU_STAR))), atol=1e-10)
    assert data["stable"] is True
    table = runner.invoke(app, ["stability", "--model", "sprag-slip", "--set", mu_k(0.98 * MU_STAR)])
    assert table.exit_code == 0 and "steady sliding is stable" in table.stdout

    above = runner.invoke(app, ["stability", "--model", "sprag-slip", "--set", mu_k(1.02 * MU_STAR)])
    lines = [ln for ln in above.output.splitlines() if ln.strip()]
    # the closed form on the open side: λ = P/(1 − 1.02) = −50, gap −P/kc − y = 0.5
    assert above.exit_code == 2 and lines == [
        "error: no steady sliding at model 'sprag-slip': contact 0 (tip) would be open (gap 0.5, normal force -50 "
        "with it closed), though it is pressed without friction: the friction jams it (sprag: the friction "
        "coefficient is past the model's threshold); lower it or simulate the motion"]
    default = runner.invoke(app, ["stability", "--model", "sprag-slip"])
    assert default.exit_code == 2 and "normal force -8.21111 with it closed" in default.output


# -- the motion above μ*: a separate event-driven solution ----------------------------------------

def _rhs(mode):
    """Right-hand side in ``mode``: "open", "stick", or slip with sign(v) = ``mode`` (±1)."""
    def f(t, s):
        x, y, dx, dy = s
        lam = 0.0 if mode == "open" else P + KC * y
        ax = -C * dx - K11 * x - K12 * y
        ay = -C * dy - K12 * x - K22 * y + P - lam
        if mode == "stick":
            return [dx, dy, 0.0, ay]
        return [dx, dy, ax if mode == "open" else ax - mode * MU * lam, ay]
    return f


def _stick_force(s):
    return C * V + K11 * s[0] + K12 * s[1]


def _event(fun, direction):
    fun.terminal, fun.direction = True, direction
    return fun


def _events(mode):
    """(event, next mode or a function of the state giving it, transition kinds) leaving ``mode``."""
    normal = lambda t, s: P + KC * s[1]  # noqa: E731  λ with the contact closed
    if mode == "open":
        return [(_event(normal, 1.0), lambda s: -1 if s[2] < V else 1, [CLOSE])]
    if mode == "stick":
        margin = lambda t, s: MU * (P + KC * s[1]) - abs(_stick_force(s))  # noqa: E731
        return [(_event(normal, -1.0), lambda s: "open", [SLIP, OPEN]),
                (_event(margin, -1.0), lambda s: 1 if _stick_force(s) < 0 else -1, [SLIP])]

    def arrive(s):  # v reaches 0 in slip: stick if the stick force is admissible, else slip on
        return "stick" if abs(_stick_force(s)) <= MU * (P + KC * s[1]) else (-1 if _stick_force(s) > 0 else 1)
    return [(_event(normal, -1.0), lambda s: "open", [OPEN]),
            (_event(lambda t, s: s[2] - V, -float(mode)), arrive, [])]


def reference(t_eval, s0):
    """DOP853 at rtol 1e-12, restarted at every located event: the states at ``t_eval`` and the
    transitions in order, as (instants, kinds)."""
    s, t0 = np.array(s0, dtype=float), 0.0
    mode = "open" if P + KC * s[1] <= 0 else (-1 if s[2] < V else 1)
    out = np.empty((t_eval.size, 4))
    switches = []
    while True:
        table = _events(mode)
        sol = solve_ivp(_rhs(mode), (t0, t_eval[-1]), s, method="DOP853", rtol=1e-12, atol=1e-14,
                        events=[e for e, _, _ in table], dense_output=True)
        inside = (t_eval >= t0) & (t_eval <= sol.t[-1])
        if inside.any():
            out[inside] = sol.sol(t_eval[inside]).T
        t0, s = sol.t[-1], sol.y[:, -1]
        if sol.status != 1:
            return out, (np.array([t for t, _ in switches]), np.array([k for _, k in switches], dtype=int))
        _, successor, kinds = table[[i for i, te in enumerate(sol.t_events) if te.size][0]]
        mode = successor(s)
        switches += [(t0, kind) for kind in kinds + ([STICK] if mode == "stick" else [])]


@pytest.fixture(scope="module")
def lifted(tmp_path_factory):
    """``simulate`` above μ* from a tip released above the belt, and the reference."""
    path = tmp_path_factory.mktemp("sprag") / "lifted.nc"
    res = runner.invoke(app, ["simulate", "--model", "sprag-slip", "--ic", f"y={LIFTED_Y}", "--t-end", str(LIFTED_T),
                              "--rtol", "1e-11", "--atol", "1e-13", "--sample-rate", "50", "--out", str(path),
                              "--no-plot", "--json"])
    assert res.exit_code == 0, res.output
    traj = stickslip.load_trajectory(path)
    ref, switches = reference(traj.t, traj.states[0])
    return traj, ref, switches


def test_above_mu_star_the_tip_hops_slips_sticks_and_locks(lifted):
    traj, _, _ = lifted
    tr = traj.transitions
    assert traj.status == "success" and traj.t[-1] == LIFTED_T
    assert all(np.sum(tr.kind == kind) >= 4 for kind in (OPEN, CLOSE, STICK, SLIP))
    last = tr.time.max()
    assert tr.kind[tr.time == last][-1] == STICK and last < LIFTED_T / 2
    locked = traj.t > last
    assert traj.stick[locked, 0].all() and not traj.open[locked, 0].any()
    np.testing.assert_allclose(traj.states[locked, 2], V, rtol=0, atol=1e-12)  # carried by the belt


def test_the_run_matches_the_scipy_solution(lifted):
    traj, ref, (instants, kinds) = lifted
    assert traj.transitions.kind.tolist() == kinds.tolist()  # the same sequence of events, one by one
    np.testing.assert_allclose(traj.transitions.time, instants, rtol=0, atol=1e-9)
    np.testing.assert_allclose(traj.states, ref, rtol=0, atol=1e-8)
    closed = ~traj.open[:, 0]
    np.testing.assert_allclose(traj.normal_force[closed, 0], P + KC * ref[closed, 1], rtol=0, atol=1e-6)


def test_the_default_run_slips_then_locks_for_good():
    """From rest at the frictionless equilibrium the tip slips, reaches the belt's speed and never
    leaves stick: x = x1 + V (t − t1), and |F|/λ creeps up to μ* < μ from below."""
    res = runner.invoke(app, ["simulate", "--model", "sprag-slip", "--rtol", "1e-11", "--atol", "1e-13", "--json"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout)
    assert summary["stick_fraction"] == 1.0 and summary["open_fraction"] == 0.0 and summary["n_transitions"] == 0
    model = stickslip.load_model("sprag-slip")
    traj = stickslip.simulate(model, 100.0, rtol=1e-11, atol=1e-13, sample_rate=10.0)
    ref, (instants, kinds) = reference(traj.t, np.zeros(4))
    assert traj.transitions.kind.tolist() == kinds.tolist() == [STICK]
    assert traj.transitions.time[0] == pytest.approx(instants[0], abs=1e-9)
    np.testing.assert_allclose(traj.states, ref, rtol=0, atol=1e-8)
    assert summary["x_max"] == pytest.approx(traj.states[-1, 0], abs=1e-6)
    ratio = np.abs(traj.friction[:, 0]) / traj.normal_force[:, 0]
    late = traj.t > 50.0
    assert np.all(ratio[late] < MU_STAR) and MU_STAR - ratio[-1] < 0.01
