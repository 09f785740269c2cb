"""Figures (matplotlib only). Functions take results and never simulate.

:func:`figure` draws any result that has a figure (``result.plot()`` calls it).
"""

from .fe import plot_mode_coupling, plot_mode_shape
from .regions import plot_regions
from .stability import plot_stability_map, save_stability_map_figure
from .trajectory import plot_trajectory, save_trajectory_figure

__all__ = ["figure", "FIGURES", "plot_trajectory", "save_trajectory_figure", "plot_stability_map",
           "save_stability_map_figure", "plot_regions", "plot_mode_coupling", "plot_mode_shape"]

#: The figure function of each result type, by the name the type gives in its ``FIGURE``.
FIGURES = {"trajectory": plot_trajectory, "stability_map": plot_stability_map, "regions": plot_regions,
           "mode_coupling": plot_mode_coupling}


def figure(result, **kwargs):
    """The figure of ``result`` (a :class:`~stickslip.Trajectory`, a stability map or a region
    map); keyword arguments go to its figure function (:data:`FIGURES`). Returns the figure."""
    draw = FIGURES.get(getattr(result, "FIGURE", None))
    if draw is None:
        raise TypeError(f"no figure for a {type(result).__name__}; results with figures name one of "
                        f"{', '.join(FIGURES)} in their FIGURE")
    return draw(result, **kwargs)
