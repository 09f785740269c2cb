"""Figures (matplotlib only). Functions take results and never simulate."""

from .stability import plot_stability_map, save_stability_map_figure
from .trajectory import plot_trajectory, save_trajectory_figure

__all__ = ["plot_trajectory", "save_trajectory_figure", "plot_stability_map", "save_stability_map_figure"]
