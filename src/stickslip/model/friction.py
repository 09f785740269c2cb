"""Friction laws, in one place: the kinetic coefficient μ(|v|) and the static limit μs of a contact.

Built-in laws (``law`` code in the contact's data row):

``coulomb``       μ(v) = μk in slip; stick holds while |F| ≤ μs N, μs = μk + Δμ.
``exponential``   μ(v) = μk + Δμ exp(−α v) + μv v (paper Eq. 4 with an optional viscous term
                  μv), so μ(0) = μs = μk + Δμ: the static coefficient is the limit of the kinetic one.
``stribeck``      μ(v) = μk + Δμ exp(−(v/v_s)²) + μv v, the Stribeck curve with Gaussian decay
                  (Armstrong-Hélouvry, Dupont and Canudas de Wit 1994, Eq. 3 with δ = 2; δ = 1 is
                  the exponential law with α = 1/v_s), v_s > 0 the Stribeck speed; μ(0) = μs.

``user``          μ(v) = a compiled function of |v| of the user's own (below); μs given with it
                  (default μ(0)).

Laws are evaluated by compiled code through :func:`friction_coefficient` (slip) and
:func:`static_coefficient` (stick), on ``float64`` or ``complex128`` speeds alike (the complex
step of the Jacobians differentiates through them), so they use ``exp``-style functions and no
``abs``.

Each contact's law is one row of :data:`LAW_WIDTH` numbers in the model's data array
(``[law, mu_k, delta_mu, alpha, mu_v]``, see :mod:`stickslip.model.bundle`; the Stribeck law holds
v_s where the exponential one holds α); a user law's row is ``[user, mu_s, 0, 0, 0]``.

**A user law** is a ``typing.NamedTuple`` class of its parameters (numbers) and a numba-compilable
function ``mu(law, speed) -> μ`` of an instance and the slip speed |v| ≥ 0 [m/s], registered once
with :func:`register_friction_law`; a contact takes it as ``FrictionLaw.from_user(instance, mu_s)``.
Like a kinematics class, the law's class travels in the model's compiled bundle
(``ModelData.law``), so the kernels are compiled for it (once, then cached on disk by its import
path) and call it like hand-written code. The function must be complex-safe: use
:mod:`stickslip.model.csmath` (``exp``, ``sqrt``, ``sin``, ``cos``) and arithmetic, no ``abs`` or
``math.*`` on the speed, branches on ``speed.real`` only. All contacts of a model that use a user
law share one instance. :mod:`stickslip.model.library.laws` holds a Stribeck law written this way
(the built-in ``stribeck`` law's curve, as a user law).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Callable, Mapping, NamedTuple

import numpy as np
from numba import njit
from numba.extending import overload

from ..errors import FrictionLawError
from . import csmath as csm
from .jit import KERNEL_OPTIONS, inlined_kernel, kernel, track_user_code

__all__ = ["FrictionLaw", "FrictionLawError", "LAWS", "LAW_COULOMB", "LAW_EXPONENTIAL", "LAW_STRIBECK", "LAW_USER",
           "LAW_WIDTH", "NoUserLaw", "register_friction_law", "friction_coefficient", "static_coefficient",
           "stribeck_coefficient"]

LAW_EXPONENTIAL = 0
LAW_COULOMB = 1
LAW_USER = 2
LAW_STRIBECK = 3
#: Law names as they appear in model files and ``--set``.
LAWS = {"exponential": LAW_EXPONENTIAL, "coulomb": LAW_COULOMB, "stribeck": LAW_STRIBECK}

#: Offsets inside a law row (the Stribeck law's v_s in the exponential law's α slot).
L_LAW, L_MU_K, L_DELTA_MU, L_ALPHA, L_MU_V = range(5)
L_STRIBECK_SPEED = L_ALPHA
#: Numbers per law row.
LAW_WIDTH = 5


# ----------------------------------------------------------------------------- user laws
class NoUserLaw(NamedTuple):
    """The user-law slot of a model whose contacts all use built-in laws."""

    unused: float = 0.0


#: Registered user-law functions by law class (compiled).
_USER_LAWS: dict[type, Callable] = {}


def register_friction_law(cls: type, mu: Callable) -> None:
    """Make ``mu(law, speed) -> μ`` the friction coefficient of contacts whose law is a ``cls`` instance.

    Parameters
    ----------
    cls : NamedTuple class
        The law's parameters (fields: numbers). Keep it importable under the same module path: the
        compiled kernels are cached on disk by it.
    mu : numba-compilable function
        Kinetic coefficient [-] at slip speed ``speed`` = |v| ≥ 0 [m/s] (float or complex:
        complex-safe as the module docstring says). Plain Python functions are compiled.
    """
    if not (isinstance(cls, type) and issubclass(cls, tuple) and hasattr(cls, "_fields")):
        raise FrictionLawError(f"friction law class {cls!r} must be a NamedTuple of numbers")
    _USER_LAWS[cls] = mu if hasattr(mu, "py_func") else njit(**KERNEL_OPTIONS)(mu)
    track_user_code(cls, mu)


def user_coefficient(law, speed):  # pragma: no cover - resolved by numba (overload below)
    """μ(|v|) of the registered user law ``law``."""
    raise NotImplementedError("user_coefficient is called from compiled code only")


@overload(user_coefficient, jit_options=KERNEL_OPTIONS)
def _user_coefficient(law, speed):
    mu = _USER_LAWS.get(getattr(law, "instance_class", None))
    if mu is None:  # NoUserLaw: no contact has the user law code (checked when the model is built)
        return lambda law, speed: speed * 0.0 + np.nan
    return lambda law, speed: mu(law, speed)


# ----------------------------------------------------------------------------- compiled laws
@kernel
def stribeck_coefficient(mu_k, delta_mu, v_s, mu_v, speed):
    """μ(|v|) = μk + Δμ exp(−(|v|/v_s)²) + μv |v| [-] of the Stribeck law at slip speed ``speed``
    [m/s] (float or complex: complex-safe), Stribeck speed ``v_s`` > 0 [m/s], viscous term
    ``mu_v`` [s/m]."""
    ratio = speed / v_s
    return mu_k + delta_mu * csm.exp(-ratio * ratio) + mu_v * speed


@inlined_kernel
def friction_coefficient(speed, row, law):
    """Kinetic friction coefficient μ(|v|) [-] of the law ``row`` (a contact's law row); ``law``
    the model's user-law instance (:class:`NoUserLaw` if none).

    ``speed`` may be complex (complex-step differentiation); branches read only the law code.
    """
    code = row[L_LAW]
    if code == LAW_COULOMB:
        return row[L_MU_K] + 0.0 * speed
    if code == LAW_USER:
        return user_coefficient(law, speed) + 0.0 * speed
    if code == LAW_STRIBECK:
        return stribeck_coefficient(row[L_MU_K], row[L_DELTA_MU], row[L_STRIBECK_SPEED], row[L_MU_V], speed)
    return row[L_MU_K] + row[L_DELTA_MU] * csm.exp(-row[L_ALPHA] * speed) + row[L_MU_V] * speed


@kernel
def static_coefficient(row):
    """Static friction coefficient μs [-]: stick holds while |F| ≤ μs N (paper Eq. 10); for the
    built-in laws μs = μk + Δμ (the exponential law's μ(0)), a user law's row holds μs there."""
    return row[L_MU_K] + row[L_DELTA_MU]


@dataclasses.dataclass(frozen=True)
class FrictionLaw:
    """A contact's friction law.

    Parameters
    ----------
    law : {"exponential", "coulomb", "stribeck", "user"}
        ``exponential``: μ = μk + Δμ exp(−α|v|) + μv |v|; ``coulomb``: μ = μk in slip;
        ``stribeck``: μ = μk + Δμ exp(−(|v|/v_s)²) + μv |v|; ``user``: a registered law of the
        user's own (build it with :meth:`from_user`).
    mu_k : float
        Kinetic coefficient μk [-] (≥ 0).
    delta_mu : float
        μs − μk [-] (≥ 0); the static coefficient is μs = μk + Δμ.
    alpha : float
        Decay of the exponential law [s/m] (≥ 0).
    mu_v : float
        Viscous term of the exponential and Stribeck laws [s/m] (≥ 0).
    user : NamedTuple, optional
        The user law's instance (law ``"user"`` only); then ``mu_k`` holds its μs and ``delta_mu`` is 0.
    v_s : float
        Stribeck speed of the Stribeck law [m/s] (> 0; 0 for the other laws).
    """

    law: str = "exponential"
    mu_k: float = 0.2
    delta_mu: float = 0.1
    alpha: float = 5.0
    mu_v: float = 0.0
    user: Any = None
    v_s: float = 0.0

    @classmethod
    def from_user(cls, law: Any, mu_s: float | None = None) -> "FrictionLaw":
        """A contact's law from a user law instance (its class registered with
        :func:`register_friction_law`); stick holds while |F| ≤ μs N, μs default μ(0)."""
        if type(law) not in _USER_LAWS:
            raise FrictionLawError(f"friction law {law!r}: its class is not registered; call "
                                   "stickslip.model.friction.register_friction_law(cls, mu) first")
        if mu_s is None:
            try:
                mu_s = float(np.real(_USER_LAWS[type(law)].py_func(law, 0.0)))
            except (ArithmeticError, ValueError, TypeError) as exc:
                raise FrictionLawError(f"friction law {law!r}: mu(0) cannot be evaluated ({exc}); check its "
                                       "parameters or give mu_s") from None
        if isinstance(mu_s, bool) or not isinstance(mu_s, (int, float)) or not math.isfinite(mu_s) or mu_s < 0.0:
            raise FrictionLawError(f"friction law {law!r}: mu_s = {mu_s!r} must be a finite number >= 0 "
                                   "(the static coefficient; give it explicitly if mu(0) is not)")
        return cls("user", mu_k=mu_s, delta_mu=0.0, alpha=0.0, mu_v=0.0, user=law)

    def __post_init__(self) -> None:
        if self.law == "user":
            if self.user is None or type(self.user) not in _USER_LAWS:
                raise FrictionLawError("friction law 'user' needs a registered law instance; build it with "
                                       "FrictionLaw.from_user(instance, mu_s)")
        elif not isinstance(self.law, str) or self.law not in LAWS:
            raise FrictionLawError(f"friction law {self.law!r} is unknown; choose one of {', '.join(LAWS)}")
        elif self.user is not None:
            raise FrictionLawError(f"friction law {self.law!r} takes no user law instance; use law='user'")
        for name in ("mu_k", "delta_mu", "alpha", "mu_v", "v_s"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise FrictionLawError(f"friction {name} must be a number, got {value!r}")
            if not math.isfinite(value) or value < 0.0:
                raise FrictionLawError(f"friction {name} = {value} must be a finite number >= 0")
            object.__setattr__(self, name, float(value))
        if (self.law == "stribeck") != (self.v_s > 0.0):
            raise FrictionLawError("friction v_s: the Stribeck law needs its Stribeck speed v_s > 0 [m/s]"
                                   if self.law == "stribeck" else
                                   f"friction v_s is the Stribeck law's; law {self.law!r} takes none (set it to 0)")

    @property
    def mu_s(self) -> float:
        """Static coefficient μs = μk + Δμ [-]."""
        return self.mu_k + self.delta_mu

    def row(self) -> np.ndarray:
        """The law as a data row (:data:`LAW_WIDTH`,) for the compiled kernels."""
        row = np.zeros(LAW_WIDTH)
        row[L_LAW] = LAW_USER if self.law == "user" else LAWS[self.law]
        row[L_MU_K] = self.mu_k
        row[L_DELTA_MU] = self.delta_mu
        row[L_ALPHA] = self.v_s if self.law == "stribeck" else self.alpha
        row[L_MU_V] = self.mu_v
        return row

    def coefficient(self, speed) -> np.ndarray:
        """μ(|v|) [-] for an array of speeds [m/s] (numpy; for plots and checks)."""
        speed = np.abs(np.asarray(speed, dtype=float))
        if self.law == "user":
            mu = _USER_LAWS[type(self.user)].py_func
            return np.vectorize(lambda v: float(np.real(mu(self.user, v))), otypes=[float])(speed)
        if self.law == "coulomb":
            return np.full_like(speed, self.mu_k)
        if self.law == "stribeck":
            return self.mu_k + self.delta_mu * np.exp(-(speed / self.v_s) ** 2) + self.mu_v * speed
        return self.mu_k + self.delta_mu * np.exp(-self.alpha * speed) + self.mu_v * speed

    def to_dict(self) -> dict:
        if self.law == "user":
            kind = type(self.user)
            return {"law": "user", "function": f"{kind.__module__}.{kind.__qualname__}", "mu_s": self.mu_s,
                    **{k: float(v) for k, v in self.user._asdict().items()}}
        out = {"law": self.law, "mu_k": self.mu_k, "delta_mu": self.delta_mu}
        if self.law == "exponential":
            out.update(alpha=self.alpha, mu_v=self.mu_v)
        if self.law == "stribeck":
            out.update(v_s=self.v_s, mu_v=self.mu_v)
        return out

    @classmethod
    def from_mapping(cls, table: Mapping, where: str = "friction") -> "FrictionLaw":
        """Build from a model file's ``[contact.friction]`` table (keys named in errors)."""
        known = {"law", "mu_k", "delta_mu", "alpha", "mu_v", "v_s"}
        unknown = sorted(set(table) - known)
        if unknown:
            raise FrictionLawError(f"{where}: unknown key(s) {', '.join(unknown)}; valid keys are {', '.join(sorted(known))}")
        law = table.get("law", "exponential")
        if law == "user":
            raise FrictionLawError(f"{where}.law = 'user' is a law of your own in Python and cannot be stated in a "
                                   "file; define the model in Python (FrictionLaw.from_user) or choose one of "
                                   f"{', '.join(LAWS)}")
        if not isinstance(law, str) or law not in LAWS:
            raise FrictionLawError(f"{where}.law = {law!r} is unknown; choose one of {', '.join(LAWS)}")
        for key in ("mu_k", "delta_mu"):
            if key not in table:
                raise FrictionLawError(f"{where}.{key} is missing; give the {'kinetic coefficient' if key == 'mu_k' else 'difference mu_s - mu_k'} (a number >= 0)")
        if law == "exponential" and "alpha" not in table:
            raise FrictionLawError(f"{where}.alpha is missing; the exponential law needs its decay alpha [s/m] (a number >= 0)")
        if law == "stribeck" and "v_s" not in table:
            raise FrictionLawError(f"{where}.v_s is missing; the Stribeck law needs its Stribeck speed v_s [m/s] (a number > 0)")
        for key, owner in (("alpha", "exponential"), ("v_s", "stribeck")):
            if key in table and law not in (owner, "coulomb"):
                raise FrictionLawError(f"{where}.{key} belongs to the {owner} law, not the {law} law; remove it")
        values = {}
        for key in ("mu_k", "delta_mu", "alpha", "mu_v", "v_s"):
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
            values.pop("v_s", None)
        if law == "stribeck" and not values["v_s"] > 0.0:
            raise FrictionLawError(f"{where}.v_s = {values['v_s']} must be > 0 (the Stribeck speed [m/s])")
        return cls(law=law, **values)
