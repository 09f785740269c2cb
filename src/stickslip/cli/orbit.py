"""``stickslip orbit`` and ``stickslip lyapunov``: a periodic orbit with its Floquet multipliers,
and the Lyapunov spectrum of the attractor reached from a start.

Parse → library call (:func:`stickslip.orbits.periodic_orbit`,
:func:`stickslip.orbits.lyapunov_spectrum`) → write NetCDF and a figure; no physics here.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import typer
from rich.table import Table
from rich.text import Text

from ..errors import SteadySlidingOrbitError
from ..files import netcdf_writer
from ..orbits import lyapunov_spectrum, periodic_orbit, resolve_section
from ..orbits.lyapunov import FRAME_TIME
from ..orbits.continuation import start_run
from ..orbits.problem import METHODS as MONODROMY_METHODS
from ..orbits.problem import stick_summary
from ..orbits.start import default_start
from ..plot.orbits import save_lyapunov_spectrum_figure, save_orbit_figure
from ._app import CLIError, app, build_system, check_below_one, check_choice, check_outputs, check_positive, console
from ._compiling import time_text, timed
from ._groups import grouped
from ._json import print_json
from ._options import (JsonSummary, Model, ModelChanges, OperatingPoint, OrbitRtol, OrbitSearch, Outputs, SlipBand,
                       StartIc, Tol)
from ._outputs import write_result
from .simulate import _parse_ic

#: Ways to compute the Lyapunov spectrum (:func:`stickslip.orbits.lyapunov_spectrum`).
_LYAPUNOV_METHODS = ("variational", "finite-difference")


def parse_start(ic: str | None):
    """``--ic``: a start's name or a state (``NAME=VALUE,...`` or 2n numbers), checked for its form
    (the model checks the name); None when not given."""
    return None if ic is None else _parse_ic(ic)


def model_system(model: str, changes: ModelChanges, slip_band, *, swept=None, **named):
    """The FrictionModel of ``--model``, ``--config``, ``--set``, the plates' named options (the CLI's
    :func:`~._app.build_system`) and ``--slip-band``."""
    system, _ = build_system(model, changes.config, changes.set_, swept=swept, **named)
    return system if slip_band is None else system.with_slip_band(slip_band)


def model_label(result) -> str:
    """The model of a result for titles: the plates' variant with N and Ω, or the model's name."""
    p = result.params
    return result.model if p is None else f"{result.model}, N = {p.N:g} N, Ω = {p.Omega:g} rad/s"


def parse_section(text: str):
    """``--section``: ``max``, ``DOF_max`` or ``DOF=LEVEL`` as :func:`stickslip.orbits.resolve_section` takes it."""
    if "=" in text:
        dof, _, level = text.partition("=")
        try:
            return dof.strip(), float(level)
        except ValueError:
            raise CLIError(f"--section {text}: {level!r} is not a number; e.g. --section x1=0.5") from None
    return text


def _finite_or_none(x: float):
    """A float for JSON, ``None`` where it is not finite (JSON has no ±inf or NaN)."""
    x = float(x)
    return x if math.isfinite(x) else None


@app.command("orbit")
@grouped
def orbit_command(
    point: OperatingPoint = OperatingPoint(),
    model: Model = "full",
    search: OrbitSearch = OrbitSearch(search_time=30.0),
    period_multiplicity: int = typer.Option(1, "--period-multiplicity", help="Section crossings per period."),
    monodromy: str = typer.Option("saltation", "--monodromy", help="Monodromy matrix: saltation | finite-difference."),
    rtol: OrbitRtol = 1e-10,
    tol: Tol = 1e-8,
    slip_band: SlipBand = None,
    changes: ModelChanges = ModelChanges(),
    outputs: Outputs = Outputs(out=Path("orbit.nc")),
    as_json: JsonSummary = False,
) -> None:
    """Find a periodic orbit by Newton shooting on a Poincaré section (default: the maximum of the model's observed coordinate, the plates' φ), with its Floquet multipliers.

    A run of --search-time seconds from --ic gives the guess (its last section crossings); Newton shooting converges it to --tol, and the monodromy matrix of the orbit gives the Floquet multipliers. Writes the orbit (section state, period, multipliers, monodromy) to --out and, beside it, φ over one period with the stick phases shaded and the multipliers with the unit circle.
    """
    start = parse_start(search.ic)
    # the command line's checks: the library refuses the monodromy and the multiplicity only after the
    # start run, calls --search-time t_end, and leaves --tol unbounded
    check_positive({"--search-time": search.search_time, "--tol": tol})
    check_below_one({"--tol": tol})
    check_choice("--monodromy", monodromy, MONODROMY_METHODS)
    if period_multiplicity < 1:
        raise CLIError(f"--period-multiplicity must be >= 1, got {period_multiplicity}")
    system = model_system(model, changes, slip_band, **point.named())
    sec = resolve_section(parse_section(search.section), system)
    out, inputs = outputs.out, changes.inputs
    check_outputs(out, not outputs.no_plot, outputs.overwrite, inputs=inputs)
    with timed() as timing:
        run = start_run(system, start, t_end=search.search_time, rtol=rtol)
        try:
            orbit = periodic_orbit(None, run, section=sec, period_multiplicity=period_multiplicity, rtol=rtol,
                                   tol=tol, monodromy=monodromy)
        except SteadySlidingOrbitError:
            x = system.dofs[system.observed_index]
            raise CLIError(f"shooting from the start run (--ic {search.ic or 'default'}) converged onto steady sliding, "
                           f"the equilibrium, not a cycle; start from a state on the cycle, e.g. --ic {x}=...,d{x}=..., "
                           "or give a longer --search-time") from None
    one_period = orbit.trajectory(1.0)
    stick = stick_summary(one_period, orbit.period)
    figure = write_result(outputs, lambda: netcdf_writer(orbit.to_xarray()), holds=f"the orbit is in {out}",
                          inputs=inputs, draw=lambda tmp: save_orbit_figure(orbit, one_period, tmp))
    others = np.abs(orbit.nontrivial_multipliers)
    summary = {
        "out": str(out), "figure": None if figure is None else str(figure), "model": orbit.model,
        "period_s": float(orbit.period), "frequency_hz": float(orbit.frequency),
        "stick_phases": int(orbit.stick_phases), **stick,
        "max_nontrivial_multiplier_abs": float(others.max()) if others.size else None,
        "trivial_multiplier_error": float(abs(orbit.trivial_multiplier - 1.0)),
        "stable": bool(orbit.stable), "verdict": orbit.verdict, "monodromy": orbit.options.get("monodromy", monodromy),
        "iterations": int(orbit.iterations), "residual": float(orbit.residual),
        "wall_time_s": timing.wall_s, "compile_time_s": timing.compile_s,
    }
    if as_json:
        print_json(summary)
        return
    table = Table(title=f"stickslip orbit ({model_label(orbit)})", show_header=False)
    table.add_row("period", f"{summary['period_s']:.10g} s ({summary['frequency_hz']:.8g} Hz)")
    for name, c in stick["contacts"].items():
        table.add_row("stick" if len(stick["contacts"]) == 1 else f"stick of {name}",
                      f"{c['stick_phases']} phase(s), {c['stick_fraction']:.4f} of the period")
    if summary["max_nontrivial_multiplier_abs"] is not None:
        table.add_row("largest |μ| (non-trivial)", f"{summary['max_nontrivial_multiplier_abs']:.8g}")
    table.add_row("|μ_trivial − 1|", f"{summary['trivial_multiplier_error']:.2e} ({summary['monodromy']})")
    table.add_row("stability", Text(orbit.verdict, style={"stable": "green", "marginal": "yellow"}.get(orbit.verdict,
                                                                                                       "bold red")))
    table.add_row("Newton", f"{summary['iterations']} iterations, residual {summary['residual']:.2e}")
    table.add_row("wall time", time_text(timing.wall_s, timing.compile_s, "start run + shooting + multipliers"))
    table.add_row("wrote", str(out) + ("" if figure is None else f", {figure}"))
    console.print(table)


@app.command("lyapunov")
@grouped
def lyapunov_command(
    *,
    point: OperatingPoint = OperatingPoint(),
    model: Model = "full",
    ic: StartIc = None,
    t_transient: float = typer.Option(50.0, "--t-transient", help="Transient simulated and discarded first [s]."),
    t_average: float = typer.Option(200.0, "--t-average", help="Averaging time [s]."),
    method: str = typer.Option("variational", "--method", help="variational (saltation matrices) | "
                               "finite-difference (perturbed trajectories; works where the variational one refuses)."),
    rtol: OrbitRtol = 1e-10,
    seed: int = typer.Option(0, "--seed", help="Seed of the random orthonormal frame the spectrum starts from "
                             "(an integer >= 0)."),
    t_frame: float = typer.Option(FRAME_TIME, "--t-frame", help="Time [s] after the transient in which the frame "
                                  "turns before the averaging, nothing counted (>= 0; 0 averages from the start)."),
    slip_band: SlipBand = None,
    changes: ModelChanges = ModelChanges(),
    outputs: Outputs = Outputs(out=Path("lyapunov.nc")),
    as_json: bool = typer.Option(False, "--json", help="Print a one-line JSON summary (exponents largest first)."),
) -> None:
    """Lyapunov spectrum (Benettin–Shimada–Nagashima) of the attractor reached from --ic.

    Runs --t-transient seconds from --ic, lets a random orthonormal frame (--seed) turn for --t-frame seconds, then averages over --t-average seconds. Writes the exponents and their running estimates to --out and, beside it, the convergence of each exponent over time. Directions collapsed by stick come out as large negative numbers (−∞ in exact arithmetic) and are left out of the figure.
    """
    start = parse_start(ic)
    # the command line's checks: the library refuses a method only after the transient run, and a
    # non-finite time in other words (t_end - t0 of a run, a memory estimate)
    check_positive({"--t-transient": t_transient, "--t-average": t_average})
    check_choice("--method", method, _LYAPUNOV_METHODS)
    if seed < 0:
        raise CLIError(f"--seed {seed}: give an integer >= 0")
    if not (math.isfinite(t_frame) and t_frame >= 0.0):
        raise CLIError(f"--t-frame {t_frame}: give a finite time >= 0 [s] (0 averages from the start)")
    system = model_system(model, changes, slip_band, **point.named())
    out, inputs = outputs.out, changes.inputs
    check_outputs(out, not outputs.no_plot, outputs.overwrite, inputs=inputs)
    start = default_start(system) if start is None else start
    with timed() as timing:
        spectrum = lyapunov_spectrum(system, start, t_transient=t_transient, t_average=t_average, rtol=rtol,
                                     method=method, seed=seed, t_frame=t_frame)
    figure = write_result(outputs, lambda: netcdf_writer(spectrum.to_xarray()), holds=f"the spectrum is in {out}",
                          inputs=inputs, draw=lambda tmp: save_lyapunov_spectrum_figure(spectrum, tmp))
    ordered = spectrum.exponents  # λ1 ≥ … ≥ λk
    summary = {
        "out": str(out), "figure": None if figure is None else str(figure), "model": spectrum.model,
        "method": method, "t_transient_s": float(t_transient), "t_average_s": float(t_average),
        "seed": seed, "t_frame_s": float(t_frame),
        "exponents": [_finite_or_none(x) for x in ordered], "largest": _finite_or_none(ordered[0]),
        "stick_phases": int(spectrum.stick_phases), "wall_time_s": timing.wall_s,
        "compile_time_s": timing.compile_s,
    }
    if as_json:
        print_json(summary)
        return
    console.print(f"stickslip lyapunov: {model_label(spectrum)}, {method}",
                  soft_wrap=True)
    table = Table()
    table.add_column("#", justify="right")
    table.add_column("λ [1/s]", justify="right")
    for i, lam in enumerate(ordered, start=1):
        table.add_row(str(i), f"{lam:+.6g}", style="bold red" if lam > 0 else None)
    console.print(table)
    console.print(f"averaged over {t_average:g} s after a {t_transient:g} s transient from --ic {ic} and "
                  f"{t_frame:g} s of the frame's turning (seed {seed}); "
                  f"{spectrum.stick_phases} stick phases; wall time {time_text(timing.wall_s, timing.compile_s)}",
                  soft_wrap=True)
    console.print(f"wrote {out}" + ("" if figure is None else f", {figure}"), soft_wrap=True)
