"""Integrators (one file per method), shared transition logic, the ``simulate`` driver."""

from .driver import METHODS, SimulationError, initial_state, simulate
from .result import Stats, Trajectory, Transitions, load_trajectory

__all__ = ["simulate", "initial_state", "METHODS", "SimulationError", "Trajectory", "Stats", "Transitions", "load_trajectory"]
