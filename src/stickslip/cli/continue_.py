"""``stickslip continue``: a branch of periodic orbits in one parameter (pseudo-arclength).

Parse → library call (:func:`stickslip.orbits.continuation.continue_orbit`) → write NetCDF and a
figure; no physics here.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import List, Optional

import typer
from rich.table import Table

from ..errors import SteadySlidingError, StickSlipError
from ..orbits import resolve_section
from ..orbits.continuation import SPECIAL_KINDS, continue_orbit, start_run
from ..orbits.models import parameter_value, with_parameter
from ..orbits.problem import METHODS as MONODROMY_METHODS
from ..plot.continuation import save_branch_figure
from ._app import (CLIError, app, check_below_one, check_choice, check_finite, check_positive, check_resumable_output,
                   console, error_line, exact, note_line, resumable_holds)
from ._compiling import time_text, timed
from ._groups import grouped
from ._json import print_json
from ._kept import keeps, keeps_figure
from ._options import (ContinuedPoint, JsonSummary, Model, ModelChanges, NoPlot, OrbitRtol, OrbitSearch, Restart,
                       ResumableOut, SlipBand, Tol)
from .orbit import model_system, parse_section, parse_start


def _check(start: float, stop: float, max_points: int, step: float, max_step: float, search_time: float,
           tol: float, stop_on: list[str]) -> None:
    """Validate the options before anything is computed (one-line CLIError naming the fix).

    These checks are the command line's: the library refuses the steps, the number of points and
    the stop kinds only after the start run, calls the start run's length ``t_end``, leaves the
    tolerance unbounded, and sees --from and --to only as the bounds and direction made of them."""
    check_finite({"--from": start, "--to": stop})
    if start == stop:
        raise CLIError(f"--from and --to are both {exact(start)}; give the end of the range to continue to")
    if max_points < 2:
        raise CLIError(f"--max-points must be >= 2, got {max_points}")
    check_positive({"--step": step, "--max-step": max_step, "--search-time": search_time, "--tol": tol})
    check_below_one({"--tol": tol})
    if step > max_step:
        raise CLIError(f"--step {exact(step)} is larger than --max-step {exact(max_step)}")
    bad = [k for k in stop_on if k not in SPECIAL_KINDS]
    if bad:
        raise CLIError(f"--stop-on {', '.join(bad)}: choose from {', '.join(SPECIAL_KINDS)}")


def _note_resume(k: int) -> None:
    """One line on stderr (stdout stays clean for --json) when a run picks up earlier work."""
    note_line(f"resuming from {k} points")


def _steady_start(exc, system) -> CLIError:
    """The one-line error of a start that converged onto steady sliding, naming the options to change."""
    x = system.dofs[system.observed_index]
    return CLIError(f"converged to steady sliding at {exc.param}={exc.value:g}: the start orbit is the equilibrium, "
                    f"not a cycle; start from a state on the cycle, e.g. --ic {x}=...,d{x}=..., or a longer "
                    "--search-time")


def _multipliers_text(mu) -> str:
    """Floquet multipliers as text, a conjugate pair once as a ± bi (NaN: none)."""
    if not all(map(math.isfinite, (abs(m) for m in mu))):
        return "none"
    return ", ".join(f"{m.real:.4g}±{m.imag:.3g}i" if m.imag > 0 else f"{m.real:.4g}" for m in mu if m.imag >= 0)


def _pairs(mu) -> list:
    """Complex numbers as JSON-ready [real, imag] pairs (NaN as null)."""
    return [[None if math.isnan(m.real) else float(m.real), None if math.isnan(m.imag) else float(m.imag)] for m in mu]


@app.command("continue")
@grouped
def continue_command(
    *,  # options only (typer reads them by name)
    param: str = typer.Option("Omega", "--param", help="Parameter to vary: any numeric parameter of the model, the "
                              "plates' N, Omega, delta_mu, alpha, mu_k, k_px, ... or a model file's path such as "
                              "contact.0.drive ('stickslip models NAME' lists them)."),
    start: float = typer.Option(..., "--from", help="Start value of the parameter [its unit: N for N, rad/s for "
                                "Omega, ...]; the first orbit is found there."),
    stop: float = typer.Option(..., "--to", help="End of the range [the unit of --param]; the branch goes from "
                               "--from towards it."),
    point: ContinuedPoint = ContinuedPoint(),
    model: Model = "full",
    search: OrbitSearch = OrbitSearch(search_time=60.0),
    max_points: int = typer.Option(200, "--max-points", help="Orbits to compute (the start included)."),
    step: float = typer.Option(0.02, "--step", help="Initial step in scaled arclength (≈ relative parameter change)."),
    max_step: float = typer.Option(0.2, "--max-step", help="Largest step in scaled arclength."),
    stop_on: Optional[List[str]] = typer.Option(None, "--stop-on", help="Stop after this special point (repeatable): "
                                                "fold, period-doubling, neimark-sacker, stick-phases, grazing."),
    rtol: OrbitRtol = 1e-10,
    tol: Tol = 1e-8,
    slip_band: SlipBand = None,
    changes: ModelChanges = ModelChanges(),
    out: ResumableOut = Path("branch.nc"),
    overwrite: Restart = False,
    no_plot: NoPlot = False,
    no_progress: bool = typer.Option(False, "--no-progress", help="Do not print a line per orbit."),
    monodromy: str = typer.Option("auto", "--monodromy", help="Monodromy of each orbit: auto (saltation where "
                                  "the model has a rigid contact, else finite-difference) | saltation | "
                                  "finite-difference."),
    as_json: JsonSummary = False,
) -> None:
    """Continue a periodic orbit in one parameter, with stability, folds, stick-phase changes and grazing.

    The first orbit is shot from a run of --search-time seconds from --ic at --from; the branch follows it towards --to (pseudo-arclength, so it passes folds) and ends at --to, after --max-points orbits, or where the stick phase vanishes. With a contact that opens and closes, grazing points (a flight phase appears or vanishes) are reported and passed. Every orbit is written to OUT.nc.journal as it is found; running the same command again after an interruption resumes from the last one (a different command with the same --out is refused). Folds, period doublings and Neimark-Sacker points are told apart by what crosses the unit circle (a real multiplier at +1, at -1, a complex pair), with the multipliers on either side. A start orbit that is steady sliding (the equilibrium, no cycle) is an error (exit 2, nothing written); a continuation that converges onto steady sliding writes the orbits before it and exits 1.
    """
    stop_on = list(stop_on or [])
    _check(start, stop, max_points, step, max_step, search.search_time, tol, stop_on)
    check_choice("--monodromy", monodromy, ("auto",) + MONODROMY_METHODS)
    ic_start = parse_start(search.ic)
    system = model_system(model, changes, slip_band, swept={param: f"--param {param}"}, **point.named())
    try:
        parameter_value(system, param)
        system = with_parameter(system, param, start)
    except StickSlipError as exc:
        raise CLIError(f"--param {param}: {exc}") from None
    sec = resolve_section(parse_section(search.section), system)
    check_resumable_output(out, not no_plot, overwrite)
    keeps(out, resumable_holds("branch"))
    progress = None if (no_progress or as_json) else (
        lambda i, v, T, st: console.print(f"  orbit {i:4d}: {param} = {v:.6g}, T = {T:.6g} s, "
                                          f"{'stable' if st else 'unstable'}"))
    with timed() as timing:
        run = start_run(system, ic_start, t_end=search.search_time, rtol=rtol)
        out.parent.mkdir(parents=True, exist_ok=True)
        try:
            branch = continue_orbit(system, param, start=run, direction=1 if stop > start else -1, step=step,
                                    max_step=max_step, max_points=max_points,
                                    bounds=(min(start, stop), max(start, stop)), stop_on=tuple(stop_on), section=sec,
                                    rtol=rtol, tol=tol, callback=progress, out=out, on_resume=_note_resume,
                                    resume=not overwrite, monodromy=monodromy)
        except SteadySlidingError as exc:
            raise _steady_start(exc, system) from None
    figure = None
    if not no_plot:
        keeps_figure(out)
        figure = save_branch_figure(branch, out.with_suffix(".png"))
    summary = {
        "out": str(out), "figure": None if figure is None else str(figure), "param": param,
        "points": len(branch), "from": float(branch.values[0]), "to": float(branch.values[-1]),
        "stable_points": int(branch.stable.sum()), "stop_reason": branch.stop_reason,
        "monodromy": branch.options.get("monodromy", "finite-difference"),
        "special": [{"kind": p.kind, "value": p.value, "located": p.located, "multipliers": _pairs(p.multipliers),
                     "multipliers_before": _pairs(p.multipliers_before),
                     "multipliers_after": _pairs(p.multipliers_after)} for p in branch.special],
        # the start run and the continuation, without the compiling inside them
        "wall_time_s": timing.wall_s, "compile_time_s": timing.compile_s, "simulations": branch.timings["simulations"],
        "points_resumed": branch.timings.get("points_resumed", 0),
    }
    steady = branch.stop_reason.startswith("steady sliding")
    if as_json:
        print_json(summary)
    else:
        _print_summary(branch, summary, param, out)
    if steady:  # the orbits before it are a result, but the branch did not end where it should
        error_line(f"the continuation converged to {branch.stop_reason} after {len(branch)} orbits (they are in "
                   f"{out}); the step left the cycle or the cycle ends there: try a smaller --max-step")
        raise typer.Exit(1)


def _print_summary(branch, summary: dict, param: str, out: Path) -> None:
    """The summary table: range, stop reason, special points with the multipliers on either side."""
    table = Table(title=f"stickslip continue ({branch.model}, in {param})", show_header=False)
    table.add_row("orbits", f"{summary['points']} ({summary['stable_points']} stable)")
    table.add_row(f"{param} range", f"{summary['from']:.6g} → {summary['to']:.6g}")
    table.add_row("period range", f"{branch.periods.min():.6g} – {branch.periods.max():.6g} s")
    table.add_row("stopped", summary["stop_reason"])
    for p in branch.special:
        table.add_row(p.label, f"{param} = {p.value:.6g}" + ("" if p.located else " (not located to tolerance)"))
        if p.kind in ("fold", "period-doubling", "neimark-sacker"):
            table.add_row("  multipliers", f"{_multipliers_text(p.multipliers_before)} → "
                                           f"{_multipliers_text(p.multipliers_after)}")
    table.add_row("wall time", time_text(summary["wall_time_s"], summary["compile_time_s"],
                                         f"{summary['simulations']} simulations"))
    if summary["points_resumed"]:
        table.add_row("resumed", f"{summary['points_resumed']} orbits read back from {out} or its journal")
    table.add_row("wrote", str(out) + ("" if summary["figure"] is None else f", {summary['figure']}"))
    console.print(table)
