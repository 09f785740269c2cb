"""Figures of bistability regions (paper Fig. 8) and stick-slip domains of several models (Fig. 9).

Every function takes a finished :class:`~stickslip.sweep.RegionMap` (or its ``xarray.Dataset``
from :func:`~stickslip.sweep.load_region_map`) and never simulates.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ._common import MODEL_LABELS, cell_edges, grid_axis, is_geometric, param_text, save_figure
from .sweep import _new_figure

__all__ = ["plot_regions", "plot_stick_slip_domains", "save_regions_figure", "REGION_STYLE", "MODEL_LABELS"]

#: Colour and label of each region code (:data:`stickslip.sweep.bistability.REGION_NAMES`).
REGION_STYLE = {
    0: ("#d9d9d9", "other: no settled stick-slip/equilibrium pair"),
    1: ("#d62728", "I: stick-slip only"),
    2: ("#ffbf69", "II: stick-slip and equilibrium coexist"),
    3: ("#4c9be8", "III: equilibrium only"),
}


def _dataset(rmap):
    return getattr(rmap, "dataset", rmap)


def _params_line(ds) -> str:
    p = json.loads(ds.attrs.get("parameters", "{}"))
    parts = [param_text(k, p[k]) for k in ("mu_k", "delta_mu", "alpha") if k in p]
    parts.append(f"{ds.attrs.get('t_end', float('nan')):g} s runs, steady window from {ds.attrs.get('t_from', float('nan')):g} s")
    return ", ".join(parts)


def plot_regions(rmap, ax=None, *, model: str | None = None, boundary: bool = True, legend: bool = True,
                 title: str | None = None):
    """Region map over (N, Ω) for one model (paper Fig. 8).

    Each grid cell is coloured by its region: I (stick-slip from both initial conditions),
    II (stick-slip from one, equilibrium from the other), III (equilibrium from both), or
    other. With ``boundary`` the upper edge of the stick-slip domain (largest grid Ω with
    stick-slip at each N, the Fig. 9 curve) is drawn as a black line.

    Parameters
    ----------
    rmap : RegionMap or xarray.Dataset
    ax : matplotlib.axes.Axes, optional
    model : str, optional
        Model to draw (default: the first one).
    boundary, legend : bool
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    ds = _dataset(rmap)
    models = [str(m) for m in ds["model"].values]
    model = models[0] if model is None else str(model)
    if model not in models:
        raise ValueError(f"model {model!r} is not in this region map; choose one of {', '.join(models)}")
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    ds = ds.sortby("N").sortby("Omega")
    N, W = ds["N"].values.astype(float), ds["Omega"].values.astype(float)
    region = ds["region"].sel(model=model).transpose("N", "Omega").values
    cmap = ListedColormap([REGION_STYLE[c][0] for c in sorted(REGION_STYLE)])
    norm = BoundaryNorm(np.arange(-0.5, 4.5), cmap.N)
    (ne, ns), (we, ws) = cell_edges(N), cell_edges(W)
    ax.pcolormesh(ne, we, region.T, cmap=cmap, norm=norm, edgecolors="white", linewidth=0.3)
    handles = [Patch(color=REGION_STYLE[c][0], label=REGION_STYLE[c][1]) for c in sorted(REGION_STYLE)
               if np.any(region == c)]
    if boundary:
        omax = ds["stick_slip_omega_max"].sel(model=model).values.astype(float)
        if np.any(np.isfinite(omax)):
            ax.plot(N, omax, "k.-", lw=1.5, ms=5)
            handles.append(Line2D([], [], color="k", marker=".", lw=1.5, label="largest Ω with stick-slip"))
    grid_axis(ax, "x", ne, ns, N)
    grid_axis(ax, "y", we, ws, W)
    ax.set_xlabel("normal load N [N]")
    ax.set_ylabel("Ω [rad/s]")
    ax.set_title(MODEL_LABELS.get(model, f"model {model}") if title is None else title, fontsize=10)
    if legend:  # below the map, so that no cell is hidden
        ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, frameon=False)
    return ax


def plot_stick_slip_domains(rmap, ax=None, *, legend: bool = True):
    """Upper edges of the stick-slip domains (regions I ∪ II) of each model against N (paper Fig. 9).

    The domain of a model lies below its curve. The curve is the largest grid Ω with
    stick-slip at each N, so it is resolved to the Ω spacing of the grid; a curve on the top
    edge of the grid means the domain extends beyond it.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ds = _dataset(rmap)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    ds = ds.sortby("N").sortby("Omega")
    N, W = ds["N"].values.astype(float), ds["Omega"].values.astype(float)
    styles = ["o-", "s--", "^-.", "v:"]
    found = False
    for i, model in enumerate(str(m) for m in ds["model"].values):
        omax = ds["stick_slip_omega_max"].sel(model=model).values.astype(float)
        found |= bool(np.any(np.isfinite(omax)))
        ax.plot(N, omax, styles[i % len(styles)], ms=4, lw=1.5, label=MODEL_LABELS.get(model, model))
    if not found:
        ax.text(0.5, 0.5, "no stick-slip on this grid", transform=ax.transAxes, ha="center", va="center", color="0.4")
    ax.axhline(W[-1], color="0.6", lw=0.8, ls=":", label="top of the Ω grid")
    ne, ns = cell_edges(N)
    grid_axis(ax, "x", ne, ns)
    if is_geometric(W):
        ax.set_yscale("log")
        ax.set_ylim(W[0] / 1.2, W[-1] * 1.2)
    else:
        ax.set_ylim(min(0.0, W[0]), W[-1] + 0.06 * (W[-1] - W[0] if W.size > 1 else 1.0))
    ax.set_xlabel("normal load N [N]")
    ax.set_ylabel("largest Ω with stick-slip [rad/s]")
    ax.set_title("stick-slip domains (below each curve)", fontsize=10)
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(fontsize=8, loc="best")
    return ax


def save_regions_figure(rmap, path, *, dpi: int = 110) -> Path:
    """Save the region map of every model and, for several models, the domain curves (Figs. 8, 9)."""
    ds = _dataset(rmap)
    models = [str(m) for m in ds["model"].values]
    n = len(models) + (1 if len(models) > 1 else 0)
    fig, axes = _new_figure(n, width=5.6, height=4.4)
    for ax, model in zip(axes, models):
        plot_regions(ds, ax, model=model)
    if len(models) > 1:
        plot_stick_slip_domains(ds, axes[-1])
    fig.suptitle(f"Steady-state regions over (N, Ω)\n{_params_line(ds)}", fontsize=10)
    path = Path(path)
    save_figure(fig, path, dpi=dpi)
    return path
