"""``stickslip models``: the model library, and what one model offers (states, contacts, ``--set`` paths)."""

from __future__ import annotations

import json
from typing import Optional

import typer
from rich.table import Table
from rich.text import Text

from ..model.library import library, load_model, plates_variant, two_plates
from ._app import app, console


@app.command()
def models(
    model: Optional[str] = typer.Argument(None, help="A library name or a model file (.toml): show its states, "
                                          "contacts and parameter paths. Without it: list the library."),
    as_json: bool = typer.Option(False, "--json", help="Print the list, or the model's description, as JSON."),
) -> None:
    """The model library, or one model's states, contacts and the parameter paths --set reaches."""
    if model is None:
        names = library()
        if as_json:
            print(json.dumps(names))
            return
        table = Table(title="stickslip model library (--model NAME; or a model file, --model FILE.toml)")
        table.add_column("name")
        table.add_column("description")
        for name, text in names.items():
            table.add_row(Text(name), Text(text))
        console.print(table)
        console.print("details and parameter paths: stickslip models NAME; model files: docs/models.md", style="dim")
        return
    variant = plates_variant(model)
    system = two_plates(None, variant) if variant is not None else load_model(model)
    if as_json:
        print(json.dumps(system.describe() | {"states": list(system.state_names),
                                              "natural_frequencies_hz": system.natural_frequencies().tolist()}))
        return
    console.print(Text(f"{system.name}: {system.description or '(no description)'}"))
    console.print(Text(f"source: {system.source}"))
    free = [d for d, f in zip(system.dofs, system.free) if f]
    console.print(Text(f"states: {', '.join(system.state_names)} (free DOFs: {', '.join(free)}; observed: "
                       f"{system.dofs[system.observed_index]})"))
    for i, c in enumerate(system.contacts):
        law = c.friction.to_dict()
        console.print(Text(f"contact {i}{' (' + c.name + ')' if c.name else ''}: {c.dim}-D slip, "
                           + ", ".join(f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}" for k, v in law.items())))
    table = Table(title="parameters (--set PATH=VALUE)")
    table.add_column("path")
    table.add_column("value", justify="right")
    for path, value in system.parameters.items():
        table.add_row(Text(path), Text(f"{value:g}" if isinstance(value, float) else str(value)))
    console.print(table)
