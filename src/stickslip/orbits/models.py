"""The model an orbit tool runs on: resolving it, naming it, and changing one of its parameters.

Every orbit tool takes the model as :func:`stickslip.simulate` does — a
:class:`~stickslip.model.system_model.FrictionModel`, a library name or model file, or the plates'
:class:`~stickslip.model.parameters.Parameters` — and works on the
:class:`FrictionModel` from then on. A parameter is any name of ``system.parameters``: the plates'
(``N``, ``Omega``, ...) or a model file's ``--set`` path (``contact.0.drive``).
"""

from __future__ import annotations

import json
import math

from ..errors import ModelError, OrbitError
from ..model.library import describe_system, resolve_model
from ..model.library.two_plates import is_plates, plates_parameters
from ..model.parameters import Parameters, parameter_attrs
from ..model.system_model import FrictionModel

__all__ = ["resolve", "ModelResult", "parameter_value", "with_parameter", "model_attrs", "is_plates",
           "plates_parameters"]


def resolve(model=None, slip_band: float | None = None) -> FrictionModel:
    """The FrictionModel that ``model`` names (as :func:`stickslip.simulate` takes it).

    Raises
    ------
    OrbitError
        For a model that cannot be resolved (the message names the fix).
    """
    try:
        return resolve_model(model, slip_band)
    except ModelError as exc:
        raise OrbitError(str(exc)) from exc


def parameter_value(system: FrictionModel, name: str) -> float:
    """The numeric value of parameter ``name`` of ``system``.

    Raises
    ------
    OrbitError
        If the model has no such parameter or it is not a finite number.
    """
    try:
        key = system.resolver(name) if system.resolver is not None else name
    except ModelError:
        key = None
    if key not in system.parameters:
        raise OrbitError(f"unknown parameter {name!r} of model {system.name!r}; valid names: "
                         f"{', '.join(system.parameters)}")
    value = system.parameters[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(float(value)):
        raise OrbitError(f"parameter {name!r} of model {system.name!r} is {value!r}, not a finite number; "
                         "continue over a numeric parameter")
    return float(value)


def with_parameter(system: FrictionModel, name: str, value: float) -> FrictionModel:
    """``system`` with parameter ``name`` set to ``value`` (same slip band)."""
    try:
        return system.replace(**{name: float(value)}).with_slip_band(system.slip_band)
    except (ModelError, ValueError) as exc:
        raise OrbitError(f"{name} = {value}: {exc}") from exc


def model_attrs(system: FrictionModel) -> dict:
    """NetCDF attributes naming the model: ``model`` (the plates' variant or the model's name), its
    description (rebuilds it: :func:`stickslip.model.library.system_from_description`), its
    parameters, the ones that name a point (``headline``) and its ``observed`` coordinate."""
    values = {k: v for k, v in system.parameters.items() if isinstance(v, (int, float, str))}
    attrs = {"model": ModelResult.label(system), "system": json.dumps(describe_system(system), default=str),
             "parameters": json.dumps(values), "headline": json.dumps(list(system.headline)),
             "observed": system.dofs[system.observed_index]}
    attrs.update(parameter_attrs({k: v for k, v in values.items() if not isinstance(v, bool)}))
    return attrs


class ModelResult:
    """``params`` and ``model`` of a result with a ``system`` attribute, as :class:`Trajectory` has them."""

    system: FrictionModel

    @staticmethod
    def label(system: FrictionModel) -> str:
        """How results name the model: the plates' variant (``full``, ``rotation``, ...) or the model's name."""
        return system.label or system.name

    @property
    def params(self) -> Parameters | None:
        """The plates' :class:`Parameters` (None for other models: see ``system.parameters``)."""
        return plates_parameters(self.system)

    @property
    def model(self) -> str:
        """The plates' variant or the model's name."""
        return self.label(self.system)
