"""``stickslip sweep``, ``stickslip bifurcation`` and ``stickslip regions``: parameter sweeps.

Parse → library call (:mod:`stickslip.sweep`) → write NetCDF and a figure; no physics here.
Every command resumes: run it again with the same arguments and it computes only what is
missing (nothing, if the output is complete).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Callable, List, Optional

import numpy as np
import typer
from rich.table import Table

from ..analysis.outcome import OUTCOMES, is_stick_slip, outcome_names
from ..memory import check_memory, largest_count
from ..model.library import plates_variant, two_plates
from ..model.library.two_plates import plates_parameters
from ..plot.regions import save_regions_figure
from ..plot.sweep import save_bifurcation_figure, save_sweep_figure
from ..sweep import regions as run_regions
from ..sweep import sweep as run_sweep
from ..sweep.bistability import REGION_NAMES
from ..sweep.spec import columns_of
from ._app import (CLIError, app, build_system, check_positive, check_resumable_output, config_values, console,
                   parse_assignments, resumable_holds)
from ._compiling import Timing, time_text, timed
from ._groups import grouped
from ._kept import keeps
from ._options import (BifurcationModel, BifurcationPlates, Friction, GridTEnd, JsonSummary, ModelChanges, NoPlot,
                       NoProgress, Parallel, RegionsTEnd, RegionsTFrom, Restart, ResumableOut, SampleRate, Settling,
                       Study, SweepModel, TFrom, Tolerances)
from ._outputs import draw_figure

_CATEGORICAL = ("model", "ic")

#: Memory per value of a parsed axis [bytes]: a Python float in a list and its array copies.
_VALUE_BYTES = 64


def parse_values(name: str, text: str, *, option: str = "--grid") -> list:
    """Values of one grid axis from ``start:stop:count`` or a comma list.

    Numbers for parameters (``10:130:13`` → 13 evenly spaced values from 10 to 130 inclusive;
    ``0.5,5,8.5``); names for ``model`` and ``ic`` (``full,rotation``).

    Raises
    ------
    CLIError
        With a one-line message naming the fix.
    """
    text = text.strip()
    named = option in ("--grid", "--axis")  # options given as NAME=VALUES
    given = f"{option} {name}={text}" if named else f"{option} {text}"
    prefix = f"{option} {name}=" if named else f"{option} "
    example = f"{prefix}10:130:13 or {prefix}30,50,70"
    if not text:
        raise CLIError(f"{given} has no values; e.g. {example}")
    if name in _CATEGORICAL:
        values = [v.strip() for v in text.split(",")]
        if not all(values):
            raise CLIError(f"{given}: empty name in the list; e.g. {prefix}full,rotation")
        return values
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise CLIError(f"{given}: a range is start:stop:count; e.g. {example}")
        try:
            start, stop = float(parts[0]), float(parts[1])
            count = int(parts[2])
        except ValueError:
            raise CLIError(f"{given}: start and stop must be numbers and count an integer; e.g. {example}") from None
        if not (math.isfinite(start) and math.isfinite(stop)):
            raise CLIError(f"{given}: start and stop must be finite numbers")
        if count < 2:
            raise CLIError(f"{given}: count must be >= 2 (for one value write {prefix}{parts[0]})")
        if start == stop:
            raise CLIError(f"{given}: start equals stop; give different ends or a single value")
        check_memory(count * float(_VALUE_BYTES), f"{given} ({count:.3g} values)",
                     lambda memory: f"give a count of at most {largest_count(_VALUE_BYTES, memory)}")
        return np.linspace(start, stop, count).tolist()
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise CLIError(f"{given}: give numbers separated by commas or start:stop:count; e.g. {example}") from None
    if not all(math.isfinite(v) for v in values):
        raise CLIError(f"{given}: values must be finite numbers")
    return values


def parse_grid(items: list[str] | None) -> dict:
    """``["N=10:130:13", "Omega=0.5,5"]`` → ``{"N": [...], "Omega": [0.5, 5.0]}`` (order kept)."""
    grid: dict = {}
    for item in items or []:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise CLIError(f"--grid expects NAME=VALUES, got {item!r}; e.g. --grid N=10:130:13 --grid Omega=0.5,5,8.5")
        if name in grid:
            raise CLIError(f"--grid {name} given twice; give each dimension once")
        grid[name] = parse_values(name, text)
    if not grid:
        raise CLIError("give at least one --grid NAME=VALUES, e.g. --grid N=10:130:13")
    return grid


def _settle_options(settling: Settling) -> dict:
    """``settle`` and ``cap`` of the sweep spec from ``--settle`` / ``--cap`` (the sweep refuses a
    cap that is not a finite number ≥ ``t_end`` itself)."""
    if settling.cap is None:
        return {"settle": True} if settling.settle else {}
    if not settling.settle:
        raise CLIError("--cap is the longest run when settling; give --settle with it")
    return {"settle": True, "cap": settling.cap}


def _plot_columns(system) -> tuple[str, ...]:
    """The reductions a sweep of ``system`` keeps (those ``--plot`` may draw)."""
    return tuple(c[0] for c in columns_of(system))


def _run_options(study: Study, t_end: float, t_from: float | None, sample_rate: float, tolerances: Tolerances,
                 as_json: bool) -> dict:
    """The run options of the sweep library from the command line.

    The run's length, rate and tolerances are checked here: the sweep does not refuse a tolerance
    (each of its runs would fail) and names neither the length nor the rate it refuses. It refuses
    ``--t-from``, ``--workers`` and ``--cap`` itself, naming their values. No progress bar with
    ``--json``: stdout is then the one JSON line."""
    rtol, atol = tolerances.rtol, tolerances.atol
    check_positive({"--t-end": t_end, "--sample-rate": sample_rate, "--rtol": rtol, "--atol": atol})
    return dict(study.parallel.options(), progress=not (study.no_progress or as_json), overwrite=study.overwrite,
                t_end=t_end, t_from=t_from, sample_rate=sample_rate, rtol=rtol, atol=atol)


def _study(study: Study, what: str, inputs: dict, compute: Callable[[], object],
           draw: Callable[[object, Path], object]) -> tuple:
    """Run a resumable study into ``study.out`` and draw its figure beside it.

    Parameters
    ----------
    study : Study
        Its outputs (checked first, before anything is computed).
    what : str
        What the output holds, for the line of a Ctrl-C (``"sweep"``).
    inputs : dict of option → Path
        Files the command reads; no output may replace them.
    compute : callable
        ``compute()``: the study's result (it resumes from the journal beside ``study.out``).
    draw : callable
        ``draw(result, tmp)`` saves the figure to ``tmp`` (not called with ``--no-plot``).

    Returns
    -------
    result
        What ``compute`` returned.
    figure : Path or None
        The figure written.
    timing : Timing
        The computation's wall time and its compiling apart.
    """
    replace_figure = check_resumable_output(study.out, not study.no_plot, study.overwrite, inputs)
    keeps(study.out, resumable_holds(what))
    with timed() as timing:
        result = compute()
    figure = draw_figure(study.out, lambda tmp: draw(result, tmp), skip=study.no_plot, overwrite=replace_figure,
                         inputs=inputs)
    return result, figure, timing


def _outcome_counts(ds) -> dict:
    """Points per outcome (:data:`~stickslip.analysis.outcome.OUTCOMES`, in their order), and how many
    of them are stick-slip oscillations."""
    names = outcome_names(ds["attractor"].values)
    counts = {name: int(np.sum(names == name)) for name in OUTCOMES if np.any(names == name)}
    return {**counts, "stick-slip": int(np.sum(is_stick_slip(names, ds["stick_fraction"].values)))}


def _report(title: str, out: Path, figure, timings: dict, timing: Timing, ds, as_json: bool,
            extra: dict | None = None) -> None:
    summary = {
        "out": str(out), "figure": None if figure is None else str(figure),
        "shape": {d: int(ds.sizes[d]) for d in ds["done"].dims},
        "points_computed": int(timings.get("points_computed", 0)), "points_resumed": int(timings.get("points_resumed", 0)),
        "wall_time_s": timing.wall_s, "compile_time_s": timing.compile_s, "outcomes": _outcome_counts(ds),
        **(extra or {}),
    }
    if as_json:
        print(json.dumps(summary))
        return
    table = Table(title=title, show_header=False)
    table.add_row("grid", " × ".join(f"{d} {n}" for d, n in summary["shape"].items()))
    table.add_row("points computed / resumed", f"{summary['points_computed']} / {summary['points_resumed']}")
    executor = timings.get("executor", "?")
    workers = "1 process" if executor == "serial" else f"{timings.get('workers', '?')} workers"
    table.add_row("wall time", time_text(timing.wall_s, timing.compile_s, f"{executor}, {workers}"))
    table.add_row("outcomes", ", ".join(f"{k} {v}" for k, v in summary["outcomes"].items()))
    for key, value in (extra or {}).items():
        table.add_row(key.replace("_", " "), str(value))
    table.add_row("wrote", str(out) + ("" if figure is None else f", {figure}"))
    console.print(table)


# ----------------------------------------------------------------------------- stickslip sweep
@app.command("sweep")
@grouped
def sweep_command(
    *,  # options only (typer reads them by name)
    grid: Optional[List[str]] = typer.Option(None, "--grid", help="Swept dimension NAME=start:stop:count or NAME=v1,v2,... "
                                             "(repeatable; order = dimension order). NAME: a parameter (plates: N, "
                                             "Omega, delta_mu, alpha, mu_k, k_px, ...; other models: a path such as "
                                             "contact.0.drive), model (plates variants), ic or perturb_<state>."),
    model: SweepModel = "full",
    ic: str = typer.Option("zero", "--ic", help="zero | far | near | equilibrium (see docs/sweeps.md) when not swept."),
    t_end: GridTEnd = 200.0,
    t_from: TFrom = None,
    sample_rate: SampleRate = 200.0,
    tolerances: Tolerances = Tolerances(),
    settling: Settling = Settling(),
    changes: ModelChanges = ModelChanges(),
    parallel: Parallel = Parallel(),
    out: ResumableOut = Path("sweep.nc"),
    plot_var: str = typer.Option("frequency", "--plot", help="Reduction drawn in the figure: frequency, amplitude, "
                                                            "stick_fraction, attractor, intensity_r_phi, ..."),
    overwrite: Restart = False,
    no_plot: NoPlot = False,
    no_progress: NoProgress = False,
    as_json: JsonSummary = False,
) -> None:
    """Simulate every point of a grid and keep its steady-state reductions.

    Grid over any parameters, models and initial conditions; kept per point: peaks of φ, kind,
    frequency, stick fraction, intensity (Eq. 16), relative-motion angle.
    """
    values = parse_grid(grid)
    system, _ = build_system(model, changes.config, changes.set_, swept={k: f"--grid {k}" for k in values})
    columns = _plot_columns(system)
    if plot_var not in columns or plot_var == "peaks":
        raise CLIError(f"--plot {plot_var}: choose one of {', '.join(c for c in columns if c != 'peaks')}")
    # the options of a Study, taken one by one because --plot stands among them
    study = Study(parallel=parallel, out=out, overwrite=overwrite, no_plot=no_plot, no_progress=no_progress)
    options = _run_options(study, t_end, t_from, sample_rate, tolerances, as_json)
    options.update(_settle_options(settling))
    result, figure, timing = _study(study, "sweep", changes.inputs,
                                    lambda: run_sweep(values, system, out=out, ic=ic, **options),
                                    lambda result, tmp: save_sweep_figure(result, tmp, var=plot_var))
    _report(f"stickslip sweep ({result.spec.model}, ic {result.spec.ic})", out, figure, result.timings,
            timing, result.dataset, as_json)


# ----------------------------------------------------------------------------- stickslip bifurcation
@app.command("bifurcation")
@grouped
def bifurcation(
    *,  # options only (typer reads them by name)
    param: str = typer.Option("N", "--param", help="Control parameter: N, Omega, delta_mu, alpha, mu_k or any parameter "
                                                  "of the plates; for another model a path such as contact.0.drive."),
    range_: str = typer.Option("10:130:121", "--range", help="Its values: start:stop:count or v1,v2,..."),
    plates: BifurcationPlates = BifurcationPlates(),
    model: BifurcationModel = "full",
    ic: str = typer.Option("zero", "--ic", help="zero | far | near | equilibrium."),
    t_end: GridTEnd = 200.0,
    t_from: TFrom = None,
    n_peaks: int = typer.Option(64, "--peaks", help="Last peak values of φ kept per point."),
    sample_rate: SampleRate = 200.0,
    tolerances: Tolerances = Tolerances(),
    settling: Settling = Settling(),
    changes: ModelChanges = ModelChanges(),
    study: Study = Study(out=Path("bifurcation.nc")),
    as_json: JsonSummary = False,
) -> None:
    """Bifurcation diagram of φ: steady-state peak values against one parameter (Figs. 12–14)."""
    if param in _CATEGORICAL:
        raise CLIError(f"--param {param}: the control parameter must be numeric; use --model full,x,y,rotation "
                       "for one panel per model")

    named = plates.named()
    values = parse_values(param, range_, option="--range")
    models = parse_values("model", model, option="--model") if "," in model else [model]
    coordinate = "φ"
    if plates_variant(models[0]) is None:  # a library model or a model file
        if len(models) > 1:
            raise CLIError(f"--model {model}: a list of models is for the plates' variants; give one model")
        target, _ = build_system(models[0], changes.config, changes.set_, swept={param: f"--param {param}"}, **named)
        coordinate = target.dofs[target.observed_index]
        models = [None]
    else:
        target = two_plates(_bifurcation_parameters(changes.config, changes.set_, named, param),
                            plates_variant(models[0]))
    grid = ({"model": models} if len(models) > 1 else {}) | {param: values}
    if n_peaks < 1:
        raise CLIError(f"--peaks must be >= 1, got {n_peaks}")
    options = _run_options(study, t_end, t_from, sample_rate, tolerances, as_json)
    options.update(_settle_options(settling))
    result, figure, timing = _study(study, "bifurcation diagram", changes.inputs,
                                    lambda: run_sweep(grid, target, out=study.out, ic=ic, n_peaks=n_peaks, **options),
                                    save_bifurcation_figure)
    _report(f"bifurcation diagram of {coordinate} against {param}", study.out, figure, result.timings, timing,
            result.dataset, as_json)


#: Base values of the paper's bifurcation diagrams (Figs. 12–14): N = 50 N and Ω = 0.5 rad/s
#: unless swept (Fig. 12(b) and 14(b, d, f) sweep Ω at N = 50 N).
BIFURCATION_BASE = {"N": 50.0, "Omega": 0.5}


def _bifurcation_parameters(config, assignments, named: dict, param: str):
    """Base parameters: :data:`BIFURCATION_BASE` for N and Ω unless the config file, ``--set`` or
    the named options give them, then everything as in :func:`build_parameters` (which refuses
    an option that sets the control parameter ``param``)."""
    params = plates_parameters(build_system("full", config, assignments, swept={param: f"--param {param}"}, **named)[0])
    given = {k for k, v in named.items() if v is not None} | set(parse_assignments(assignments))
    if config is not None:
        given |= set(config_values(config))
    changes = {k: v for k, v in BIFURCATION_BASE.items() if k != param and k not in given}
    return params.replace(**changes) if changes else params


# ----------------------------------------------------------------------------- stickslip regions
#: Default length of the steady window of region maps [s]: the window of the maps in
#: docs/sweeps.md, ≥ 80 cycles of the slowest stick-slip measured there (dominant frequency
#: ~0.8 Hz at 120 N, Ω = 0.5 rad/s, Fig. 12(a)), enough for the return-map classification.
REGIONS_WINDOW_S = 100.0

@app.command("regions")
@grouped
def regions_command(
    N: str = typer.Option("10:130:13", "--N", help="Normal loads [N]: start:stop:count or v1,v2,..."),
    omega: str = typer.Option("1:15:15", "--omega", help="Ω values [rad/s]: start:stop:count or v1,v2,..."),
    model: str = typer.Option("full", "--model", help="Comma list of full, x, y, rotation (Fig. 9 compares all four)."),
    friction: Friction = Friction(),
    # 300 s: the 'near' start leaves a weakly unstable equilibrium slowly (growth rate
    # 0.05 1/s at N = 50 N, Ω = 5 rad/s: ~150 s until stick-slip), see docs/sweeps.md
    t_end: RegionsTEnd = 300.0,
    t_from: RegionsTFrom = None,
    sample_rate: SampleRate = 200.0,
    tolerances: Tolerances = Tolerances(),
    changes: ModelChanges = ModelChanges(),
    study: Study = Study(out=Path("regions.nc")),
    as_json: JsonSummary = False,
) -> None:
    """Regions I/II/III over (N, Ω) (Fig. 8) and stick-slip domains of several models (Fig. 9).

    Every (model, N, Ω) is run from the 'far' and the 'near' initial condition (docs/sweeps.md).
    """
    system, _ = build_system("full", changes.config, changes.set_, swept={"N": "--N", "Omega": "--omega"},
                             **friction.named())
    n_values = parse_values("N", N, option="--N")
    w_values = parse_values("Omega", omega, option="--omega")
    models = parse_values("model", model, option="--model")
    if t_from is None and math.isfinite(t_end):
        t_from = t_end - min(REGIONS_WINDOW_S, 0.5 * t_end)
    options = _run_options(study, t_end, t_from, sample_rate, tolerances, as_json)
    rmap, figure, timing = _study(study, "region map", changes.inputs,
                                  lambda: run_regions(n_values, w_values, system, variants=models, out=study.out,
                                                      **options),
                                  save_regions_figure)

    region = rmap.region
    counts = {REGION_NAMES[c]: int(np.sum(region == c)) for c in sorted(REGION_NAMES) if np.any(region == c)}
    omax = rmap.dataset["stick_slip_omega_max"]
    edges = {m: [None if not np.isfinite(v) else float(v) for v in omax.sel(model=m).values] for m in rmap.models}
    extra = {"regions": ", ".join(f"{k}: {v}" for k, v in counts.items())}
    if as_json:
        extra = {"regions": counts, "stick_slip_omega_max": edges}
    _report("regions of steady states over (N, Ω)", study.out, figure, rmap.timings, timing, rmap.dataset,
            as_json, extra)
