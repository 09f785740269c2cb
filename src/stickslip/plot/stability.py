"""Figures of stability maps (paper Figs. 3, 4). Takes a computed map; never computes one."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["plot_stability_map", "save_stability_map_figure"]


def plot_stability_map(smap, ax=None, *, title: str | None = None, shade: bool = True):
    """Draw the stable/unstable regions of a :class:`~stickslip.stability.StabilityMap`.

    x: normal load N [N]; y: Ω [rad/s]. Per family member: the unstable region (max Re λ > 0)
    lightly shaded, and the boundary Ω_c(N) from root finding as a line (solid where the
    equilibrium is stable above Ω_c, dashed where it is unstable above). Grid points without a
    steady-sliding equilibrium are grey.

    Returns
    -------
    matplotlib.axes.Axes
    """
    import matplotlib
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.8), layout="constrained")
    colors = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    N, W = smap.N, smap.Omega
    handles = []
    missing = np.zeros((N.size, W.size), dtype=bool)
    for f, label in enumerate(smap.family_labels):
        color = colors[f % len(colors)]
        mrp = smap.max_real_part[f]
        missing |= ~np.isfinite(mrp)
        if shade and N.size > 1 and W.size > 1:
            unstable = np.where(np.isfinite(mrp), (mrp > 0).astype(float), np.nan)
            ax.contourf(N, W, unstable.T, levels=[0.5, 1.5], colors=[color], alpha=0.15)
        b = smap.boundary[f]
        d = smap.boundary_direction[f]
        for c in range(b.shape[1]):
            for direction, style in ((-1, "-"), (1, "--")):
                y = np.where(d[:, c] == direction, b[:, c], np.nan)
                if np.any(np.isfinite(y)):
                    ax.plot(N, y, style, color=color, lw=1.8)
        handles.append(Line2D([], [], color=color, lw=1.8, label=label))
    if np.any(missing) and N.size > 1 and W.size > 1:
        ax.contourf(N, W, missing.T.astype(float), levels=[0.5, 1.5], colors=["0.6"], alpha=0.6)
        handles.append(Patch(color="0.6", alpha=0.6, label="no steady sliding found"))
    handles.append(Patch(color="0.5", alpha=0.25, label="shaded: unstable (max Re λ > 0)"))
    ax.set_xlabel("normal load N [N]")
    ax.set_ylabel("Ω [rad/s]")
    ax.set_xlim(N[0], N[-1])
    ax.set_ylim(W[0], W[-1])
    p = smap.params
    if title is None:
        fixed = {"mu_k": f"μk = {p.mu_k:g}", "delta_mu": f"Δμ = {p.delta_mu:g}", "alpha": f"α = {p.alpha:g}"}
        fixed.pop(smap.family_name, None)
        model = "" if smap.family_name == "model" else f"model {smap.model}, "
        title = "Stability of steady sliding: " + model + ", ".join(fixed.values())
    ax.set_title(title, fontsize=10)
    ax.legend(handles=handles, fontsize=8, loc="best")
    return ax


def save_stability_map_figure(smap, path: str | Path, *, dpi: int = 110, **kwargs) -> Path:
    """Draw :func:`plot_stability_map` into a new figure and save it (Agg backend, no display)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 4.8), layout="constrained")  # Agg canvas: no display, no pyplot state
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    plot_stability_map(smap, ax, **kwargs)
    path = Path(path)
    fig.savefig(path, dpi=dpi)
    return path
