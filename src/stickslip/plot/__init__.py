"""Figures (matplotlib only). Functions take results and never simulate."""

from .trajectory import plot_trajectory, save_trajectory_figure

__all__ = ["plot_trajectory", "save_trajectory_figure"]
