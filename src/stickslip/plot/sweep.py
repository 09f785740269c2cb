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

from ..analysis.outcome import OUTCOMES, STOPPED, outcome_code
from ..model.parameters import PARAMETER_UNITS
from ._common import (MODEL_LABELS, SYMBOLS, agg_figure, cell_edges, grid_axis, is_geometric, param_text, save_figure,
                      symbol, unit_text)

__all__ = ["plot_reduction", "save_sweep_figure", "plot_bifurcation", "save_bifurcation_figure", "CLASS_STYLE",
           "PERIODIC_SLIP", "point_classes", "axis_label"]


def _observed(ds) -> tuple[str, str, str]:
    """(name, symbol, unit) of the coordinate a sweep's peaks follow (the plates' φ [rad])."""
    name = ds.attrs.get("observed", "phi")
    unit = ds["peaks"].attrs.get("units", "") if "peaks" in ds.variables else ""
    return name, symbol(name), unit


#: The class of a periodic point without stick; the other classes are the outcome codes
#: (:data:`~stickslip.analysis.outcome.OUTCOMES`), a periodic one with stick among them.
PERIODIC_SLIP = len(OUTCOMES)

_COLOURS = {"equilibrium": "#7f7f7f", "periodic": "#000000", "quasiperiodic": "#2ca02c", "chaotic": "#ff7f0e",
            "unsettled": "#bcbd22", "unbounded": "#8c564b", "contact-lost": "#17becf", "failed": "#d62728"}



def _class_style() -> dict[int, tuple[str, str]]:
    style = {}
    for name, colour in _COLOURS.items():
        if name == "periodic":
            style[outcome_code(name)] = (colour, "periodic stick-slip")
            style[PERIODIC_SLIP] = ("#1f77b4", "periodic slip")
        else:
            style[outcome_code(name)] = (colour, name.replace("-", " "))
    return style


#: Colour and label of each class a sweep's points are drawn in (:func:`point_classes`): the outcome
#: of the point's run, a periodic one told apart by whether it sticks.
CLASS_STYLE = _class_style()

#: Classes without an oscillation: their cells carry their own colour in maps of :data:`OSCILLATION_VARS`.
NOT_OSCILLATING = ("failed", "equilibrium", "unbounded", "contact lost")

#: Reductions that describe an oscillation and mean nothing at rest (at an equilibrium the
#: sweep stores the decay frequency and the peak-to-peak range of the dying transient).
OSCILLATION_VARS = ("frequency", "fft_frequency", "fundamental_frequency", "dominant_frequency", "period",
                    "multiplicity", "period_count", "amplitude", "n_peaks")

#: Colour and label of a cell without a value whose run did not say why (not computed, or NaN).
NO_VALUE = ("#e0e0e0", "no value")

#: Most panels drawn by :func:`save_sweep_figure`; further combinations of the panel dimensions
#: are left out (named in the title) so a figure stays readable.
MAX_PANELS = 12

_CATEGORICAL = ("model", "ic")

#: Names of reductions on axes and colour bars (others go by their variable name).
_VAR_NAMES = {"stick_fraction": "stick fraction", "fft_frequency": "FFT frequency", "intensity_r_phi": "I(rφ)",
              "intensity_x1": "I(x1)", "intensity_y1": "I(y1)", "intensity_translation": "I(x1, y1)"}


def _dataset(result):
    return getattr(result, "dataset", result)


def axis_label(ds, name: str) -> str:
    """``"Ω [rad/s]"``-style label of a coordinate or variable from its attributes (``[-]`` when
    dimensionless)."""
    try:
        attrs = ds[name].attrs  # a variable or coordinate of a Dataset, a coordinate of a DataArray
    except KeyError:
        attrs = {}
    units = attrs.get("units", PARAMETER_UNITS.get(name, ""))
    unit = unit_text(units)
    symbol = SYMBOLS.get(name, _VAR_NAMES.get(name, name))
    return f"{symbol} {unit}" if unit else symbol


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


def point_classes(ds):
    """The class of each point of a sweep (``xarray.DataArray`` over its grid; NaN where not computed):
    the outcome code of its ``attractor``, or :data:`PERIODIC_SLIP` for a periodic point whose
    ``stick_fraction`` is 0."""
    code = ds["attractor"]
    if "stick_fraction" not in ds.variables:  # the stick character unknown: periodic stays one class
        return code
    slip = (code == outcome_code("periodic")) & ~(ds["stick_fraction"] > 0)
    return code.where(~slip, PERIODIC_SLIP)


