"""``stickslip reduce``: a reduced model file (Craig–Bampton or modal truncation, the contact DOFs kept)
and how far its steady-sliding eigenvalues are from the full model's. No physics here."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer
from rich.table import Table

from ..reduction import METHODS, reduce_model, reduction_report, write_model_file
from ..reduction.model_writer import output_paths
from ._app import CLIError, app, build_system, check_choice, check_finite, check_output, console
from ._compiling import time_text, timed
from ._groups import grouped
from ._json import print_json
from ._options import Model, ModelChanges


def _check(method: str, modes: int | None, mode_frequency: float | None, check_frequency: float | None,
           residual: int, out: Path) -> None:
    check_choice("--method", method, METHODS)
    check_finite({"--mode-frequency": mode_frequency, "--check-frequency": check_frequency})
    if modes is None and mode_frequency is None:
        raise CLIError("give the modes to keep: --modes N, or --mode-frequency W (every mode below W rad/s)")
    if modes is not None and modes < 1:
        raise CLIError(f"--modes {modes} must be >= 1")
    if residual < 0:
        raise CLIError(f"--residual {residual} must be >= 0 (blocks of residual vectors; 0: the modes alone)")
    for flag, value in (("--mode-frequency", mode_frequency), ("--check-frequency", check_frequency)):
        if value is not None and not value > 0:
            raise CLIError(f"{flag} {value:g} must be an angular frequency > 0 [rad/s]")
    if out.suffix != ".toml":
        raise CLIError(f"--out {out}: give the reduced model file's path, ending in .toml")


@app.command()
@grouped
def reduce(
    model: Model = "full",
    changes: ModelChanges = ModelChanges(),
    method: str = typer.Option("craig-bampton", "--method", help="craig-bampton (fixed-interface modes) or modal "
                               "(free modes of the structure in contact, with static modes of the kept DOFs)."),
    modes: Optional[int] = typer.Option(None, "--modes", help="The number of modes kept."),
    mode_frequency: Optional[float] = typer.Option(None, "--mode-frequency", help="Keep every mode below this "
                                                   "angular frequency [rad/s] (with --modes: at most that many)."),
    residual: int = typer.Option(0, "--residual", help="Blocks of residual vectors added to the modes: the "
                                 "interior's static response to the contact DOFs' inertia, then its Krylov "
                                 "sequence (docs/fe.md); each block at most one coordinate per kept DOF."),
    check_frequency: Optional[float] = typer.Option(None, "--check-frequency", help="The band of the error report "
                                                    "[rad/s] (default half the highest mode kept)."),
    no_check: bool = typer.Option(False, "--no-check", help="Skip the error report (the full model's CEA)."),
    out: Path = typer.Option(..., "--out", help="The reduced model file (.toml); its matrices (_M, _K, _C .npz) "
                             "and nodes (_nodes.csv) go beside it."),
    overwrite: bool = typer.Option(False, "--overwrite", help="Replace existing output files."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object instead of the tables."),
) -> None:
    """Reduce a sparse (finite-element) model to its contact and loaded DOFs and a few modes, write it as a
    model file every tool takes, and report how far its steady-sliding eigenvalues are from the full model's."""
    _check(method, modes, mode_frequency, check_frequency, residual, out)
    inputs = {**changes.inputs, "--model": Path(model) if Path(model).suffix == ".toml" else None}
    for target in output_paths(out).values():
        check_output(target, overwrite, inputs=inputs)
    system, _ = build_system(model, changes.config, changes.set_)
    with timed() as timing:
        reduced = reduce_model(system, method=method, modes=modes, max_frequency=mode_frequency, residual=residual)
        band = check_frequency if check_frequency is not None else 0.5 * float(reduced.frequencies[-1])
        report = None if no_check else reduction_report(system, reduced.form, band)
    written = write_model_file(reduced.form, out, overwrite=overwrite, inputs=inputs,
                               description=f"{method} reduction of {system.name} ({reduced.frequencies.size} modes)")
    summary = {"out": str(out), "written": [str(p) for p in written], "method": method, "dofs": system.n,
               "reduced_dofs": reduced.form.n, "kept_dofs": int(reduced.boundary.size),
               "modes": int(reduced.frequencies.size), "highest_mode": float(reduced.frequencies[-1]),
               "residual_vectors": reduced.residual,
               "check": None if report is None else report.summary(), "wall_time_s": timing.wall_s,
               "compile_time_s": timing.compile_s}
    if as_json:
        print_json(summary)
        return
    console.print(f"{method}: {system.n} dofs → {reduced.form.n} ({reduced.boundary.size} contact and loaded dofs "
                  f"kept, {reduced.frequencies.size} modes up to {reduced.frequencies[-1]:.6g} rad/s, "
                  f"{reduced.residual} residual vectors); wrote {out}")
    if report is not None:
        table = Table(title=f"steady-sliding eigenvalues with |Im λ| ≤ {band:.6g} rad/s: full model and reduced")
        for head in ("full: growth rate [1/s]", "angular frequency [rad/s]", "reduced: growth rate",
                     "angular frequency", "relative error"):
            table.add_column(head, justify="right")
        for row in report.rows():
            table.add_row(f"{row['full'][0]:.6g}", f"{row['full'][1]:.8g}", f"{row['reduced'][0]:.6g}",
                          f"{row['reduced'][1]:.8g}", f"{row['relative_error']:.2e}")
        console.print(table)
        console.print(f"largest relative error {report.max_error:.2e}")
    console.print(f"wall time {time_text(timing.wall_s, timing.compile_s)}", style="dim")
