"""Commands imported when they run: ``stickslip --version`` and ``--help`` import none of them.

A command's module imports what the command computes with (numpy, scipy, numba, xarray, the
compiled kernels), which takes a second or more; the top-level options and the list of commands
need none of it. :data:`COMMANDS` names every command, the module that registers it on the typer
application, and the line ``stickslip --help`` shows for it (the first paragraph of the command's
own help; a test keeps the two equal). :class:`LazyCommands` is the group's part that lists the
commands from this table and imports a command's module when the command is asked for by name
(to run it, or to print its own help).
"""

from __future__ import annotations

import importlib
from typing import NamedTuple

from rich.markup import escape
from typer.core import TyperCommand

__all__ = ["COMMANDS", "LazyCommands", "runs_kernels"]


class Entry(NamedTuple):
    """One command: the module (in :mod:`stickslip.cli`) that registers it, its help line, and
    whether it runs compiled kernels (numba's compile notice is set up for those alone: numba
    takes 0.3 s to import)."""

    module: str
    line: str
    kernels: bool = True


#: Every command in the order ``stickslip --help`` lists them.
COMMANDS: dict[str, Entry] = {
    "simulate": Entry("simulate", "Simulate a model with exact stick-slip (default: the two plates, Table 1, "
                                  "N = 50 N, Ω = 5 rad/s, 100 s)."),
    "sweep": Entry("sweep", "Simulate every point of a grid and keep its steady-state reductions."),
    "bifurcation": Entry("sweep", "Bifurcation diagram of φ: steady-state peak values against one parameter "
                                  "(Figs. 12–14)."),
    "regions": Entry("sweep", "Regions I/II/III over (N, Ω) (Fig. 8) and stick-slip domains of several models "
                              "(Fig. 9)."),
    "stability": Entry("stability", "Equilibrium of steady sliding (plates: Eq. 14) and its eigenvalues (Eq. 15), "
                                    "for any model; for sparse (finite-element) models every eigenvalue of a band "
                                    "(complex eigenvalue analysis, --max-frequency)."),
    "stability-map": Entry("stability", "Stable/unstable regions of steady sliding over two parameters of any "
                                        "model, with the boundary by root finding (plates: (N, Ω), Figs. 3, 4)."),
    "reproduce": Entry("reproduce", "Paper Sects. 4.1–4.2: Figs. 3–16 and Table 2 beside the paper's statements, "
                                    "with a table \"paper says / we measure / agrees?\" (OUT/report.md)."),
    "orbit": Entry("orbit", "Find a periodic orbit by Newton shooting on a Poincaré section (default: the maximum "
                            "of the model's observed coordinate, the plates' φ), with its Floquet multipliers."),
    "lyapunov": Entry("orbit", "Lyapunov spectrum (Benettin–Shimada–Nagashima) of the attractor reached from --ic."),
    "continue": Entry("continue_", "Continue a periodic orbit in one parameter, with stability, folds, stick-phase "
                                   "changes and grazing."),
    "basins": Entry("basins", "Basin stability: which attractor each initial state reaches (exact stick), and how "
                              "often."),
    "models": Entry("models", "The model library, or one model's states, contacts and the parameter paths --set "
                              "reaches.", kernels=False),
    "warmup": Entry("warmup", "Compile the kernels ahead (cluster nodes, container images, CI caches): later "
                              "commands on this machine load them from numba's cache and start at once."),
    "reduce": Entry("reduce", "Reduce a sparse (finite-element) model to its contact and loaded DOFs and a few "
                              "modes, write it as a model file every tool takes, and report how far its "
                              "steady-sliding eigenvalues are from the full model's."),
    "mode-coupling": Entry("mode_coupling", "The mode-coupling diagram of any model with constant contact "
                                            "kinematics: frequencies and real parts of the band's eigenvalues "
                                            "against the friction coefficient, the instabilities' onsets located "
                                            "by root finding."),
    "study": Entry("study", "Reproducible studies of the paper (tables, JSON and figures)."),
}


def runs_kernels(name: str) -> bool:
    """Whether the command ``name`` may run compiled kernels (an unknown name: it may)."""
    entry = COMMANDS.get(name)
    return entry is None or entry.kernels


def import_all() -> None:
    """Import every command's module (each registers its commands on the application)."""
    for entry in COMMANDS.values():
        importlib.import_module(f"{__package__}.{entry.module}")


class LazyCommands:
    """Mixin of the ``stickslip`` click group: commands listed from :data:`COMMANDS`, built when asked for.

    ``build`` (set by the group) returns the click group of every command registered so far on the
    typer application; a command asked for by name has its module imported and is taken from
    there. While the group's own help is formatted, a command not yet imported is shown by a
    stand-in that carries only its name and help line.
    """

    #: Builds the click group of the commands registered so far (set by the application).
    build = None
    _listing = False

    def list_commands(self, ctx) -> list[str]:
        return list(COMMANDS) + [name for name in self.commands if name not in COMMANDS]

    def get_command(self, ctx, name: str):
        if name not in self.commands and name in COMMANDS:
            if self._listing:
                return TyperCommand(name=name, help=escape(COMMANDS[name].line))
            importlib.import_module(f"{__package__}.{COMMANDS[name].module}")
            self.commands.update(type(self).build().commands)
        return self.commands.get(name)

    def resolve_command(self, ctx, args):
        if args and args[0] not in COMMANDS and args[0] not in self.commands:
            for name in COMMANDS:  # a name that is none: typer suggests the close ones among those it holds
                self.get_command(ctx, name)
        return super().resolve_command(ctx, args)

    def format_help(self, ctx, formatter) -> None:
        self._listing = True
        try:
            super().format_help(ctx, formatter)
        finally:
            self._listing = False
