"""The options that several commands take, each defined once, and the groups they come in.

Each option is a :data:`typing.Annotated` alias that a command uses as a parameter's type, with
its default where the parameter is declared (``rtol: Rtol = 1e-8``): the flag, the type and the
help text live here, the default stays with the command, since commands differ in it (the event
method of a sweep runs at 1e-8, the flow maps of shooting at 1e-10). An option means one thing
wherever its alias is used; where commands mean different things by the same flag (``--overwrite``
of a one-shot command replaces its outputs, of a resumable one it also discards the work kept for
a resume), each meaning has its own alias. An option that only one command takes, or that means
something only one command means (``simulate --t-end auto``, a command's own JSON object), is
declared with that command.

Options that commands take together are a group (:mod:`._groups`): a frozen dataclass whose
fields are the options, in the order ``--help`` lists them, taken as one parameter
(``plates: Plates = Plates()``). A field's default is that of every command taking the group;
where commands differ, the field has none and the command gives it (``Outputs(out=Path("orbit.nc"))``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Annotated, List, Optional

import typer

from ..model.catalog import library_names
from ._app import executor_of

# ----------------------------------------------------------------------------- the model
#: Help text of ``--model`` for commands that take any model.
MODEL_HELP = (f"The model: a library name ({', '.join(library_names())}; see 'stickslip models'), a model "
              "file (.toml), or a variant of the two plates: full | x | y | rotation (paper Models 1–4) or DOFs, "
              "e.g. phi,psi.")

#: Help text of ``--set``.
SET_HELP = ("A parameter as PATH=VALUE (repeatable): a plates parameter (--set k_px=400) or a model file's number "
            "by its path (--set contact.0.drive=1.8; 'stickslip models NAME' lists them).")

#: Help text of ``--config``.
CONFIG_HELP = "TOML file with a [parameters] table (names not given keep their defaults; --set and named options win)."

Model = Annotated[str, typer.Option("--model", help=MODEL_HELP)]
#: ``--model`` of ``sweep``, where ``--grid model=...`` may sweep the plates' variants instead.
SweepModel = Annotated[str, typer.Option("--model", help=MODEL_HELP + " (Plates: the variant when not swept.)")]
#: ``--model`` of ``bifurcation``, which draws one panel per variant of the plates.
BifurcationModel = Annotated[str, typer.Option("--model", help=MODEL_HELP + " For the plates also a comma list of "
                                                "variants (one panel each, Fig. 14).")]
#: ``--model`` of ``stability-map``, whose ``--family model=...`` replaces the variant.
MapModel = Annotated[str, typer.Option("--model", help=MODEL_HELP + " (Plates variants are ignored with "
                                       "--family model=...)")]
SetItems = Annotated[Optional[List[str]], typer.Option("--set", help=SET_HELP)]
Config = Annotated[Optional[Path], typer.Option("--config", help=CONFIG_HELP)]


@dataclass(frozen=True, kw_only=True)
class ModelChanges:
    """The model's parameters as given: ``--set`` and ``--config``."""

    set_: SetItems = None
    config: Config = None

    @property
    def inputs(self) -> dict:
        """``{option: path}`` of the files read, which no output may replace."""
        return {"--config": self.config}


# The plates' parameters with options of their own (None: not given, the model's value holds).
NormalLoad = Annotated[Optional[float], typer.Option("--N", help="The plates: normal preload N [N] (default 50).")]
Omega = Annotated[Optional[float], typer.Option("--omega", help="The plates: angular velocity Ω of the lower plate "
                                                "[rad/s] (default 5).")]
MuK = Annotated[Optional[float], typer.Option("--mu-k", help="The plates: kinetic friction coefficient μk "
                                              "(default 0.2).")]
DeltaMu = Annotated[Optional[float], typer.Option("--delta-mu", help="The plates: μs − μk (default 0.1).")]
Alpha = Annotated[Optional[float], typer.Option("--alpha", help="The plates: decay factor α of Eq. (4) [s/m] "
                                                "(default 5).")]
#: ``--N`` of a command that varies one parameter (``--param``).
VariedLoad = Annotated[Optional[float], typer.Option("--N", help="The plates: normal preload N [N] when --param is "
                                                     "another parameter (default 50).")]
#: ``--omega`` of ``continue``.
ContinuedOmega = Annotated[Optional[float], typer.Option("--omega", help="The plates: angular velocity Ω of the lower "
                                                         "plate [rad/s] when --param is another parameter "
                                                         "(default 5).")]
