"""``stickslip simulate``: one run, written to NetCDF with a figure and a summary.

Parse → library call (:func:`stickslip.simulate`) → write; no physics here. ``--ic RUN.nc``
continues a saved run: its model, parameters and settings, from its last sample on (a ``--model``
other than the run's is refused: a different model cannot continue it).

Ctrl-C during the run ends it with the part done; that part, or a finished run when Ctrl-C comes
while it is written, is written whole (a second Ctrl-C stops the write), and the command then
stops without drawing the figure.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import Optional

import numpy as np
import typer
from rich.table import Table
from rich.text import Text

from ..attractors import run_summary
from ..integrate.driver import simulate as run_simulation
from ..files import netcdf_writer, write_output
from ..integrate.interrupt import finish_first, on_ctrl_c, stop_if_interrupted
from ..integrate.result import load_trajectory
from ..integrate.status import Status
from ..model.compile_ahead import meanwhile
from ..model.library import load_model, plates_variant
from ._app import (CLIError, app, build_system, check_finite, check_outputs, check_positive, console, error_line, exact,
                   given, note_line, warning_line)
from ._compiling import time_text, timed
from ._groups import grouped
from ._json import print_json
from ._kept import keeps, on_interrupt
from ._options import Model, ModelChanges, NoPlot, Overwrite, Plates, SampleRate, Tolerances
from ._outputs import draw_figure, prepare_outputs

#: Most steps a run may need: ``--dt`` is the fixed step, or the largest step of ``event``. At about
#: 0.5 µs a step (measured: 5e7 fixed steps in 23 s) this is hours of computing; a step that
#: needs more is refused rather than left to run for days.
MAX_RUN_STEPS = 10**10

#: Samples the steady-state summary needs in its window (the classification of the response).
WINDOW_SAMPLES = 8

#: Settings of a run that ``--ic RUN.nc`` takes from the saved run unless given: option → parameter name.
_SETTINGS = {"--model": "model", "--method": "method", "--rtol": "rtol", "--atol": "atol", "--dt": "dt",
             "--sample-rate": "sample_rate"}


def _parse_ic(text: str):
    """'zero' | 'equilibrium' | FILE.nc | NAME=VALUE,... (by state name, the others 0) | 2n numbers."""
    if "=" in text:
        values = {}
        for item in text.split(","):
            name, _, value = item.partition("=")
            try:
                values[name.strip()] = float(value)
            except ValueError:
                raise CLIError(f"--ic {text}: {item.strip()!r} is not NAME=NUMBER; e.g. --ic x=1,dx=0.5") from None
        return values
    if "," in text:
        try:
            return [float(v) for v in text.split(",")]
        except ValueError:
            raise CLIError(f"--ic {text}: give one number per state, or NAME=VALUE pairs (e.g. x=1,dx=0.5)") from None
    return text


def _continuation(ctx: typer.Context, ic: str, settings: dict):
    """The saved run ``ic`` (a .nc path) and the settings it gives: those not on the command line.

    Returns
    -------
    system : FrictionModel
        The saved run's model, with its parameters.
    t0 : float
        Time of its last sample [s], where the continuation starts.
    settings : dict
        ``settings`` with every option not given replaced by the saved run's, plus its slip band.
    overridden : list of str
        The options of :data:`_SETTINGS` given on the command line.
    """
    saved = load_trajectory(ic)
    stored = dict(saved.options, model=saved.model, method=saved.method)
    if given(ctx, "model"):
        _check_same_model(settings["model"], saved, ic)
        settings = dict(settings, model=saved.model)
    overridden = [flag for flag, name in _SETTINGS.items() if given(ctx, name) and name != "model"]
    settings = {name: (value if given(ctx, name) or name not in stored else stored[name])
                for name, value in settings.items()}
    if stored.get("slip_band") is not None:
        settings["slip_band"] = stored["slip_band"]
    return saved.system, float(saved.t[-1]), settings, overridden


def _check_same_model(model: str, saved, ic: str) -> None:
    """``--model`` with ``--ic RUN.nc`` must name the run's own model (the plates: its variant)."""
    system = saved.system
    variant = plates_variant(model)
    if system.name == "two-plates":
        same = variant is not None and variant == plates_variant(str(system.parameters.get("variant", "full")))
    else:
        same = variant is None and load_model(model).name == system.name
    if not same:
        raise CLIError(f"--model {model}: {ic} is a run of model {_model_label(system)}, and a run continues its own "
                       f"model; drop --model to continue it, or start a run of {model} from a state "
                       "(--ic NAME=VALUE,... or --ic zero)")


