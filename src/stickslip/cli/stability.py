"""``stickslip stability`` and ``stickslip stability-map``: linear stability of steady sliding.

Parse → library call → print/write; no physics here.
"""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import numpy as np
import typer
from rich.table import Table
from rich.text import Text

from ..errors import StickSlipError
from ..files import netcdf_writer
from ..memory import check_memory, largest_count
from ..plot.stability import save_stability_map_figure
from ..stability.analysis import stability as run_stability
from ..stability.maps import parse_family
from ..stability.maps import stability_map as run_map
from ..stability.sparse_input import is_sparse_model
from ..stability.verdict import stability_verdict
from ._app import CLIError, app, build_system, check_finite, check_outputs, console
from ._band import Band, report_band, verdict_words
from ._compiling import time_text, timed
from ._groups import grouped
from ._json import print_json
from ._options import Friction, JsonSummary, MapModel, Model, ModelChanges, Outputs, Plates
from ._outputs import write_result
from .sweep import _VALUE_BYTES, parse_values


@app.command()
@grouped
def stability(
    plates: Plates = Plates(),
    model: Model = "full",
    changes: ModelChanges = ModelChanges(),
    band: Band = Band(),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object: equilibrium, eigenvalues, max_real_part, "
                                 "stable, verdict (stable | marginal | unstable), marginal_tolerance."),
) -> None:
    """Equilibrium of steady sliding (plates: Eq. 14) and its eigenvalues (Eq. 15), for any model; for sparse
    (finite-element) models every eigenvalue of a band (complex eigenvalue analysis, --max-frequency)."""
    system, _ = build_system(model, changes.config, changes.set_, **plates.named())
    sparse = band.asked or is_sparse_model(system)
    if sparse:
        band.check(changes.inputs)
        if band.max_frequency is None:
            raise CLIError(f"model {system.name!r} has {system.n} dofs: give --max-frequency, the top of the band whose "
                           "eigenvalues are computed [rad/s]")
    with timed() as timing:
        if sparse:
            result = run_stability(system, max_frequency=band.max_frequency, method=band.method, cutoff=band.cutoff,
                                   residual=not band.no_residual_vectors)
        else:
            result = run_stability(system)
    if sparse:
        report_band(result, timing, band.write(result, changes.inputs), as_json)
        return
    if as_json:
        print_json({**result.summary(), "wall_time_s": timing.wall_s, "compile_time_s": timing.compile_s})
        return
    p = result.params
    title = f"steady sliding: model {result.model}"
    if p is not None:
        title += f", N = {p.N:g} N, Ω = {p.Omega:g} rad/s, μk = {p.mu_k:g}, Δμ = {p.delta_mu:g}, α = {p.alpha:g}"
    eq = Table(title=title)
    for name in result.dofs:
        eq.add_column(name, justify="right")
    eq.add_row(*[f"{result.equilibrium_dict[d]:.6g}" for d in result.dofs])
    console.print(eq)
    if result.open_contacts:
        console.print(f"open at steady sliding (no force, nothing in the linearisation): "
                      f"{', '.join(result.open_contacts)}")
    modes = Table(title="modes (one per conjugate pair), sorted by growth rate")
    for head in ("#", "growth rate [1/s]", "frequency [Hz]", "dominant DOF", "shape |.| (" + ", ".join(result.dofs) + ")"):
        modes.add_column(head, justify="right" if head != "dominant DOF" else "left")
    for number, row in enumerate(result.modes(), start=1):  # 1, 2, … (row["index"] counts both of each pair)
        shape = ", ".join(f"{abs(c):.3g}" for c in row["shape"].values())
        style = {"unstable": "bold red", "marginal": "yellow"}.get(stability_verdict(row["growth_rate"],
                                                                                       result.tolerance))
        modes.add_row(str(number), f"{row['growth_rate']:.6g}", f"{row['frequency_hz']:.6g}",
                      row["dominant_dof"], shape, style=style)
    console.print(modes)
    console.print(Text.assemble(f"max real part {result.max_real_part:.6g} 1/s: steady sliding is ",
                                verdict_words(result)))
    console.print(f"wall time {time_text(timing.wall_s, timing.compile_s)}", style="dim")


