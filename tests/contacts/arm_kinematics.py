"""Kinematics of an arm over a belt with a nonlinear gap, shared by the tests that use it (one
compiled kernel set): an arm of length L at angle θ from the downward vertical, on a hinge at
height H + y above a belt moving at V, its tip at x = L sin θ and at height

    g = H + y − L cos θ,   W = ∂g/∂q = [L sin θ, 1],   v = L cos θ θ' − V   (G = [L cos θ, 0]).
"""

from __future__ import annotations

from typing import NamedTuple

from stickslip.model import register_kinematics
from stickslip.model import csmath as csm


class HingedArm(NamedTuple):
    """Kinematics data: arm length L, hinge height H at y = 0, belt speed V."""

    L: float
    H: float
    V: float


def arm_frame(kin, s, c, m, G, w):
    G[0, 0] = kin.L * csm.cos(s[0])
    G[0, 1] = 0.0
    G[1, 0] = 0.0
    G[1, 1] = 0.0
    w[0] = kin.V
    w[1] = 0.0
    return csm.zero(s[0])


def arm_gap(kin, s, c, m, W):
    W[0] = kin.L * csm.sin(s[0])
    W[1] = 1.0
    return kin.H + s[1] - kin.L * csm.cos(s[0])


register_kinematics(HingedArm, arm_frame, ndof=2, ncontacts=1, dim=1, gap=arm_gap)
