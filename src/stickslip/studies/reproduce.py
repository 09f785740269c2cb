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

Figs. 10–15 judge what each run settles to (:mod:`stickslip.analysis.settle`): every run is
extended from its final state until it has settled or reaches ``settle_cap``; "periodic" is a
settled, confirmed period, "non-periodic" a settled chaotic or quasi-periodic attractor, and a
run still drifting at the cap is "unsettled" and counted as neither.

Resolutions (:data:`RESOLUTIONS`): ``full`` is the paper's (stability maps 100 × 100, 100 s
time-step study down to Δt = 1e-5 s, 121-point bifurcation diagrams over N and 100-point ones
over Ω, Δμ, α, 100 × 100 region maps of 300 s runs from two ICs for four models), ``quick`` uses
coarse grids (7 × 8 region maps, 11–41-point bifurcation diagrams; measured 189 s for all
figures on the shared 2-core machine, 406 s under heavier load and before the event integrator's
change of the slip force law; docs/reproduce.md), ``micro`` is for tests.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
import traceback
from pathlib import Path
from typing import Callable

import numpy as np

from ..files import atomic_write_text
from ..plot._common import save_figure

__all__ = ["Resolution", "RESOLUTIONS", "Recipe", "RecipeResult", "Row", "RECIPES", "NOT_YET",
           "recipe_names", "reproduce", "render_report"]


@dataclasses.dataclass(frozen=True)
class Resolution:
    """How fine and how long the recipes compute."""

    name: str
    stab_N: int                  # points along N of the stability maps (2–200 N)
    stab_Omega: int              # points along Ω (0.2–20 rad/s)
    timestep_dts: tuple          # Δt of the Table 2 study [s]
    timestep_t_end: float        # simulated time of the study [s] (paper: 100)
    timestep_event_rtols: tuple
    fig7_t_end: float            # run length of the Fig. 7 runs [s]
    fig10_t_end: float           # run length of the Fig. 10/11 runs [s] (window: last half)
    fig10_N: tuple               # normal loads of Fig. 10 [N]
    fig12_N: int                 # points of the Fig. 12(a) sweep over 10–130 N
    fig12_t_end: float
    workers: int | None = None   # worker processes (None: every CPU this process may use)
    executor: str = "processes"
    # Figs. 8, 9, 16: region maps over N in [10, 130] N × Ω in [1, 15] rad/s, two ICs, all four models
    regions_N: int = 100
    regions_Omega: int = 100
    regions_t_end: float = 300.0          # the near IC leaves a weakly unstable equilibrium slowly
    regions_t_from: float = 200.0         # (docs/sweeps.md); steady window = last 100 s
    # Figs. 12(b), 13, 14: bifurcation diagrams (points per control range, run length [s])
    bif_points: int = 100               # Figs. 12(b), 13
    fig14_N: int = 121                  # Fig. 14: points over N and over Ω (Model 3 is slow: ≤ 60 s a run)
    bif_t_end: float = 200.0
    fig15_t_end: float = 200.0
    # Figs. 10–15: every run is extended from its final state until it has settled, up to this
    # many seconds (stickslip.analysis.settle; the run lengths above are the first runs)
    settle_cap: float = 2000.0


RESOLUTIONS = {
    "full": Resolution("full", 100, 100, (0.1, 0.01, 1e-3, 1e-4, 1e-5), 100.0, (1e-4, 1e-6, 1e-8),
                       300.0, 200.0, (30, 50, 70, 90, 110, 120), 121, 200.0),
    "quick": Resolution("quick", 100, 100, (0.1, 0.01, 1e-3, 1e-4), 100.0, (1e-4, 1e-6, 1e-8),
                        300.0, 200.0, (30, 50, 70, 90, 110, 120), 41, 200.0,
                        regions_N=7, regions_Omega=8, bif_points=15, fig14_N=11),
    "micro": Resolution("micro", 8, 10, (0.1, 0.01), 4.0, (1e-4,), 4.0, 4.0, (30, 120), 3, 3.0,
                        workers=1, executor="serial", regions_N=2, regions_Omega=2, regions_t_end=4.0,
                        regions_t_from=2.0, bif_points=3, fig14_N=3, bif_t_end=3.0, fig15_t_end=4.0,
                        settle_cap=6.0),
}


@dataclasses.dataclass
class Row:
    """One line of the comparison table."""

    item: str          # e.g. "Fig. 3(a)"
    paper: str         # what the paper says (quoted or paraphrased with its numbers)
    measured: str      # what we measure in this run
    agrees: str        # "yes", "no" or "not compared"
    criterion: str     # the rule that gave the verdict


@dataclasses.dataclass
class RecipeResult:
    figures: list
    rows: list
    measured: dict
    notes: str = ""


@dataclasses.dataclass(frozen=True)
class Recipe:
    name: str                      # key for --only, e.g. "fig3"
    title: str
    statement: str                 # the paper's statement about the figure (quoted)
    run: Callable                  # (out_dir, Resolution, cache) -> RecipeResult


def _yes(ok: bool) -> str:
    return "yes" if ok else "no"


def _fmt(x, digits=3) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.{digits}g}"


# ----------------------------------------------------------------------------- Figs. 3, 4
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
    from ..plot.stability import save_stability_map_figure
    from ..stability import stability_map

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
    from ..plot.stability import save_stability_map_figure
    from ..stability import stability_map

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


