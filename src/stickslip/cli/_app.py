"""The typer application and helpers shared by the commands."""

from __future__ import annotations

import math
import sys
from contextlib import contextmanager

import typer
from rich.console import Console

app = typer.Typer(
    name="stickslip",
    help="Exact 2-D stick-slip simulation and analysis of two rigid plates in frictional contact.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console()
err_console = Console(stderr=True)

#: Help text of every --config option (the backslash keeps rich from reading [parameters] as markup).
CONFIG_HELP = "TOML file with a \\[parameters] table (names not given keep their defaults)."

#: Errors that are the user's to fix: printed as one line, exit code 2.
USER_ERRORS: tuple[type[BaseException], ...] = (ValueError, FileNotFoundError, RuntimeError)


@contextmanager
def user_errors():
    """Turn library errors into a one-line message and exit code 2."""
    try:
        yield
    except USER_ERRORS as exc:
        err_console.print(f"[bold red]error:[/] {exc}", highlight=False, soft_wrap=True)
        sys.exit(2)


def parse_assignments(items: list[str] | None) -> dict:
    """``["N=50", "friction_law=coulomb"]`` → ``{"N": 50.0, "friction_law": "coulomb"}``."""
    values: dict = {}
    for item in items or []:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ValueError(f"--set expects NAME=VALUE, got {item!r}; e.g. --set k_px=400")
        text = text.strip()
        try:
            values[name] = float(text)
        except ValueError:
            values[name] = text
    return values


def check_nc_path(out) -> None:
    """A NetCDF output path must end in ``.nc`` (ValueError naming the fix)."""
    if out.suffix != ".nc":
        raise ValueError(f"--out {out}: give a path ending in .nc")


def check_choice(flag: str, value, choices) -> None:
    """``value`` of option ``flag`` must be one of ``choices``."""
    if value not in choices:
        raise ValueError(f"{flag} {value}: choose one of {', '.join(choices)}")


def check_positive(flags: dict) -> None:
    """Every ``{flag: value}`` must be a finite number > 0 (``None``: not given, skipped)."""
    for flag, value in flags.items():
        if value is not None and not (math.isfinite(value) and value > 0):
            raise ValueError(f"{flag} must be a finite number > 0, got {value}")


def build_parameters(config, assignments, **named):
    """Parameters from an optional TOML file, then ``--set`` pairs, then the named options (not None)."""
    from ..model.parameters import Parameters

    params = Parameters.load_toml(config) if config is not None else Parameters()
    changes = parse_assignments(assignments)
    changes.update({k: v for k, v in named.items() if v is not None})
    return params.replace(**changes) if changes else params


def _version(value: bool) -> None:
    if value:
        from .. import __version__

        console.print(f"stickslip {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(False, "--version", callback=_version, is_eager=True, help="Print the version and exit."),
) -> None:
    """Exact 2-D stick-slip simulation and analysis of two rigid plates in frictional contact."""
