"""``stickslip study ...``: reproducible studies. Parse → library call → write; no physics here."""

from __future__ import annotations

from pathlib import Path

import typer

from ..plot.timestep import save_timestep_figures
from ..studies.timestep import DT_FULL, DT_QUICK, run_timestep_study
from ._app import app, check_output_folder, console, note_line
from ._options import OverwriteFolder

study_app = typer.Typer(help="Reproducible studies of the paper (tables, JSON and figures).", no_args_is_help=True)
app.add_typer(study_app, name="study")


@study_app.command("timestep")
def timestep(
    out: Path = typer.Option(Path("study_timestep"), "--out", help="Output folder (created)."),
    quick: bool = typer.Option(False, "--quick", help="Leave out Δt = 1e-5 s (under 2 minutes)."),
    t_end: float = typer.Option(100.0, "--t-end", help="Simulated time [s] (paper: 100)."),
    overwrite: OverwriteFolder = False,
) -> None:
    """Paper Sect. 4.2.1: AEOM and NAEOM for Δt = 0.1 … 1e-5 s against a converged `event` run
    (Table 2 beside ours, Figs. 5 and 6)."""
    check_output_folder(out, overwrite)
    study = run_timestep_study(DT_QUICK if quick else DT_FULL, t_end=t_end, progress=note_line)
    files = study.save(out)
    figures = save_timestep_figures(study, out)
    console.print(study.markdown(), soft_wrap=True)
    for path in list(files.values()) + list(figures.values()):
        console.print(f"wrote {path}")
