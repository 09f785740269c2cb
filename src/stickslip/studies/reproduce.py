"""Reproduce the paper's figures and Table 2 (Sects. 4.1–4.2) and write a Markdown report.

Every figure is a *recipe*: it computes with the library (``stability_map``, the time-step
study, ``simulate``, ``sweep``), saves PNGs, and returns rows "paper says / we measure /
agrees?". The "we measure" values come from the runs of this call, never from stored numbers;
the "paper says" column quotes the paper. Each row's verdict follows an explicit criterion,
printed in the report beside it:

* ``yes`` / ``no``: the criterion (stated in the row) holds / fails on our numbers;
* ``not compared``: the paper gives no number or testable statement for that quantity.

:func:`reproduce` runs the recipes in order and rewrites ``report.md`` (and ``results.json``)
after each one, so an interrupted run keeps what it has done. A recipe that raises is reported
as failed (with the error) and the next one runs.

Figs. 10–15 judge what each run settles to (:mod:`stickslip.attractors`): every run is
extended from its final state until it has settled or reaches ``settle_cap``; "periodic" is a
settled, confirmed period, "non-periodic" a settled chaotic or quasi-periodic attractor, and a
run still drifting at the cap is "unsettled" and counted as neither.

Resolutions (:data:`RESOLUTIONS`): ``full`` is the paper's (stability maps 100 × 100, 100 s
time-step study down to Δt = 1e-5 s, 121-point bifurcation diagrams over N and 100-point ones
over Ω, Δμ, α, 100 × 100 region maps of 300 s runs from two ICs for four models), ``quick`` uses
coarse grids (7 × 8 region maps, 11–41-point bifurcation diagrams; a few minutes on 2 cores,
timings in docs/reproduce.md), ``micro`` is for tests.

This module holds the command's driver and the list of recipes; the rest is split by what it
does:

===========================  ================================================================
``reproduce_resolutions``    :class:`Resolution` and the presets :data:`RESOLUTIONS`
``reproduce_report``         :class:`Row`, :class:`RecipeResult`, :class:`Recipe`, the report
``reproduce_stability``      Figs. 3, 4: stability maps
``reproduce_runs``           Table 2 (Figs. 5–6), Figs. 7, 10, 11, 15: single runs
``reproduce_sweeps``         Figs. 8, 9, 16: region maps; Figs. 12–14: bifurcation diagrams
===========================  ================================================================
"""

from __future__ import annotations

import dataclasses
import json
import time
import traceback
from pathlib import Path
from typing import Callable

from ..attractors import jsonable
from ..files import atomic_write_text
from .reproduce_report import NOT_YET, Recipe, RecipeResult, Row, render_report  # noqa: F401  (public here)
from .reproduce_resolutions import RESOLUTIONS, Resolution
from .reproduce_runs import _recipe_fig7, _recipe_fig10, _recipe_fig11, _recipe_fig15, _recipe_table2
from .reproduce_stability import _recipe_fig3, _recipe_fig4
from .reproduce_sweeps import (FIG12B_OMEGA_RANGE, FIG13_ALPHA_RANGE, FIG13_DELTA_MU_RANGE, _recipe_fig8, _recipe_fig9,
                               _recipe_fig12a, _recipe_fig12b, _recipe_fig13, _recipe_fig14, _recipe_fig16)
from .reproduce_sweeps import REGIONS_N_RANGE, REGIONS_OMEGA_RANGE, _regimes, _spearman  # noqa: F401  (importable here)

__all__ = ["Resolution", "RESOLUTIONS", "Recipe", "RecipeResult", "Row", "RECIPES", "NOT_YET",
           "recipe_names", "reproduce", "render_report"]


