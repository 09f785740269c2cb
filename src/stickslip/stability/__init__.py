"""Steady sliding of any model: equilibrium (plates: Eq. 14), linear stability (Eq. 15) and stability maps;
for sparse (finite-element) models the complex eigenvalues of a band and the mode-coupling diagram."""

from .. import _startup
from ..errors import EquilibriumError

#: Public name → the module that defines it, imported on first use (:func:`stickslip._startup.export_on_first_use`).
_EXPORTS = {
    **dict.fromkeys(["StabilityResult", "linearization", "stability"], ".analysis"),
    **dict.fromkeys(["BandError", "BandStability", "band_stability"], ".band"),
    **dict.fromkeys(["equilibrium", "equilibrium_residual"], ".equilibrium"),
    **dict.fromkeys(["StabilityMap", "load_stability_map", "stability_map"], ".maps"),
    **dict.fromkeys(["ModeCoupling", "mode_coupling"], ".mode_coupling"),
}

__all__ = ["equilibrium", "equilibrium_residual", "EquilibriumError",
           "stability", "StabilityResult", "linearization",
           "stability_map", "StabilityMap", "load_stability_map", "band_stability", "BandStability", "BandError",
           "mode_coupling", "ModeCoupling"]

_startup.export_on_first_use(__name__, _EXPORTS)