def _check_axis(name: str, lo: float, hi: float, n: int) -> None:
    """``n`` values from ``lo`` to ``hi`` must make a map axis ``name`` (``N`` or ``omega``)."""
    check_finite({f"--{name}-min": lo, f"--{name}-max": hi})
    if n < 2:
        raise CLIError(f"--{name}-points must be >= 2, got {n}")
    if not hi > lo:
        raise CLIError(f"--{name}-max {hi:g} must be greater than --{name}-min {lo:g}")
    check_memory(n * float(_VALUE_BYTES), f"--{name}-points {n}",
                 lambda memory: f"give --{name}-points {largest_count(_VALUE_BYTES, memory)} or fewer")
    if name == "N" and lo <= 0:
        raise CLIError(f"--N-min {lo:g}: normal loads must be > 0 (the plates are pressed together)")
    if name == "omega" and lo <= 0 <= hi:
        raise CLIError(f"--omega-min {lo:g} and --omega-max {hi:g} straddle 0, where there is no steady sliding; "
                       "give a range on one side of 0, e.g. --omega-min 0.2 --omega-max 20")


@app.command("stability-map")
@grouped
def stability_map(
    *,  # options only (typer reads them by name)
    n_min: float = typer.Option(2.0, "--N-min", help="Smallest normal load [N]."),
    n_max: float = typer.Option(200.0, "--N-max", help="Largest normal load [N]."),
    n_points: int = typer.Option(100, "--N-points", help="Number of N values."),
    omega_min: float = typer.Option(0.2, "--omega-min", help="Smallest Ω [rad/s] (the range must not straddle 0)."),
    omega_max: float = typer.Option(20.0, "--omega-max", help="Largest Ω [rad/s]."),
    omega_points: int = typer.Option(100, "--omega-points", help="Number of Ω values (brackets for the boundary search)."),
    axis: Optional[List[str]] = typer.Option(None, "--axis", help="An axis as PATH=start:stop:count or PATH=v1,v2,... "
                                             "(give two: the first is x, the boundary is sought along the second), "
                                             "e.g. --axis contact.0.normal_force=0.5:2:31 --axis contact.0.drive=0.2:3:57. "
                                             "Default for the plates: N and Ω from the options above."),
    family: Optional[str] = typer.Option(None, "--family", help="Third parameter and its values, e.g. delta_mu=0.1,0.2,0.3, "
                                         "model=full,rotation or contact.0.friction.alpha=1.5,2."),
    friction: Friction = Friction(),
    model: MapModel = "full",
    changes: ModelChanges = ModelChanges(),
    no_boundary: bool = typer.Option(False, "--no-boundary", help="Skip the root-finding of the boundary along the second axis."),
    outputs: Outputs = Outputs(out=Path("stability_map.nc")),
    as_json: JsonSummary = False,
) -> None:
    """Stable/unstable regions of steady sliding over two parameters of any model, with the boundary by
    root finding (plates: (N, Ω), Figs. 3, 4)."""
    try:
        members = parse_family(family)
    except ValueError as exc:  # the parser's messages name the fix; here they also name the option
        raise CLIError(f"--family: {exc}") from None
    names, values = _map_axes(axis, (n_min, n_max, n_points), (omega_min, omega_max, omega_points))
    if members is not None and members[0] in names:
        raise CLIError(f"--family {family}: {members[0]} is an axis of the map; choose another parameter or model")
    swept = ({name: f"--axis {name}" for name in names} if axis else
             {"N": "--N-min/--N-max", "Omega": "--omega-min/--omega-max"})
    if members is not None and members[0] != "model":
        swept[members[0]] = f"--family {members[0]}"
    system, _ = build_system(model, changes.config, changes.set_, swept=swept, **friction.named())
    if axis is None and system.name != "two-plates":
        raise CLIError(f"model {system.name!r} has no N and Ω: give its two axes, e.g. "
                       "--axis contact.0.normal_force=0.5:2:31 --axis contact.0.drive=0.2:3:57")
    out, inputs = outputs.out, changes.inputs
    check_outputs(out, not outputs.no_plot, outputs.overwrite, inputs=inputs)
    _check_axes(system, names, values, axis)
    with timed() as timing:
        try:
            smap = run_map(system, values[0], values[1], family=members, boundary=not no_boundary, axes=names)
        except ValueError as exc:
            if isinstance(exc, StickSlipError):
                raise
            raise _map_error(exc, names, axis, family) from None
    figure = write_result(outputs, lambda: netcdf_writer(smap.to_xarray()), holds=f"the map is in {out}",
                          inputs=inputs, draw=lambda tmp: save_stability_map_figure(smap, tmp))
    rows = []
    for f, label in enumerate(smap.family_labels):
        mrp, verdicts = smap.max_real_part[f], smap.verdicts[f]
        found = np.isfinite(mrp)
        rows.append({
            "member": label,
            "unstable_fraction": float(np.mean(verdicts[found] == "unstable")) if np.any(found) else None,
            "marginal_fraction": float(np.mean(verdicts[found] == "marginal")) if np.any(found) else None,
            "no_equilibrium_fraction": float(np.mean(~found)),
            "boundary_points": int(np.sum(np.isfinite(smap.boundary[f]))),
        })
    if as_json:
        print_json({"out": str(out), "figure": None if figure is None else str(figure), "axes": list(names),
                     "family": smap.family_name, "members": rows, "timings": smap.timings,
                     "wall_time_s": timing.wall_s, "compile_time_s": timing.compile_s})
        return
    table = Table(title=f"stability map {values[0].size} × {values[1].size} ({names[0]} × {names[1]}), "
                        f"model {smap.model}")
    for head in ("member", "unstable fraction", "marginal", "no equilibrium", "boundary points"):
        table.add_column(head)
    for r in rows:
        uf, mf = ("–" if r[key] is None else f"{r[key]:.3f}" for key in ("unstable_fraction", "marginal_fraction"))
        table.add_row(r["member"], uf, mf, f"{r['no_equilibrium_fraction']:.3f}", str(r["boundary_points"]))
    console.print(table)
    t = smap.timings
    detail = f"grid {t['grid_s']:.2f} s, boundary {t['boundary_s']:.2f} s"
    console.print(f"wall time {time_text(timing.wall_s, timing.compile_s, detail)}; wrote {out}"
                  + ("" if figure is None else f", {figure}"))