#: ``--omega`` of ``bifurcation``, whose base differs from the plates' default (the paper's diagrams).
BifurcationOmega = Annotated[Optional[float], typer.Option("--omega", help="The plates: angular velocity Ω of the "
                                                           "lower plate [rad/s] when --param is another parameter "
                                                           "(default 0.5, as in Figs. 12(a), 13, 14).")]


class PlatesOptions:
    """A group of the plates' parameters with options of their own (None: not given, the model's value holds)."""

    #: The parameter of each field whose name is not the parameter's (the plates' Ω is ``--omega``).
    _PARAMETERS = {"omega": "Omega"}

    def named(self) -> dict:
        """``{parameter name: value}`` of the group's options, those of groups within included, as
        :func:`~._app.build_system` takes the plates' named options."""
        named = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, PlatesOptions):
                named.update(value.named())
            else:
                named[self._PARAMETERS.get(f.name, f.name)] = value
        return named


@dataclass(frozen=True, kw_only=True)
class OperatingPoint(PlatesOptions):
    """The plates' operating point: ``--N`` and ``--omega``."""

    N: NormalLoad = None
    omega: Omega = None


@dataclass(frozen=True, kw_only=True)
class ContinuedPoint(OperatingPoint):
    """:class:`OperatingPoint` of ``continue``, whose ``--param`` may be N or Ω."""

    N: VariedLoad = None
    omega: ContinuedOmega = None


@dataclass(frozen=True, kw_only=True)
class Friction(PlatesOptions):
    """The plates' friction law: ``--mu-k``, ``--delta-mu``, ``--alpha``."""

    mu_k: MuK = None
    delta_mu: DeltaMu = None
    alpha: Alpha = None


@dataclass(frozen=True, kw_only=True)
class Plates(OperatingPoint):
    """The plates' parameters with options of their own: :class:`OperatingPoint` and :class:`Friction`."""

    friction: Friction = field(default_factory=Friction)


@dataclass(frozen=True, kw_only=True)
class BifurcationPlates(Plates):
    """:class:`Plates` of ``bifurcation``, whose ``--param`` may vary N or Ω and whose Ω has a base of its own."""

    N: VariedLoad = None
    omega: BifurcationOmega = None


# ----------------------------------------------------------------------------- runs
#: Tolerances of the event method (``simulate`` and every run of a sweep or basin study).
Rtol = Annotated[float, typer.Option("--rtol", help="Relative tolerance of the event method.")]
Atol = Annotated[float, typer.Option("--atol", help="Absolute tolerance of the event method.")]
#: Tolerance of the runs and flow maps of the orbit commands (``orbit``, ``lyapunov``, ``continue``).
OrbitRtol = Annotated[float, typer.Option("--rtol", help="Relative tolerance of every run and flow map "
                                          "(atol = 1e-3 rtol).")]
Tol = Annotated[float, typer.Option("--tol", help="Newton tolerance of every orbit (scaled shooting residual).")]
SlipBand = Annotated[Optional[float], typer.Option("--slip-band", help="Low-speed band of the slip direction [m/s] "
                                                   "(default: that of stickslip.simulate).")]
SampleRate = Annotated[float, typer.Option("--sample-rate", help="Output samples per second of each run [Hz].")]


@dataclass(frozen=True, kw_only=True)
class Tolerances:
    """``--rtol`` and ``--atol`` of the event method."""

    rtol: Rtol = 1e-8
    atol: Atol = 1e-10


# ----------------------------------------------------------------------------- orbits
#: Help text of ``--ic`` of the commands that start from a run (``orbit``, ``lyapunov``, ``continue``).
IC_HELP = ("Start run: zero | near | equilibrium | a start of the model's own (the plates' far; `stickslip models "
           "NAME` lists them) | NAME=VALUE,... by state name, e.g. x=0,dx=1.5. Default: the model's own first "
           "start (the plates' far), else zero.")

StartIc = Annotated[Optional[str], typer.Option("--ic", help=IC_HELP)]
SearchTime = Annotated[float, typer.Option("--search-time", help="Length of the start run [s]; the guess is taken "
                                           "from its last section crossings.")]
Section = Annotated[str, typer.Option("--section", help="Poincaré section: max (maximum of the model's observed "
                                      "coordinate, the plates' φ) | DOF_max | DOF=LEVEL (up-crossing of a level), "
                                      "e.g. x2_max.")]


@dataclass(frozen=True, kw_only=True)
class OrbitSearch:
    """Where shooting starts: a run of ``--search-time`` from ``--ic``, and its last ``--section`` crossings."""

    ic: StartIc = None
    section: Section = "max"
    search_time: SearchTime


# ----------------------------------------------------------------------------- sweeps
_TEND_HELP = "Simulated time of every grid point [s]."
_SETTLE_HELP = ("Extend every run from its end until it has settled (or reaches --cap); --t-end is then the first "
                "run's length and --t-end minus --t-from the window and the step.")

