"""A sustained sprag-slip cycle: a rigid arm on a sprung hinge over a moving belt, with the tip's
gap and the friction's lever nonlinear in the arm's angle (``register_kinematics(..., gap=...)``),
against a separate event-driven scipy solution (docs/models/sprag-slip.md, "A sprag-slip cycle
with a nonlinear gap").

The model: an arm of length L, inertia J, on a hinge at height H + y above the belt, the arm at
angle θ from the downward vertical, a torsional spring k that holds it at the rest angle α (a
preload torque k α), the hinge on a vertical spring ky under the load P. The tip is at
x = L sin θ and at height g = H + y − L cos θ; the belt moves at V < 0, towards the hinge's foot,
so friction turns the arm towards the vertical, where the tip digs into the belt (the sprag):

    g = H + y − L cos θ,   W = [L sin θ, 1],   v = L cos θ θ' − V   (G = [L cos θ, 0]),

    J θ'' + c θ' + k (θ − α) = L cos θ F + L sin θ λ,    my y'' + cy y' + ky y = −P + λ,

λ = −kc g while closed (compliant, no contact damping), Coulomb friction μk, μs = μk + Δμ with
μk > tan α: at the rest angle the friction's moment beats the normal force's. H puts the tip
δ = 0.02 into the belt at the frictionless rest state (θ = α, y = −P/ky).

From that rest state the motion settles, within about 40 s, on a cycle of period 1.0488: the tip
lands, slips briefly and sticks; the belt carries it towards the vertical and the normal force
climbs to about 15 times its steady-sliding value; the stick breaks away, the tip slips and lifts
off, the arm springs back past α in flight and lands again.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import stickslip
from stickslip.analysis.signal import CLOSE, OPEN, SLIP, STICK
from stickslip.model import Contact, FrictionLaw, FrictionModel
from stickslip.model.system_model import NormalLaw

from .arm_kinematics import HingedArm
from .event_reference import OPEN_MODE, STICK_MODE, assert_matches, event_driven

J, C, K, ALPHA, L, V = 0.1, 0.05, 5.0, 0.6, 1.0, -0.2
MY, CY, KY, P = 1.0, 3.0, 10.0, 1.0
KC, MU_K, DELTA_MU, DELTA = 100.0, 0.75, 0.2, 0.02
H = P / KY + L * math.cos(ALPHA) - DELTA
T_END, RATE = 80.0, 100.0


def sprag_arm() -> FrictionModel:
    return FrictionModel(
        name="sprag-arm", dofs=("theta", "y"), mass=[[J, 0.0], [0.0, MY]], damping=[[C, 0.0], [0.0, CY]],
        stiffness=[[K, 0.0], [0.0, KY]], force=[K * ALPHA, -P],
        contacts=(Contact(dim=1, friction=FrictionLaw("coulomb", MU_K, DELTA_MU),
                          normal=NormalLaw("compliant", KC, 0.0), name="tip"),),
        kinematics=HingedArm(L, H, V), units={"theta": "rad", "y": "m"})


def gap(s):
    return H + s[1] - L * math.cos(s[0])


def lam(s):
    return -KC * gap(s)


def equations():
    """The model by hand, for :func:`event_driven`."""
    def stick_force(s):
        th, _, dth, _ = s
        return (J * math.tan(th) * dth * dth + C * dth + K * (th - ALPHA) - L * math.sin(th) * lam(s)) / (L * math.cos(th))

    def field(mode):
        def f(t, s):
            th, y, dth, dy = s
            if mode == OPEN_MODE:
                return [dth, dy, (-C * dth - K * (th - ALPHA)) / J, (-CY * dy - KY * y - P) / MY]
            n = lam(s)
            ddy = (-CY * dy - KY * y - P + n) / MY
            if mode == STICK_MODE:  # v = L cos θ θ' − V stays 0: θ'' = tan θ θ'²
                return [dth, dy, math.tan(th) * dth * dth, ddy]
            F = -mode * MU_K * n
            return [dth, dy, (-C * dth - K * (th - ALPHA) + L * math.cos(th) * F + L * math.sin(th) * n) / J, ddy]
        return f

    return dict(field=field, phi=lambda s: min(-gap(s), lam(s) / KC), slip_speed=lambda s: L * math.cos(s[0]) * s[2] - V,
                stick_force=stick_force, limit=lambda s: (MU_K + DELTA_MU) * lam(s))


def steady_sliding():
    """The tip at rest (v = −V > 0, F = −μk λ), y at its spring's balance: the roots in θ of
    k (α − θ) = λ(θ) L (μk cos θ − sin θ), λ(θ) = kc ky / (kc + ky) (L cos θ − H + P/ky), over the
    angles where the tip is pressed."""
    keff = KC * KY / (KC + KY)

    def lam_of(th):
        return keff * (L * math.cos(th) - H + P / KY)

    def f(th):
        return K * (ALPHA - th) - lam_of(th) * L * (MU_K * math.cos(th) - math.sin(th))

    edge = math.acos((H - P / KY) / L)
    grid = np.linspace(-edge, edge, 4001)
    vals = [f(x) for x in grid]
    roots = [brentq(f, a, b, xtol=1e-15) for a, b, fa, fb in zip(grid, grid[1:], vals, vals[1:]) if fa * fb < 0]
    return [(th, lam_of(th)) for th in roots]


S0 = np.array([ALPHA, -P / KY, 0.0, 0.0])  # the frictionless rest state: the tip DELTA into the belt


@pytest.fixture(scope="module")
def runs():
    traj = stickslip.simulate(sprag_arm(), T_END, ic=S0, rtol=1e-12, atol=1e-14, sample_rate=RATE)
    ref, switches = event_driven(**equations(), t_eval=traj.t, y0=S0)
    return traj, ref, switches


def test_the_cycle_matches_the_scipy_solution(runs):
    """Every transition of each kind at the reference's instant and every sample's state to 1e-9
    (measured: 75 sticks, 1.0e-10 in time, 1.6e-10 in state, 6.7e-12 in the positions), and the
    late transitions in the cycle's order."""
    traj, ref, switches = runs
    assert traj.t[-1] == T_END
    assert_matches(traj, ref, switches, atol=1e-9, least=70)
    tr = traj.transitions
    late = tr.time > T_END / 2  # the same order in the late part: close, stick, slip, open, ...
    kinds = tr.kind[late]
    start = int(np.argmax(kinds == CLOSE))
    cycles = (len(kinds) - start) // 4
    np.testing.assert_array_equal(kinds[start:start + 4 * cycles].reshape(cycles, 4),
                                  np.tile([CLOSE, STICK, SLIP, OPEN], (cycles, 1)))


