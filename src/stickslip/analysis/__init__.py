"""Analysis of trajectories: steady state, spectra."""

from .steady import SteadyState, fundamental_frequency, spectrum, stick_time, summarize

__all__ = ["SteadyState", "fundamental_frequency", "spectrum", "stick_time", "summarize"]
