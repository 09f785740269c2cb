"""Physical parameters of the two-plate model (paper Table 1 and Sect. 4).

Every symbol of the paper has a field; defaults are Table 1 plus the operating point
N = 50 N, Ω = 5 rad/s, μk = 0.2, Δμ = 0.1, α = 5 s/m used throughout Sect. 4.2.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from typing import Any, Mapping

from ..errors import ParameterError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised only on Python 3.10
    import tomli as tomllib

__all__ = ["Parameters", "PARAMETER_UNITS", "PARAMETER_DESCRIPTIONS", "FRICTION_LAWS", "parameter_attrs"]

#: Friction laws understood by the kernels. ``exponential`` is paper Eq. (4),
#: μ(v) = μk + Δμ exp(−α v); ``coulomb`` is the classic static/kinetic law, μ = μk in slip.
#: Both use the static limit μs = μk + Δμ of Eq. (10) for stick.
FRICTION_LAWS = ("exponential", "coulomb")

#: SI unit of each parameter (written into NetCDF attributes and the CLI help).
PARAMETER_UNITS: dict[str, str] = {
    "m_p": "kg", "m_d": "kg", "J_p": "kg m^2", "J_d": "kg m^2",
    "c_px": "N s/m", "k_px": "N/m", "c_py": "N s/m", "k_py": "N/m",
    "c_dx": "N s/m", "k_dx": "N/m", "c_dy": "N s/m", "k_dy": "N/m",
    "c_pphi": "N m s", "k_pphi": "N m", "c_dpsi": "N m s", "k_dpsi": "N m",
    "r": "m", "N": "N", "Omega": "rad/s",
    "mu_k": "1", "delta_mu": "1", "alpha": "s/m", "friction_law": "",
}

PARAMETER_DESCRIPTIONS: dict[str, str] = {
    "m_p": "mass of the upper plate",
    "m_d": "mass of the lower plate (disc)",
    "J_p": "rotational inertia of the upper plate",
    "J_d": "rotational inertia of the lower plate",
    "c_px": "damping of the upper plate along x1",
    "k_px": "stiffness of the upper plate along x1",
    "c_py": "damping of the upper plate along y1",
    "k_py": "stiffness of the upper plate along y1",
    "c_dx": "damping of the lower plate along x2",
    "k_dx": "stiffness of the lower plate along x2",
    "c_dy": "damping of the lower plate along y2",
    "k_dy": "stiffness of the lower plate along y2",
    "c_pphi": "torsional damping of the upper plate (phi)",
    "k_pphi": "torsional stiffness of the upper plate (phi)",
    "c_dpsi": "torsional damping of the lower plate (psi)",
    "k_dpsi": "torsional stiffness of the lower plate (psi)",
    "r": "distance of the contact point from the centre O1",
    "N": "normal preload",
    "Omega": "imposed angular velocity of the lower plate",
    "mu_k": "kinetic (asymptotic) friction coefficient, Eq. (4)",
    "delta_mu": "mu_s - mu_k, Eq. (4)",
    "alpha": "exponential decay factor of the friction law, Eq. (4)",
    "friction_law": "friction law: 'exponential' (Eq. 4) or 'coulomb' (mu = mu_k in slip)",
}

_STRICTLY_POSITIVE = ("m_p", "m_d", "J_p", "J_d", "r", "N")
_NON_NEGATIVE = (
    "c_px", "k_px", "c_py", "k_py", "c_dx", "k_dx", "c_dy", "k_dy",
    "c_pphi", "k_pphi", "c_dpsi", "k_dpsi", "mu_k", "delta_mu", "alpha",
)


def parameter_attrs(values: Mapping[str, Any], units: Mapping[str, str] | None = None) -> dict[str, Any]:
    """NetCDF attributes ``param_<name>`` (and ``param_<name>_units``) for a parameter mapping;
    ``units`` default the plates' (:data:`PARAMETER_UNITS`)."""
    units = PARAMETER_UNITS if units is None else units
    attrs: dict[str, Any] = {}
    for name, value in values.items():
        attrs[f"param_{name}"] = value
        if units.get(name):
            attrs[f"param_{name}_units"] = units[name]
    return attrs


