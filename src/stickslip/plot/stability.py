"""Figures of stability maps (paper Figs. 3, 4). Takes a computed map; never computes one.

One member of a family is drawn as a cell map over the true cells of the (N, Ω) grid: stable,
unstable and "no steady sliding" in three opaque colours, each a legend entry, with the boundary
Ω_c(N) from root finding on top. Several members are compared by their boundaries in one panel
and shown cell by cell in one panel each: translucent regions stacked over each other would mix
into colours that no legend entry names.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._common import agg_figure, cell_edges, grid_axis, param_text, save_figure

__all__ = ["plot_stability_map", "save_stability_map_figure", "STABLE_COLOUR", "MISSING_COLOUR"]

#: Colour of grid cells where steady sliding is stable (max Re λ < 0).
STABLE_COLOUR = "#ffffff"
#: Colour of grid cells where no steady-sliding equilibrium was found.
MISSING_COLOUR = "#9e9e9e"
#: Weight of a member's colour in the (opaque) colour of its unstable cells; the rest is white.
UNSTABLE_TINT = 0.35

_STYLES = ((-1, "-", "Ω_c: stable above the line"), (1, "--", "Ω_c: unstable above the line"))


def _colours():
    import matplotlib

    return matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]


def _tint(colour, weight: float = UNSTABLE_TINT):
    """Opaque RGBA of ``colour`` mixed with white (``weight`` of the colour)."""
    from matplotlib.colors import to_rgb

    rgb = weight * np.asarray(to_rgb(colour)) + (1.0 - weight) * np.ones(3)
    return (*rgb, 1.0)


def _boundary_lines(ax, smap, f: int, colour) -> set[int]:
    """Draw Ω_c(N) of member ``f`` (solid: stable above, dashed: unstable above) and mark jumps
    of max Re λ across zero; returns the directions drawn."""
    N = smap.N
    b, d = smap.boundary[f], smap.boundary_direction[f]
    drawn = set()
    for c in range(b.shape[1]):
        for direction, style, _ in _STYLES:
            y = np.where(d[:, c] == direction, b[:, c], np.nan)
            ok = np.isfinite(y)
            if np.any(ok):
                ax.plot(N, y, style, color=colour, lw=1.8)
                lone = ok & ~np.r_[False, ok[:-1]] & ~np.r_[ok[1:], False]  # no neighbour: no line shows
                if np.any(lone):
                    ax.plot(N[lone], y[lone], style, marker="o", ms=3, color=colour, lw=1.8)
                drawn.add(direction)
    jump = smap.boundary_jump[f] & np.isfinite(b)
    if np.any(jump):
        rows, cols = np.nonzero(jump)
        ax.plot(N[rows], b[rows, cols], "x", color="k", ms=6, mew=1.5)
        drawn.add(0)
    return drawn


def _style_handles(drawn: set[int], colour="0.3"):
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color=colour, ls=style, lw=1.8, label=label)
               for direction, style, label in _STYLES if direction in drawn]
    if 0 in drawn:
        handles.append(Line2D([], [], color="k", ls="", marker="x", ms=6, mew=1.5,
                              label="max Re λ jumps across 0 (branch switch)"))
    return handles


def _member_index(smap, member) -> int:
    if member is None:
        return 0
    if isinstance(member, (int, np.integer)) and not isinstance(member, bool):
        return int(member)
    values = [str(v) for v in smap.family_values]
    if str(member) in values:
        return values.index(str(member))
    raise ValueError(f"member {member!r} is not in this map; choose one of {', '.join(values)} or an index")


def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=(6.4, 4.8), layout="constrained")[1]


def _grid_axes(ax, smap):
    (ne, ns), (we, ws) = cell_edges(smap.N), cell_edges(smap.Omega)
    grid_axis(ax, "x", ne, ns)
    grid_axis(ax, "y", we, ws)
    ax.set_xlabel("normal load N [N]")
    ax.set_ylabel("Ω [rad/s]")
    return ne, we


def _draw_member(ax, smap, f: int, shade: bool):
    """Cell map and boundary of one member; returns its legend handles."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    colour = _colours()[f % len(_colours())]
    ne, we = _grid_axes(ax, smap)
    mrp = smap.max_real_part[f]
    handles = []
    if shade:
        # 0 stable, 1 unstable, 2 no steady sliding; max Re λ = 0 exactly counts as stable
        cls = np.where(np.isfinite(mrp), (mrp > 0).astype(float), 2.0)
        names = (("stable (max Re λ < 0)", STABLE_COLOUR), ("unstable (max Re λ > 0)", _tint(colour)),
                 ("no steady sliding found", MISSING_COLOUR))
        cmap = ListedColormap([c for _, c in names])
        ax.pcolormesh(ne, we, cls.T, cmap=cmap, vmin=-0.5, vmax=2.5)
        handles += [Patch(facecolor=c, edgecolor="0.5", lw=0.5, label=name)
                    for k, (name, c) in enumerate(names) if np.any(cls == k)]
    drawn = _boundary_lines(ax, smap, f, colour)
    return handles + _style_handles(drawn, colour)


