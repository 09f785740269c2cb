"""Figures of continuation branches and of the Region II edge (matplotlib only; no simulation).

Every function takes a finished :class:`~stickslip.orbits.continuation.Branch` (or the dataset
read back by :func:`~stickslip.orbits.continuation.load_branch`) or a
:class:`~stickslip.orbits.continuation.FoldCurve` (or its dataset), and never simulates.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ._common import param_label, param_text, save_figure, symbol
from .regions import REGION_STYLE, plot_regions

__all__ = ["plot_branch", "save_branch_figure", "plot_region_edge", "SPECIAL_MARKERS"]

#: Marker and colour of each kind of special point.
SPECIAL_MARKERS = {
    "fold": ("o", "#d62728"),
    "period-doubling": ("s", "#9467bd"),
    "neimark-sacker": ("D", "#2ca02c"),
    "stick-phases": ("^", "#ff7f0e"),
    "stick-vanishing": ("v", "#ff7f0e"),
    "grazing": ("P", "#17becf"),
    "hopf": ("*", "#8c564b"),
}


_YLABELS = {"period": "period T [s]", "amplitude": "peak-to-peak {coordinate}{unit}",
            "stick_time": "time in stick per period [s]"}


def _branch_data(branch) -> dict:
    """Arrays of a Branch or of its dataset, in one form."""
    if hasattr(branch, "to_xarray") and hasattr(branch, "values"):
        system = branch.system
        observed = system.dofs[system.observed_index]
        sp = branch.special
        return {"param": branch.param, "value": branch.values, "period": branch.periods,
                "amplitude": branch.amplitude, "stick_time": branch.stick_time, "stable": branch.stable.astype(bool),
                "special": [(p.kind, p.index, p.value) for p in sp], "model": branch.model,
                "fixed": [(k, system.parameters[k]) for k in system.headline], "coordinate": observed,
                "unit": system.units.get(observed, ""), "stop_reason": branch.stop_reason}
    ds = branch
    headline = json.loads(ds.attrs["headline"]) if "headline" in ds.attrs else ["N", "Omega"]
    return {"param": ds.attrs["param"], "value": ds["value"].values, "period": ds["period"].values,
            "amplitude": ds["amplitude"].values, "stick_time": ds["stick_time"].values,
            "stable": ds["stable"].values.astype(bool),
            "special": [(str(k), int(i), float(v)) for k, i, v in zip(ds["special_kind"].values, ds["special_index"].values,
                                                                       ds["special_value"].values)],
            "model": ds.attrs["model"], "fixed": [(k, ds.attrs.get(f"param_{k}")) for k in headline],
            "coordinate": ds["amplitude"].attrs.get("coordinate", ds.attrs.get("observed", "phi")),
            "unit": ds["amplitude"].attrs.get("units", ""), "stop_reason": ds.attrs.get("stop_reason")}


def _stability_segments(x, y, stable):
    """Runs of consecutive points with the same stability: [(x, y, stable), ...]; each run shares
    its first point with the previous one so the curve is continuous."""
    runs, start = [], 0
    for i in range(1, len(x) + 1):
        if i == len(x) or stable[i] != stable[start]:
            lo = max(start - 1, 0)
            runs.append((x[lo:i], y[lo:i], bool(stable[start])))
            start = i
    return runs


def plot_branch(branch, ax=None, *, y: str = "period", legend: bool = True, color: str = "k", label: str | None = None):
    """One branch: period (or amplitude) against the parameter; stable solid, unstable dashed.

    Special points are marked (fold ○, period doubling □, Neimark–Sacker ◇, change of the number
    of stick phases △, stick phase vanishing ▽, Hopf ☆) at the interpolated branch value.

    Parameters
    ----------
    branch : Branch or xarray.Dataset
    ax : matplotlib Axes, optional
    y : {"period", "amplitude", "stick_time"}
        Period [s], peak-to-peak of the model's observed coordinate (the plates' φ [rad]) or
        time in stick per period [s].
    legend : bool
    color : str
        Colour of the branch.
    label : str, optional
        Name of the branch in the legend (then stable/unstable entries carry it).

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.lines import Line2D

    if y not in _YLABELS:
        raise ValueError(f"y = {y!r}: choose one of {', '.join(_YLABELS)}")
    d = _branch_data(branch)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.0), layout="constrained")
    x, yv, stable = d["value"], d[y], d["stable"]
    for xs, ys, st in _stability_segments(x, yv, stable):
        ax.plot(xs, ys, "-" if st else "--", color=color, lw=1.4)
    prefix = "" if label is None else f"{label}: "
    handles = [Line2D([], [], color=color, ls=ls, label=prefix + name)
               for ls, name, on in (("-", "stable", stable.any()), ("--", "unstable", (~stable).any())) if on]
    seen = set()
    for kind, i, value in d["special"]:
        marker, colour = SPECIAL_MARKERS.get(kind, ("x", "k"))
        j = min(i + 1, len(x) - 1)
        yy = np.interp(value, sorted([x[i], x[j]]), [yv[i], yv[j]] if x[i] <= x[j] else [yv[j], yv[i]])
        ax.plot([value], [yy], marker, color=colour, ms=8, mfc="none", mew=1.8)
        if kind not in seen:
            handles.append(Line2D([], [], marker=marker, color=colour, ls="", mfc="none", mew=1.8, label=kind))
            seen.add(kind)
    ax.set_xlabel(param_label(d["param"]))
    unit = d["unit"].strip("-")
    ax.set_ylabel(_YLABELS[y].format(coordinate=symbol(d["coordinate"]), unit=f" [{unit}]" if unit else ""))
    ax.grid(alpha=0.3)
    if legend:
        ax.legend(handles=handles, fontsize=7, loc="best")
    return ax


