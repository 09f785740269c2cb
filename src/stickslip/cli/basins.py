"""``stickslip basins``: basin stability of any model, with exact stick.

Parse → library call (:func:`stickslip.basins.basin_stability`) → NetCDF, a figure and a
summary; no physics here. The command resumes: run it again with the same arguments and it
classifies only the states it had not finished (none, if the output is complete). Ctrl-C ends it
with one line saying how many states the output holds (the journal keeps them for the resume).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import List, Optional

import typer
from rich.table import Table

from ..basins import basin_stability, from_csv, parse_param, parse_range
from ..basins import box as random_box
from ..basins import grid as regular_grid
from ..basins.engine import load_result
from ..integrate.interrupt import stop_if_interrupted
from ..plot.basins import save_basins_figure
from ._app import CLIError, app, build_system, check_resumable_output, console, journal_of, parse_assignments
from ._compiling import Timing, time_text, timed
from ._groups import grouped
from ._kept import keeps, on_interrupt
from ._options import Model, SetItems, Study, Tolerances
from ._outputs import draw_figure

_BOX_HELP = ("A state to vary and its range, NAME=LO:HI (repeatable), e.g. --box x=-2:2 --box dx=-2:2; the "
             "other states are held at the base state.")


def _states(model, box, n, seed, grid, ics, base, state):
    """The initial states from the options (one line naming the fix for a bad combination)."""
    if ics is not None:
        if box or grid or state or base is not None:
            raise CLIError("--ics gives every state of every row; drop --box, --grid, --base and --state")
        if n is not None:
            raise CLIError("--ics gives the states itself; drop --n")
        return from_csv(model, ics)
    ranges = [parse_range(text) for text in box or []]
    fixed = parse_assignments(state, option="--state")
    base = base or "equilibrium"
    if grid is not None:
        if n is not None:
            raise CLIError("--grid gives the number of states per axis; drop --n (random draws)")
        try:
            counts = [int(k) for k in grid.split(",")]
        except ValueError:
            raise CLIError(f"--grid {grid}: give points per axis, one integer or one per --box (e.g. 50 or 50,40)") from None
        return regular_grid(model, ranges, counts[0] if len(counts) == 1 else counts, base=base, fixed=fixed)
    return random_box(model, ranges, 1000 if n is None else n, seed=seed, base=base, fixed=fixed)


@app.command()
@grouped
def basins(
    *,  # options only (typer reads them by name)
    model: Model = "two-plates",
    set_: SetItems = None,
    box: Optional[List[str]] = typer.Option(None, "--box", help=_BOX_HELP),
    n: Optional[int] = typer.Option(None, "--n", help="Uniform random states in the box (default 1000)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the random states."),
    grid: Optional[str] = typer.Option(None, "--grid", help="A regular grid over the box instead of random "
                                       "states: points per axis, one number or one per --box (e.g. 50 or 50,40)."),
    ics: Optional[Path] = typer.Option(None, "--ics", help="CSV file of initial states: a header naming every "
                                       "state, one state per row (results keep the row order)."),
    base: Optional[str] = typer.Option(None, "--base", help="State outside the box: equilibrium (steady sliding, "
                                       "default) or zero (at rest)."),
    state: Optional[List[str]] = typer.Option(None, "--state", help="Fix a state outside the box, NAME=VALUE "
                                              "(repeatable), e.g. --state dy1=1.7."),
    param: Optional[str] = typer.Option(None, "--param", help="Basin stability against a parameter: "
                                        "PATH=LO:HI:K (any --set path), e.g. contact.0.drive=0.8:2:13."),
    t_end: float = typer.Option(500.0, "--t-end", help="Longest run of a state [s]."),
    tolerances: Tolerances = Tolerances(),
    match_rtol: float = typer.Option(1e-3, "--match-rtol", help="Tolerance of the cycle matches, relative to a "
                                     "cycle's amplitude and period."),
    no_confirm: bool = typer.Option(False, "--no-confirm", help="Do not shoot orbits to confirm periods of "
                                    "several maxima (such runs stay unsettled)."),
    lyapunov: bool = typer.Option(False, "--lyapunov", help="Compute Lyapunov exponents of runs still "
                                  "non-periodic at --t-end (needed for a chaos claim)."),
    study: Study = Study(out=Path("basins.nc")),
    as_json: bool = typer.Option(False, "--json", help="Print {n, fractions, standard_errors, attractors} as JSON."),
) -> None:
    """Basin stability: which attractor each initial state reaches (exact stick), and how often."""
    out, inputs = study.out, {"--ics": ics}
    replace_figure = check_resumable_output(out, not study.no_plot, study.overwrite, inputs)
    m, _ = build_system(model, None, set_)
    states = _states(m, box, n, seed, grid, ics, base, state)
    path, values = parse_param(param) if param is not None else (None, ())
    parallel = study.parallel.options()
    keeps(out, _holds)
    on_interrupt(f"the states classified before are kept in {journal_of(out)}; run the same command again to resume",
                 journal_of(out))
    with timed() as timing:
        result = basin_stability(m, states, param=path, values=values, out=out, t_end=t_end, **parallel,
                                 progress=not (study.no_progress or as_json), overwrite=study.overwrite,
                                 rtol=tolerances.rtol, atol=tolerances.atol, match_rtol=match_rtol,
                                 confirm=not no_confirm, lyapunov=lyapunov)
    stop_if_interrupted()  # the study took a Ctrl-C: it wrote what it had
    figure = draw_figure(out, lambda tmp: save_basins_figure(result, tmp), skip=study.no_plot,
                         overwrite=replace_figure, inputs=inputs)
    if as_json:
        print(json.dumps({**result.to_json(), "wall_time_s": timing.wall_s, "compile_time_s": timing.compile_s}))
    else:
        _print_summary(result, out, figure, timing)


def _holds(out: Path) -> str:
    """What the study's output holds, read from it: the states classified, and how to go on."""
    ds = load_result(out).dataset
    done, total = int(ds.attrs["states_done"]), int(ds["done"].size)
    if int(ds.attrs["complete"]):
        return f"{out} holds all {total} states, classified"
    return f"{out} holds {done} of {total} states classified; run the same command again to resume"


