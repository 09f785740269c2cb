"""Integrators (one file per method), shared transition logic, the ``simulate`` driver."""

from ..errors import SimulationError
from .driver import METHODS, simulate
from .initial import NAMED_STARTS, initial_state, start_names
from .result import Stats, Trajectory, Transitions, load_trajectory

__all__ = ["simulate", "initial_state", "NAMED_STARTS", "start_names", "METHODS", "SimulationError", "Trajectory", "Stats", "Transitions", "load_trajectory"]
