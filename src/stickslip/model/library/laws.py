"""Friction laws of the user's kind, written as a user writes one (:mod:`stickslip.model.friction`).

``Stribeck``: the Stribeck curve with Gaussian decay and a viscous term,

    μ(v) = μc + (μs − μc) exp(−(v / v_s)²) + μv v,

μ(0) = μs the static coefficient (Armstrong-Hélouvry, Dupont and Canudas de Wit 1994, Eq. 3 with
δ = 2). Use it as ``FrictionLaw.from_user(Stribeck(mu_c, mu_s, v_s, mu_v))``. Model files state the
same law as the built-in ``law = "stribeck"`` (:mod:`stickslip.model.friction`), which each contact
may have with its own numbers.
"""

from __future__ import annotations

from typing import NamedTuple

from .. import csmath as csm
from ..friction import register_friction_law
from ..jit import kernel

__all__ = ["Stribeck", "stribeck"]


class Stribeck(NamedTuple):
    """Parameters of the Stribeck law: Coulomb level μc, static μs [-], Stribeck speed v_s [m/s] (> 0),
    viscous term μv [s/m]."""

    mu_c: float
    mu_s: float
    v_s: float
    mu_v: float = 0.0


@kernel
def stribeck(law, speed):
    """μ(|v|) [-] of :class:`Stribeck` at slip speed ``speed`` [m/s] (float or complex)."""
    ratio = speed / law.v_s
    return law.mu_c + (law.mu_s - law.mu_c) * csm.exp(-ratio * ratio) + law.mu_v * speed


register_friction_law(Stribeck, stribeck)
