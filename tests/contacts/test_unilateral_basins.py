"""Basins of a model whose contact opens and closes, with two coexisting attractors: the
``slider-belt`` library model at belt speed V = 0.6, tangential damper cx = 0.1 and a steep
friction fall α = 8 (the file's other values), where steady sliding is linearly stable and a
stick-slip cycle with a flight (the contact open 39 % of each period) persists for large starts.
Every label of a small grid is checked against a separate event-driven solution written here with
scipy (``event_reference``), and the cycle's period, amplitude, open and stick fractions against
that solution's settled cycle.

Equations (the file's model with these three values, written out by hand as in
``test_slider_belt.py``): K = [[13/4, −3√3/4], [−3√3/4, 7/4]], dampers 0.1 on x and 0.2 on y,
preload 0.5 towards the belt, contact stiffness 5 (no contact damping), belt speed 0.6,
μ(|v|) = 0.3 + 0.6 exp(−8 |v|), μs = 0.9. y points away from the belt, g = y − 0.1, and while
closed λ = 0.5 − 5 y > 0:

    x'' = −13/4 x + 3√3/4 y − 0.1 x' + F,      y'' = 3√3/4 x − 7/4 y − 0.2 y' − 0.5 + λ,
    slip: F = −μ(|v|) λ sign(v), v = x' − 0.6;  stick: x' = 0.6, x'' = 0, F = 13/4 x − 3√3/4 y
    + 0.1 · 0.6 while |F| ≤ 0.9 λ;  open: F = 0, λ = 0.

Steady sliding (x' = y' = 0, v = −0.6): 13/4 x − 3√3/4 y = μ(0.6) (0.5 − 5 y) and
−3√3/4 x + (7/4 + 5) y = 0.

Why these values: with the file's α = 2 steady sliding loses stability at V = 1.30 and the
flight cycle that the slip from rest grows into persists only up to V ≈ 1.355, where steady
sliding decays at 0.0027 1/s (measured by continuation in V). A steeper fall (α = 8) moves the
whole picture to lower speeds where the friction's slope is spent, and cx = 0.1 doubles the decay:
at V = 0.6 steady sliding decays at 0.0395 1/s and the cycle sticks, slips, separates and lands
once per period (3.4759932; stick 0.0454 and flight 0.3895 of it).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import stickslip
from stickslip.analysis.signal import CLOSE, OPEN, SLIP, STICK
from stickslip.basins import basin_stability, grid

from . import test_slider_belt as slider_belt
from .event_reference import event_driven

K11, K12, K22 = 13 / 4, -3 * math.sqrt(3) / 4, 7 / 4
CX, CY, P, KC, V = 0.1, 0.2, 0.5, 5.0, 0.6
MU_K, DELTA_MU, ALPHA = 0.3, 0.6, 8.0
#: The values set on the library model (its other values are the file's).
SETTINGS = {"V": V, "cx": CX, "contact.0.friction.alpha": ALPHA}
#: The grid: x and x' of the slider, y and y' held at steady sliding (the basins' default base).
BOX, COUNTS = {"x": (0.0, 2.0), "dx": (-2.0, 2.0)}, 8
#: Reference runs: every grid state to T_CLASSIFY, the two first and last states of each label
#: to T_LONG (steady sliding then within 1e-6 of its state; the cycle's periods equal to 1e-7).
T_CLASSIFY, T_LONG = 200.0, 400.0
#: Samples of the basins' runs per characteristic period, and the window the cycle's features
#: are taken over, in characteristic periods (docs/basins.md, "How each state is classified").
SAMPLES_PER_T_C, WINDOW_T_C = 64, 16


def mu(speed):
    return MU_K + DELTA_MU * math.exp(-ALPHA * speed)


def equations():
    """The model by hand for :func:`event_driven`: ``test_slider_belt.equations`` at this case's
    values, without contact damping."""
    return slider_belt.equations(0.0, V=V, CX=CX, ALPHA=ALPHA)


def steady_sliding():
    """(x_e, y_e) of steady sliding, solved by hand (module docstring)."""
    return np.linalg.solve([[K11, K12 + mu(V) * KC], [K12, K22 + KC]], [mu(V) * P, 0.0])


def linearisation():
    """Eigenvalues of steady sliding linearised by hand, as in ``test_slider_belt.py``: the
    falling friction law puts cx − λ0 μ'(V) on x, the friction's share μ(V) kc y of the contact
    force couples y into x."""
    q = steady_sliding()
    slope = ALPHA * DELTA_MU * math.exp(-ALPHA * V)  # dμ/dx' at x' = 0, where |v| = V − x'
    K = np.array([[K11, K12 + mu(V) * KC], [K12, K22 + KC]])
    C = np.array([[CX - (P - KC * q[1]) * slope, 0.0], [0.0, CY]])
    return np.linalg.eigvals(np.block([[np.zeros((2, 2)), np.eye(2)], [-K, -C]]))


def _reference(s0, t_eval):
    """:func:`event_driven` of the model from ``s0``."""
    return event_driven(**equations(), t_eval=np.asarray(t_eval, dtype=float), y0=np.asarray(s0, dtype=float))


def settled_cycle(switches, states, t_eval):
    """The features of the reference's last period (between its last two landings), and the
    relative spread of its last 10 periods."""
    closes, opens, sticks, slips = (switches[k] for k in (CLOSE, OPEN, STICK, SLIP))
    periods = np.diff(closes[-11:])
    t0, t1 = closes[-2], closes[-1]
    within = (t_eval > t0) & (t_eval <= t1)
    stick = sum(min(b, t1) - max(a, t0) for a in sticks for b in slips[slips > a][:1] if b > t0 and a < t1)
    return {"period": t1 - t0, "spread": float(np.ptp(periods) / periods.mean()),
            "flight": t1 - opens[opens < t1][-1], "stick": stick,
            "openings": int(np.sum((opens > t0) & (opens <= t1))),
            "sticks": int(np.sum((sticks > t0) & (sticks <= t1))),
            "amplitude": float(np.ptp(states[within, 0]))}


def reference_label(s0):
    """What the reference reaches from ``s0`` by T_CLASSIFY: ``equilibrium`` (within 1e-2 of
    steady sliding, no flight or stick over the last 50), ``periodic`` (flights over the last
    50, the last landing-to-landing interval the cycle's period (3.4759932) to 1e-4), else
    ``unknown``."""
    out, switches = _reference(s0, [0.0, T_CLASSIFY])
    late = {k: int(np.sum(v > T_CLASSIFY - 50.0)) for k, v in switches.items()}
    closes = switches[CLOSE]
    if np.abs(out[-1] - [*steady_sliding(), 0.0, 0.0]).max() < 1e-2 and late[OPEN] == late[STICK] == 0:
        return "equilibrium"
    if late[OPEN] >= 5 and abs(closes[-1] - closes[-2] - 3.4759932) < 1e-4:
        return "periodic"
    return "unknown"


@pytest.fixture(scope="module")
def model():
    return stickslip.load_model("slider-belt").replace(**SETTINGS)


@pytest.fixture(scope="module")
def result(model):
    return basin_stability(model, grid(model, BOX, COUNTS), t_end=500.0, executor="serial")


@pytest.fixture(scope="module")
def long_runs(result):
    """The reference from the first and the last state (in state order) of each label, to
    T_LONG, sampled densely over its last 7 time units (two periods of the cycle)."""
    states, labels = result.dataset["initial_state"].values, np.array(result.labels())
    t_eval = np.concatenate([[0.0], np.linspace(T_LONG - 7.0, T_LONG, 14001)])
    runs = {}
    for name in ("equilibrium", "periodic"):
        where = np.flatnonzero(labels == name)
        runs[name] = [(states[i], *_reference(states[i], t_eval)) for i in (where[0], where[-1])]
    return t_eval, runs


def test_the_settings_give_the_equations_written_here(model):
    np.testing.assert_allclose(model.stiffness, [[K11, K12], [K12, K22]], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(model.damping, [[CX, 0.0], [0.0, CY]])
    np.testing.assert_array_equal(model.force, [0.0, -P])
    params = model.parameters
    assert (params["V"], params["P"], params["kc"]) == (V, P, KC)
    assert params["contact.0.normal.damping"] == 0.0
    assert (params["contact.0.friction.mu_k"], params["contact.0.friction.delta_mu"],
            params["contact.0.friction.alpha"]) == (MU_K, DELTA_MU, ALPHA)


def test_steady_sliding_is_stable_and_the_contact_pressed_there(result):
    """The linearisation by hand: both pairs decay (the slower at 0.0395 1/s); the basins'
    steady sliding is the state solved by hand, pressed (λ = 0.455 > 0)."""
    eig = linearisation()
    assert eig.real.max() == pytest.approx(-0.039485, abs=1e-6)
    q = steady_sliding()
    assert P - KC * q[1] > 0.4
    [eq] = [a for a in result.attractors() if a["name"] == "equilibrium"]
    np.testing.assert_allclose([eq["state"][k] for k in ("x", "y", "dx", "dy")], [*q, 0.0, 0.0], rtol=0, atol=1e-12)
    assert eq["open_fraction"] == 0.0


def test_both_attractors_have_a_basin_and_every_label_is_the_references(result):
    """Two attractors on the 8 × 8 grid over x ∈ [0, 2], x' ∈ [−2, 2]: steady sliding and one
    cycle that sticks and flies. Every state's label is where the reference goes from it by
    t = 200 (measured 64 of 64: 34 steady sliding, 30 the cycle), so the fractions are the
    reference's fractions."""
    assert set(result.fractions) == {"equilibrium", "periodic"}
    assert result.complete
    states, labels = result.dataset["initial_state"].values, result.labels()
    reference = [reference_label(s0) for s0 in states]
    disagree = [(s0.round(4).tolist(), lab, ref) for s0, lab, ref in zip(states, labels, reference) if lab != ref]
    assert not disagree, disagree
    for name, fraction in result.fractions.items():
        assert fraction == reference.count(name) / len(reference)
    assert 0.25 < result.fractions["periodic"] < 0.75


def test_the_reference_from_states_labelled_steady_sliding_slides_steadily(long_runs):
    """From the first and the last state labelled ``equilibrium``: by t = 400 the state is
    within 1e-5 of steady sliding solved by hand (slider at rest, slip velocity −V), and over the
    last 200 the contact neither opens nor sticks (measured: within 3e-7)."""
    _, runs = long_runs
    q = steady_sliding()
    for s0, out, switches in runs["equilibrium"]:
        np.testing.assert_allclose(out[-1], [*q, 0.0, 0.0], rtol=0, atol=1e-5, err_msg=str(s0))
        assert out[-1, 2] - V == pytest.approx(-V, abs=1e-5)
        for kind in (OPEN, CLOSE, STICK, SLIP):
            assert not np.any(switches[kind] > T_LONG - 200.0), (s0, kind)


def test_the_cycle_is_the_references_settled_cycle(result, long_runs):
    """From the first and the last state labelled ``periodic`` the reference settles on one
    cycle (its last 10 periods equal to 1e-7) with one stick, one lift-off and one landing per
    period. The basins' cycle has its period (to 1e-5; measured 3e-7) and amplitude of x (to
    1e-5; measured 8e-7), and its open and stick fractions to the window's sample spacing: taken
    over the whole periods that end the window, which starts on a sample, they are off by at most
    dt / (window − dt), dt = T_c / 64, the window 15 or more periods."""
    t_eval, runs = long_runs
    cycles = [settled_cycle(switches, out, t_eval) for s0, out, switches in runs["periodic"]]
    for c in cycles:
        assert c["spread"] < 1e-7
        assert c["openings"] == 1 and c["sticks"] == 1
        assert c["period"] == pytest.approx(cycles[0]["period"], rel=1e-7)
        assert c["amplitude"] == pytest.approx(cycles[0]["amplitude"], rel=1e-6)
    ref = cycles[0]
    assert ref["period"] == pytest.approx(3.4759932, abs=1e-7)
    [cycle] = [a for a in result.attractors() if a["name"] == "periodic"]
    assert cycle["multiplicity"] == 1
    assert cycle["period"] == pytest.approx(ref["period"], rel=1e-5)
    assert cycle["amplitude"] == pytest.approx(ref["amplitude"], rel=1e-5)
    # T_c of the linearisation by hand: its slowest oscillation
    eig = linearisation()
    t_c = 2 * math.pi / eig.imag[eig.imag > 0].min()
    whole = math.floor(WINDOW_T_C * t_c / ref["period"]) * ref["period"]
    assert whole >= 15 * ref["period"]
    dt = t_c / SAMPLES_PER_T_C
    assert cycle["open_fraction"] == pytest.approx(ref["flight"] / ref["period"], abs=dt / (whole - dt))
    assert cycle["stick_fraction"] > 0.0
    assert cycle["stick_fraction"] == pytest.approx(ref["stick"] / ref["period"], abs=dt / (whole - dt))
