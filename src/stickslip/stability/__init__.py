"""Steady sliding of any model: equilibrium (plates: Eq. 14), linear stability (Eq. 15) and stability maps;
for sparse (finite-element) models the complex eigenvalues of a band and the mode-coupling diagram."""

from ..errors import EquilibriumError
from .analysis import StabilityResult, linearization, stability
from .band import BandError, BandStability, band_stability
from .equilibrium import equilibrium, equilibrium_residual
from .maps import StabilityMap, load_stability_map, stability_map
from .mode_coupling import ModeCoupling, mode_coupling

__all__ = ["equilibrium", "equilibrium_residual", "EquilibriumError",
           "stability", "StabilityResult", "linearization",
           "stability_map", "StabilityMap", "load_stability_map", "band_stability", "BandStability", "BandError",
           "mode_coupling", "ModeCoupling"]
