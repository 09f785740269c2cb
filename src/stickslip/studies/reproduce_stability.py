"""Recipes of the paper's Figs. 3 and 4 (Sect. 4.1): linear stability of steady sliding over (N, Ω).

Both figures are stability maps (:func:`stickslip.stability.stability_map`) over the same
(N, Ω) grid; the recipes judge the paper's statements from the first stabilising crossing
Ω_c(N) of each family member, which the helpers here extract from a map.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..plot.stability import save_stability_map_figure
from ..stability import stability_map
from .reproduce_report import RecipeResult, Row, _fmt, _yes
from .reproduce_resolutions import Resolution


def _stab_grids(res):
    return np.linspace(2.0, 200.0, res.stab_N), np.linspace(0.2, 20.0, res.stab_Omega)


def _first_boundary(smap, i_family: int, N_value: float) -> float:
    """Ω_c at the grid N nearest to ``N_value``: the first crossing above which it is stable."""
    j = int(np.argmin(np.abs(smap.N - N_value)))
    b = smap.boundary[i_family, j]
    d = smap.boundary_direction[i_family, j]
    sel = np.isfinite(b) & (d == -1)
    return float(b[sel][0]) if sel.any() else math.nan


def _boundary_curve(smap, i_family: int) -> np.ndarray:
    return np.array([_first_boundary(smap, i_family, n) for n in smap.N])


def _monotone_family(smap, increasing: bool) -> tuple[bool, int]:
    """Whether Ω_c(N) moves with the family value in the stated direction at every N where all
    members have a boundary; returns (holds, number of N compared)."""
    curves = np.array([_boundary_curve(smap, i) for i in range(len(smap.family_values))])
    ok = np.all(np.isfinite(curves), axis=0)
    if not ok.any():
        return False, 0
    diff = np.diff(curves[:, ok], axis=0)
    return bool(np.all(diff > 0) if increasing else np.all(diff < 0)), int(ok.sum())


def _recipe_fig3(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    N, Om = _stab_grids(res)
    ma = stability_map(N=N, Omega=Om, family=("delta_mu", [0.1, 0.2, 0.3]))
    mb = stability_map(N=N, Omega=Om, family=("alpha", [2.0, 5.0, 10.0]))
    save_stability_map_figure(ma, out / "fig3a.png")
    save_stability_map_figure(mb, out / "fig3b.png")
    cache["fig3a"] = ma
    # low Ω / large N unstable: Ω_c(N) exists and rises with N (Δμ = 0.1 member)
    curve = _boundary_curve(ma, 0)
    fin = np.isfinite(curve)
    rising = fin.sum() >= 2 and bool(np.all(np.diff(curve[fin]) > 0))
    low_unstable = bool(np.all(ma.max_real_part[0, :, 0][np.isfinite(ma.max_real_part[0, :, 0])] > 0))
    inc_dmu, n_dmu = _monotone_family(ma, increasing=True)
    dec_alpha, n_alpha = _monotone_family(mb, increasing=False)
    oc_dmu = [_first_boundary(ma, i, 50.0) for i in range(3)]
    oc_alpha = [_first_boundary(mb, i, 50.0) for i in range(3)]
    n50 = float(ma.N[np.argmin(np.abs(ma.N - 50.0))])
    rows = [
        Row("Fig. 3", "“the equilibrium point of the system is unstable at sufficiently low Ω and large N”",
            f"lowest Ω ({Om[0]:g} rad/s) unstable at every N with sliding: {_yes(low_unstable)}; Ω_c(N) rises with N "
            f"(Δμ 0.1): {_yes(rising)}; Ω_c = {_fmt(np.nanmin(curve))}–{_fmt(np.nanmax(curve))} rad/s",
            _yes(low_unstable and rising),
            "max Re λ > 0 at the lowest grid Ω for every N, and the first crossing Ω_c(N) strictly increasing in N"),
        Row("Fig. 3(a)", "“the increase of Δμ … expands … the range of operating parameters (N, Ω) for instability”",
            f"Ω_c at N = {n50:.3g} N for Δμ = 0.1, 0.2, 0.3: {', '.join(_fmt(v, 4) for v in oc_dmu)} rad/s "
            f"(increasing at all {n_dmu} N compared: {_yes(inc_dmu)})",
            _yes(inc_dmu), "Ω_c(N) strictly increasing in Δμ at every grid N where all three have a boundary"),
        Row("Fig. 3(b)", "“the increase of … α … narrows the range of operating parameters (N, Ω) for instability”",
            f"Ω_c at N = {n50:.3g} N for α = 2, 5, 10: {', '.join(_fmt(v, 4) for v in oc_alpha)} rad/s "
            f"(decreasing at all {n_alpha} N compared: {_yes(dec_alpha)})",
            _yes(dec_alpha), "Ω_c(N) strictly decreasing in α at every grid N where all three have a boundary"),
    ]
    return RecipeResult(["fig3a.png", "fig3b.png"], rows,
                        {"omega_c_N50_delta_mu": oc_dmu, "omega_c_N50_alpha": oc_alpha,
                         "omega_c_range_dmu01": [float(np.nanmin(curve)), float(np.nanmax(curve))]})


def _recipe_fig4(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    N, Om = _stab_grids(res)
    m = stability_map(N=N, Omega=Om, family=("model", ["full", "rotation"]))
    save_stability_map_figure(m, out / "fig4.png")
    c_full, c_rot = _boundary_curve(m, 0), _boundary_curve(m, 1)
    ok = np.isfinite(c_full) & np.isfinite(c_rot)
    ratio = c_full[ok] / c_rot[ok]
    unstable_full = np.nansum(m.max_real_part[0] > 0)
    unstable_rot = np.nansum(m.max_real_part[1] > 0)
    holds = bool(ok.any() and np.all(ratio > 1.0))
    rows = [Row("Fig. 4", "“the unstable ranges of (N, Ω) … of the present model are significantly larger than "
                "those of the reduced model”",
                f"Ω_c(Model 1) / Ω_c(Model 4) = {_fmt(ratio.min() if ratio.size else math.nan)}–"
                f"{_fmt(ratio.max() if ratio.size else math.nan)} over {int(ok.sum())} N; unstable grid cells "
                f"{int(unstable_full)} vs {int(unstable_rot)}",
                _yes(holds), "Ω_c of Model 1 above that of Model 4 at every grid N where both exist")]
    return RecipeResult(["fig4.png"], rows, {"omega_c_ratio_min": float(ratio.min()) if ratio.size else None,
                                             "omega_c_ratio_max": float(ratio.max()) if ratio.size else None,
                                             "unstable_cells": [int(unstable_full), int(unstable_rot)]})
