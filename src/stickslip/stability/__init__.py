"""Steady sliding of any model: equilibrium (plates: Eq. 14), linear stability (Eq. 15) and stability maps."""

from ..errors import EquilibriumError
from .analysis import StabilityResult, linearization, stability
from .equilibrium import equilibrium, equilibrium_residual
from .maps import StabilityMap, load_stability_map, stability_map

__all__ = ["equilibrium", "equilibrium_residual", "EquilibriumError",
           "stability", "StabilityResult", "linearization",
           "stability_map", "StabilityMap", "load_stability_map"]
