"""Option groups: options that several commands take together, declared once as a dataclass.

typer reads a command's options from its signature, one parameter each. A group is a frozen
dataclass whose fields are options (:mod:`._options` aliases) or other groups; a command takes it
as one parameter, ``plates: Plates = Plates()``, whose default gives the fields' defaults.
:func:`grouped` puts the group's options in that parameter's place, in field order, so that
typer sees (and ``--help`` lists) each of them as if the command declared it there, and hands the
command the group built from the values parsed.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import typing
from typing import Any, Callable

__all__ = ["grouped"]

#: Builds a group from the parsed values, taking its options out of them.
_Builder = Callable[[dict], Any]


def _is_group(hint) -> bool:
    """Whether the annotation ``hint`` is an option group (a dataclass)."""
    return isinstance(hint, type) and dataclasses.is_dataclass(hint)


def _options_of(group: type, default) -> tuple[list[inspect.Parameter], _Builder]:
    """The options of ``group``, with their defaults from the instance ``default``.

    Parameters
    ----------
    group : type
        An option group (a dataclass); a field that is a group contributes its own options.
    default : group
        The instance whose field values are the options' defaults.

    Returns
    -------
    parameters : list of inspect.Parameter
        One keyword parameter per option, in field order, annotated with the field's type.
    build : callable
        ``build(values)``: the group of the values parsed (a dict by option name), its options
        removed from ``values``.
    """
    hints = typing.get_type_hints(group, include_extras=True)
    parameters: list[inspect.Parameter] = []
    parts: dict[str, _Builder | None] = {}
    for field in dataclasses.fields(group):
        hint, value = hints[field.name], getattr(default, field.name)
        if _is_group(hint):
            inner, parts[field.name] = _options_of(hint, value)
            parameters += inner
        else:
            parameters.append(inspect.Parameter(field.name, inspect.Parameter.KEYWORD_ONLY, default=value,
                                                annotation=hint))
            parts[field.name] = None

    def build(values: dict):
        return group(**{name: values.pop(name) if part is None else part(values) for name, part in parts.items()})

    return parameters, build


def grouped(command: Callable) -> Callable:
    """The command as typer should read it: each option group parameter replaced by its options.

    Put it under ``@app.command(...)``. The other parameters keep their place and annotation
    (resolved, as typer would resolve them).

    Parameters
    ----------
    command : callable
        A typer command whose parameters may be annotated with option groups.

    Returns
    -------
    callable
        A function with the expanded signature (and annotations, name and docstring) that builds
        each group from its options' values and calls ``command``.

    Raises
    ------
    TypeError
        When two options of the expanded signature have the same name.
    """
    hints = typing.get_type_hints(command, include_extras=True)
    parameters: list[inspect.Parameter] = []
    builders: dict[str, _Builder] = {}
    for parameter in inspect.signature(command).parameters.values():
        hint = hints.get(parameter.name, parameter.annotation)
        if _is_group(hint):
            default = hint() if parameter.default is inspect.Parameter.empty else parameter.default
            options, builders[parameter.name] = _options_of(hint, default)
            parameters += options
        else:
            parameters.append(parameter.replace(kind=inspect.Parameter.KEYWORD_ONLY, annotation=hint))
    names = [p.name for p in parameters]
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise TypeError(f"{command.__name__}: options {', '.join(twice)} are declared twice")

    @functools.wraps(command)
    def run(**values):
        for name, build in builders.items():
            values[name] = build(values)
        return command(**values)

    run.__signature__ = inspect.Signature(parameters, return_annotation=hints.get("return", inspect.Signature.empty))
    run.__annotations__ = {p.name: p.annotation for p in parameters if p.annotation is not inspect.Parameter.empty}
    return run
