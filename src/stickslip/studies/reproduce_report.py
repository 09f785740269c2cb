"""What a recipe of :mod:`stickslip.studies.reproduce` hands back, and the Markdown report
written from it.

A recipe returns a :class:`RecipeResult`: the PNGs it saved, its comparison rows
(:class:`Row`: "paper says / we measure / agrees?" with the criterion that gave the verdict) and
the measured numbers for ``results.json``. :func:`render_report` turns the finished entries into
``report.md``. The verdict words (``yes``, ``no``, ``not compared``) and the number format of the
rows are fixed here, in one place, so that every recipe writes them alike.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable

from .._version import __version__
from .reproduce_resolutions import Resolution

__all__ = ["Row", "RecipeResult", "Recipe", "NOT_YET", "render_report"]


@dataclasses.dataclass
class Row:
    """One line of the comparison table."""

    item: str          # e.g. "Fig. 3(a)"
    paper: str         # what the paper says (quoted or paraphrased with its numbers)
    measured: str      # what we measure in this run
    agrees: str        # "yes", "no" or "not compared"
    criterion: str     # the rule that gave the verdict


@dataclasses.dataclass
class RecipeResult:
    figures: list
    rows: list
    measured: dict
    notes: str = ""


@dataclasses.dataclass(frozen=True)
class Recipe:
    name: str                      # key for --only, e.g. "fig3"
    title: str
    statement: str                 # the paper's statement about the figure (quoted)
    run: Callable                  # (out_dir, Resolution, cache) -> RecipeResult


def _yes(ok: bool) -> str:
    return "yes" if ok else "no"


def _fmt(x, digits=3) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.{digits}g}"


#: Figures of Sects. 4.1–4.2 that no recipe reproduces yet (listed in the report; none left).
NOT_YET: dict = {}


def _cell(text: str) -> str:
    """Escape the Markdown table separator (|F_f| would split a cell)."""
    return str(text).replace("|", "\\|")


def render_report(entries: list, res: Resolution, pending: list, elapsed: float) -> str:
    """Markdown report from the finished recipe entries (dicts written by
    :func:`~stickslip.studies.reproduce.reproduce`)."""
    lines = ["# Reproduction of the paper's Sects. 4.1–4.2", "",
             f"stickslip {__version__}, resolution `{res.name}`, {elapsed:.0f} s so far. "
             "“We measure” is computed by this run; “agrees?” follows the criterion in the last column "
             "(“not compared” where the paper gives no number).", ""]
    all_rows = []
    for e in entries:
        lines += [f"## {e['title']}", "", f"Paper: {e['statement']}", ""]
        if e["status"] == "failed":
            lines += [f"**Failed** after {e['seconds']:.1f} s: `{e['error']}`", ""]
            continue
        for fig in e["figures"]:
            lines += [f"![{fig}]({fig})", ""]
        lines += ["| item | paper says | we measure | agrees? |", "|---|---|---|---|"]
        for r in e["rows"]:
            lines.append(f"| {_cell(r['item'])} | {_cell(r['paper'])} | {_cell(r['measured'])} | {r['agrees']} |")
            all_rows.append(r)
        lines += ["", f"Computed in {e['seconds']:.1f} s.", ""]
    if pending:
        lines += ["## Still running or not started", ""] + [f"- {p}" for p in pending] + [""]
    lines += ["## Summary: paper says / we measure / agrees?", "",
              "| item | paper says | we measure | agrees? | criterion |", "|---|---|---|---|---|"]
    for r in all_rows:
        lines.append(f"| {_cell(r['item'])} | {_cell(r['paper'])} | {_cell(r['measured'])} | {r['agrees']} | "
                     f"{_cell(r['criterion'])} |")
    for e in entries:
        if e["status"] == "failed":
            lines.append(f"| {e['name']} | – | recipe failed | not compared | – |")
    if NOT_YET:
        lines += ["", "## Not yet reproduced", ""] + [f"- {k}: {v}" for k, v in NOT_YET.items()]
    lines += [""]
    return "\n".join(lines)