RECIPES = [
    Recipe("fig3", "Fig. 3 — stability of steady sliding over (N, Ω), families of Δμ and α",
           "“It is observed that the equilibrium point of the system is unstable at sufficiently low Ω and large N. "
           "… the increase of Δμ and α expands and narrows the range of operating parameters (N, Ω) for instability, "
           "respectively.” (Sect. 4.1)", _recipe_fig3),
    Recipe("fig4", "Fig. 4 — present model (Model 1) against the reduced rotation-only model (Model 4)",
           "“the unstable ranges of (N, Ω) … of the present model are significantly larger than those of the reduced "
           "model.” (Sect. 4.1)", _recipe_fig4),
    Recipe("table2", "Table 2, Figs. 5–6 — AEOM and NAEOM at fixed time steps",
           "“When Δt = 0.1s or 0.01s, there are no sticking phases in the results from either numerical method … "
           "The computation time taken by the NAEOM method is much longer than that by the AEOM method.” (Sect. 4.2.1)",
           _recipe_table2),
    Recipe("fig7", "Fig. 7 — bistability at N = 50 N, Ω = 5, 8.5, 12 rad/s",
           "“when Ω = 5rad/s, the dynamic responses from two different initial conditions will approach the same "
           "stick-slip oscillation; when Ω = 12rad/s … approach the equilibrium point; when Ω = 8.5rad/s, one set of "
           "initial condition leads to a stick-slip oscillation, the other leads to the equilibrium point” (Sect. 4.2.2)",
           _recipe_fig7),
    Recipe("fig8", "Fig. 8 — regions I, II, III over (N, Ω) from two initial conditions (Model 1)",
           "“the parameter plane of (N, Ω) can be divided into three different regions I, II, III that contain the values "
           "of the operating parameters leading to a single stable stick-slip oscillation, coexistence of a stable "
           "stick-slip oscillation and a stable equilibrium point, and a single stable equilibrium point … Fig. 8 "
           "indicates that a low Ω or a high N promotes stick-slip oscillation.” (Sect. 4.2.2) Our initial conditions "
           "(`far`, `near`) are documented in docs/sweeps.md; the paper does not print its own.", _recipe_fig8),
    Recipe("fig9", "Fig. 9 — stick-slip domains (regions I ∪ II) of Models 1–4",
           "“the ‘stick-slip’ domain for the reduced model with only rotational motion is significantly smaller than "
           "those for other three models, which demonstrates that the addition of the translational motion increases "
           "the possibility of occurrence of stick-slip oscillation in the system.” (Sect. 4.2.3)", _recipe_fig9),
    Recipe("fig10", "Fig. 10 — time histories, phase plots and spectra of φ at Ω = 0.5 rad/s",
           "“A periodic oscillation … at the frequency of 1.46Hz … at N = 30N. When N = 50N, 70N, 90N, 110N, the "
           "responses of ϕ are also periodic but not harmonic, with the fundamental frequency of 0.99Hz, 0.78Hz, "
           "0.58Hz, 0.43Hz … When N = 120N, however, ϕ is non-periodic” (Sect. 4.2.3)", _recipe_fig10),
    Recipe("fig11", "Fig. 11 — angle of v_r against the circumferential direction, N = 30 N and 120 N",
           "“The angle … varies periodically within [5°, 15°] at N = 30N and non-periodically within [0°, 20°] at "
           "N = 120N … always along the fixed circumferential direction when the centres of the two rigid plates are "
           "rigidly constrained” (Sect. 4.2.3)", _recipe_fig11),
    Recipe("fig12a", "Fig. 12(a) — bifurcation diagram of φ over N at Ω = 0.5 rad/s",
           "“the bifurcations of ϕ with the variations of operating parameters are monotonous, namely, the response "
           "of ϕ changes from periodic stick-slip oscillation with growing period to non-periodic stick-slip "
           "oscillation with the increase of N and decrease of Ω.” (Sect. 4.2.3)", _recipe_fig12a),
    Recipe("fig12b", "Fig. 12(b) — bifurcation diagram of φ over Ω at N = 50 N (IC `far`)",
           "“the response of ϕ changes from periodic stick-slip oscillation with growing period to non-periodic "
           "stick-slip oscillation with the increase of N and decrease of Ω.” (Sect. 4.2.3) Ω range "
           f"{FIG12B_OMEGA_RANGE[0]:g}–{FIG12B_OMEGA_RANGE[1]:g} rad/s is ours (not printed in the text).", _recipe_fig12b),
    Recipe("fig13", "Fig. 13 — bifurcation diagrams of φ over Δμ (α = 5) and α (Δμ = 0.1), N = 50 N, Ω = 0.5 rad/s",
           "“By increasing Δμ, the response of ϕ changes from periodic oscillation to non-periodic oscillation and "
           "eventually back to periodic oscillation. By increasing α, the response of ϕ changes from periodic "
           "oscillation to non-periodic oscillation, and then back to periodic oscillation and non-periodic oscillation "
           "in turn, and eventually back to periodic oscillation.” (Sect. 4.2.3) Ranges Δμ "
           f"{FIG13_DELTA_MU_RANGE[0]:g}–{FIG13_DELTA_MU_RANGE[1]:g}, α {FIG13_ALPHA_RANGE[0]:g}–{FIG13_ALPHA_RANGE[1]:g} "
           "s/m are ours.", _recipe_fig13),
    Recipe("fig14", "Fig. 14 — bifurcation diagrams of φ over N (Ω = 0.5 rad/s) and Ω (N = 50 N) for Models 2, 3, 4",
           "“for the two models with the rotational motion and the translational motion in the fixed direction … "
           "periodic stick-slip oscillations with different periods (or frequencies) appear as N or Ω varies. For the "
           "reduced model with only rotational motion …, however, no bifurcation appears, i.e, ϕ has periodic stick-slip "
           "oscillation with unchanged period (or frequency) with the variation of N or Ω.” (Sect. 4.2.3)", _recipe_fig14),
    Recipe("fig15", "Fig. 15 — a response of φ of the rotation-only model (Model 4)",
           "“In Fig. 15, a representation of the response in the reduced model in which the two rigid plates undergo "
           "only rotational motion is shown.” (Sect. 4.2.3; N and Ω not printed)", _recipe_fig15),
    Recipe("fig16", "Fig. 16 — intensity of oscillation, Eq. (16), over (N, Ω): rφ of Models 4 and 1, translation of "
           "the upper plate (IC `far`)",
           "“Fig. 16(a) and (b) … indicate that the addition of the two-dimensional translational motion for both rigid "
           "plates has no significant effect on the intensity of oscillation of rφ. Besides, the intensity of "
           "oscillation of the translational motion of the upper rigid plate … has the same-order magnitude as that of "
           "rφ” (Sect. 4.2.3). The axes of Fig. 16 are not stated in the text; we use the (N, Ω) grid of Figs. 8–9.",
           _recipe_fig16),
]