def test_the_cycle_from_the_reference(runs):
    """The cycle's features, all from the scipy solution: a period of 1.04884 (the last ten
    periods agree to 1e-9: it is a limit cycle, reached within about 40 s), a stick fraction of
    0.2361, a flight fraction of 0.6697, and a peak normal force 14.8 times the steady-sliding one
    (the only steady sliding, θ = 0.59779, λ = 0.19312). During the stick the arm turns from 0.565
    to 0.509, towards the vertical, and the normal force climbs to 2.859."""
    traj, ref, switches = runs
    sticks, slips, opens, closes = (switches[k] for k in (STICK, SLIP, OPEN, CLOSE))
    periods = np.diff(sticks[-11:])
    assert np.ptp(periods) < 1e-9
    period = periods[-1]
    assert period == pytest.approx(1.0488366, abs=1e-7)
    t1 = sticks[-2]  # the last whole cycle: stick at t1, breakaway, lift-off, landing, stick at t1 + period
    release = slips[slips > t1][0]
    lift = opens[opens > t1][0]
    land = closes[closes > t1][0]
    assert release < lift < land < sticks[-1]
    assert (release - t1) / period == pytest.approx(0.2361, abs=1e-4)
    assert (land - lift) / period == pytest.approx(0.6697, abs=1e-4)
    roots = steady_sliding()
    assert len(roots) == 1
    th_s, lam_s = roots[0]
    assert th_s == pytest.approx(0.59779, abs=1e-5) and lam_s == pytest.approx(0.19312, abs=1e-5)
    window = (traj.t >= t1) & (traj.t <= t1 + period)
    lam_ref = np.array([max(0.0, lam(s)) for s in ref[window]])
    assert lam_ref.max() / lam_s == pytest.approx(14.8, abs=0.05)
    in_stick = window & (traj.t > t1) & (traj.t < release)
    assert np.argmax(lam_ref) == np.argmax([lam(s) for s in ref[window]])
    assert np.all(ref[in_stick, 0] < ALPHA) and ref[in_stick, 0].max() - ref[in_stick, 0].min() > 0.05
    assert lam(ref[in_stick][0]) < lam_ref.max()  # the normal force climbs during the stick


def test_the_steady_sliding_by_hand_is_the_package_s():
    """``stability()``'s equilibrium is the hand root above."""
    (th_s, lam_s), = steady_sliding()
    result = stickslip.stability(sprag_arm())
    np.testing.assert_allclose(result.equilibrium, [th_s, (lam_s - P) / KY], rtol=0, atol=1e-10)
