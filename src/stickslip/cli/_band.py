"""The sparse path of ``stickslip stability``: its options, its table and its outputs (no physics here)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.table import Table
from rich.text import Text

from ..files import netcdf_writer, write_output
from ._app import CLIError, check_choice, check_finite, check_nc_path, check_output, console
from ._compiling import time_text

__all__ = ["Band", "report_band"]

MaxFrequency = Annotated[Optional[float], typer.Option(
    "--max-frequency", help="Sparse (FE) models: the top of the band [rad/s, the model's angular-frequency unit]; "
    "every eigenvalue with |Im λ| below it is computed (complex eigenvalue analysis). Any model with constant "
    "contact kinematics takes it.")]
Method = Annotated[Optional[str], typer.Option(
    "--method", help="Sparse path: direct (shift-invert Arnoldi on the full model, default), modal (real modes below "
    "--cutoff, refined on the full model) or dense (every eigenvalue; a few thousand DOFs).")]
Cutoff = Annotated[Optional[float], typer.Option(
    "--cutoff", help="--method modal: the real modes' cutoff [rad/s] (default 2 × --max-frequency).")]
NoResidual = Annotated[bool, typer.Option(
    "--no-residual-vectors", help="--method modal: project on the real modes alone, without the residual vectors "
    "(the static response to the contact forces) that make the projection converge.")]
ShapesOut = Annotated[Optional[Path], typer.Option(
    "--out", help="Sparse path: NetCDF of the band's eigenvalues and the unstable modes' shapes.")]
Vtk = Annotated[Optional[Path], typer.Option(
    "--vtk", help="Sparse path: the unstable modes' shapes on the model's nodes for ParaView (.vtu; needs the fe "
    "extra, meshio).")]
AllShapes = Annotated[bool, typer.Option("--all-shapes", help="Write the shapes of every mode of the band, not only "
                                         "the unstable ones.")]
Overwrite = Annotated[bool, typer.Option("--overwrite", help="Replace existing --out and --vtk files.")]


@dataclass(frozen=True, kw_only=True)
class Band:
    """The sparse path's options of ``stickslip stability``."""

    max_frequency: MaxFrequency = None
    method: Method = None
    cutoff: Cutoff = None
    no_residual_vectors: NoResidual = False
    out: ShapesOut = None
    vtk: Vtk = None
    all_shapes: AllShapes = False
    overwrite: Overwrite = False

    @property
    def asked(self) -> bool:
        """Whether an option of the sparse path was given."""
        return self.no_residual_vectors or any(v is not None for v in (self.max_frequency, self.method, self.cutoff,
                                                                        self.out, self.vtk))

    def check(self, inputs: dict) -> None:
        """Refuse values and outputs before any work."""
        check_finite({"--max-frequency": self.max_frequency, "--cutoff": self.cutoff})
        for flag, value in (("--max-frequency", self.max_frequency), ("--cutoff", self.cutoff)):
            if value is not None and not value > 0:
                raise CLIError(f"{flag} {value:g} must be an angular frequency > 0 [rad/s]")
        if self.method is not None:
            check_choice("--method", self.method, ("direct", "modal", "dense"))
        for flag, given in (("--cutoff", self.cutoff is not None), ("--no-residual-vectors", self.no_residual_vectors)):
            if given and self.method != "modal":
                raise CLIError(f"{flag} belongs to --method modal (the real modes' projection); give --method modal "
                               "too")
        if self.cutoff is not None and self.max_frequency is not None and self.cutoff < self.max_frequency:
            raise CLIError(f"--cutoff {self.cutoff:g} is below --max-frequency {self.max_frequency:g}; give a cutoff "
                           "above the band (1.5 to 2 times it)")
        if self.out is not None:
            check_nc_path(self.out)
            check_output(self.out, self.overwrite, inputs=inputs)
        if self.vtk is not None:
            if self.vtk.suffix not in (".vtu", ".vtk"):
                raise CLIError(f"--vtk {self.vtk}: give a path ending in .vtu or .vtk")
            check_output(self.vtk, self.overwrite, flag="--vtk", inputs=inputs)

    def write(self, result, inputs: dict) -> list[Path]:
        """Write --out and --vtk; the paths written."""
        shapes = "all" if self.all_shapes else "unstable"
        written = []
        if self.out is not None:
            write_output(self.out, netcdf_writer(result.to_xarray(shapes)), overwrite=self.overwrite, inputs=inputs)
            written.append(self.out)
        if self.vtk is not None:
            fmt = "vtu" if self.vtk.suffix == ".vtu" else "vtk"
            write_output(self.vtk, lambda tmp: result.write_vtk(tmp, shapes, file_format=fmt),
                         overwrite=self.overwrite, inputs=inputs, flag="--vtk")
            written.append(self.vtk)
        return written


def report_band(result, timing, written: list[Path], as_json: bool) -> None:
    """Print the band's eigenvalues: a JSON line, or the tables."""
    if as_json:
        print(json.dumps({**result.summary(), "written": [str(p) for p in written], "wall_time_s": timing.wall_s,
                          "compile_time_s": timing.compile_s}))
        return
    modes = Table(title=f"steady sliding of model {result.model}: eigenvalues with |Im λ| ≤ {result.max_frequency:.6g} "
                        f"rad/s ({result.method}; one per conjugate pair), by growth rate")
    for head in ("#", "growth rate [1/s]", "angular frequency [rad/s]", "frequency [Hz]", "backward error"):
        modes.add_column(head, justify="right")
    for number, row in enumerate(result.modes(), start=1):
        style = "bold red" if row["growth_rate"] > 0 else None
        modes.add_row(str(number), f"{row['growth_rate']:.6g}", f"{row['angular_frequency']:.8g}",
                      f"{row['angular_frequency'] / (2 * math.pi):.6g}", f"{row['backward_error']:.1e}", style=style)
    console.print(modes)
    if result.modal is not None:
        modal = result.modal
        conv = Table(title=f"modal CEA: {modal.modes} real modes below {modal.cutoff:.6g} rad/s and "
                           f"{modal.residual_vectors} residual vectors; the approximations' largest distance from the "
                           "full eigenvalues as modes are added (relative; the band's eigenvalues within 1e-2)")
        for head in ("modes", "highest mode [rad/s]", "residual vectors", "with them", "within 1e-2", "modes alone",
                     "within 1e-2 "):
            conv.add_column(head, justify="right")
        for row in modal.convergence:
            conv.add_row(str(row["modes"]), f"{row['highest_mode']:.6g}", str(row["residual_vectors"]),
                         f"{row['max_relative_error']:.2e}" if row["residual_vectors"] else "-",
                         str(row["found"]) if row["residual_vectors"] else "-", f"{row['modes_only_error']:.2e}",
                         str(row["modes_only_found"]))
        console.print(conv)
    count = result.frictionless_count
    console.print(f"{len(result.dofs)} dofs, {len(result.contact_names)} contacts; every eigenvalue with |λ| ≤ "
                  f"{result.radius:.6g} rad/s found"
                  + ("" if count is None else f" (the frictionless structure has {count} modes there)"), style="dim")
    verdict = Text("stable", style="green") if result.stable else Text("unstable", style="bold red")
    console.print(Text.assemble(f"max real part in the band {result.max_real_part:.6g} 1/s: steady sliding is ",
                                verdict))
    tail = "" if not written else "; wrote " + ", ".join(str(p) for p in written)
    console.print(f"wall time {time_text(timing.wall_s, timing.compile_s)}{tail}", style="dim")