def _check_window(steady_from: float | None, t0: float, t_end: float, sample_rate: float) -> None:
    """The steady-state window (default: the last half) must lie in the run and hold
    :data:`WINDOW_SAMPLES` samples."""
    if steady_from is not None and not t0 <= steady_from < t_end:
        raise CLIError(f"--steady-from {exact(steady_from)} s is outside the run, which goes from {t0:g} to "
                       f"{t_end:g} s; give a time in that range")
    start = t0 + 0.5 * (t_end - t0) if steady_from is None else steady_from
    if not (sample_rate > 0 and math.isfinite((t_end - t0) * sample_rate)):
        return  # a rate of 0 or less, or samples beyond counting: the run refuses them itself
    first = math.ceil((start - t0) * sample_rate - 1e-9)
    n = math.floor((t_end - t0) * sample_rate + 1e-9) - first + 1
    if n < WINDOW_SAMPLES:
        raise CLIError(f"the steady window {start:g} – {t_end:g} s holds {n} samples at {sample_rate:g} Hz and its "
                       f"summary needs {WINDOW_SAMPLES}; give a longer --t-end, a higher --sample-rate"
                       + ("" if steady_from is None else " or an earlier --steady-from"))


def _parse_t_end(text: str, steady_from: float | None) -> float | None:
    """The run length [s] from ``--t-end``, or None for ``auto`` (run until settled, up to ``--cap``).

    A length is checked here, not left to the run: ``--t-end`` is the time added after the end of
    a continued run, and the window and step checks below need it first."""
    if text.strip().lower() == "auto":
        if steady_from is not None:
            raise CLIError("--steady-from and --t-end auto both set the steady window (auto: the last 100 s); "
                           "give one of them")
        return None
    try:
        duration = float(text)
    except ValueError:
        raise CLIError(f"--t-end {text}: give a time in seconds or auto") from None
    check_positive({"--t-end": duration})
    return duration


def _check_steps(duration: float, dt: float | None, time_flag: str = "--t-end") -> None:
    """A step of ``dt`` must cover ``duration`` within :data:`MAX_RUN_STEPS` steps (a step or a
    length that is not a finite number > 0 is the run's to refuse)."""
    if dt is not None and 0 < dt < math.inf and 0 < duration < math.inf and not duration / dt <= MAX_RUN_STEPS:
        raise CLIError(f"--dt {exact(dt)} s takes at least {duration / dt:.3g} steps for {time_flag} "
                       f"{exact(duration)} s, more than the {MAX_RUN_STEPS:.0e} (hours of computing) a run may take "
                       "from the command line; give "
                       f"--dt {duration / MAX_RUN_STEPS:.3g} or more, or a shorter {time_flag}")


def _warn_aliasing(system, sample_rate: float) -> None:
    """One warning line when the samples cannot resolve the model's fastest linear mode."""
    highest = float(system.natural_frequencies().max(initial=0.0))
    if 0 < sample_rate < 2.0 * highest:  # a rate of 0 or less is the run's to refuse
        observed = system.dofs[system.observed_index]
        warning_line(f"--sample-rate {sample_rate:g} Hz is below twice the highest linear mode frequency of model "
                     f"{_model_label(system)} ({highest:.4g} Hz): the spectrum and the frequency of {observed} alias; "
                     f"give --sample-rate {math.ceil(2.0 * highest)} or more")


def _model_label(system) -> str:
    """The model's name, with the plates' variant."""
    variant = system.parameters.get("variant") if system.name == "two-plates" else None
    return system.name + (f" ({variant})" if variant else "")