#: Class of a cell drawn on the colour scale, and of a cell without a value and without a class
#: that explains it (:data:`NO_VALUE`); other classes are those of :data:`CLASS_STYLE`.
_ON_SCALE, _NO_VALUE = -1000, -999


def _classes(values, kind, styles, var) -> np.ndarray:
    """Class of each cell (int array): :data:`_ON_SCALE`, or the point's class where it has no
    oscillation and either ``var`` describes one or the value is missing, or :data:`_NO_VALUE`
    where the value is missing otherwise. For ``var == "attractor"`` the values are the classes."""
    values = np.asarray(values, dtype=float)
    if var == "attractor":
        return np.where(np.isfinite(values), values, _NO_VALUE).astype(int)
    kind = np.full(values.shape, np.nan) if kind is None else np.asarray(kind, dtype=float)
    out = np.full(values.shape, _ON_SCALE, dtype=int)
    for code, (_, label) in styles.items():
        if label in NOT_OSCILLATING:
            out[(kind == code) & ((var in OSCILLATION_VARS) | ~np.isfinite(values))] = code
    out[(out == _ON_SCALE) & ~np.isfinite(values)] = _NO_VALUE
    return out


def _class_style(key: int, styles, var: str) -> tuple[str, str]:
    """(colour, legend label) of a cell class; a class without oscillation says what it lacks."""
    if key == _NO_VALUE:
        return NO_VALUE
    colour, label = styles.get(int(key), ("#000080", f"class {int(key)}"))
    if var in OSCILLATION_VARS and label in NOT_OSCILLATING:
        label += f" (no {var})"
    return colour, label


