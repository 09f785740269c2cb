"""The options that several commands take, each defined once.

Each option is a :data:`typing.Annotated` alias that a command uses as a parameter's type, with
its default where the parameter is declared (``rtol: Rtol = 1e-8``): the flag, the type and the
help text live here, the default stays with the command, since commands differ in it (the event
method of a sweep runs at 1e-8, the flow maps of shooting at 1e-10). An option means one thing
wherever its alias is used; where commands mean different things by the same flag (``--overwrite``
of a one-shot command replaces its outputs, of a resumable one it also discards the work kept for
a resume), each meaning has its own alias. An option that only one command takes, or that means
something only one command means (``simulate --t-end auto``, a command's own JSON object), is
declared with that command.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, List, Optional

import typer

# ----------------------------------------------------------------------------- the model
#: Help text of ``--model`` for commands that take any model.
MODEL_HELP = ("The model: a library name (two-plates, belt, hoffmann, popp-stelter; see 'stickslip models'), a model "
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

# ----------------------------------------------------------------------------- parallel work
Executor = Annotated[Optional[str], typer.Option("--executor", help="serial | processes | dask (default processes; "
                                                 "dask when --scheduler is given).")]
Workers = Annotated[Optional[int], typer.Option("--workers", help="Worker processes (default: all cores); with dask "
                                                "and no --scheduler, the LocalCluster size.")]
Scheduler = Annotated[Optional[str], typer.Option("--scheduler", help="dask.distributed scheduler address, e.g. "
                                                  "tcp://head-node:8786 (implies --executor dask).")]
NoProgress = Annotated[bool, typer.Option("--no-progress", help="No progress bar.")]

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
