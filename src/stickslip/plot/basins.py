"""Figures of basin-stability studies: the basin image or the states coloured by attractor, the
fractions with their standard errors, and the fractions against a parameter.

Every function takes a finished :class:`~stickslip.basins.BasinResult` (or its dataset from
:func:`~stickslip.basins.load_basins`) and never simulates.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ._common import agg_figure, cell_edges, param_label, save_figure

__all__ = ["plot_basins", "plot_fractions", "plot_parameter_study", "save_basins_figure", "label_colors"]

#: Colours of the verdict labels; cycles (``periodic``, ``periodic-2``, …) take :data:`CYCLE_COLORS`.
VERDICT_COLORS = {"equilibrium": "#4c9be8", "quasiperiodic": "#2ca02c", "chaotic": "#9467bd", "unbounded": "#8c564b",
                  "unsettled": "#bdbdbd", "contact-lost": "#e377c2", "failed": "#000000"}
CYCLE_COLORS = ("#d62728", "#ff7f0e", "#bcbd22", "#17becf", "#7f7f7f", "#aec7e8")


def _dataset(result):
    return getattr(result, "dataset", result)


def _one(result, ax, param_index: int, figsize):
    """The dataset of one parameter value, and the axes to draw on (a new figure's if None)."""
    ds = _dataset(result)
    if "param" in ds.dims:
        ds = ds.isel(param=param_index)
    return ds, (agg_figure(figsize).add_subplot() if ax is None else ax)


def _with_unit(name: str, units: dict) -> str:
    """An axis label: the name with its unit from ``units`` (the model's), else the plates' parameter units."""
    unit = units.get(name, "").strip("-")
    return f"{name} [{unit}]" if unit else param_label(name)


def label_colors(names) -> list[str]:
    """One colour per attractor label, the same label always the same colour."""
    out = []
    for name in names:
        if name in VERDICT_COLORS:
            out.append(VERDICT_COLORS[name])
        else:
            rank = int(name.split("-")[1]) - 1 if "-" in name else 0
            out.append(CYCLE_COLORS[rank % len(CYCLE_COLORS)])
    return out


def _names(ds) -> list[str]:
    return [str(x) for x in ds["attractor"].values]


def _axes_names(ds) -> list[str]:
    """The states the picture spans: the box axes, else (a CSV table) the first two states."""
    box = json.loads(ds.attrs.get("box", "{}"))
    names = list(box) if box else [str(x) for x in ds["state_name"].values[:2]]
    return names[:2]


def plot_basins(result, ax=None, *, param_index: int = 0, legend: bool = True):
    """The basins: a grid as an image of labels over its first two axes, other states as points
    coloured by the attractor they reach (over the first two box axes, or the first two states).

    Parameters
    ----------
    result : BasinResult or xarray.Dataset
    ax : matplotlib.axes.Axes, optional
    param_index : int
        The parameter value to draw (parameter studies).
    legend : bool

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    ds, ax = _one(result, ax, param_index, (5.5, 4.5))
    names = _names(ds)
    colors = label_colors(names)
    label = ds["label"].values
    axes = _axes_names(ds)
    states = [str(x) for x in ds["state_name"].values]
    counts = json.loads(ds.attrs.get("grid_counts", "[]"))
    if ds.attrs.get("sampler") == "grid" and len(counts) == 2:
        x = ds["initial_state"].values[:, states.index(axes[0])].reshape(counts)[:, 0]
        y = ds["initial_state"].values[:, states.index(axes[1])].reshape(counts)[0, :]
        image = np.ma.masked_less(label.reshape(counts).T.astype(float), 0)
        cmap = ListedColormap(colors or ["w"])
        xe, ye = cell_edges(x)[0], cell_edges(y)[0]
        ax.pcolormesh(xe, ye, image, cmap=cmap, norm=BoundaryNorm(np.arange(len(names) + 1) - 0.5, cmap.N))
    else:
        s = ds["initial_state"].values
        xs = s[:, states.index(axes[0])]
        ys = s[:, states.index(axes[1])] if len(axes) > 1 else np.zeros(xs.size)
        size = max(2.0, min(20.0, 4000.0 / max(xs.size, 1)))
        for code, (name, color) in enumerate(zip(names, colors)):
            sel = label == code
            ax.scatter(xs[sel], ys[sel], s=size, c=color, lw=0, label=name)
    units = json.loads(ds.attrs.get("state_units", "{}"))
    ax.set_xlabel(_with_unit(axes[0], units))
    ax.set_ylabel(_with_unit(axes[1], units) if len(axes) > 1 else "")
    if legend and names:
        present = [i for i in range(len(names)) if np.any(label == i)]
        ax.legend(handles=[Patch(color=colors[i], label=names[i]) for i in present], fontsize="small", loc="best")
    ax.set_title(f"{ds.attrs.get('model', '')}: attractor reached from each state", fontsize="medium")
    return ax


def plot_fractions(result, ax=None, *, param_index: int = 0):
    """Bars of the fractions with ±1 standard error."""
    ds, ax = _one(result, ax, param_index, (4.0, 4.0))
    names = _names(ds)
    p = ds["fraction"].values
    se = ds["standard_error"].values
    pos = np.arange(len(names))
    ax.bar(pos, p, yerr=se, color=label_colors(names), capsize=4)
    for x, v, e in zip(pos, p, se):
        ax.text(x, v + e + 0.01, f"{v:.3f}", ha="center", va="bottom", fontsize="small")
    ax.set_xticks(pos, names, rotation=30, ha="right")
    ax.set_ylim(0, 1.08)
    ax.set_ylabel("basin stability (fraction of states)")
    ax.set_title(f"n = {int(ds['done'].sum())} states", fontsize="medium")
    return ax


def plot_parameter_study(result, ax=None):
    """Fractions against the parameter, one line per attractor with a ±1 standard error band."""
    ds = _dataset(result)
    if ax is None:
        ax = agg_figure((6.0, 4.0)).add_subplot()
    names = _names(ds)
    x = ds["param"].values
    for i, (name, color) in enumerate(zip(names, label_colors(names))):
        p = ds["fraction"].values[:, i]
        se = ds["standard_error"].values[:, i]
        ax.plot(x, p, "o-", color=color, label=name, ms=4)
        ax.fill_between(x, p - se, p + se, color=color, alpha=0.25, lw=0)
    path = ds.attrs.get("param", "")
    ax.set_xlabel(_with_unit(path, json.loads(ds.attrs.get("state_units", "{}"))))
    ax.set_ylabel("basin stability (fraction of states)")
    ax.set_ylim(-0.02, 1.02)
    ax.legend(fontsize="small")
    ax.set_title(f"{ds.attrs.get('model', '')}: basin stability against {path}", fontsize="medium")
    return ax


def save_basins_figure(result, path) -> Path:
    """Draw the study and write it as PNG: the basins beside the fractions, or for a parameter
    study the fractions against the parameter beside the basins at its first value."""
    ds = _dataset(result)
    path = Path(path)
    fig = agg_figure((11.0, 4.5))
    if "param" in ds.dims:
        a, b = fig.subplots(1, 2, width_ratios=[1.3, 1.0])
        plot_parameter_study(ds, a)
        plot_basins(ds, b, param_index=0)
        b.set_title(f"basins at {ds.attrs.get('param')} = {float(ds['param'].values[0]):g}", fontsize="medium")
    else:
        a, b = fig.subplots(1, 2, width_ratios=[1.4, 1.0])
        plot_basins(ds, a)
        plot_fractions(ds, b)
    path.parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, path, dpi=120)
    return path
