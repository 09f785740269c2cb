"""The ``belt`` library model against its closed-form stick and slip phases and bSTAB's attractors.

m x'' + c x' + k x = F,  v = x' − V (belt speed V), N constant. In stick x' = V, so x is linear
in t and the contact breaks away where the stick force k x + c V reaches μs N (any friction law).
With the Coulomb law the slip phase is a damped oscillator about μk N / k in closed form, so the
whole stick-slip cycle is known; the slip end (x' back to V) is a root of that closed form.
"""

import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from stickslip import simulate
from stickslip.model.library import load_model

#: The defaults of bSTAB's friction case (m, c, k, V, N, μk, μs), written out independently of
#: belt.toml: x'' + 2ξ x' + x = friction, ξ = 0.05, v_d = 1.5, μd = 0.5, μs = μd μsd = 1.0.
BSTAB = dict(m=1.0, c=0.1, k=1.0, V=1.5, N=1.0, mu_k=0.5, mu_s=1.0)


def breakaway_position(p):
    """x where the stick force k x + c V reaches μs N."""
    return (p["mu_s"] * p["N"] - p["c"] * p["V"]) / p["k"]


def coulomb_slip(p, tau):
    """(x, x') a time τ after breakaway, Coulomb slip with x' < V (friction +μk N): closed form."""
    w0 = math.sqrt(p["k"] / p["m"])
    zeta = p["c"] / (2.0 * p["m"] * w0)
    wd = w0 * math.sqrt(1.0 - zeta * zeta)
    xk = p["mu_k"] * p["N"] / p["k"]
    A = breakaway_position(p) - xk
    B = (p["V"] + zeta * w0 * A) / wd
    e = np.exp(-zeta * w0 * tau)
    cs, sn = np.cos(wd * tau), np.sin(wd * tau)
    x = xk + e * (A * cs + B * sn)
    dx = e * ((wd * B - zeta * w0 * A) * cs - (zeta * w0 * B + wd * A) * sn)
    return x, dx


def coulomb_cycle(p):
    """(slip duration, stick duration, x at the start of stick) of the Coulomb stick-slip cycle."""
    tau = np.linspace(1e-6, 4.0 * math.pi * math.sqrt(p["m"] / p["k"]), 40001)
    gap = coulomb_slip(p, tau)[1] - p["V"]
    assert gap[0] < 0.0, "after breakaway the mass must fall behind the belt"
    i = int(np.flatnonzero((gap[:-1] < 0.0) & (gap[1:] >= 0.0))[0])
    t_slip = brentq(lambda s: coulomb_slip(p, s)[1] - p["V"], tau[i], tau[i + 1], xtol=1e-15, rtol=1e-15)
    x_stick = float(coulomb_slip(p, t_slip)[0])
    assert abs(p["k"] * x_stick + p["c"] * p["V"]) <= p["mu_s"] * p["N"], "the mass must stick at x' = V"
    return t_slip, (breakaway_position(p) - x_stick) / p["V"], x_stick


def phases(traj):
    """Transition times and kinds from the first breakaway on (every later phase is on the cycle)."""
    tr = traj.transitions
    first = int(np.flatnonzero(tr.kind == -1)[0])
    return tr.time[first:], tr.kind[first:], tr.state[first:]


@pytest.mark.parametrize("damping, delta_mu", [(0.0, 0.5), (0.02, 1.5)])
def test_coulomb_stick_slip_cycle_is_the_closed_form(damping, delta_mu):
    p = dict(BSTAB, c=damping, mu_s=BSTAB["mu_k"] + delta_mu)
    model = load_model("belt").replace(**{"contact.0.friction.law": "coulomb", "damping.x.x": damping,
                                          "contact.0.friction.delta_mu": delta_mu})
    t_slip, t_stick, x_stick = coulomb_cycle(p)
    period = t_slip + t_stick
    # start stuck to the belt at x = 0: the first breakaway is closed form too
    traj = simulate(model, 6.5 * period, ic={"x": 0.0, "dx": p["V"]}, rtol=1e-11, atol=1e-13, sample_rate=50)
    assert traj.status == "success"
    t, kind, state = phases(traj)
    assert t[0] == pytest.approx(breakaway_position(p) / p["V"], rel=1e-10)
    assert len(t) >= 10 and np.all(kind[0::2] == -1) and np.all(kind[1::2] == 1)
    slips = t[1::2] - t[0::2][: len(t[1::2])]
    sticks = t[2::2] - t[1::2][: len(t[2::2])]
    np.testing.assert_allclose(slips, t_slip, rtol=1e-9)
    np.testing.assert_allclose(sticks, t_stick, rtol=1e-9)
    scale = breakaway_position(p)
    np.testing.assert_allclose(state[1::2, 0], x_stick, rtol=0, atol=1e-9 * scale)  # x entering stick
    np.testing.assert_allclose(state[0::2, 0], scale, rtol=1e-10)                    # x at breakaway
    np.testing.assert_allclose(state[:, 1], p["V"], rtol=1e-10)               # v = 0 at every transition