def recipe_names() -> list[str]:
    return [r.name for r in RECIPES]


def reproduce(out_dir, resolution: str | Resolution = "quick", *, only: list[str] | None = None,
              progress: Callable[[str], None] | None = None) -> Path:
    """Run the recipes and write ``out_dir/report.md`` (+ PNGs, ``results.json``).

    Parameters
    ----------
    out_dir : path
        Created if missing.
    resolution : "full", "quick", "micro" or a :class:`Resolution`
    only : list of recipe names, optional
        Subset of :func:`recipe_names` (unknown names raise ``ValueError`` before anything runs).
    progress : callable, optional
        Called with a one-line message when a recipe starts and ends.

    Returns
    -------
    Path of the report. A recipe that raises is reported as failed; the others still run.
    """
    import matplotlib


    matplotlib.use("Agg")
    if isinstance(resolution, str) and resolution not in RESOLUTIONS:
        raise ValueError(f"unknown resolution {resolution!r}; choose one of {', '.join(RESOLUTIONS)}")
    res = RESOLUTIONS[resolution] if isinstance(resolution, str) else resolution
    selected = RECIPES
    if only:
        unknown = [n for n in only if n not in recipe_names()]
        if unknown:
            raise ValueError(f"unknown figure {', '.join(map(repr, unknown))}; choose from {', '.join(recipe_names())}")
        selected = [r for r in RECIPES if r.name in only]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    report = out / "report.md"
    entries: list = []
    cache: dict = {}
    t_start = time.perf_counter()

    def write(pending):
        atomic_write_text(report, render_report(entries, res, pending, time.perf_counter() - t_start))
        atomic_write_text(out / "results.json", json.dumps(jsonable({"resolution": dataclasses.asdict(res),
                                                                     "recipes": entries}), indent=1))

    for i, recipe in enumerate(selected):
        write([r.title for r in selected[i:]])
        if progress:
            progress(f"{recipe.name}: running")
        t0 = time.perf_counter()
        entry = {"name": recipe.name, "title": recipe.title, "statement": recipe.statement}
        try:
            result = recipe.run(out, res, cache)
            entry.update(status="done", figures=result.figures, rows=[dataclasses.asdict(r) for r in result.rows],
                         measured=result.measured)
        except Exception as exc:  # noqa: BLE001  (reported in the report, the next recipe runs)
            entry.update(status="failed", error=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc(),
                         figures=[], rows=[])
        entry["seconds"] = time.perf_counter() - t0
        entries.append(entry)
        if progress:
            progress(f"{recipe.name}: {entry['status']} in {entry['seconds']:.1f} s")
    write([])
    return report
