"""Figure of the intensity of oscillation, paper Eq. (16), over (N, Ω) (Fig. 16).

Takes a finished region map or sweep (dims include ``model``, ``N``, ``Omega`` and optionally
``ic``) with the variables ``intensity_r_phi`` and ``intensity_translation`` written by
:func:`stickslip.sweep.sweep`; never simulates.
"""

from __future__ import annotations

from pathlib import Path

from ._common import save_figure
from .sweep import _new_figure, plot_reduction

__all__ = ["FIG16_PANELS", "save_intensity_figure"]

#: Panels of Fig. 16: (title, model, variable).
FIG16_PANELS = (
    ("(a) I of rφ, Model 4 (rotation only)", "rotation", "intensity_r_phi"),
    ("(b) I of rφ, Model 1 (full)", "full", "intensity_r_phi"),
    ("(c) I of the translation (x1, y1), Model 1", "full", "intensity_translation"),
)


def save_intensity_figure(result, path, *, ic: str | None = "far", dpi: int = 110) -> Path:
    """Save heat maps of the intensity index I of Eq. (16) over (N, Ω), as in Fig. 16.

    Parameters
    ----------
    result : RegionMap, SweepResult or xarray.Dataset
        Needs models ``rotation`` and/or ``full`` and the grid dims ``N`` [N], ``Omega`` [rad/s].
    path : path
        PNG output.
    ic : str, optional
        Initial condition to show when ``ic`` is a dimension (default ``far``).
    dpi : int

    Returns
    -------
    Path
        ``path``. Panels whose model is missing are left out. I is in m s^-1/2 (Eq. 16 as
        printed: √(∫_T (X − X_e)² dt) / T over the steady window of length T).
    """
    ds = getattr(result, "dataset", result)
    if ic is not None and "ic" in ds.dims:
        ds = ds.sel(ic=ic)
    models = {str(m) for m in ds["model"].values}
    panels = [p for p in FIG16_PANELS if p[1] in models]
    if not panels:
        raise ValueError(f"no model of Fig. 16 (rotation, full) in this dataset; models: {', '.join(sorted(models))}")
    fig, axes = _new_figure(len(panels), width=5.4, height=4.2)
    for ax, (title, model, var) in zip(axes, panels):
        plot_reduction(ds, var, ax, select={"model": model})
        ax.set_title(title, fontsize=9)
    fig.suptitle("Intensity of oscillation, Eq. (16), in the steady window"
                 + (f" (initial condition {ic})" if ic is not None else ""), fontsize=10)
    path = Path(path)
    save_figure(fig, path, dpi=dpi)
    return path
