"""Integrators (one file per method), shared transition logic, the ``simulate`` driver."""

from .. import _startup
from ..errors import SimulationError

#: Public name → the module that defines it, imported on first use (:func:`stickslip._startup.export_on_first_use`).
_EXPORTS = {
    **dict.fromkeys(["METHODS", "simulate"], ".driver"),
    **dict.fromkeys(["NAMED_STARTS", "initial_state", "start_names"], ".initial"),
    **dict.fromkeys(["Stats", "Trajectory", "Transitions", "load_trajectory"], ".result"),
}

__all__ = ["simulate", "initial_state", "NAMED_STARTS", "start_names", "METHODS", "SimulationError", "Trajectory", "Stats", "Transitions", "load_trajectory"]

_startup.export_on_first_use(__name__, _EXPORTS)
