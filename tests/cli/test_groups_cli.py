"""Option groups: typer reads a command's group parameter as the group's options, in its place."""

import dataclasses
import inspect
from typing import Annotated

import pytest
import typer
from typer.testing import CliRunner

from stickslip.cli._groups import grouped


@dataclasses.dataclass(frozen=True, kw_only=True)
class Inner:
    b: Annotated[int, typer.Option("--b", help="Option b.")] = 2


@dataclasses.dataclass(frozen=True, kw_only=True)
class Outer:
    a: Annotated[str, typer.Option("--a", help="Option a.")]
    inner: Inner = dataclasses.field(default_factory=Inner)


def _app(seen: dict) -> typer.Typer:
    app = typer.Typer()

    @app.command()
    @grouped
    def command(first: Annotated[int, typer.Option("--first")] = 0, outer: Outer = Outer(a="x"),
                last: Annotated[bool, typer.Option("--last")] = False) -> None:
        """A command with a group between two options."""
        seen.update(first=first, outer=outer, last=last)

    return app


def test_a_group_stands_as_its_options_in_its_place_and_comes_back_built():
    seen: dict = {}
    app = _app(seen)
    command = app.registered_commands[0].callback
    assert list(inspect.signature(command).parameters) == ["first", "a", "b", "last"]
    assert command.__doc__ == "A command with a group between two options."
    res = CliRunner().invoke(app, ["--b", "5", "--last"])
    assert res.exit_code == 0, res.output
    assert seen == {"first": 0, "outer": Outer(a="x", inner=Inner(b=5)), "last": True}


def test_help_lists_a_groups_options_in_its_place():
    res = CliRunner().invoke(_app({}), ["--help"], env={"COLUMNS": "120"})
    assert res.exit_code == 0, res.output
    flags = [flag for flag in ("--first", "--a", "--b", "--last") if flag in res.output]
    assert sorted(flags, key=res.output.index) == ["--first", "--a", "--b", "--last"]


def test_an_option_declared_twice_is_refused():
    with pytest.raises(TypeError, match="options a are declared twice"):
        @grouped
        def command(a: Annotated[str, typer.Option("--a")] = "", outer: Outer = Outer(a="x")) -> None:
            """Declares --a beside a group that has it."""