@app.command()
@grouped
def simulate(
    *,  # options only (typer reads them by name)
    ctx: typer.Context,
    plates: Plates = Plates(),
    model: Model = "full",
    t_end: str = typer.Option("100", "--t-end", help="Simulated time [s], or 'auto': extend the run until it has "
                              "settled, up to --cap (the steady window is then the last 100 s). With --ic RUN.nc, "
                              "the time added after the end of that run."),
    cap: float = typer.Option(2000.0, "--cap", help="With --t-end auto: the longest run [s]."),
    method: str = typer.Option("event", "--method", help="Integration method: event | aeom | naeom."),
    dt: Optional[float] = typer.Option(None, "--dt", help="Fixed step (fixed-step methods) or largest step (event) [s]."),
    tolerances: Tolerances = Tolerances(),
    ic: str = typer.Option("zero", "--ic", help="zero | equilibrium (steady sliding) | NAME=VALUE,... by state name "
                           "(e.g. x=1,dx=1; the others 0) | one number per state, comma-separated | RUN.nc: continue "
                           "that run from its end, with its model, parameters and settings unless given here."),
    perturb: Optional[float] = typer.Option(None, "--perturb", help="Added to the observed coordinate of the initial "
                                            "state (the plates' φ [rad])."),
    sample_rate: SampleRate = 1000.0,
    steady_from: Optional[float] = typer.Option(None, "--steady-from", help="Start of the steady-state window, in the "
                                                "run's time [s] (default: the last half of the run)."),
    changes: ModelChanges = ModelChanges(),
    out: Optional[Path] = typer.Option(None, "--out", help="NetCDF output (default run.nc; with --json, nothing is "
                                       "written unless --out is given); the figure goes beside it as .png."),
    overwrite: Overwrite = False,
    no_plot: NoPlot = False,
    as_json: bool = typer.Option(False, "--json", help="Print the steady-state summary as one JSON object."),
) -> None:
    """Simulate a model with exact stick-slip (default: the two plates, Table 1, N = 50 N, Ω = 5 rad/s, 100 s)."""
    start = _parse_ic(ic)
    settings = dict(model=model, method=method, rtol=tolerances.rtol, atol=tolerances.atol, dt=dt,
                    sample_rate=sample_rate)
    run_file = Path(start) if isinstance(start, str) and start.endswith(".nc") else None
    base, t0, overridden = None, 0.0, []
    if run_file is not None:
        base, t0, settings, overridden = _continuation(ctx, start, settings)
    system, set_by = build_system(settings.pop("model"), changes.config, changes.set_, base=base, **plates.named())
    if "slip_band" in settings:
        system = system.with_slip_band(settings.pop("slip_band"))
    duration = _parse_t_end(t_end, steady_from)
    check_finite({"--perturb": perturb, "--steady-from": steady_from})
    time_flag = "--cap" if duration is None else "--t-end"
    longest = cap if duration is None else duration
    if duration is not None:  # with --t-end auto the window is the last part of the settled run
        _check_window(steady_from, t0, t0 + duration, settings["sample_rate"])
    _check_steps(longest, settings["dt"], time_flag)
    write = out is not None or not as_json
    out = Path("run.nc") if out is None else out
    inputs = {"--ic": run_file, **changes.inputs}
    if write:
        check_outputs(out, not no_plot, overwrite, inputs=inputs)
    if run_file is not None:
        overridden = set_by + overridden
        note_line(f"continuing {run_file} from t = {t0:g} s with its model, parameters and settings"
                  + (f"; overridden: {', '.join(overridden)}" if overridden else ""))
    _warn_aliasing(system, settings["sample_rate"])

    prepare = functools.partial(prepare_outputs, not no_plot) if write else lambda: None
    # Ctrl-C ends the run with the part done, written below
    with on_ctrl_c(partial=True), meanwhile(prepare), timed() as timing:
        if duration is None:
            from ..attractors import simulate_until_settled  # noqa: PLC0415 - it loads the orbits layer

            settled = simulate_until_settled(system, cap=cap, t0=t0, ic=start, perturbation=perturb, **settings)
            traj, verdict = settled.trajectory, settled.attractor
        else:
            traj = run_simulation(system, t0 + duration, t0=t0, ic=start, perturbation=perturb,
                                  steady_from=steady_from, **settings)
            verdict = None
    # a run that stopped early can be too short for its steady-state window, which the file needs
    keep = write and int(np.count_nonzero(traj.t >= traj.steady_from)) >= 2
    interrupted = traj.status_code == Status.INTERRUPTED
    if keep:
        out.parent.mkdir(parents=True, exist_ok=True)
        keeps(out, f"the run up to t = {traj.t[-1]:g} s is in {out}" if interrupted else
              f"the finished run is in {out}")
        with finish_first():  # what is done is kept: a Ctrl-C now waits for the file
            write_output(out, netcdf_writer(traj.to_xarray()), overwrite=overwrite, inputs=inputs)
    if interrupted and not keep:
        on_interrupt(f"the run stopped at t = {traj.t[-1]:g} s with too few samples to write; nothing was written"
                     if write else "nothing was written (--json without --out)")
    stop_if_interrupted()  # a Ctrl-C during the run (its part is written) or as it finished
    figure = draw_figure(out, lambda tmp: _save_figure(traj, tmp), skip=not keep or no_plot,
                         overwrite=overwrite, inputs=inputs)
    if traj.status != "success":
        error_line(f"the run stopped early: {traj.status}; " + (f"what it computed is in {out}" if keep else
                   "it kept too few samples to write" if write else "nothing was written (--json without --out)"))
        raise typer.Exit(1)
    summary = {**run_summary(traj, verdict), "compile_time_s": timing.compile_s}
    if as_json:
        print_json(summary)
    else:
        _print_summary(traj, summary, out if write else None, figure)