def _check_axes(system, names: tuple[str, str], values: list, axis: list[str] | None) -> None:
    """Refuse, naming ``--axis``, a parameter the model lacks or a value it refuses (before the map)."""
    for name, vals, item in zip(names, values, axis or ()):
        try:
            for v in vals:
                system.replace(**{name: float(v)})
        except StickSlipError as exc:
            raise CLIError(f"--axis {item.strip()}: {exc}") from None


def _map_error(exc: ValueError, names: tuple[str, str], axis: list[str] | None, family: str | None) -> CLIError:
    """The library's refusal of the map as one line naming the option it is about (an axis value
    without steady sliding, a family the model cannot have)."""
    text = str(exc)
    for name, item in zip(names, axis or ()):
        if text.startswith(f"{name} "):
            return CLIError(f"--axis {item.strip()}: {text}")
    return CLIError(f"--family {family}: {text}" if family is not None else text)


def _map_axes(axis: list[str] | None, n_range: tuple, omega_range: tuple) -> tuple[tuple[str, str], list]:
    """The map's two parameter names and values: from ``--axis`` (two), else N and Ω of the plates' options."""
    if not axis:
        _check_axis("N", *n_range)
        _check_axis("omega", *omega_range)
        return ("N", "Omega"), [np.linspace(*n_range), np.linspace(*omega_range)]
    if len(axis) != 2:
        raise CLIError(f"give --axis exactly twice (the map's two parameters), got {len(axis)}")
    names, values = [], []
    for item in axis:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise CLIError(f"--axis expects PATH=VALUES, got {item!r}; e.g. --axis contact.0.drive=0.2:3:57")
        vals = np.asarray(parse_values(name, text, option="--axis"), dtype=float)
        if vals.size < 2 or not np.all(np.diff(vals) > 0):
            raise CLIError(f"--axis {item}: give at least 2 increasing values, e.g. {name}=0.2:3:57")
        names.append(name)
        values.append(vals)
    if names[0] == names[1]:
        raise CLIError(f"--axis {names[0]} given twice; the map needs two different parameters")
    return (names[0], names[1]), values