def test_exponential_law_stick_phases_are_linear_and_break_away_at_mu_s():
    """bSTAB's defaults from its limit-cycle template (2, 2): each stick phase moves with the belt
    and ends where k x + c V = μs N (the slip phases of the exponential law have no closed form)."""
    p = BSTAB
    traj = simulate("belt", 100.0, ic={"x": 2.0, "dx": 2.0}, rtol=1e-11, atol=1e-13, sample_rate=100)
    assert traj.status == "success"
    tr = traj.transitions
    enter = np.flatnonzero(tr.kind == 1)
    enter = enter[enter + 1 < len(tr)]
    assert enter.size >= 10
    x_s = tr.state[enter, 0]
    duration = tr.time[enter + 1] - tr.time[enter]
    np.testing.assert_allclose(duration, (breakaway_position(p) - x_s) / p["V"], rtol=1e-9)
    np.testing.assert_allclose(tr.state[enter + 1, 0], breakaway_position(p), rtol=1e-10)
    # every sample in stick lies on the straight line of its stick phase
    for i in enter:
        inside = (traj.t > tr.time[i]) & (traj.t < tr.time[i + 1])
        assert np.all(traj.mode[inside] == 1)
        np.testing.assert_allclose(traj.states[inside, 0], tr.state[i, 0] + p["V"] * (traj.t[inside] - tr.time[i]),
                                   rtol=0, atol=1e-10)
        np.testing.assert_allclose(traj.states[inside, 1], p["V"], rtol=0, atol=1e-10)


def test_bstab_templates_reach_their_attractors():
    """bSTAB's friction case labels the initial condition (0.1, 0.1) a fixed point (steady sliding)
    and (2, 2) the limit cycle (stick-slip); its feature is max |x'| after t = 400 (FP if ≤ 0.2)."""
    p = BSTAB
    mu_at_belt_speed = p["mu_k"] + (p["mu_s"] - p["mu_k"]) * math.exp(-2.0 * p["V"])  # α = 1 / v0 = 2
    fp = simulate("belt", 500.0, ic={"x": 0.1, "dx": 0.1}, rtol=1e-10, atol=1e-12, sample_rate=10)
    lc = simulate("belt", 500.0, ic={"x": 2.0, "dx": 2.0}, rtol=1e-10, atol=1e-12, sample_rate=10)
    late = fp.t >= 400.0
    assert np.max(np.abs(fp.states[late, 1])) <= 0.2
    assert not np.any(fp.mode[late])
    assert fp.states[-1, 0] == pytest.approx(mu_at_belt_speed * p["N"] / p["k"], abs=1e-3)
    assert np.max(np.abs(lc.states[late, 1])) > 0.2
    assert np.any(lc.mode[late] == 1) and np.any(lc.mode[late] == 0)


def test_the_python_definition_in_the_docs_is_the_library_belt():
    """docs/models.md defines the belt with FrictionModel directly; it runs as the library's file."""
    text = (Path(__file__).resolve().parents[2] / "docs" / "models.md").read_text()
    block = next(b for b in re.findall(r"```python\n(.*?)```", text, flags=re.S) if 'name="my-belt"' in b)
    namespace = {}
    exec(block, namespace)
    reference = simulate("belt", 100.0, ic={"x": 2.0, "dx": 2.0})
    np.testing.assert_array_equal(namespace["traj"].states, reference.states)
    np.testing.assert_array_equal(namespace["traj"].transitions.time, reference.transitions.time)


@pytest.mark.parametrize("V", [0.8, 1.0, 1.1, 1.2, 1.5, 2.0])
def test_steady_sliding_and_its_eigenvalues_are_the_analytic_ones(V):
    """Linearised about steady sliding x = μ(V) N / k, the falling law adds −α Δμ e^(−αV) N to the
    damping: x'' + (c − α Δμ e^(−αV) N) x' + k x = 0 (m = 1), unstable below V = ln(α Δμ N / c) / α."""
    from stickslip.stability.analysis import stability

    p, alpha, delta_mu = BSTAB, 2.0, 0.5
    res = stability(load_model("belt").replace(**{"contact.0.drive": V}))
    d = p["c"] - alpha * delta_mu * math.exp(-alpha * V) * p["N"]
    expected = np.roots([p["m"], d, p["k"]])
    np.testing.assert_allclose(np.sort_complex(res.eigenvalues), np.sort_complex(expected), rtol=0, atol=1e-13)
    assert res.equilibrium[0] == pytest.approx((p["mu_k"] + delta_mu * math.exp(-alpha * V)) * p["N"] / p["k"],
                                               rel=1e-13)
    assert res.stable == (V > math.log(alpha * delta_mu * p["N"] / p["c"]) / alpha)