@dataclasses.dataclass(frozen=True)
class Parameters:
    """Parameters of the two-plate friction model, SI units (paper Table 1).

    Parameters
    ----------
    m_p, m_d : float
        Masses of the upper plate and the lower plate [kg].
    J_p, J_d : float
        Rotational inertias [kg m^2].
    c_px, c_py, c_dx, c_dy : float
        Translational viscous damping [N s/m].
    k_px, k_py, k_dx, k_dy : float
        Translational stiffness [N/m].
    c_pphi, c_dpsi : float
        Torsional damping [N m s].
    k_pphi, k_dpsi : float
        Torsional stiffness [N m] (per radian).
    r : float
        Radius of the contact point from O1 [m].
    N : float
        Normal preload [N]; must be > 0.
    Omega : float
        Imposed angular velocity of the lower plate [rad/s].
    mu_k, delta_mu : float
        Kinetic friction coefficient and μs − μk, Eq. (4) [-].
    alpha : float
        Decay factor of Eq. (4) [s/m].
    friction_law : str
        ``"exponential"`` (Eq. 4, default) or ``"coulomb"`` (μ = μk in slip, μs in stick).

    Raises
    ------
    ParameterError
        On a non-finite, non-physical or mistyped value, naming the field and the fix.
    """

    m_p: float = 1.0
    m_d: float = 10.0
    J_p: float = 0.5
    J_d: float = 5.0
    c_px: float = 0.1
    k_px: float = 300.0
    c_py: float = 0.1
    k_py: float = 300.0
    c_dx: float = 0.1
    k_dx: float = 3000.0
    c_dy: float = 0.1
    k_dy: float = 3000.0
    c_pphi: float = 0.1
    k_pphi: float = 100.0
    c_dpsi: float = 0.1
    k_dpsi: float = 1000.0
    r: float = 0.2
    N: float = 50.0
    Omega: float = 5.0
    mu_k: float = 0.2
    delta_mu: float = 0.1
    alpha: float = 5.0
    friction_law: str = "exponential"

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            if field.name == "friction_law":
                continue
            value = getattr(self, field.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(
                    f"parameter {field.name} must be a number, got {value!r}; "
                    f"give it in {PARAMETER_UNITS[field.name] or 'no unit'}"
                )
            if not math.isfinite(value):
                raise ParameterError(f"parameter {field.name} = {value} is not finite; give a finite number")
            object.__setattr__(self, field.name, float(value))
        for name in _STRICTLY_POSITIVE:
            if getattr(self, name) <= 0.0:
                hint = " (the plates must be pressed together)" if name == "N" else ""
                raise ParameterError(
                    f"parameter {name} = {getattr(self, name)} must be > 0{hint}; "
                    f"set a positive value in {PARAMETER_UNITS[name]}"
                )
        for name in _NON_NEGATIVE:
            if getattr(self, name) < 0.0:
                raise ParameterError(
                    f"parameter {name} = {getattr(self, name)} must be >= 0; "
                    f"set a non-negative value in {PARAMETER_UNITS[name] or 'no unit'}"
                )
        if self.friction_law not in FRICTION_LAWS:
            raise ParameterError(
                f"friction_law = {self.friction_law!r} is unknown; choose one of {', '.join(FRICTION_LAWS)}"
            )

    # ------------------------------------------------------------------ derived
    @property
    def mu_s(self) -> float:
        """Static friction coefficient μs = μk + Δμ (Eq. 4) [-]."""
        return self.mu_k + self.delta_mu

    # ------------------------------------------------------------------ editing
    def replace(self, **changes: Any) -> "Parameters":
        """Return a copy with some fields changed (validated like the constructor)."""
        unknown = sorted(set(changes) - set(self.names()))
        if unknown:
            raise ParameterError(
                f"unknown parameter(s) {', '.join(unknown)}; valid names are {', '.join(self.names())}"
            )
        return dataclasses.replace(self, **changes)

    @classmethod
    def names(cls) -> tuple[str, ...]:
        """Field names in declaration order."""
        return tuple(f.name for f in dataclasses.fields(cls))

    def to_dict(self) -> dict[str, Any]:
        """Plain ``{name: value}`` mapping."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, values: Mapping[str, Any]) -> "Parameters":
        """Build from a mapping; unknown keys raise :class:`ParameterError`."""
        return cls().replace(**dict(values))

    # ------------------------------------------------------------------ TOML
    def to_toml(self) -> str:
        """TOML text with a ``[parameters]`` table (units as comments)."""
        lines = ["# stickslip parameters (SI units)", "[parameters]"]
        for name, value in self.to_dict().items():
            text = f'"{value}"' if isinstance(value, str) else repr(value)
            unit = PARAMETER_UNITS[name]
            lines.append(f"{name} = {text}" + (f"  # {unit}" if unit else ""))
        return "\n".join(lines) + "\n"

    def save_toml(self, path: str | Path) -> None:
        """Write :meth:`to_toml` to ``path``."""
        Path(path).write_text(self.to_toml())

    @classmethod
    def load_toml(cls, path: str | Path) -> "Parameters":
        """Read parameters from a TOML file.

        The file holds either a ``[parameters]`` table or the names at top level; names not
        given keep their defaults.
        """
        path = Path(path)
        if not path.is_file():
            raise ParameterError(f"parameter file {path} does not exist; give the path of a .toml file")
        try:
            data = tomllib.loads(path.read_text())
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise ParameterError(f"{path} is not valid TOML ({exc}); fix the syntax or write one with `Parameters.save_toml`") from exc
        table = data.get("parameters", data)
        if not isinstance(table, dict):
            raise ParameterError(f"{path}: [parameters] must be a table of name = value")
        return cls.from_dict(table)