GridTEnd = Annotated[float, typer.Option("--t-end", help=_TEND_HELP)]
#: ``--t-end`` of ``regions``, whose default is long for the reason it gives.
RegionsTEnd = Annotated[float, typer.Option("--t-end", help=_TEND_HELP + " Long, because the 'near' start leaves a "
                                            "weakly unstable equilibrium slowly.")]
TFrom = Annotated[Optional[float], typer.Option("--t-from", help="Start of the steady-state window [s] "
                                                "(default t_end/2).")]
#: ``--t-from`` of ``regions``, whose default window is the last 100 s.
RegionsTFrom = Annotated[Optional[float], typer.Option("--t-from", help="Start of the steady-state window [s] "
                                                       "(default: the last 100 s, or the last half of shorter runs).")]
Settle = Annotated[bool, typer.Option("--settle", help=_SETTLE_HELP)]
Cap = Annotated[Optional[float], typer.Option("--cap", help="Longest run of a point when settling [s] "
                                              "(default 2000).")]


@dataclass(frozen=True, kw_only=True)
class Settling:
    """``--settle`` and ``--cap``: runs of a grid extended until they have settled."""

    settle: Settle = False
    cap: Cap = None


# ----------------------------------------------------------------------------- parallel work
Executor = Annotated[Optional[str], typer.Option("--executor", help="serial | processes | dask (default processes; "
                                                 "dask when --scheduler is given).")]
Workers = Annotated[Optional[int], typer.Option("--workers", help="Worker processes (default: all cores); with dask "
                                                "and no --scheduler, the LocalCluster size.")]
Scheduler = Annotated[Optional[str], typer.Option("--scheduler", help="dask.distributed scheduler address, e.g. "
                                                  "tcp://head-node:8786 (implies --executor dask).")]
NoProgress = Annotated[bool, typer.Option("--no-progress", help="No progress bar.")]


@dataclass(frozen=True, kw_only=True)
class Parallel:
    """Where the runs of a study go: ``--executor``, ``--workers``, ``--scheduler``."""

    executor: Executor = None
    workers: Workers = None
    scheduler: Scheduler = None

    def options(self) -> dict:
        """``executor``, ``workers`` and ``address`` as the library's parallel studies take them.

        Raises
        ------
        CLIError
            For a scheduler with an executor other than dask (:func:`~._app.executor_of`).
        """
        return dict(executor=executor_of(self.executor, self.scheduler), workers=self.workers, address=self.scheduler)


# ----------------------------------------------------------------------------- outputs
#: Help text of ``--overwrite`` of a command whose outputs are not resumable.
OVERWRITE_HELP = "Replace existing output files instead of refusing."

#: Help text of ``--overwrite`` of a command that writes into a folder.
OVERWRITE_FOLDER_HELP = "Write into a folder that is not empty, replacing files of the same names."

#: Help text of ``--overwrite`` of a resumable command.
RESTART_HELP = ("Start over: replace the output, its journal and its figure (of this or another run) instead of "
                "resuming or refusing.")

#: ``--out`` of a one-shot command.
Out = Annotated[Path, typer.Option("--out", help="NetCDF output; the figure goes beside it as .png.")]
#: ``--out`` of a resumable command.
ResumableOut = Annotated[Path, typer.Option("--out", help="NetCDF output, journaled as it goes (OUT.nc.journal): "
                                            "the same command again resumes; the figure goes beside it as .png.")]
Overwrite = Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)]
Restart = Annotated[bool, typer.Option("--overwrite", help=RESTART_HELP)]
OverwriteFolder = Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_FOLDER_HELP)]
NoPlot = Annotated[bool, typer.Option("--no-plot", help="Do not draw the figure.")]
#: ``--json`` of a command that prints a summary table.
JsonSummary = Annotated[bool, typer.Option("--json", help="Print a one-line JSON summary instead of the table.")]


@dataclass(frozen=True, kw_only=True)
class Outputs:
    """A one-shot command's outputs: ``--out``, ``--overwrite``, ``--no-plot``."""

    out: Out
    overwrite: Overwrite = False
    no_plot: NoPlot = False


@dataclass(frozen=True, kw_only=True)
class Study:
    """A resumable study's runs and outputs: :class:`Parallel`, ``--out``, ``--overwrite``,
    ``--no-plot``, ``--no-progress``."""

    parallel: Parallel = field(default_factory=Parallel)
    out: ResumableOut
    overwrite: Restart = False
    no_plot: NoPlot = False
    no_progress: NoProgress = False
