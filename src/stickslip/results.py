"""What every result type shares: ``.plot()`` hands the result to its figure in :mod:`stickslip.plot`.

Results (:class:`~stickslip.integrate.result.Trajectory`,
:class:`~stickslip.stability.maps.StabilityMap`, :class:`~stickslip.sweep.bistability.RegionMap`)
hold data and write themselves to NetCDF; figures are drawn by :mod:`stickslip.plot`, the top
layer, which takes results and never computes physics. This module does not import it: the
package (``stickslip/__init__.py``, above every layer) hands :class:`Plottable` the plot layer's
figure function when it is imported, which is before any result exists (docs/architecture.md).
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

    #: ``draw(result, **kwargs) -> figure``: :func:`stickslip.plot.figure`, set by the package.
    draw: ClassVar = None

    def plot(self, **kwargs):
        """The result's figure (keyword arguments go to its figure function in
        :data:`stickslip.plot.FIGURES`). Returns the matplotlib figure."""
        return Plottable.draw(self, **kwargs)
