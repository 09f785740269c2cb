"""``stickslip warmup``: compile the kernels ahead, so that later commands start at once.

numba compiles a kernel set per kind of model (the plates; model files whose contacts are pressed;
model files with contacts that open; each Python kinematics class or user friction law) on its
first call and caches it on disk. On a cluster node, in a container image or a CI cache that
first call is better made once, ahead: this command makes the calls that compile what
``simulate`` (the event method, and the fixed-step methods if asked), ``stability`` and the orbit
tools (``orbit``, ``continue``, ``lyapunov``: the variational equations) need, on runs too short
to matter, and says how long each took. A second warmup loads everything from the cache.
"""

from __future__ import annotations

import time
from typing import List, Optional

import typer
from rich.table import Table
from rich.text import Text

from ..errors import StickSlipError
from ..integrate.driver import simulate
from ..model.library.two_plates import is_plates
from ..orbits import flow_jacobian
from ..stability import stability
from ._app import CLIError, app, build_system, console, note_line
from ._json import print_json

#: The library models whose kernel sets cover the built-in kinds of model: the plates, a model
#: file with pressed contacts, a model file with a contact that opens.
DEFAULT_MODELS = ("two-plates", "belt", "hoffmann")

METHODS = ("event", "aeom", "naeom")

#: Simulated time of each warm-up run [s]: long enough to take steps, short enough to cost nothing.
_T_RUN = 1e-2


def _stages(system, methods):
    """(name, call) for each kernel set to compile for ``system`` (the fixed-step methods are the
    plates' only)."""
    methods = [m for m in methods if m == "event" or is_plates(system)]
    stages = [(f"simulate ({m})", lambda m=m: simulate(system, _T_RUN, method=m, dt=None if m == "event" else 1e-3,
                                                       sample_rate=100.0))
              for m in methods]
    stages.append(("stability", lambda: stability(system)))
    stages.append(("orbits (variational equations)",
                   lambda: flow_jacobian(system, simulate(system, _T_RUN, sample_rate=100.0).final_state, _T_RUN)))
    return stages


@app.command()
def warmup(
    model: Optional[List[str]] = typer.Option(None, "--model", help="A model to compile for (repeatable; a library "
                                              "name or a model file). Default: two-plates, belt and hoffmann, which "
                                              "cover the plates and model files with pressed contacts and with "
                                              "contacts that open."),
    methods: str = typer.Option("event", "--methods", help="Integration methods of simulate to compile, comma-"
                                "separated: event, aeom, naeom (the last two: the plates only)."),
    as_json: bool = typer.Option(False, "--json", help="Print the seconds of each stage as one JSON line."),
) -> None:
    """Compile the kernels ahead (cluster nodes, container images, CI caches): later commands on this
    machine load them from numba's cache and start at once."""
    chosen = [m.strip() for m in methods.split(",") if m.strip()]
    unknown = [m for m in chosen if m not in METHODS]
    if unknown or not chosen:
        raise CLIError(f"--methods {methods!r}: give a comma-separated list of {', '.join(METHODS)}")
    report = []
    for name in model or DEFAULT_MODELS:
        system, _ = build_system(name, None, [])
        for stage, call in _stages(system, chosen):
            start = time.perf_counter()
            try:
                call()
                outcome = "ready"
            except StickSlipError as exc:  # e.g. no steady sliding: its kernels compiled before the refusal
                outcome = f"ran into: {exc}"
            report.append({"model": name, "stage": stage, "seconds": round(time.perf_counter() - start, 2),
                           "outcome": outcome})
    if as_json:
        print_json(report)
        return
    table = Table(title="kernels compiled, or loaded from the cache")
    for column in ("model", "stage", "seconds", "outcome"):
        table.add_column(column, justify="right" if column == "seconds" else "left")
    for row in report:
        table.add_row(Text(row["model"]), Text(row["stage"]), f"{row['seconds']:.1f}", Text(row["outcome"]))
    console.print(table)
    note_line(f"{sum(row['seconds'] for row in report):.1f} s in all; a second warmup loads every kernel from the cache")