def save_branch_figure(branch, path, *, dpi: int = 110) -> Path:
    """Period, amplitude and stick time against the parameter, side by side, to ``path`` (PNG)."""
    import matplotlib.pyplot as plt

    d = _branch_data(branch)
    fig, axes = plt.subplots(1, 3, figsize=(14.0, 4.2), layout="constrained")
    plot_branch(branch, axes[0], y="period")
    plot_branch(branch, axes[1], y="amplitude", legend=False)
    plot_branch(branch, axes[2], y="stick_time", legend=False)
    fixed = ", ".join(param_text(k, v) for k, v in d["fixed"] if k != d["param"] and v is not None)
    about = "; ".join(part for part in (f"model {d['model']}", fixed,
                                        f"stopped: {d['stop_reason']}" if d.get("stop_reason") else "") if part)
    fig.suptitle(f"Branch of periodic orbits in {symbol(d['param'])} ({about})", fontsize=10)
    path = Path(path)
    save_figure(fig, path, dpi=dpi)
    plt.close(fig)
    return path


def plot_region_edge(curve, rmap=None, ax=None, *, model: str = "full", omega_c=None):
    """The end of the stick-slip branch Ω_edge(N) over the brute-force region map (paper Fig. 8).

    Parameters
    ----------
    curve : FoldCurve or xarray.Dataset
        From :func:`~stickslip.orbits.continuation.fold_curve`.
    rmap : RegionMap or xarray.Dataset, optional
        Brute-force map from :func:`~stickslip.sweep.regions`, drawn underneath.
    ax : matplotlib Axes, optional
    model : str
        Model of ``rmap`` to draw.
    omega_c : (N, Omega_c) arrays, optional
        Linear-stability boundary (lower edge of Region II) to draw as well.

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.lines import Line2D

    ds = curve.to_xarray() if hasattr(curve, "to_xarray") else curve
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 5.0), layout="constrained")
    handles = []
    if rmap is not None:
        plot_regions(rmap, ax, model=model, legend=False)
        from matplotlib.patches import Patch

        handles += [Patch(color=REGION_STYLE[c][0], label=f"brute force: {REGION_STYLE[c][1]}") for c in (1, 2, 3)]
        handles.append(Line2D([], [], color="k", marker=".", label="brute force: largest grid Ω with stick-slip"))
    N, edge = ds["N"].values, ds["edge"].values
    kind = ds["kind"].values.astype(str)
    ok = np.isfinite(edge)
    ax.plot(N[ok], edge[ok], "-", color="#7b2cbf", lw=2.2)
    for k, marker in (("stick-vanishing", "v"), ("fold", "o")):
        sel = ok & (kind == k)
        if sel.any():
            ax.plot(N[sel], edge[sel], marker, color="#7b2cbf", ms=6)
            handles.append(Line2D([], [], color="#7b2cbf", marker=marker, lw=2.2,
                                  label=f"continuation: end of stick-slip orbit ({k})"))
    if omega_c is not None:
        ax.plot(omega_c[0], omega_c[1], "-.", color="0.2", lw=1.4)
        handles.append(Line2D([], [], color="0.2", ls="-.", label="Ω_c(N): equilibrium loses stability"))
    top = np.nanmax(edge) if ok.any() else 1.0
    lo, hi = ax.get_ylim() if rmap is not None else (0.0, top)
    ax.set_ylim(min(lo, 0.0), max(hi, 1.08 * top))
    ax.set_xlabel("normal load N [N]")
    ax.set_ylabel("Ω [rad/s]")
    ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=1, frameon=False)
    return ax
