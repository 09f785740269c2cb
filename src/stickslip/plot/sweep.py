"""Figures of parameter sweeps: any reduction over a 1-D or 2-D grid (line plot or heat map, with
small multiples over the remaining dimensions) and bifurcation diagrams (paper Figs. 12–14:
steady-state peak values of φ against the control parameter).

Every function takes a finished sweep (a :class:`~stickslip.sweep.SweepResult` or the
``xarray.Dataset`` of :func:`~stickslip.sweep.load_sweep`) and never simulates.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np

__all__ = ["plot_reduction", "save_sweep_figure", "plot_bifurcation", "save_bifurcation_figure", "KIND_STYLE",
           "axis_label"]

#: Colour and label of each steady-state kind code (:data:`stickslip.analysis.classify.KINDS`,
#: −1 = the run failed).
KIND_STYLE = {
    -1: ("#d62728", "failed"),
    0: ("#7f7f7f", "equilibrium"),
    1: ("#1f77b4", "periodic slip"),
    2: ("#000000", "periodic stick-slip"),
    3: ("#ff7f0e", "non-periodic"),
}

#: Most panels drawn by :func:`save_sweep_figure`; further combinations of the panel dimensions
#: are left out (named in the title) so a figure stays readable.
MAX_PANELS = 12

_SYMBOLS = {"N": "N", "Omega": "Ω", "mu_k": "μk", "delta_mu": "Δμ", "alpha": "α"}
_CATEGORICAL = ("model", "ic")


def _dataset(result):
    return getattr(result, "dataset", result)


def axis_label(ds, name: str) -> str:
    """``"Ω [rad/s]"``-style label of a coordinate or variable from its attributes."""
    attrs = ds[name].attrs if name in ds.variables else {}
    symbol = _SYMBOLS.get(name, name)
    text = symbol
    units = attrs.get("units", "")
    return f"{text} [{units}]" if units and units != "1" else text


def _grid_dims(ds) -> list[str]:
    return [d for d in ds["done"].dims]


def _is_numeric(ds, dim: str) -> bool:
    return dim not in _CATEGORICAL and np.issubdtype(ds[dim].dtype, np.number)


def _split_dims(ds, var: str):
    """(plotted dims ≤ 2, panel dims): plotted are the last numeric dims with more than one value."""
    dims = [d for d in ds[var].dims if d != "peak" and ds.sizes[d] > 1]
    numeric = [d for d in dims if _is_numeric(ds, d)]
    plotted = numeric[-2:] if numeric else dims[-1:]
    panels = [d for d in dims if d not in plotted]
    return plotted, panels


def _fmt(value) -> str:
    return f"{value:g}" if isinstance(value, (float, np.floating)) else str(value)


def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around grid values (midpoints; half a spacing beyond the ends)."""
    v = np.asarray(v, dtype=float)
    if v.size == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _kind_cmap():
    from matplotlib.colors import BoundaryNorm, ListedColormap

    codes = sorted(KIND_STYLE)
    cmap = ListedColormap([KIND_STYLE[c][0] for c in codes])
    return cmap, BoundaryNorm(np.arange(codes[0] - 0.5, codes[-1] + 1.5), cmap.N)


