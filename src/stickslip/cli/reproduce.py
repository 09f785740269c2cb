"""``stickslip reproduce``: regenerate the paper's figures and Table 2 with a Markdown report.
Parse → library call → write; no physics here."""

from __future__ import annotations

from pathlib import Path

import typer

from ..studies.reproduce import recipe_names
from ..studies.reproduce import reproduce as run_reproduce
from ._app import CLIError, app, check_output_folder, console, note_line
from ._kept import on_interrupt
from ._options import OverwriteFolder


@app.command("reproduce")
def reproduce(
    out: Path = typer.Option(Path("paper"), "--out", help="Output folder: report.md, PNGs, results.json."),
    quick: bool = typer.Option(False, "--quick", help="Coarse grids (3-7 minutes on 2 cores)."),
    only: list[str] = typer.Option(None, "--only", help="Run only these figures (repeatable): "
                                   "fig3, fig4, table2, fig7, fig8, fig9, fig10, fig11, fig12a, "
                                   "fig12b, fig13, fig14, fig15, fig16."),
    overwrite: OverwriteFolder = False,
) -> None:
    """Paper Sects. 4.1–4.2: Figs. 3–16 and Table 2 beside the paper's statements, with a table
    "paper says / we measure / agrees?" (OUT/report.md)."""
    if only:
        unknown = [n for n in only if n not in recipe_names()]
        if unknown:
            raise CLIError(f"unknown figure {', '.join(map(repr, unknown))} for --only; "
                           f"choose from {', '.join(recipe_names())}")
    check_output_folder(out, overwrite)
    on_interrupt(f"the figures finished so far are listed in {out / 'report.md'}")
    report = run_reproduce(out, "quick" if quick else "full", only=only or None, progress=note_line)
    console.print(f"wrote {report}")
