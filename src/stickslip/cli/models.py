"""``stickslip models``: the model library, and what one model offers (states, contacts, ``--set`` paths).

The list is read from the library's table of contents (:mod:`stickslip.model.catalog`) without
building a model: it answers without importing numpy or numba. One model is built to be described.

A model of finite-element size has 10⁴–10⁶ dofs, hundreds of contacts and a parameter per contact
node: the text lists are then given by their counts with a short head and tail, runs of alike
contacts are one line each, and parameters that differ only in their numbers (``contact_set.pad.
nodes.12.gap``, ``force.u21``) one row with the range of their values. ``--json`` stays complete (and adds the counts).
"""

from __future__ import annotations

import re
from typing import Optional

import typer
from rich.table import Table
from rich.text import Text

from ..model.catalog import library
from ._app import app, console
from ._json import print_json

#: Lists longer than this are shown as their count, head and tail.
LIST_LIMIT = 12
#: Names shown at the head and the tail of a long list.
HEAD, TAIL = 5, 3
#: Parameters of one pattern (indices replaced by ``*``) beyond this many are shown as one row.
GROUP_LIMIT = 8

_INDEX = re.compile(r"\d+")


def brief(names, limit: int = LIST_LIMIT) -> str:
    """``a, b, c`` for a short list; ``N (a, b, …, y, z)`` for a long one."""
    names = list(names)
    if len(names) <= limit:
        return ", ".join(names)
    return f"{len(names)} ({', '.join(names[:HEAD])}, …, {', '.join(names[-TAIL:])})"


def contact_lines(system) -> list[str]:
    """One line per run of consecutive contacts with the same slip dimension and friction law."""
    lines, start = [], 0
    contacts, names = system.contacts, system.contact_names
    described = [(0, "") if c.frictionless else
                 (c.dim, ", ".join(f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}"
                                   for k, v in c.friction.to_dict().items())) for c in contacts]
    for end in range(1, len(contacts) + 1):
        if end < len(contacts) and described[end] == described[start]:
            continue
        dim, law = described[start]
        if end - start == 1:
            label = f"contact {start}" + (f" ({names[start]})" if names[start] else "")
        else:
            label = f"contacts {start}–{end - 1}" + (f" ({names[start]} … {names[end - 1]})" if names[start] else "")
        lines.append(f"{label}: {f'{dim}-D slip, {law}' if dim else 'no friction (normal only)'}")
        start = end
    return lines


def _shown(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def parameter_rows(parameters) -> list[tuple[str, str]]:
    """(path, value) rows: each parameter, or one row per pattern of more than :data:`GROUP_LIMIT`
    paths that differ only in their numbers (the pattern with ``*`` for each, the count and the
    values' range), in the order of first appearance."""
    groups: dict = {}
    for path, value in parameters.items():
        groups.setdefault(_INDEX.sub("*", path), []).append((path, value))
    rows = []
    for pattern, members in groups.items():
        if len(members) <= GROUP_LIMIT:
            rows += [(path, _shown(value)) for path, value in members]
            continue
        values = [v for _, v in members]
        numbers = [v for v in values if isinstance(v, float)]
        if len(numbers) == len(values):
            low, high = min(numbers), max(numbers)
            shown = f"{low:g}" if low == high else f"{low:g} … {high:g}"
        else:
            distinct = sorted({_shown(v) for v in values})
            shown = ", ".join(distinct) if len(distinct) <= 3 else \
                f"{len(distinct)} values: {', '.join(distinct[:2])}, …"
        rows.append((f"{pattern} ({len(members)} paths)", shown))
    return rows


@app.command()
def models(
    model: Optional[str] = typer.Argument(None, help="A library name or a model file (.toml): show its states, "
                                          "contacts and parameter paths. Without it: list the library."),
    as_json: bool = typer.Option(False, "--json", help="Print the list, or the model's description, as JSON "
                                 "(complete: every dof, contact and parameter)."),
) -> None:
    """The model library, or one model's states, contacts and the parameter paths --set reaches."""
    if model is None:
        names = library()
        if as_json:
            print_json(names)
            return
        table = Table(title="stickslip model library (--model NAME; or a model file, --model FILE.toml)")
        table.add_column("name")
        table.add_column("description")
        for name, text in names.items():
            table.add_row(Text(name), Text(text))
        console.print(table)
        console.print("details and parameter paths: stickslip models NAME; model files: docs/models.md", style="dim")
        return
    # the list above needs no model built; one model needs the model layer, numpy and numba (0.5 s)
    from ..model.library import load_model, plates_variant, two_plates  # noqa: PLC0415

    variant = plates_variant(model)
    system = two_plates(None, variant) if variant is not None else load_model(model)
    dense = getattr(system, "dense", True)
    if as_json:
        counts = {"dofs": system.n, "states": len(system.state_names), "contacts": len(system.contacts),
                  "parameters": len(system.parameters)}
        print_json(system.describe() | {
            "states": list(system.state_names), "counts": counts,
            # every natural frequency needs the dense M⁻¹K: a sparse model's lowest modes come from
            # its sparse form (stickslip stability --max-frequency, docs/fe.md)
            "natural_frequencies_hz": system.natural_frequencies().tolist() if dense else None})
        return
    _show(system)


def _show(system) -> None:
    """The text description of one model (module docstring)."""
    console.print(Text(f"{system.name}: {system.description or '(no description)'}"))
    console.print(Text(f"source: {system.source}"))
    free = [d for d, f in zip(system.dofs, system.free) if f]
    observed = system.dofs[system.observed_index]
    if len(system.dofs) <= LIST_LIMIT:
        console.print(Text(f"states: {', '.join(system.state_names)} (free DOFs: {', '.join(free)}; observed: "
                           f"{observed})"))
    else:
        locked = [d for d, f in zip(system.dofs, system.free) if not f]
        console.print(Text(f"dofs: {brief(system.dofs)}; states: {len(system.state_names)} (the dofs, then d<dof>); "
                           f"free DOFs: {'all' if not locked else f'{len(free)} (locked: {brief(locked)})'}; "
                           f"observed: {observed}"))
    lines = contact_lines(system)
    if len(system.contacts) > LIST_LIMIT:
        console.print(Text(f"contacts: {len(system.contacts)}"))
    for line in lines[:LIST_LIMIT] if len(lines) > LIST_LIMIT else lines:
        console.print(Text(line))
    if len(lines) > LIST_LIMIT:
        console.print(Text(f"… {len(lines) - LIST_LIMIT} more runs of contacts (--json lists every contact)"))
    rows = parameter_rows(system.parameters)
    table = Table(title=f"parameters (--set PATH=VALUE; {len(system.parameters)} paths, * any number)"
                  if len(rows) < len(system.parameters) else "parameters (--set PATH=VALUE)")
    table.add_column("path")
    table.add_column("value", justify="right")
    for path, value in rows:
        table.add_row(Text(path), Text(value))
    console.print(table)
