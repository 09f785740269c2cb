"""Friction laws, in one place: the kinetic coefficient μ(|v|) and the static limit μs of a contact.

Built-in laws (``law`` code in the contact's data row):

``coulomb``       μ(v) = μk in slip; stick holds while |F| ≤ μs N, μs = μk + Δμ.
``exponential``   μ(v) = μk + Δμ exp(−α v) + μv v (paper Eq. 4 with an optional viscous term
                  μv), so μ(0) = μs = μk + Δμ: the static coefficient is the limit of the kinetic one.

Laws are evaluated by compiled code through :func:`friction_coefficient` (slip) and
:func:`static_coefficient` (stick), on ``float64`` or ``complex128`` speeds alike (the complex
step of the Jacobians differentiates through them), so they use ``exp``-style functions and no
``abs``. A law of the user's own (a compiled function of |v|) is not available yet.

Each contact's law is one row of :data:`LAW_WIDTH` numbers in the model's data array
(``[law, mu_k, delta_mu, alpha, mu_v]``, see :mod:`stickslip.model.bundle`).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Mapping

import numpy as np

from ..errors import StickSlipError
from . import csmath as csm
from .jit import inlined_kernel

__all__ = ["FrictionLaw", "FrictionLawError", "LAWS", "LAW_COULOMB", "LAW_EXPONENTIAL", "LAW_WIDTH",
           "friction_coefficient", "static_coefficient"]

LAW_EXPONENTIAL = 0
LAW_COULOMB = 1
#: Law names as they appear in model files and ``--set``.
LAWS = {"exponential": LAW_EXPONENTIAL, "coulomb": LAW_COULOMB}

#: Offsets inside a law row.
L_LAW, L_MU_K, L_DELTA_MU, L_ALPHA, L_MU_V = range(5)
#: Numbers per law row.
LAW_WIDTH = 5


class FrictionLawError(StickSlipError, ValueError):
    """A friction law that cannot be used (unknown name, negative coefficient, ...)."""


@inlined_kernel
def friction_coefficient(speed, row):
    """Kinetic friction coefficient μ(|v|) [-] of the law ``row`` (a contact's law row).

    ``speed`` may be complex (complex-step differentiation); branches read only the law code.
    """
    law = row[L_LAW]
    if law == LAW_COULOMB:
        return row[L_MU_K] + 0.0 * speed
    return row[L_MU_K] + row[L_DELTA_MU] * csm.exp(-row[L_ALPHA] * speed) + row[L_MU_V] * speed


@inlined_kernel
def static_coefficient(row):
    """Static friction coefficient μs [-]: stick holds while |F| ≤ μs N (paper Eq. 10); for both
    laws μs = μk + Δμ (the exponential law's μ(0))."""
    return row[L_MU_K] + row[L_DELTA_MU]


@dataclasses.dataclass(frozen=True)
class FrictionLaw:
    """A contact's friction law.

    Attributes
    ----------
    law : {"exponential", "coulomb"}
        ``exponential``: μ = μk + Δμ exp(−α|v|) + μv |v|; ``coulomb``: μ = μk in slip.
    mu_k : float
        Kinetic coefficient μk [-] (≥ 0).
    delta_mu : float
        μs − μk [-] (≥ 0); the static coefficient is μs = μk + Δμ.
    alpha : float
        Decay of the exponential law [s/m] (≥ 0).
    mu_v : float
        Viscous term of the exponential law [s/m] (≥ 0).
    """

    law: str = "exponential"
    mu_k: float = 0.2
    delta_mu: float = 0.1
    alpha: float = 5.0
    mu_v: float = 0.0

    def __post_init__(self) -> None:
        if not isinstance(self.law, str) or self.law not in LAWS:
            raise FrictionLawError(f"friction law {self.law!r} is unknown; choose one of {', '.join(LAWS)}")
        for name in ("mu_k", "delta_mu", "alpha", "mu_v"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise FrictionLawError(f"friction {name} must be a number, got {value!r}")
            if not math.isfinite(value) or value < 0.0:
                raise FrictionLawError(f"friction {name} = {value} must be a finite number >= 0")
            object.__setattr__(self, name, float(value))

    @property
    def mu_s(self) -> float:
        """Static coefficient μs = μk + Δμ [-]."""
        return self.mu_k + self.delta_mu

    def row(self) -> np.ndarray:
        """The law as a data row (:data:`LAW_WIDTH`,) for the compiled kernels."""
        row = np.zeros(LAW_WIDTH)
        row[L_LAW] = LAWS[self.law]
        row[L_MU_K] = self.mu_k
        row[L_DELTA_MU] = self.delta_mu
        row[L_ALPHA] = self.alpha
        row[L_MU_V] = self.mu_v
        return row

    def coefficient(self, speed) -> np.ndarray:
        """μ(|v|) [-] for an array of speeds [m/s] (numpy; for plots and checks)."""
        speed = np.abs(np.asarray(speed, dtype=float))
        if self.law == "coulomb":
            return np.full_like(speed, self.mu_k)
        return self.mu_k + self.delta_mu * np.exp(-self.alpha * speed) + self.mu_v * speed

    def to_dict(self) -> dict:
        out = {"law": self.law, "mu_k": self.mu_k, "delta_mu": self.delta_mu}
        if self.law == "exponential":
            out.update(alpha=self.alpha, mu_v=self.mu_v)
        return out

    @classmethod
    def from_mapping(cls, table: Mapping, where: str = "friction") -> "FrictionLaw":
        """Build from a model file's ``[contact.friction]`` table (keys named in errors)."""
        known = {"law", "mu_k", "delta_mu", "alpha", "mu_v"}
        unknown = sorted(set(table) - known)
        if unknown:
            raise FrictionLawError(f"{where}: unknown key(s) {', '.join(unknown)}; valid keys are {', '.join(sorted(known))}")
        law = table.get("law", "exponential")
        if not isinstance(law, str) or law not in LAWS:
            raise FrictionLawError(f"{where}.law = {law!r} is unknown; choose one of {', '.join(LAWS)}")
        for key in ("mu_k", "delta_mu"):
            if key not in table:
                raise FrictionLawError(f"{where}.{key} is missing; give the {'kinetic coefficient' if key == 'mu_k' else 'difference mu_s - mu_k'} (a number >= 0)")
        if law == "exponential" and "alpha" not in table:
            raise FrictionLawError(f"{where}.alpha is missing; the exponential law needs its decay alpha [s/m] (a number >= 0)")
        values = {}
        for key in ("mu_k", "delta_mu", "alpha", "mu_v"):
            if key in table:
                value = table[key]
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise FrictionLawError(f"{where}.{key} = {value!r} is not a number; give a number >= 0")
                if not math.isfinite(value) or value < 0:
                    raise FrictionLawError(f"{where}.{key} = {value} must be a finite number >= 0")
                values[key] = float(value)
        if law == "coulomb":
            values.pop("alpha", None)
            values.pop("mu_v", None)
        return cls(law=law, **values)
