"""``stickslip mode-coupling``: the band's eigenvalues against the friction coefficient, with the
coalescences marked (computing in :mod:`stickslip.stability.mode_coupling`, figure in
:mod:`stickslip.plot.fe`). No physics here."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import typer
from rich.table import Table

from ..files import netcdf_writer
from ..plot._common import save_figure
from ..plot.fe import plot_mode_coupling
from ..stability.mode_coupling import mode_coupling as run_mode_coupling
from ._app import CLIError, app, build_system, check_choice, check_finite, check_outputs, console
from ._compiling import time_text, timed
from ._groups import grouped
from ._options import JsonSummary, Model, ModelChanges, Outputs
from ._outputs import write_result
from .sweep import parse_values


@app.command("mode-coupling")
@grouped
def mode_coupling(
    model: Model = "full",
    changes: ModelChanges = ModelChanges(),
    mu: str = typer.Option(..., "--mu", help="The friction coefficients, start:stop:count or v1,v2,... (every "
                           "contact's mu_k is set to each), e.g. --mu 0:1:41."),
    max_frequency: float = typer.Option(..., "--max-frequency", help="The top of the band [rad/s]."),
    method: str = typer.Option("direct", "--method", help="The CEA of each point: direct, modal or dense."),
    outputs: Outputs = Outputs(out=Path("mode_coupling.nc")),
    as_json: JsonSummary = False,
) -> None:
    """The mode-coupling diagram of any model with constant contact kinematics: frequencies and real parts of
    the band's eigenvalues against the friction coefficient, the instabilities' onsets located by root finding."""
    check_choice("--method", method, ("direct", "modal", "dense"))
    check_finite({"--max-frequency": max_frequency})
    if not max_frequency > 0:
        raise CLIError(f"--max-frequency {max_frequency:g} must be an angular frequency > 0 [rad/s]")
    values = np.asarray(parse_values("mu", mu, option="--mu"), dtype=float)
    if values.size < 2 or not np.all(np.diff(values) > 0) or values[0] < 0:
        raise CLIError(f"--mu {mu}: give at least 2 increasing values >= 0, e.g. --mu 0:1:41")
    out, inputs = outputs.out, changes.inputs
    check_outputs(out, not outputs.no_plot, outputs.overwrite, inputs=inputs)
    system, _ = build_system(model, changes.config, changes.set_, swept={"mu_k": "--mu"})
    with timed() as timing:
        result = run_mode_coupling(system, values, max_frequency, method=method)
    figure = write_result(outputs, lambda: netcdf_writer(result.to_xarray()), holds=f"the diagram is in {out}",
                          inputs=inputs, draw=lambda tmp: save_figure(plot_mode_coupling(result), tmp))
    if as_json:
        print(json.dumps({"out": str(out), "figure": None if figure is None else str(figure), "onsets": result.onsets,
                          "critical_mu": result.critical_mu, "wall_time_s": timing.wall_s,
                          "compile_time_s": timing.compile_s}))
        return
    table = Table(title=f"mode coupling of model {result.model}: onsets of instability (Re λ through 0) in "
                        f"{values[0]:g} ≤ μ ≤ {values[-1]:g}")
    for head in ("μ", "angular frequency [rad/s]", "branch", "partner"):
        table.add_column(head, justify="right")
    for onset in result.onsets:
        table.add_row(f"{onset['mu']:.8g}", f"{onset['angular_frequency']:.8g}", str(onset["branch"]),
                      str(onset["partner"]))
    console.print(table if result.onsets else "no onset: steady sliding is stable over the sweep")
    console.print(f"wall time {time_text(timing.wall_s, timing.compile_s)}; wrote {out}"
                  + ("" if figure is None else f", {figure}"))