def _print_summary(result, out: Path, figure, timing: Timing) -> None:
    ds = result.dataset
    timings = result.timings
    if "param" in ds.dims:
        table = Table(title=f"basin stability of {ds.attrs['model']} against {ds.attrs['param']}")
        table.add_column(ds.attrs["param"])
        for name in result.names:
            table.add_column(name)
        for p, value in enumerate(ds["param"].values):
            table.add_row(f"{value:g}", *(f"{ds['fraction'].values[p, i]:.3f} ± {ds['standard_error'].values[p, i]:.3f}"
                                          for i in range(len(result.names))))
    else:
        table = Table(title=f"basin stability of {ds.attrs['model']}: {result.n} states")
        opens = "open_fraction" in ds  # a model with contacts that open
        for col in ("attractor", "fraction ± se", "period", "amplitude", "stick fraction") + (("open fraction",) if opens
                                                                                             else ()):
            table.add_column(col)

        def cell(value, form):
            return "–" if value is None else format(value, form)

        for a in result.attractors():
            table.add_row(a["name"], f"{a['fraction']:.4f} ± {a['standard_error']:.4f}", cell(a["period"], ".6g"),
                          cell(a["amplitude"], ".4g"), cell(a["stick_fraction"], ".3f"),
                          *((cell(a["open_fraction"], ".3f"),) if opens else ()))
    console.print(table)
    computed = timings.get("states_computed", 0)
    console.print(f"states computed / resumed: {computed} / {timings.get('states_resumed', 0)}; "
                  f"wall time {time_text(timing.wall_s, timing.compile_s)}; wrote {out}"
                  + ("" if figure is None else f", {figure}"))