def _draw_boundaries(ax, smap):
    """Boundaries of every member in one panel (no shading); returns the legend handles."""
    from matplotlib.lines import Line2D

    _grid_axes(ax, smap)
    colours = _colours()
    handles, drawn = [], set()
    for f, label in enumerate(smap.family_labels):
        colour = colours[f % len(colours)]
        drawn |= _boundary_lines(ax, smap, f, colour)
        handles.append(Line2D([], [], color=colour, lw=1.8, label=label))
    return handles + _style_handles(drawn)


def _fixed_text(smap) -> str:
    """``"model full, μk = 0.2, Δμ = 0.1, α = 5 s/m"``: what all members share."""
    p = smap.params
    fixed = {name: param_text(name, getattr(p, name)) for name in ("mu_k", "delta_mu", "alpha")}
    fixed.pop(smap.family_name, None)
    model = "" if smap.family_name == "model" else f"model {smap.model}, "
    return model + ", ".join(fixed.values())


def plot_stability_map(smap, ax=None, *, member=None, title: str | None = None, shade: bool = True):
    """Draw a :class:`~stickslip.stability.StabilityMap` (x: normal load N [N]; y: Ω [rad/s]).

    A single map, or one ``member`` of a family: every grid cell, spanning its true edges
    (:func:`~stickslip.plot._common.cell_edges`), is white where steady sliding is stable, tinted
    with the member's colour where it is unstable (max Re λ > 0) and grey where no steady-sliding
    equilibrium was found; the boundary Ω_c(N) from root finding is drawn on top (solid where the
    equilibrium is stable above Ω_c, dashed where it is unstable above). The cells show the grid
    evaluation and the line the root-found boundary, so they agree to within half a cell.

    A family with ``member=None``: the boundaries of all members in one panel, without shading
    (:func:`save_stability_map_figure` adds one cell map per member).

    Parameters
    ----------
    smap : StabilityMap
    ax : matplotlib.axes.Axes, optional
    member : int or family value, optional
        Member of a family to draw as a cell map (index, or value such as ``0.2`` or ``"rotation"``).
    title : str, optional
    shade : bool
        Draw the cells (else only the boundary).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax)
    several = len(smap.family_labels) > 1
    if several and member is None:
        handles = _draw_boundaries(ax, smap)
        default = "Ω_c(N) of every member"
    else:
        f = _member_index(smap, member)
        handles = _draw_member(ax, smap, f, shade)
        default = smap.family_labels[f] if several else ""
    if title is None:
        title = default if several else "Stability of steady sliding: " + _fixed_text(smap)
    ax.set_title(title, fontsize=10)
    ax.legend(handles=handles, fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, frameon=False)
    return ax


def save_stability_map_figure(smap, path: str | Path, *, dpi: int = 110, **kwargs) -> Path:
    """Save the map (Agg backend, no display): one panel for a single map; for a family, the
    boundaries of all members side by side with one cell map per member.

    ``kwargs`` go to :func:`plot_stability_map` (``shade``; ``title`` for a single map).
    """
    n = len(smap.family_labels)
    if n == 1:
        fig = agg_figure((6.4, 5.4))
        plot_stability_map(smap, fig.add_subplot(), **kwargs)
    else:
        kwargs.pop("title", None)
        cols = 2 if n == 3 else min(n + 1, 3)
        rows = -(-(n + 1) // cols)
        fig = agg_figure((5.4 * cols, 5.0 * rows))
        plot_stability_map(smap, fig.add_subplot(rows, cols, 1), **kwargs)
        for f in range(n):
            plot_stability_map(smap, fig.add_subplot(rows, cols, f + 2), member=f, **kwargs)
        fig.suptitle("Stability of steady sliding: " + _fixed_text(smap), fontsize=11)
    path = Path(path)
    save_figure(fig, path, dpi=dpi)
    return path
