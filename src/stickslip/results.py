"""What every result type shares: ``.plot()`` hands the result to its figure in :mod:`stickslip.plot`.

Results (:class:`~stickslip.integrate.result.Trajectory`,
:class:`~stickslip.stability.maps.StabilityMap`, :class:`~stickslip.sweep.bistability.RegionMap`)
hold data and write themselves to NetCDF; figures are drawn by :mod:`stickslip.plot`, the top
layer, which takes results and never computes physics. This module's one import of
:mod:`stickslip.plot` is the package's one import that runs up the layers (docs/architecture.md):
it happens when a figure is asked for, so matplotlib is loaded only then.
"""

from __future__ import annotations

from typing import ClassVar

__all__ = ["Plottable"]


class Plottable:
    """Mixin of result types: ``result.plot(**kwargs)`` draws the result's figure.

    A subclass names its figure in ``FIGURE`` (a key of :data:`stickslip.plot.FIGURES`), so that
    the plot layer finds the figure function without importing the result types.
    """

    #: Name of the figure function of this result type in :data:`stickslip.plot.FIGURES`.
    FIGURE: ClassVar[str] = ""

    def plot(self, **kwargs):
        """The result's figure (keyword arguments go to its figure function in
        :data:`stickslip.plot.FIGURES`). Returns the matplotlib figure."""
        from .plot import figure  # the one upward import: results hand their figure to the plot layer

        return figure(self, **kwargs)