def _save_figure(traj, path: Path) -> None:
    """The run's figure at ``path``; the plot layer is imported here, where a figure is drawn
    (``--json`` without ``--out``, and ``--no-plot``, draw none)."""
    from ..plot.trajectory import save_trajectory_figure  # noqa: PLC0415

    save_trajectory_figure(traj, path)


def _print_summary(traj, summary: dict, out: Path | None, figure) -> None:
    s = traj.steady
    p = traj.params
    system = traj.system
    observed = system.dofs[system.observed_index]
    symbol = "φ" if p is not None else observed
    title = (f"stickslip: model {traj.model}, N = {p.N:g} N, Ω = {p.Omega:g} rad/s, μk = {p.mu_k:g}, "
             f"Δμ = {p.delta_mu:g}, α = {p.alpha:g}" if p is not None else
             f"stickslip: model {system.name} ({system.source}; parameters: stickslip models)")
    table = Table(title=Text(title), show_header=False)
    freq, dominant = summary["fundamental_frequency_hz"], summary["dominant_frequency_hz"]
    kind = summary["attractor"] + (f", {summary['period_count']} peak(s) of {symbol} per period" if summary["period_count"] else "")
    confirmed = f"; confirmed by {summary['confirmed_by']}" if summary.get("confirmed_by") else ""
    kind += (f" (settled by {summary['settle_time_s']:g} s{confirmed})" if summary["settled"]
             else f" ({summary['evidence'].get('reason', 'no verdict')})")
    wrote = "nothing" if out is None else str(out) + ("" if figure is None else f", {figure}")
    rows = [
        ("status", traj.status),
        ("time", f"{traj.t[0]:g} – {traj.t[-1]:g} s"),
        ("steady window", f"{s.t_from:g} – {s.t_to:g} s"),
        ("response", kind),
        (f"fundamental frequency of {symbol}", "–" if freq is None else f"{freq:.6g} Hz"),
        (f"dominant frequency of {symbol}", "–" if dominant is None else f"{dominant:.6g} Hz"),
        ("stick fraction", f"{s.stick_fraction:.4f}"),
        *([("open fraction", f"{s.open_fraction:.4f}")] if s.open_fraction is not None else []),
        *([("impacts", f"{s.impacts}"), ("max impact speed", f"unknown: {s.max_impact_speed_reason}"
                                          if s.max_impact_speed_reason else f"{s.max_impact_speed:.4g}")]
          if s.impacts is not None else []),
        ("transitions in window", str(s.n_transitions)),
        (f"{symbol} min / max", f"{s.minimum:.6g} / {s.maximum:.6g}" + f" {system.units.get(observed, '')}".rstrip(" -")),
        ("steps (accepted + rejected)", f"{traj.stats.steps} ({traj.method})"),
        ("wall time", time_text(traj.stats.wall_time_s, summary["compile_time_s"], "the integration")),
        ("wrote", wrote),
    ]
    for key, value in rows:
        table.add_row(key, Text(value))
    console.print(table)
    if not summary["settled"]:
        console.print("not settled in the window: no period is claimed (the dominant frequency is the highest "
                      "peak of the spectrum); run longer or use --t-end auto", style="dim")
