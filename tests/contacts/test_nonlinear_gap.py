"""A unilateral contact whose gap is nonlinear in the coordinates, stated by a Python kinematics
class (``register_kinematics(..., gap=...)``), against a separate event-driven scipy solution and
a linearisation by hand.

The model: an arm of length L on a hinge that rides a vertical spring; the hinge is at height
H + y above a belt moving at V, the arm at angle θ from the downward vertical, so its tip is at
x = L sin θ and at height H + y − L cos θ above the belt:

    g = H + y − L cos θ,   W = ∂g/∂q = [L sin θ, 1],   v = L cos θ θ' − V   (G = [L cos θ, 0]),

    J θ'' + c θ' + k θ = L cos θ F + L sin θ λ,    m y'' + c_y y' + k_y y = −P + λ,

with the compliant normal force λ = −k_c g − c_c ġ (ġ = L sin θ θ' + y') while closed and Coulomb
friction at the tip (μk, μs = μk + Δμ). Both W and G turn with θ, so the normal force's lever
L sin θ and the friction's L cos θ change along the motion. From rest at θ = y = 0 the tip is
pressed 0.1 into the belt (λ = 5 > P): it is thrown off, flies, lands, slides, sticks and is
thrown off again.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import fsolve

import stickslip
from stickslip.model import Contact, FrictionLaw, FrictionModel, ModelError
from stickslip.model.system_model import NormalLaw

from .arm_kinematics import HingedArm
from .event_reference import OPEN_MODE, STICK_MODE, assert_matches, event_driven

J, C, K, L, H, V = 1.0, 0.05, 1.0, 1.0, 0.9, 0.2
MY, CY, KY, P = 1.0, 0.1, 1.0, 1.0
KC, MU_K, DELTA_MU = 50.0, 0.3, 0.2
T_END = 60.0


def hinged_arm(contact_damping=0.0, **contact) -> FrictionModel:
    return FrictionModel(
        name="hinged-arm", dofs=("theta", "y"), mass=[[J, 0.0], [0.0, MY]], damping=[[C, 0.0], [0.0, CY]],
        stiffness=[[K, 0.0], [0.0, KY]], force=[0.0, -P],
        contacts=(Contact(dim=1, friction=FrictionLaw("coulomb", MU_K, DELTA_MU),
                          normal=NormalLaw("compliant", KC, contact_damping), name="tip", **contact),),
        kinematics=HingedArm(L, H, V), units={"theta": "rad", "y": "m"})


def equations(cc):
    """The model by hand, for :func:`event_driven`."""
    def gap(s):
        return H + s[1] - L * math.cos(s[0])

    def lam(s):
        return -KC * gap(s) - cc * (L * math.sin(s[0]) * s[2] + s[3])

    def stick_force(s):
        th, _, dth, _ = s
        return (J * math.tan(th) * dth * dth + C * dth + K * th - L * math.sin(th) * lam(s)) / (L * math.cos(th))

    def field(mode):
        def f(t, s):
            th, y, dth, dy = s
            if mode == OPEN_MODE:
                return [dth, dy, (-C * dth - K * th) / J, (-CY * dy - KY * y - P) / MY]
            n = lam(s)
            ddy = (-CY * dy - KY * y - P + n) / MY
            if mode == STICK_MODE:  # v = L cos θ θ' − V stays 0: θ'' = tan θ θ'²
                return [dth, dy, math.tan(th) * dth * dth, ddy]
            F = -mode * MU_K * n
            return [dth, dy, (-C * dth - K * th + L * math.cos(th) * F + L * math.sin(th) * n) / J, ddy]
        return f

    return dict(field=field, phi=lambda s: min(-gap(s), lam(s) / KC), slip_speed=lambda s: L * math.cos(s[0]) * s[2] - V,
                stick_force=stick_force, limit=lambda s: (MU_K + DELTA_MU) * lam(s))


@pytest.fixture(scope="module", params=(0.0, 0.5), ids=lambda c: f"contact damping {c}")
def runs(request):
    traj = stickslip.simulate(hinged_arm(request.param), T_END, ic=np.zeros(4), rtol=1e-12, atol=1e-14,
                              sample_rate=20.0)
    ref, switches = event_driven(**equations(request.param), t_eval=traj.t, y0=np.zeros(4))
    return traj, ref, switches


def test_the_run_matches_the_scipy_solution(runs):
    """Every transition of each kind at the reference's instant and every sample's state to 1e-9,
    with flights, landings, sticks and breakaways all present (measured: 31 flights and 7 stick
    phases without contact damping, 3.0e-10 in time and 2.3e-10 in state; 5 and 5 with it,
    9.6e-12; the difference is the run's own error: 2.5e-9 at rtol 1e-11)."""
    traj, ref, switches = runs
    assert traj.t[-1] == T_END
    assert_matches(traj, ref, switches, atol=1e-9, least=3)


def test_the_reported_gap_is_the_nonlinear_one(runs):
    """``Trajectory.gap`` is g(q) of the kinematics, positive only while the contact is open."""
    traj, _, _ = runs
    theta, y = traj.states[:, 0], traj.states[:, 1]
    np.testing.assert_allclose(traj.gap[:, 0], H + y - L * np.cos(theta), rtol=0, atol=1e-15)
    assert traj.open[:, 0].any() and not np.any((traj.gap[:, 0] > 1e-12) & ~traj.open[:, 0])


def test_steady_sliding_and_its_eigenvalues_match_the_hand_linearisation():
    """Steady sliding (tip at rest, v = −V, F = +μk λ) solved by hand, and the eigenvalues of the
    hand-written field's Jacobian (central differences of the equations above, h = 1e-6)."""
    cc = 0.5
    f = equations(cc)["field"](-1)

    def residual(q):
        return np.array(f(0.0, [q[0], q[1], 0.0, 0.0])[2:])

    q = fsolve(residual, [0.1, 0.0], xtol=1e-14)
    assert np.abs(residual(q)).max() < 1e-12
    s0 = np.array([q[0], q[1], 0.0, 0.0])
    A = np.empty((4, 4))
    for j in range(4):
        e = np.zeros(4)
        e[j] = 1e-6
        A[:, j] = (np.array(f(0.0, s0 + e)) - np.array(f(0.0, s0 - e))) / 2e-6
    result = stickslip.stability(hinged_arm(cc))
    np.testing.assert_allclose(result.equilibrium, q, rtol=0, atol=1e-10)
    by_hand = sorted(np.linalg.eigvals(A), key=lambda z: (-z.real, -z.imag))
    np.testing.assert_allclose(result.eigenvalues, by_hand, rtol=0, atol=1e-7)


def test_a_gap_gradient_beside_a_gap_function_is_refused():
    with pytest.raises(ModelError, match="computes the gap"):
        hinged_arm(gap_gradient=[0.0, 1.0])
