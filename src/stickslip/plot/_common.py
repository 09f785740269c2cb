"""Shared pieces of the figures: grid cell edges (uniform, non-uniform, geometric) and their axes,
parameter labels with units, and a figure on the Agg canvas. Nothing here computes physics."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..files import atomic_write
from ..model.parameters import PARAMETER_UNITS

#: Symbols of the parameters that name axes and titles.
SYMBOLS = {"N": "N", "Omega": "Ω", "mu_k": "μk", "delta_mu": "Δμ", "alpha": "α"}

#: Greek names of coordinates written as their letters (any model's dofs).
GREEK = {"phi": "φ", "psi": "ψ", "theta": "θ", "alpha": "α", "beta": "β", "gamma": "γ", "omega": "ω"}


def symbol(name: str) -> str:
    """How a figure writes a parameter or coordinate: ``Omega`` → Ω, ``phi`` → φ, others as named."""
    return SYMBOLS.get(name) or GREEK.get(name, name)

#: The paper's names of the model variants (Sect. 4.2.3).
MODEL_LABELS = {"full": "Model 1 (full)", "x": "Model 2 (x translation)", "y": "Model 3 (y translation)",
                "rotation": "Model 4 (rotation only)"}

#: Relative tolerance on the ratio of neighbours for a grid to count as geometric (log axis).
GEOMETRIC_RTOL = 1e-6


def save_figure(fig, path, **savefig_kwargs) -> Path:
    """Write ``fig`` to ``path`` all at once (a temporary beside it, then a rename): an interrupted
    write never leaves a truncated image in place of a good one. The format follows the suffix."""
    path = Path(path)
    fmt = path.suffix.lstrip(".") or "png"
    return atomic_write(path, lambda tmp: fig.savefig(tmp, format=fmt, **savefig_kwargs))


def unit_text(units: str | None) -> str:
    """``"[rad/s]"`` for a unit string, ``"[-]"`` for a dimensionless one (``"1"``), ``""`` for none."""
    if units is None or units == "":
        return ""
    return "[-]" if units == "1" else f"[{units}]"


def param_label(name: str) -> str:
    """Axis label of a model parameter with its unit, e.g. ``"Ω [rad/s]"``, ``"Δμ [-]"``."""
    unit = unit_text(PARAMETER_UNITS.get(name))
    symbol = SYMBOLS.get(name, name)
    return f"{symbol} {unit}" if unit else symbol


def param_text(name: str, value) -> str:
    """``"Ω = 0.5 rad/s"``: a parameter value with its unit (none for dimensionless ones)."""
    unit = PARAMETER_UNITS.get(name, "")
    shown = f"{value:g}" if isinstance(value, (int, float, np.integer, np.floating)) else str(value)
    return f"{SYMBOLS.get(name, name)} = {shown}" + (f" {unit}" if unit and unit != "1" else "")


def is_geometric(values) -> bool:
    """Whether ``values`` (≥ 3, one sign, no zero) have a constant ratio ≠ 1 between neighbours."""
    v = np.asarray(values, dtype=float)
    if v.size < 3 or not (np.all(v > 0) or np.all(v < 0)):
        return False
    ratio = v[1:] / v[:-1]
    return bool(abs(ratio[0] - 1.0) > GEOMETRIC_RTOL and np.allclose(ratio, ratio[0], rtol=GEOMETRIC_RTOL, atol=0.0))


def cell_edges(values) -> tuple[np.ndarray, str]:
    """Edges of the cells around sorted grid values, and the axis scale to draw them on.

    A geometric grid (:func:`is_geometric`) gets edges at the geometric means of neighbours, the
    outer ones mirrored in log space, and scale ``"log"``, so that every cell has the same width on
    the log axis. Any other grid gets edges at the midpoints of neighbours, the outer ones mirrored
    (half a spacing beyond the end values), and scale ``"linear"``; an outer edge that would cross
    zero while every value has one sign stops at zero, so that no cell claims Ω or N values of the
    other sign that were never computed. A single value gets a cell of its own magnitude
    (width 1 at 0).

    Parameters
    ----------
    values : array-like (n,)
        Strictly increasing grid values.

    Returns
    -------
    edges : ndarray (n + 1,)
    scale : {"linear", "log"}
    """
    v = np.asarray(values, dtype=float)
    if v.size == 1:
        half = 0.5 * (abs(v[0]) if v[0] != 0 else 1.0)
        return np.array([v[0] - half, v[0] + half]), "linear"
    if is_geometric(v):
        sign = np.sign(v[0])
        lv = np.log(np.abs(v))
        mid = 0.5 * (lv[1:] + lv[:-1])
        le = np.concatenate([[2 * lv[0] - mid[0]], mid, [2 * lv[-1] - mid[-1]]])
        return sign * np.exp(le), "log"
    mid = 0.5 * (v[1:] + v[:-1])
    edges = np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])
    if v[0] > 0 and edges[0] < 0:
        edges[0] = 0.0
    if v[-1] < 0 and edges[-1] > 0:
        edges[-1] = 0.0
    return edges, "linear"


#: Axes of a cell map with at most this many grid values get one tick per value.
MAX_VALUE_TICKS = 8


def grid_axis(ax, which: str, edges: np.ndarray, scale: str, values=None) -> None:
    """Limits and scale of the x or y axis of a cell map (``which``: ``"x"`` or ``"y"``); with
    few ``values`` (≤ :data:`MAX_VALUE_TICKS`) the ticks sit at the grid values, so that a
    non-uniform grid shows where it was computed."""
    from matplotlib.ticker import NullLocator

    if which == "x":
        axis = ax.xaxis
        ax.set_xscale(scale)
        ax.set_xlim(edges[0], edges[-1])
    else:
        axis = ax.yaxis
        ax.set_yscale(scale)
        ax.set_ylim(edges[0], edges[-1])
    if values is not None and len(values) <= MAX_VALUE_TICKS:
        axis.set_ticks(values, [f"{v:g}" for v in values])
        axis.set_minor_locator(NullLocator())


def agg_figure(figsize, **kwargs):
    """A new constrained-layout Figure on an Agg canvas (no display, no pyplot state)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained", **kwargs)
    FigureCanvasAgg(fig)
    return fig