def plot_reduction(result, var: str = "frequency", ax=None, *, select: dict | None = None, colorbar: bool = True):
    """Draw one reduced quantity of a sweep over its grid.

    After ``select`` (``{dim: value}``, nearest value for numbers) and dropping dimensions of
    length 1, the variable must have at most two dimensions:

    * one numeric dimension: a line with markers against it;
    * two numeric dimensions: a heat map (cells centred on the grid values, colour bar with the
      variable's units; ``kind`` drawn with one colour per steady-state kind);
    * one numeric and one categorical (``model``, ``ic``) dimension: one line per category.

    Parameters
    ----------
    result : SweepResult or xarray.Dataset
    var : str
        A variable of the sweep (``frequency`` [Hz], ``amplitude`` [rad], ``stick_fraction``,
        ``kind``, ``intensity_r_phi`` [m s^-1/2], ...).
    ax : matplotlib.axes.Axes, optional
    select : dict, optional
        Values of the other dimensions.
    colorbar : bool
        Draw a colour bar (heat maps).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ds = _dataset(result)
    if var not in ds.data_vars or var == "peaks":
        choices = ", ".join(v for v in ds.data_vars if v not in ("peaks", "done"))
        raise ValueError(f"cannot plot {var!r}; choose one of {choices} (peaks: use the bifurcation diagram)")
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    da = ds[var]
    for dim, value in (select or {}).items():
        da = da.sel({dim: value}, method=None if not _is_numeric(ds, dim) else "nearest")
    da = da.squeeze(drop=False)
    dims = [d for d in da.dims if da.sizes[d] > 1]
    numeric = [d for d in dims if _is_numeric(ds, d)]
    categorical = [d for d in dims if d not in numeric]
    is_kind = var == "kind"
    label = axis_label(ds, var)
    if len(dims) > 2 or len(categorical) > 1 or (len(dims) == 2 and not numeric):
        raise ValueError(f"{var} has dimensions {tuple(dims)} after selection; select values of all but two "
                         "(at most one of them model or ic)")
    if len(numeric) == 2:
        x, y = numeric[0], numeric[1]  # first swept dimension across, as N in Figs. 8–9
        z = da.transpose(y, x).values.astype(float)
        xe, ye = _edges(ds[x].values), _edges(ds[y].values)
        if is_kind:
            cmap, norm = _kind_cmap()
            mesh = ax.pcolormesh(xe, ye, np.where(np.isfinite(z), z, -1), cmap=cmap, norm=norm)
            _kind_legend(ax, np.unique(np.where(np.isfinite(z), z, -1)))
        else:
            mesh = ax.pcolormesh(xe, ye, np.ma.masked_invalid(z), cmap="viridis")
            if colorbar:
                ax.figure.colorbar(mesh, ax=ax, label=label)
            if np.any(~np.isfinite(z)):
                ax.set_facecolor("0.85")  # NaN cells (e.g. no frequency at an equilibrium) stay light grey
        ax.set_xlim(xe[0], xe[-1])
        ax.set_ylim(ye[0], ye[-1])
        ax.set_xlabel(axis_label(ds, x))
        ax.set_ylabel(axis_label(ds, y))
    elif len(numeric) == 1:
        x = numeric[0]
        xs = ds[x].values
        groups = [(None, da)] if not categorical else [(c, da.sel({categorical[0]: c})) for c in da[categorical[0]].values]
        for cat, line in groups:
            ys = line.transpose(x).values.astype(float)
            ax.plot(xs, ys, "o-", ms=3, lw=1.2, label=None if cat is None else f"{categorical[0]} = {cat}")
        if is_kind:
            ax.set_yticks(sorted(KIND_STYLE), [KIND_STYLE[c][1] for c in sorted(KIND_STYLE)])
        if categorical:
            ax.legend(fontsize=8)
        ax.set_xlabel(axis_label(ds, x))
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    else:  # only categories (or a single point)
        cats = [str(c) for c in da[dims[0]].values] if dims else ["point"]
        ax.bar(cats, np.atleast_1d(da.values.astype(float)), color="0.4")
        ax.set_ylabel(label)
        if dims:
            ax.set_xlabel(dims[0])
    return ax


def _kind_legend(ax, codes, loc="best"):
    from matplotlib.patches import Patch

    handles = [Patch(color=KIND_STYLE[int(c)][0], label=KIND_STYLE[int(c)][1]) for c in codes if int(c) in KIND_STYLE]
    ax.legend(handles=handles, fontsize=8, loc=loc)


def _new_figure(n_panels: int, width: float = 5.2, height: float = 4.0):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    cols = min(n_panels, 3)
    rows = -(-n_panels // cols)
    fig = Figure(figsize=(width * cols, height * rows), layout="constrained")  # Agg canvas: no display
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(rows, cols, i + 1) for i in range(n_panels)]
    return fig, axes


def _conditions(ds, skip=()) -> str:
    """Short line of the fixed operating/friction parameters and run options."""
    params = json.loads(ds.attrs.get("parameters", "{}"))
    parts = [f"{_SYMBOLS[k]} = {params[k]:g}" for k in ("N", "Omega", "mu_k", "delta_mu", "alpha")
             if k in params and k not in skip and k not in ds.dims]
    if "model" not in ds.dims and "model" not in skip:
        parts.insert(0, f"model {ds.attrs.get('model', '?')}")
    parts.append(f"steady window {ds.attrs.get('t_from', float('nan')):g}–{ds.attrs.get('t_end', float('nan')):g} s")
    return ", ".join(parts).replace("Omega", "Ω")


def save_sweep_figure(result, path, var: str = "frequency", *, dpi: int = 110) -> Path:
    """Save :func:`plot_reduction` of ``var``, one panel per combination of the other dimensions.

    The last one or two numeric dimensions with more than one value are the axes; every other
    dimension with more than one value (``model``, ``ic``, further parameters) makes panels, at
    most :data:`MAX_PANELS` (the rest are left out and the title says so).
    """
    ds = _dataset(result)
    plotted, panel_dims = _split_dims(ds, var) if var in ds.data_vars else ([], [])
    if var not in ds.data_vars or var == "peaks":
        plot_reduction(ds, var)  # raises the helpful error
    combos = list(itertools.product(*[ds[d].values for d in panel_dims])) or [()]
    shown = combos[:MAX_PANELS]
    fig, axes = _new_figure(len(shown))
    for ax, combo in zip(axes, shown):
        sel = dict(zip(panel_dims, combo))
        plot_reduction(ds, var, ax, select=sel)
        if sel:
            ax.set_title(", ".join(f"{_SYMBOLS.get(k, k)} = {_fmt(v)}" for k, v in sel.items()), fontsize=9)
    title = f"{var}: {ds[var].attrs.get('long_name', var)}\n{_conditions(ds)}"
    if len(combos) > len(shown):
        title += f" (first {len(shown)} of {len(combos)} panels)"
    fig.suptitle(title, fontsize=10)
    path = Path(path)
    fig.savefig(path, dpi=dpi)
    return path


# ----------------------------------------------------------------------------- bifurcation diagram
def _control_dim(ds) -> str:
    numeric = [d for d in _grid_dims(ds) if _is_numeric(ds, d)]
    if len(numeric) != 1:
        raise ValueError(f"a bifurcation diagram needs exactly one numeric grid dimension, got {tuple(numeric)}; "
                         "use `stickslip bifurcation` or select a value of the others")
    return numeric[0]


def plot_bifurcation(result, ax=None, *, select: dict | None = None, legend: bool = True, marker_size: float = 3.0):
    """Bifurcation diagram: the steady-state peak values of φ (events φ̇ = 0) against the control
    parameter, as dots (paper Figs. 12–14).

    Dots are coloured by the steady-state kind of the point (periodic stick-slip black,
    non-periodic orange, periodic slip blue). Equilibria have no peaks and are drawn as grey
    crosses at the resting φ (the time mean in the window); failed runs as red ticks on the
    lower edge.

    Parameters
    ----------
    result : SweepResult or xarray.Dataset
        A sweep with one numeric dimension (plus ``model``/``ic`` when ``select`` picks one).
    ax : matplotlib.axes.Axes, optional
    select : dict, optional
        Values of categorical dimensions, e.g. ``{"model": "x"}``.
    legend : bool
    marker_size : float
        Dot size [points²].

    Returns
    -------
    matplotlib.axes.Axes
    """
    ds = _dataset(result)
    for dim, value in (select or {}).items():
        ds = ds.sel({dim: value})
    extra = [d for d in _grid_dims(ds) if not _is_numeric(ds, d) and ds.sizes[d] > 1]
    if extra:
        raise ValueError(f"select one value of {', '.join(extra)} (e.g. select={{'{extra[0]}': ...}})")
    ds = ds.squeeze(drop=True) if any(ds.sizes[d] == 1 for d in _grid_dims(ds) if not _is_numeric(ds, d)) else ds
    x = _control_dim(ds)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    xs = ds[x].values.astype(float)
    peaks = ds["peaks"].transpose(x, "peak").values
    kind = np.where(np.isfinite(ds["kind"].values), ds["kind"].values, -1).astype(int)
    present = []
    for code in (2, 3, 1):
        rows = kind == code
        xx = np.repeat(xs[rows], peaks.shape[1])
        yy = peaks[rows].ravel()
        ok = np.isfinite(yy)
        if np.any(ok):
            ax.scatter(xx[ok], yy[ok], s=marker_size, color=KIND_STYLE[code][0], linewidths=0, rasterized=True,
                       label=KIND_STYLE[code][1])
            present.append(code)
    eq = kind == 0
    if np.any(eq):
        ax.plot(xs[eq], ds["phi_mean"].values[eq], "x", color=KIND_STYLE[0][0], ms=4, label="equilibrium (φ at rest)")
    failed = kind == -1
    if np.any(failed):
        ax.plot(xs[failed], np.zeros(failed.sum()), "|", color=KIND_STYLE[-1][0], ms=10,
                transform=ax.get_xaxis_transform(), label="run failed")
    ax.set_xlabel(axis_label(ds, x))
    ax.set_ylabel("peak values of φ [rad]")
    if xs.size > 1:
        ax.set_xlim(xs.min() - 0.02 * np.ptp(xs), xs.max() + 0.02 * np.ptp(xs))
    ax.grid(alpha=0.3)
    if legend and (present or np.any(eq) or np.any(failed)):
        ax.legend(fontsize=8, markerscale=4, loc="best")
    return ax


def save_bifurcation_figure(result, path, *, dpi: int = 130) -> Path:
    """Save the bifurcation diagram; one panel per ``model`` (and ``ic``) value when swept."""
    ds = _dataset(result)
    panel_dims = [d for d in _grid_dims(ds) if not _is_numeric(ds, d) and ds.sizes[d] > 1]
    combos = list(itertools.product(*[ds[d].values for d in panel_dims])) or [()]
    fig, axes = _new_figure(len(combos), width=6.4, height=4.4)
    x = _control_dim(ds)
    for ax, combo in zip(axes, combos):
        sel = dict(zip(panel_dims, combo))
        plot_bifurcation(ds, ax, select=sel)
        if sel:
            ax.set_title(", ".join(f"{k} {_fmt(v)}" for k, v in sel.items()), fontsize=9)
    fig.suptitle(f"Bifurcation diagram of φ against {_SYMBOLS.get(x, x)}\n{_conditions(ds, skip=(x,))}", fontsize=10)
    path = Path(path)
    fig.savefig(path, dpi=dpi)
    return path