def _heat_map(ax, da, kind, x, y, var, styles, label, colorbar):
    """Cells over the true cell edges of (x, y); off-scale classes in their own colours, named
    in a legend below the axes (where it hides no cell)."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    z = da.transpose(y, x).values.astype(float)
    cls = _classes(z, None if kind is None else kind.transpose(y, x).values, styles, var)
    (xe, xs), (ye, ys) = cell_edges(da[x].values), cell_edges(da[y].values)
    on_scale = cls == _ON_SCALE
    if np.any(on_scale):
        mesh = ax.pcolormesh(xe, ye, np.ma.masked_where(~on_scale, z), cmap="viridis")
        if colorbar:
            ax.figure.colorbar(mesh, ax=ax, label=label)
    keys = np.unique(cls[~on_scale])  # sorted: no value first, then the classes
    if keys.size:
        styled = [_class_style(k, styles, var) for k in keys]
        index = np.searchsorted(keys, cls)
        cmap = ListedColormap([colour for colour, _ in styled])
        ax.pcolormesh(xe, ye, np.ma.masked_where(on_scale, index), cmap=cmap, vmin=-0.5, vmax=keys.size - 0.5)
        ax.legend(handles=[Patch(color=c, label=t) for c, t in styled], fontsize=7, loc="upper center",
                  bbox_to_anchor=(0.5, -0.14), ncol=min(3, keys.size), frameon=False)
    grid_axis(ax, "x", xe, xs, da[x].values)
    grid_axis(ax, "y", ye, ys, da[y].values)
    ax.set_xlabel(axis_label(da, x))
    ax.set_ylabel(axis_label(da, y))


def _line_plot(ax, da, kind, x, categorical, var, styles, label):
    """Values against one parameter; off-scale points as ticks on the lower edge, in their colours."""
    groups = [(None, da, kind)] if not categorical else [
        (c, da.sel({categorical: c}), None if kind is None else kind.sel({categorical: c}))
        for c in da[categorical].values]
    xs = da[x].values.astype(float)
    marked = {}
    for cat, line, kline in groups:
        ys = line.transpose(x).values.astype(float)
        cls = (np.full(ys.shape, _ON_SCALE) if var == "attractor" else
               _classes(ys, None if kline is None else kline.transpose(x).values, styles, var))
        ax.plot(xs, np.where(cls == _ON_SCALE, ys, np.nan), "o-", ms=3, lw=1.2,
                label=None if cat is None else f"{categorical} = {cat}")
        for key in np.unique(cls[cls != _ON_SCALE]):
            marked.setdefault(int(key), []).extend(xs[cls == key])
    for key in sorted(marked):
        colour, text = _class_style(key, styles, var)
        ax.plot(marked[key], np.zeros(len(marked[key])), "|", color=colour, ms=12, mew=2,
                transform=ax.get_xaxis_transform(), label=text)
    if var == "attractor":
        ax.set_yticks(sorted(styles), [styles[c][1] for c in sorted(styles)])
    if categorical or marked:
        ax.legend(fontsize=8)
    ax.set_xlabel(axis_label(da, x))
    ax.set_ylabel(label)
    ax.grid(alpha=0.3)


def plot_reduction(result, var: str = "frequency", ax=None, *, select: dict | None = None, colorbar: bool = True):
    """Draw one reduced quantity of a sweep over its grid.

    After ``select`` (``{dim: value}``, nearest value for numbers) and dropping dimensions of
    length 1, the variable must have at most two dimensions:

    * one numeric dimension: a line with markers against it;
    * two numeric dimensions: a heat map whose cells span their true edges (midpoints between
      grid values; geometric grids on a log axis, see :func:`~stickslip.plot._common.cell_edges`),
      with a colour bar in the variable's units; ``attractor`` drawn with one colour per class
      (:func:`point_classes`: the outcome, a periodic one split by whether it sticks);
    * one numeric and one categorical (``model``, ``ic``) dimension: one line per category.

    Points without an oscillation (equilibrium, a run that stopped) are never drawn on the scale
    of a quantity of an oscillation (:data:`OSCILLATION_VARS`): they get their class's colour and
    a legend entry, as do cells without a value.

    Parameters
    ----------
    result : SweepResult or xarray.Dataset
    var : str
        A variable of the sweep (``frequency`` [Hz], ``amplitude`` [rad], ``stick_fraction`` [-],
        ``attractor``, ``intensity_r_phi`` [m s^-1/2], ...).
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
    classes = point_classes(ds) if "attractor" in ds.data_vars else None
    da = classes if var == "attractor" else ds[var]
    kind = classes if var != "attractor" else None
    for dim, value in (select or {}).items():
        method = None if not _is_numeric(ds, dim) else "nearest"
        da = da.sel({dim: value}, method=method)
        kind = None if kind is None else kind.sel({dim: value}, method=method)
    da = da.squeeze(drop=False)
    kind = None if kind is None else kind.squeeze(drop=False)
    dims = [d for d in da.dims if da.sizes[d] > 1]
    numeric = [d for d in dims if _is_numeric(ds, d)]
    categorical = [d for d in dims if d not in numeric]
    for d in numeric:  # a grid given out of order is drawn in order
        da = da.sortby(d)
        kind = None if kind is None else kind.sortby(d)
    styles = dict(CLASS_STYLE)
    label = axis_label(ds, var)
    if len(dims) > 2 or len(categorical) > 1 or (len(dims) == 2 and not numeric):
        raise ValueError(f"{var} has dimensions {tuple(dims)} after selection; select values of all but two "
                         "(at most one of them model or ic)")
    if len(numeric) == 2:
        _heat_map(ax, da, kind, numeric[0], numeric[1], var, styles, label, colorbar)  # first swept dim across
    elif len(numeric) == 1:
        _line_plot(ax, da, kind, numeric[0], categorical[0] if categorical else None, var, styles, label)
    else:  # only categories (or a single point)
        cats = [str(c) for c in da[dims[0]].values] if dims else ["point"]
        ax.bar(cats, np.atleast_1d(da.values.astype(float)), color="0.4")
        ax.set_ylabel(label)
        if dims:
            ax.set_xlabel(dims[0])
    return ax