# ----------------------------------------------------------------------------- Table 2, Figs. 5–6
def _recipe_table2(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    from ..plot.timestep import save_timestep_figures
    from .timestep import PAPER_TABLE2, run_timestep_study

    study = run_timestep_study(res.timestep_dts, t_end=res.timestep_t_end, event_rtols=res.timestep_event_rtols)
    study.save(out / "timestep")
    figs = save_timestep_figures(study, out)
    rows = []
    measured = {"runs": []}
    aeom = {r.dt: r for r in study.fixed("aeom")}
    naeom = {r.dt: r for r in study.fixed("naeom")}
    for dt in sorted(aeom, reverse=True):
        a, n = aeom[dt], naeom.get(dt)
        pa, pn = PAPER_TABLE2.get(dt, (None, None))
        measured["runs"].append({"dt": dt, "aeom_s": a.wall_time_s, "naeom_s": n.wall_time_s if n else None,
                                 "aeom_stick": a.stick_phases, "naeom_stick": n.stick_phases if n else None})
        paper_stick = "no sticking phases" if dt >= 0.01 else "sticking phases found"
        ratio = n.wall_time_s / a.wall_time_s if n else math.nan
        no_stick = a.stick_phases == 0 and (n is None or n.stick_phases == 0)
        stick_ok = no_stick if dt >= 0.01 else (a.stick_phases > 0 and (n is None or n.stick_phases > 0))
        rows.append(Row(f"Table 2, Δt = {dt:g} s",
                        f"AEOM {_fmt(pa)} s, NAEOM {_fmt(pn)} s (ratio {_fmt(pn / pa if pa else math.nan)}); {paper_stick}",
                        f"AEOM {a.wall_time_s:.3g} s, NAEOM {_fmt(n.wall_time_s if n else math.nan)} s (ratio {_fmt(ratio)}); "
                        f"stick phases {a.stick_phases} / {n.stick_phases if n else '–'}; "
                        f"φ amplitude error {a.errors['phi_pp_error']:.2g} / {_fmt(n.errors['phi_pp_error'] if n else math.nan, 2)}"
                        + (f" (over {study.t_end:g} s, not the paper's 100 s)" if study.t_end != 100.0 else ""),
                        _yes(stick_ok),
                        "sticking phases present (both methods) exactly where the paper reports them; "
                        "times are machine-dependent and not judged"))
    if 1e-3 in aeom and 1e-3 in naeom:
        ratio = naeom[1e-3].wall_time_s / aeom[1e-3].wall_time_s
        rows.append(Row("Table 2, efficiency", "“the AEOM method is much more efficient than the NAEOM method” "
                        "(NAEOM/AEOM = 277 at Δt = 1e-3 s)", f"NAEOM/AEOM = {ratio:.3g} at Δt = 1e-3 s",
                        _yes(ratio > 10.0), "NAEOM at least 10× slower than AEOM at Δt = 1e-3 s"))
    for method, fig in (("aeom", "Fig. 5"), ("naeom", "Fig. 6")):
        runs = study.fixed(method)
        if runs:
            best = runs[-1]
            rows.append(Row(fig, "steady φ and |F_f| by " + method.upper() + ": only Δt = 1e-4, 1e-5 s accurate "
                            "(1e-1, 1e-2, 1e-3 s “quite different”)",
                            f"finest Δt = {best.dt:g} s: φ shape error {best.errors['phi_shape_error']:.2g}, "
                            f"|F| shape error {best.errors['F_shape_error']:.2g} against event rtol 1e-10",
                            "not compared", "the paper prints no error numbers; the curves are in the figure"))
    return RecipeResult([Path(p).name for p in figs.values()], rows, measured)


# ----------------------------------------------------------------------------- Fig. 7
def _simulate_named(params, t_end, ic_name, model="full"):
    from ..integrate.driver import simulate
    from ..sweep.spec import initial_condition

    ic, pert = initial_condition(ic_name, params, model)
    return simulate(params, t_end, model=model, ic=ic, perturbation=pert, sample_rate=200.0)


def _recipe_fig7(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    import matplotlib.pyplot as plt

    from ..analysis.classify import classify
    from ..model.parameters import Parameters

    t_from = res.fig7_t_end * 2.0 / 3.0
    omegas = (5.0, 8.5, 12.0)
    paper = {5.0: (True, True), 8.5: (True, False), 12.0: (False, False)}
    fig, axes = plt.subplots(3, 2, figsize=(11, 8), sharex=True, constrained_layout=True)
    rows, measured = [], {}
    for i, om in enumerate(omegas):
        p = Parameters(N=50.0, Omega=om)
        ss = []
        for j, ic in enumerate(("far", "near")):
            tr = _simulate_named(p, res.fig7_t_end, ic)
            c = classify(tr, t_from=t_from)
            ss.append(c.is_stick_slip)
            measured[f"Omega={om:g},{ic}"] = {"kind": c.kind, "stick_fraction": c.stick_fraction}
            ax = axes[i, j]
            ax.plot(tr.t, tr.states[:, 4], lw=0.6, label="φ")
            ax.plot(tr.t, tr.states[:, 5], lw=0.6, label="ψ")
            ax.set_title(f"Ω = {om:g} rad/s, IC {ic}: {c.kind}, stick {c.stick_fraction:.2f}", fontsize=9)
            ax.set_ylabel("angle [rad]")
            if i == 2:
                ax.set_xlabel("t [s]")
            if i == 0 and j == 0:
                ax.legend(fontsize=8)
        word = lambda s: "stick-slip" if s else "no stick-slip"  # noqa: E731
        pf, pn = paper[om]
        rows.append(Row(f"Fig. 7, Ω = {om:g} rad/s",
                        f"far IC: {word(pf)}, near IC: {word(pn)} (N = 50 N)",
                        f"far: {measured[f'Omega={om:g},far']['kind']}, near: {measured[f'Omega={om:g},near']['kind']} "
                        f"(window {t_from:g}–{res.fig7_t_end:g} s)",
                        _yes(tuple(ss) == (pf, pn)),
                        "stick-slip (stick in the window, not at equilibrium) from each IC as in the paper"))
    save_figure(fig, out / "fig7.png", dpi=110)
    plt.close(fig)
    return RecipeResult(["fig7.png"], rows, measured)


# ----------------------------------------------------------------------------- Figs. 10, 11
PAPER_FIG10 = {30: (1.46, "periodic"), 50: (0.99, "periodic"), 70: (0.78, "periodic"), 90: (0.58, "periodic"),
               110: (0.43, "periodic"), 120: (None, "non-periodic")}
PAPER_FIG11 = {30: (5.0, 15.0), 120: (0.0, 20.0)}


def _settled_run(params, res: Resolution, t_min: float, **options):
    """A run extended until it has settled (or reaches ``res.settle_cap``), window ≤ 100 s."""
    from ..analysis.settle import simulate_until_settled

    window = min(100.0, 0.5 * t_min)
    return simulate_until_settled(params, cap=res.settle_cap, t_min=t_min, window=window, step=window,
                                  sample_rate=200.0, **options)


def _verdict_text(tr) -> str:
    """What a settled run shows, in words, with its frequency."""
    a = tr.attractor
    if a.attractor == "periodic":
        return (f"periodic, {a.period_count} peak(s) per period, fundamental {_fmt(a.fundamental_frequency_hz, 4)} Hz "
                f"(settled by {a.settle_time_s:g} s)")
    if a.settled:
        return f"{a.attractor}, dominant {_fmt(a.dominant_frequency_hz)} Hz (settled by {a.settle_time_s:g} s)"
    return f"unsettled at {tr.t[-1]:g} s, dominant {_fmt(a.dominant_frequency_hz)} Hz"


def _fig10_runs(res: Resolution, cache: dict):
    from ..model.parameters import Parameters

    if "fig10_runs" not in cache:
        cache["fig10_runs"] = {int(n): _settled_run(Parameters(N=float(n), Omega=0.5), res, res.fig10_t_end)
                               for n in res.fig10_N}
    return cache["fig10_runs"]


def _recipe_fig10(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    import matplotlib.pyplot as plt

    from ..analysis.steady import spectrum

    runs = _fig10_runs(res, cache)
    fig, axes = plt.subplots(len(runs), 3, figsize=(12, 2.2 * len(runs)), constrained_layout=True, squeeze=False)
    rows, measured = [], {}
    for k, (n, tr) in enumerate(runs.items()):
        a = tr.attractor
        sel = tr.t >= tr.steady_from
        t, phi, dphi = tr.t[sel], tr.states[sel, 4], tr.states[sel, 10]
        f, amp = spectrum(t, phi)
        axes[k, 0].plot(t, phi, lw=0.6)
        axes[k, 0].set_ylabel(f"N = {n} N\nφ [rad]")
        axes[k, 1].plot(phi, dphi, lw=0.4)
        axes[k, 1].set_ylabel("dφ/dt [rad/s]")
        axes[k, 2].plot(f, amp, lw=0.6)
        axes[k, 2].set_xlim(0, 8)
        axes[k, 2].set_ylabel("|Φ| [rad]")
        axes[k, 0].set_title(_verdict_text(tr), fontsize=8)
        freq = a.fundamental_frequency_hz if a.fundamental_frequency_hz is not None else a.dominant_frequency_hz
        measured[n] = {"attractor": a.attractor, "settled": a.settled, "period_count": a.period_count,
                       "fundamental_frequency_hz": a.fundamental_frequency_hz,
                       "dominant_frequency_hz": a.dominant_frequency_hz, "frequency_hz": freq,
                       "settle_time_s": a.settle_time_s, "t_end_s": float(tr.t[-1]),
                       "stick_fraction": a.classification.stick_fraction if a.classification else None}
        pf, pk = PAPER_FIG10.get(n, (None, None))
        if pf is not None:
            ok = a.attractor == "periodic" and abs(a.fundamental_frequency_hz - pf) / pf <= 0.1
            ratio = f" ({freq / pf:.2f}× paper)" if freq else ""
            rows.append(Row(f"Fig. 10, N = {n} N", f"{pk}, fundamental {pf:g} Hz", _verdict_text(tr) + ratio,
                            _yes(ok), "settled periodic, fundamental frequency within 10 % of the paper's"))
        elif pk is not None:
            rows.append(Row(f"Fig. 10, N = {n} N", pk, _verdict_text(tr),
                            _yes(a.attractor in ("chaotic", "quasiperiodic")),
                            "settled non-periodic (chaotic or quasi-periodic, by the largest Lyapunov exponent)"))
    axes[-1, 0].set_xlabel("t [s]")
    axes[-1, 1].set_xlabel("φ [rad]")
    axes[-1, 2].set_xlabel("f [Hz]")
    save_figure(fig, out / "fig10.png", dpi=100)
    plt.close(fig)
    fr = [(n, m["frequency_hz"]) for n, m in measured.items()]
    falling = len(fr) >= 2 and all(a[1] is not None and b[1] is not None and b[1] < a[1] for a, b in zip(fr, fr[1:]))
    rows.append(Row("Fig. 10, trend", "frequency falls as N rises (1.46 → 0.43 Hz over 30–110 N)",
                    ", ".join(f"{n}: {_fmt(f)} Hz" for n, f in fr), _yes(falling),
                    "frequency (fundamental where settled periodic, else dominant) strictly decreasing in N"))
    return RecipeResult(["fig10.png"], rows, {str(k): v for k, v in measured.items()})


def _recipe_fig11(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    import matplotlib.pyplot as plt

    from ..analysis.intensity import angle_range

    runs = _fig10_runs(res, cache)
    chosen = [n for n in (30, 120) if n in runs]
    fig, axes = plt.subplots(len(chosen), 1, figsize=(9, 2.6 * len(chosen)), constrained_layout=True, squeeze=False)
    rows, measured = [], {}
    for k, n in enumerate(chosen):
        tr = runs[n]
        sel = tr.t >= tr.steady_from
        axes[k, 0].plot(tr.t[sel], tr.sliding_angle_deg[sel], lw=0.6, label="Model 1 (slip samples)")
        axes[k, 0].axhline(0.0, color="r", ls="--", lw=1, label="plate centres fixed")
        axes[k, 0].set_ylabel(f"N = {n} N\nangle of v_r [deg]")
        lo, hi = angle_range(tr)
        measured[n] = [lo, hi]
        plo, phi_ = PAPER_FIG11[n]
        ok = abs(lo - plo) <= 2.5 and abs(hi - phi_) <= 2.5
        rows.append(Row(f"Fig. 11, N = {n} N", f"angle varies within [{plo:g}°, {phi_:g}°]",
                        f"[{_fmt(lo)}°, {_fmt(hi)}°] (slip samples with |v_r| ≥ 1 % of Ω r)", _yes(ok),
                        "both ends within 2.5° of the paper's"))
    axes[0, 0].legend(fontsize=8)
    axes[-1, 0].set_xlabel("t [s]")
    save_figure(fig, out / "fig11.png", dpi=110)
    plt.close(fig)
    return RecipeResult(["fig11.png"], rows, {str(k): v for k, v in measured.items()})


# ----------------------------------------------------------------------------- Fig. 12(a)
def _recipe_fig12a(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    from ..model.parameters import Parameters

    N = np.linspace(10.0, 130.0, res.fig12_N)
    ds = _bifurcation_sweep(out, res, "fig12a", {"N": N}, Parameters(Omega=0.5), t_end=res.fig12_t_end)
    f = ds["dominant_frequency"].values
    labels = _attractor_names(ds)
    ok = np.isfinite(f)
    rho = float(np.corrcoef(np.argsort(np.argsort(N[ok])), np.argsort(np.argsort(f[ok])))[0, 1]) if ok.sum() > 2 else math.nan
    stick = ds["stick_fraction"].values
    rows = [
        Row("Fig. 12(a), period", "“periodic stick-slip oscillation with growing period … with the increase of N”",
            f"dominant frequency {_fmt(f[0])} Hz at {N[0]:g} N → {_fmt(f[-1])} Hz at {N[-1]:g} N; "
            f"Spearman ρ(N, f) = {_fmt(rho)}; stick at all N: {_yes(bool(np.all(stick > 0)))}",
            _yes(rho < -0.9), "Spearman rank correlation of the dominant frequency with N below −0.9"),
        Row("Fig. 12(a), kind", "monotonous: periodic at low N → non-periodic at high N",
            "regimes along N: " + _regimes_text(_regimes(N, labels)) + "; " + _settle_text(ds),
            _yes(labels[-1] in NON_PERIODIC and not any(lab in NON_PERIODIC for lab in labels[: len(N) // 2])),
            "settled non-periodic at the largest N and none in the lower half of the N range"),
    ]
    return RecipeResult(["fig12a.png"], rows, {"N": N.tolist(), "dominant_frequency": f.tolist(),
                                               "attractors": [str(k) for k in labels],
                                               "settle_time": ds["settle_time"].values.tolist()})


# ----------------------------------------------------------------------------- helpers of Figs. 8–16
#: Grids of the region maps (Figs. 8, 9, 16): the paper prints no ranges; these cover its Fig. 7
#: points (N = 50 N; Ω = 5, 8.5, 12 rad/s) and the Fig. 10–12 loads.
REGIONS_N_RANGE = (10.0, 130.0)        # [N]
REGIONS_OMEGA_RANGE = (1.0, 15.0)      # [rad/s]
#: Control ranges of the bifurcation diagrams (not printed in the paper's text; ours).
FIG12B_OMEGA_RANGE = (0.1, 10.0)       # [rad/s], N = 50 N
FIG13_DELTA_MU_RANGE = (0.02, 0.4)     # [-], α = 5 s/m
FIG13_ALPHA_RANGE = (1.0, 20.0)        # [s/m], Δμ = 0.1
#: Model 4 period counted "unchanged" (Fig. 14(e)(f)) when max/min − 1 of the return-map period
#: over the stick-slip points stays within this fraction.
UNCHANGED_PERIOD_RTOL = 0.05
#: Models 2 and 3 show "different periods" (Fig. 14(a)–(d)) when max/min − 1 of the period
#: exceeds this fraction, or more than one period multiplicity occurs.
DIFFERENT_PERIOD_RTOL = 0.10


def _kind_names(ds) -> np.ndarray:
    """Kind names of a sweep dataset (``failed`` for −1 / missing)."""
    from ..analysis.classify import KINDS

    code = ds["kind"].values
    names = np.array(KINDS + ("failed",), dtype=object)
    return names[np.where(np.isfinite(code), code, -1).astype(int)]


def _stick_slip(ds) -> np.ndarray:
    """Boolean: the point is a stick-slip oscillation (not equilibrium, not failed, sticks)."""
    k = np.where(np.isfinite(ds["kind"].values), ds["kind"].values, -1)
    return (k > 0) & (np.nan_to_num(ds["stick_fraction"].values) > 0)


def _spearman(x, y) -> float:
    """Spearman rank correlation of two 1-D arrays (NaN with fewer than 3 pairs)."""
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 3:
        return math.nan
    rx = np.argsort(np.argsort(np.asarray(x)[ok]))
    ry = np.argsort(np.argsort(np.asarray(y)[ok]))
    return float(np.corrcoef(rx, ry)[0, 1])


#: Verdicts that count as the paper's "non-periodic": settled, and not periodic.
NON_PERIODIC = ("chaotic", "quasiperiodic")


def _attractor_names(ds) -> np.ndarray:
    """Verdict names of a sweep dataset (:data:`~stickslip.analysis.settle.ATTRACTORS`; ``failed``
    for −1 / missing)."""
    from ..analysis.settle import ATTRACTORS

    code = ds["attractor"].values
    names = np.array(ATTRACTORS + ("failed",), dtype=object)
    return names[np.where(np.isfinite(code), code, -1).astype(int)]


def _regimes(values, labels) -> list:
    """Runs of periodic (``P``), settled non-periodic (``NP``: chaotic or quasi-periodic) and
    unsettled (``U``) responses along a control parameter.

    Equilibrium, unbounded and failed points are skipped. Returns a list of (label, first value,
    last value).
    """
    runs: list = []
    for v, k in zip(values, labels):
        label = {"periodic": "P", "chaotic": "NP", "quasiperiodic": "NP", "unsettled": "U"}.get(str(k))
        if label is None:
            continue
        if runs and runs[-1][0] == label:
            runs[-1][2] = float(v)
        else:
            runs.append([label, float(v), float(v)])
    return [tuple(r) for r in runs]


def _regimes_text(runs) -> str:
    return " → ".join(f"{lab} [{a:.3g}–{b:.3g}]" for lab, a, b in runs) or "no oscillation"


def _settle_text(ds) -> str:
    """Settle times of a sweep in words: how many settled, by when, and the cap."""
    st = ds["settle_time"].values
    done = np.isfinite(st)
    cap = ds.attrs.get("cap", math.nan)
    text = f"settled {int(done.sum())} of {st.size}"
    if done.any():
        text += f" (by {np.nanmin(st):g}–{np.nanmax(st):g} s)"
    return text + f", cap {cap:g} s"


def _bifurcation_sweep(out: Path, res: Resolution, name: str, grid: dict, params, ic: str = "zero",
                       t_end: float | None = None):
    """Run one bifurcation sweep with the library, every point extended until settled (up to
    ``res.settle_cap``); save ``name``.nc/.png; return the dataset."""
    from ..plot.sweep import save_bifurcation_figure
    from ..sweep import sweep

    t_end = res.bif_t_end if t_end is None else t_end
    r = sweep(grid, params, out=out / f"{name}.nc", t_end=t_end, t_from=max(0.5 * t_end, t_end - 100.0), ic=ic,
              executor=res.executor, workers=res.workers, overwrite=True, settle=True,
              cap=max(res.settle_cap, t_end))
    save_bifurcation_figure(r, out / f"{name}.png")
    return r.to_xarray()


# ----------------------------------------------------------------------------- Figs. 8, 9, 16
def _region_maps(out: Path, res: Resolution, models, cache: dict):
    """Region map dataset (dims model, N, Omega, ic) of ``models``; models already computed by an
    earlier recipe of this run are reused (Figs. 8, 9 and 16 share one grid)."""
    import xarray as xr

    from ..sweep import regions

    have = cache.setdefault("regions", {})
    missing = [m for m in models if m not in have]
    if missing:
        N = np.linspace(*REGIONS_N_RANGE, res.regions_N)
        Om = np.linspace(*REGIONS_OMEGA_RANGE, res.regions_Omega)
        rm = regions(N, Om, models=missing, out=out / f"regions_{'_'.join(missing)}.nc", t_end=res.regions_t_end,
                     t_from=res.regions_t_from, executor=res.executor, workers=res.workers, overwrite=True)
        for m in missing:
            have[m] = rm.dataset.sel(model=[m])
    return xr.concat([have[m] for m in models], dim="model", combine_attrs="override")


def _recipe_fig8(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    from ..plot.regions import save_regions_figure
    from ..sweep.bistability import REGION_NAMES

    ds = _region_maps(out, res, ["full"], cache)
    save_regions_figure(ds, out / "fig8.png")
    region = ds["region"].sel(model="full").transpose("N", "Omega").values
    N, Om = ds["N"].values, ds["Omega"].values
    counts = {REGION_NAMES[c]: int(np.sum(region == c)) for c in (1, 2, 3, 0)}
    ss = (region == 1) | (region == 2)
    # stick-slip below equilibrium-only at every N: largest stick-slip Ω < smallest region-III Ω
    ordered = []
    for j in range(N.size):
        if ss[j].any() and (region[j] == 3).any():
            ordered.append(bool(Om[ss[j]].max() < Om[region[j] == 3].min()))
    omax = ds["stick_slip_omega_max"].sel(model="full").values
    fin = np.isfinite(omax)
    rising = bool(fin.sum() >= 2 and np.all(np.diff(omax[fin]) >= 0))
    jn = int(np.argmin(np.abs(N - 50.0)))
    checks = []
    for om, want in ((5.0, 1), (12.0, 3)):
        k = int(np.argmin(np.abs(Om - om)))
        checks.append((float(N[jn]), float(Om[k]), int(region[jn, k]), want))
    rows = [
        Row("Fig. 8, regions", "(N, Ω) divides into regions I (stick-slip only), II (coexistence), III (equilibrium only)",
            "; ".join(f"{k}: {v} cells" for k, v in counts.items()) + f" (grid {N.size} × {Om.size})",
            _yes(all(counts[REGION_NAMES[c]] > 0 for c in (1, 2, 3))),
            "each of regions I, II and III occupies at least one grid cell"),
        Row("Fig. 8, trend", "“a low Ω or a high N promotes stick-slip oscillation”",
            f"stick-slip below region III at {sum(ordered)} of {len(ordered)} N; largest Ω with stick-slip "
            + ", ".join(f"{n:g}: {_fmt(o)}" for n, o in zip(N, omax)) + " rad/s",
            _yes(bool(ordered) and all(ordered) and rising),
            "at every N, all stick-slip cells (I, II) lie below all region-III cells, and the largest Ω with "
            "stick-slip is non-decreasing in N"),
        Row("Fig. 8 vs Fig. 7", "N = 50 N: Ω = 5 rad/s in region I, Ω = 12 rad/s in region III",
            "; ".join(f"cell ({n:g} N, {o:g} rad/s): {REGION_NAMES[r]}" for n, o, r, _ in checks),
            _yes(all(r == w for *_, r, w in checks)), "region of the grid cell nearest to each Fig. 7 point as stated"),
    ]
    return RecipeResult(["fig8.png"], rows, {"counts": counts, "omega_ss": omax.tolist(), "N": N.tolist(),
                                             "Omega": Om.tolist()})


def _recipe_fig9(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    from ..plot.regions import MODEL_LABELS, save_regions_figure

    models = ["full", "x", "y", "rotation"]
    ds = _region_maps(out, res, models, cache)
    save_regions_figure(ds, out / "fig9.png")
    region = ds["region"].transpose("model", "N", "Omega").values
    ss = (region == 1) | (region == 2)
    cells = {m: int(ss[i].sum()) for i, m in enumerate(models)}
    kinds = _kind_names(ds.transpose("model", "N", "Omega", "ic", ...))
    slip_only = {m: int(np.sum(kinds[i] == "periodic-slip")) for i, m in enumerate(models)}
    failed = {m: int(np.sum(kinds[i] == "failed")) for i, m in enumerate(models)}
    smaller = all(cells[m] > 0 and cells["rotation"] <= 0.75 * cells[m] for m in ("full", "x", "y"))
    inside = bool(np.all(ss[0][ss[3]])) and cells["full"] > cells["rotation"]
    measured = "; ".join(f"{MODEL_LABELS[m].split(' (')[0]}: {cells[m]} cells" for m in models)
    rows = [
        Row("Fig. 9, Model 4", "“the ‘stick-slip’ domain for the reduced model with only rotational motion is "
            "significantly smaller than those for other three models”",
            measured + f" with stick-slip (of {ss[0].size}); periodic slip-only runs: "
            + ", ".join(f"{m} {slip_only[m]}" for m in models) + "; failed runs: "
            + ", ".join(f"{m} {failed[m]}" for m in models),
            _yes(smaller), "stick-slip cells of Model 4 at most 3/4 of those of each of Models 1, 2 and 3 (each with some)"),
        Row("Fig. 9, translation", "“the addition of the translational motion increases the possibility of "
            "occurrence of stick-slip oscillation”",
            f"Model 4 stick-slip cells inside Model 1's domain: {int(np.sum(ss[0] & ss[3]))} of {cells['rotation']}; "
            f"Model 1 {cells['full']} cells",
            _yes(inside), "every stick-slip cell of Model 4 is stick-slip in Model 1, and Model 1 has more"),
    ]
    return RecipeResult(["fig9.png"], rows, {"stick_slip_cells": cells, "periodic_slip_runs": slip_only,
                                             "failed_runs": failed})


def _recipe_fig16(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    from ..plot.intensity import save_intensity_figure

    ds = _region_maps(out, res, ["full", "rotation"], cache)
    save_intensity_figure(ds, out / "fig16.png", ic="far")
    far = ds.sel(ic="far").transpose("model", "N", "Omega", ...)
    both = _stick_slip(far.sel(model="full")) & _stick_slip(far.sel(model="rotation"))
    i_full = far["intensity_r_phi"].sel(model="full").values
    i_rot = far["intensity_r_phi"].sel(model="rotation").values
    ratio = i_full[both] / i_rot[both]
    full_ss = _stick_slip(far.sel(model="full"))
    tr = far["intensity_translation"].sel(model="full").values[full_ss] / i_full[full_ss]
    med = float(np.median(ratio)) if ratio.size else math.nan
    rows = [
        Row("Fig. 16(a), (b)", "“the addition of the two-dimensional translational motion … has no significant effect "
            "on the intensity of oscillation of rφ”",
            f"I(rφ) Model 1 / Model 4 at the {ratio.size} cells where both stick-slip (far IC): median {_fmt(med)}, "
            f"range {_fmt(ratio.min() if ratio.size else math.nan)}–{_fmt(ratio.max() if ratio.size else math.nan)}",
            _yes(ratio.size > 0 and 0.8 <= med <= 1.25), "median ratio within [0.8, 1.25] (±25 %)"),
        Row("Fig. 16(c)", "the intensity of the translation of the upper plate “has the same-order magnitude as that "
            "of rφ”",
            f"I(x1, y1) / I(rφ), Model 1, {tr.size} stick-slip cells: "
            f"{_fmt(tr.min() if tr.size else math.nan)}–{_fmt(tr.max() if tr.size else math.nan)}",
            _yes(tr.size > 0 and bool(np.all((tr >= 0.1) & (tr <= 10.0)))),
            "ratio within [0.1, 10] at every stick-slip cell"),
    ]
    return RecipeResult(["fig16.png"], rows, {"ratio_full_rot_median": med, "n_common": int(ratio.size),
                                              "translation_over_rphi": [float(np.min(tr)), float(np.max(tr))]
                                              if tr.size else None})


# ----------------------------------------------------------------------------- Figs. 12(b), 13
def _recipe_fig12b(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    from ..model.parameters import Parameters

    Om = np.linspace(*FIG12B_OMEGA_RANGE, res.bif_points)
    ds = _bifurcation_sweep(out, res, "fig12b", {"Omega": Om}, Parameters(N=50.0), ic="far")
    labels = _attractor_names(ds)
    ss = _stick_slip(ds)
    f = ds["dominant_frequency"].values
    rho = _spearman(Om[ss], f[ss])
    top = float(Om[ss].max()) if ss.any() else math.nan
    upper = ss & (Om > 0.5 * (Om[0] + top))
    rows = [
        Row("Fig. 12(b), period", "periodic stick-slip “with growing period … with the … decrease of Ω” (N = 50 N)",
            f"stick-slip at {int(ss.sum())} of {Om.size} Ω up to {_fmt(top)} rad/s; dominant frequency "
            f"{_fmt(f[ss][0] if ss.any() else math.nan)} Hz at {_fmt(Om[ss][0] if ss.any() else math.nan)} rad/s … "
            f"{_fmt(f[ss][-1] if ss.any() else math.nan)} Hz at {_fmt(top)} rad/s; Spearman ρ(Ω, f) = {_fmt(rho)}",
            _yes(rho > 0.9), "Spearman rank correlation of the dominant frequency with Ω above 0.9 over the stick-slip points"),
        Row("Fig. 12(b), kind", "“changes from periodic stick-slip … to non-periodic stick-slip … with the decrease of Ω”",
            "regimes along Ω: " + _regimes_text(_regimes(Om, labels)) + "; " + _settle_text(ds),
            _yes(labels[0] in NON_PERIODIC and not np.any(np.isin(labels[upper], NON_PERIODIC))),
            "settled non-periodic at the smallest Ω and none in the upper half of the stick-slip Ω range"),
    ]
    return RecipeResult(["fig12b.png"], rows, {"Omega": Om.tolist(), "dominant_frequency": f.tolist(),
                                               "attractors": [str(k) for k in labels],
                                               "settle_time": ds["settle_time"].values.tolist()})


def _recipe_fig13(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    from ..model.parameters import Parameters

    base = Parameters(N=50.0, Omega=0.5)
    dmu = np.linspace(*FIG13_DELTA_MU_RANGE, res.bif_points)
    alpha = np.linspace(*FIG13_ALPHA_RANGE, res.bif_points)
    ds_a = _bifurcation_sweep(out, res, "fig13a", {"delta_mu": dmu}, base)
    ds_b = _bifurcation_sweep(out, res, "fig13b", {"alpha": alpha}, base)
    runs_a, runs_b = _regimes(dmu, _attractor_names(ds_a)), _regimes(alpha, _attractor_names(ds_b))
    pat_a, pat_b = [r[0] for r in runs_a], [r[0] for r in runs_b]
    rows = [
        Row("Fig. 13(a)", "“By increasing Δμ, the response of ϕ changes from periodic oscillation to non-periodic "
            "oscillation and eventually back to periodic oscillation” (α = 5)",
            "regimes along Δμ: " + _regimes_text(runs_a) + "; " + _settle_text(ds_a), _yes(pat_a == ["P", "NP", "P"]),
            "the sequence of periodic (P) / settled non-periodic (NP) / unsettled (U) runs along Δμ (equilibria "
            "skipped) is exactly P → NP → P"),
        Row("Fig. 13(b)", "“By increasing α, the response of ϕ changes from periodic oscillation to non-periodic "
            "oscillation, and then back to periodic oscillation and non-periodic oscillation in turn, and eventually "
            "back to periodic oscillation” (Δμ = 0.1)",
            "regimes along α: " + _regimes_text(runs_b) + "; " + _settle_text(ds_b),
            _yes(pat_b == ["P", "NP", "P", "NP", "P"]), "the sequence of P / NP / U runs along α is exactly "
            "P → NP → P → NP → P"),
    ]
    return RecipeResult(["fig13a.png", "fig13b.png"], rows,
                        {"delta_mu_regimes": runs_a, "alpha_regimes": runs_b,
                         "delta_mu_settle_time": ds_a["settle_time"].values.tolist(),
                         "alpha_settle_time": ds_b["settle_time"].values.tolist()})


# ----------------------------------------------------------------------------- Figs. 14, 15
def _period_summary(ds, model: str) -> dict:
    """Stick-slip points of one model of a Fig. 14 sweep: count, verdicts, peaks per period, period range."""
    d = ds.sel(model=model)
    ss = _stick_slip(d)
    labels = _attractor_names(d)
    period = d["period"].values[ss]
    count = d["period_count"].values[ss]
    fin = np.isfinite(period)
    spread = float(period[fin].max() / period[fin].min() - 1.0) if fin.any() else math.nan
    return {"n": int(ss.sum()), "of": int(ss.size), "all_periodic": bool(ss.any() and np.all(labels[ss] == "periodic")),
            "multiplicities": sorted({int(m) for m in count[np.isfinite(count) & (count > 0)]}), "period_spread": spread,
            "period_range": [float(period[fin].min()), float(period[fin].max())] if fin.any() else None,
            "attractors": {str(k): int(np.sum(labels == k)) for k in np.unique(labels)},
            "settled": int(np.sum(np.isfinite(d["settle_time"].values)))}


def _recipe_fig14(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    from ..model.parameters import Parameters
    from ..plot.regions import MODEL_LABELS

    models = ["x", "y", "rotation"]
    N = np.linspace(10.0, 130.0, res.fig14_N)
    Om = np.linspace(*FIG12B_OMEGA_RANGE, res.fig14_N)
    ds_n = _bifurcation_sweep(out, res, "fig14_N", {"model": models, "N": N}, Parameters(Omega=0.5))
    ds_o = _bifurcation_sweep(out, res, "fig14_Omega", {"model": models, "Omega": Om}, Parameters(N=50.0), ic="far")
    rows, measured = [], {}
    for m in models:
        s_n, s_o = _period_summary(ds_n, m), _period_summary(ds_o, m)
        measured[m] = {"N": s_n, "Omega": s_o}
        text = "; ".join(
            f"over {lab}: stick-slip at {s['n']}/{s['of']}, all settled periodic: {_yes(s['all_periodic'])}, "
            f"peaks per period {s['multiplicities'] or '–'}, period spread {_fmt(100 * s['period_spread'], 2)} %, "
            f"verdicts {s['attractors']}" for lab, s in (("N", s_n), ("Ω", s_o)))
        label = MODEL_LABELS[m].split(" (")[0]
        if m == "rotation":
            ok = all(s["all_periodic"] and s["multiplicities"] == [1] and s["period_spread"] <= UNCHANGED_PERIOD_RTOL
                     for s in (s_n, s_o))
            rows.append(Row(f"Fig. 14(e)(f), {label}", "“no bifurcation appears, i.e, ϕ has periodic stick-slip "
                            "oscillation with unchanged period (or frequency) with the variation of N or Ω”", text,
                            _yes(ok), f"over N and over Ω every stick-slip point settles periodic with one peak "
                            f"per period and the period varies by at most {100 * UNCHANGED_PERIOD_RTOL:g} %"))
        else:
            ok = all(s["all_periodic"] and (s["period_spread"] > DIFFERENT_PERIOD_RTOL or len(s["multiplicities"]) > 1)
                     for s in (s_n, s_o))
            panel = "(a)(b)" if m == "x" else "(c)(d)"
            rows.append(Row(f"Fig. 14{panel}, {label}", "“periodic stick-slip oscillations with different periods "
                            "(or frequencies) appear as N or Ω varies”", text, _yes(ok),
                            f"over N and over Ω every stick-slip point settles periodic, and the period varies "
                            f"by more than {100 * DIFFERENT_PERIOD_RTOL:g} % or the peaks per period change"))
    return RecipeResult(["fig14_N.png", "fig14_Omega.png"], rows, measured)


def _recipe_fig15(out: Path, res: Resolution, cache: dict) -> RecipeResult:
    from ..model.parameters import Parameters
    from ..plot.trajectory import save_trajectory_figure

    tr = _settled_run(Parameters(N=50.0, Omega=0.5), res, res.fig15_t_end, model="rotation")
    a = tr.attractor
    save_trajectory_figure(tr, out / "fig15.png")
    rows = [Row("Fig. 15", "Model 4 (rotation only): periodic stick-slip of φ with one period (Sect. 4.2.3, with Fig. 14(e)(f))",
                f"N = 50 N, Ω = 0.5 rad/s: {_verdict_text(tr)}, period {_fmt(a.period_s, 4)} s, stick fraction "
                f"{_fmt(a.classification.stick_fraction if a.classification else math.nan)}",
                _yes(a.kind == "periodic-stick-slip" and a.period_count == 1),
                "settled periodic stick-slip with one peak per period (the paper does not print N, Ω of Fig. 15; "
                "ours are those of Figs. 12(a)/14 at N = 50 N)")]
    return RecipeResult(["fig15.png"], rows, a.to_dict())


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

#: Figures of Sects. 4.1–4.2 that no recipe reproduces yet (listed in the report; none left).
NOT_YET: dict = {}


def recipe_names() -> list[str]:
    return [r.name for r in RECIPES]


# ----------------------------------------------------------------------------- report
def _cell(text: str) -> str:
    """Escape the Markdown table separator (|F_f| would split a cell)."""
    return str(text).replace("|", "\\|")


def render_report(entries: list, res: Resolution, pending: list, elapsed: float) -> str:
    """Markdown report from the finished recipe entries (dicts written by :func:`reproduce`)."""
    from .. import __version__

    lines = ["# Reproduction of the paper's Sects. 4.1–4.2", "",
             f"stickslip {__version__}, resolution `{res.name}`, {elapsed:.0f} s so far. "
             "“We measure” is computed by this run; “agrees?” follows the criterion in the last column "
             "(“not compared” where the paper gives no number).", ""]
    all_rows = []
    for e in entries:
        lines += [f"## {e['title']}", "", f"Paper: {e['statement']}", ""]
        if e["status"] == "failed":
            lines += [f"**Failed** after {e['seconds']:.1f} s: `{e['error']}`", ""]
            continue
        for fig in e["figures"]:
            lines += [f"![{fig}]({fig})", ""]
        lines += ["| item | paper says | we measure | agrees? |", "|---|---|---|---|"]
        for r in e["rows"]:
            lines.append(f"| {_cell(r['item'])} | {_cell(r['paper'])} | {_cell(r['measured'])} | {r['agrees']} |")
            all_rows.append(r)
        lines += ["", f"Computed in {e['seconds']:.1f} s.", ""]
    if pending:
        lines += ["## Still running or not started", ""] + [f"- {p}" for p in pending] + [""]
    lines += ["## Summary: paper says / we measure / agrees?", "",
              "| item | paper says | we measure | agrees? | criterion |", "|---|---|---|---|---|"]
    for r in all_rows:
        lines.append(f"| {_cell(r['item'])} | {_cell(r['paper'])} | {_cell(r['measured'])} | {r['agrees']} | "
                     f"{_cell(r['criterion'])} |")
    for e in entries:
        if e["status"] == "failed":
            lines.append(f"| {e['name']} | – | recipe failed | not compared | – |")
    if NOT_YET:
        lines += ["", "## Not yet reproduced", ""] + [f"- {k}: {v}" for k, v in NOT_YET.items()]
    lines += [""]
    return "\n".join(lines)


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

    from ..analysis.settle import jsonable

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