def _new_figure(n_panels: int, width: float = 5.2, height: float = 4.0):
    cols = min(n_panels, 3)
    rows = -(-n_panels // cols)
    fig = agg_figure((width * cols, height * rows))
    axes = [fig.add_subplot(rows, cols, i + 1) for i in range(n_panels)]
    return fig, axes


def _panel_title(sel: dict) -> str:
    """``"Model 2 (x translation), Δμ = 0.2"``: the values that make a panel, with units."""
    parts = []
    for k, v in sel.items():
        if k == "model":
            parts.append(MODEL_LABELS.get(str(v), f"model {v}"))
        elif k in _CATEGORICAL:
            parts.append(f"{k} {v}")
        else:
            parts.append(param_text(k, v))
    return ", ".join(parts)


def _conditions(ds, skip=()) -> str:
    """Short line of the fixed operating/friction parameters (with units) and run options: from
    the base parameters, or the one value of a grid dimension of length 1."""
    params = json.loads(ds.attrs.get("parameters", "{}"))
    single = {d: ds[d].values[0] for d in _grid_dims(ds) if ds.sizes[d] == 1 and d not in skip}
    model = single.pop("model", None if "model" in ds.dims else ds.attrs.get("model", "?"))
    ic = single.pop("ic", None if "ic" in ds.dims else ds.attrs.get("ic"))
    parts = [f"{text} {value}" for dim, text, value in (("model", "model", model), ("ic", "initial condition", ic))
             if value is not None and dim not in skip]
    for k in ("N", "Omega", "mu_k", "delta_mu", "alpha"):
        if k in single:
            parts.append(param_text(k, single.pop(k)))
        elif k in params and k not in skip and k not in ds.dims:
            parts.append(param_text(k, params[k]))
    parts += [param_text(k, v) for k, v in single.items()]
    parts.append(f"steady window {ds.attrs.get('t_from', float('nan')):g}–{ds.attrs.get('t_end', float('nan')):g} s")
    return ", ".join(parts)


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
            ax.set_title(_panel_title(sel), fontsize=9)
    title = f"{var}: {ds[var].attrs.get('long_name', var)}\n{_conditions(ds)}"
    if len(combos) > len(shown):
        title += f" (first {len(shown)} of {len(combos)} panels)"
    fig.suptitle(title, fontsize=10)
    path = Path(path)
    save_figure(fig, path, dpi=dpi)
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

    Dots are coloured by the point's class (:func:`point_classes`, :data:`CLASS_STYLE`: periodic
    stick-slip black, periodic slip blue, chaotic orange, ...). Equilibria have no peaks and are
    drawn as grey crosses at the resting φ (the time mean in the window); runs that stopped as
    ticks on the lower edge. A geometric control grid is drawn on a log axis.

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
    from matplotlib.lines import Line2D

    ds = _dataset(result)
    for dim, value in (select or {}).items():
        ds = ds.sel({dim: value})
    extra = [d for d in _grid_dims(ds) if not _is_numeric(ds, d) and ds.sizes[d] > 1]
    if extra:
        raise ValueError(f"select one value of {', '.join(extra)} (e.g. select={{'{extra[0]}': ...}})")
    ds = ds.squeeze(drop=True) if any(ds.sizes[d] == 1 for d in _grid_dims(ds) if not _is_numeric(ds, d)) else ds
    x = _control_dim(ds)
    ds = ds.sortby(x)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    styles = dict(CLASS_STYLE)
    xs = ds[x].values.astype(float)
    peaks = ds["peaks"].transpose(x, "peak").values
    classes = point_classes(ds).transpose(x).values
    pending = ~np.isfinite(classes)  # not computed (yet)
    kind = np.where(pending, -99, classes).astype(int)
    handles = []
    for code, (colour, label) in styles.items():
        rows = kind == code
        if label in NOT_OSCILLATING or not np.any(rows):
            continue
        xx = np.repeat(xs[rows], peaks.shape[1])
        yy = peaks[rows].ravel()
        ok = np.isfinite(yy)
        if np.any(ok):
            ax.scatter(xx[ok], yy[ok], s=marker_size, color=colour, linewidths=0, rasterized=True)
            handles.append(Line2D([], [], ls="", marker="o", ms=5, color=colour, label=label))
    coordinate, symbol, unit = _observed(ds)
    eq = kind == outcome_code("equilibrium")
    if np.any(eq):
        colour = styles[outcome_code("equilibrium")][0]
        ax.plot(xs[eq], ds[f"{coordinate}_mean"].values[eq], "x", color=colour, ms=5)
        handles.append(Line2D([], [], ls="", marker="x", ms=5, color=colour, label=f"equilibrium ({symbol} at rest)"))
    stopped = [(kind == outcome_code(name), styles[outcome_code(name)][0], f"run {styles[outcome_code(name)][1]}")
               for name in STOPPED]
    for where, colour, label in stopped + [(pending, "#b0b0b0", "not computed")]:
        if np.any(where):  # ticks on the lower edge: these points have no value to show
            ax.plot(xs[where], np.zeros(where.sum()), "|", color=colour, ms=10, transform=ax.get_xaxis_transform())
            handles.append(Line2D([], [], ls="", marker="|", ms=5, mew=1.5, color=colour, label=label))
    ax.set_xlabel(axis_label(ds, x))
    ax.set_ylabel(f"peak values of {symbol}" + (f" [{unit}]" if unit else ""))
    if is_geometric(xs):
        ax.set_xscale("log")
    elif xs.size > 1:
        ax.set_xlim(xs.min() - 0.02 * np.ptp(xs), xs.max() + 0.02 * np.ptp(xs))
    ax.grid(alpha=0.3)
    if legend and handles:
        ax.legend(handles=handles, fontsize=8, loc="best")
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
            ax.set_title(_panel_title(sel), fontsize=9)
    fig.suptitle(f"Bifurcation diagram: peak values of φ against {axis_label(ds, x)}\n{_conditions(ds, skip=(x,))}",
                 fontsize=10)
    path = Path(path)
    save_figure(fig, path, dpi=dpi)
    return path
