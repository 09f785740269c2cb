"""The typer application, its one error path, and helpers shared by the commands.

Every command runs inside :class:`_Application`, which turns what the user can fix into one line
on stderr and exit code 2: option values the parser refuses, any
:class:`~stickslip.errors.StickSlipError` (the library's and this package's :class:`CLIError`),
and operating-system errors with a path (read-only, missing or wrong kind of file or folder, full
disk). Anything else is a bug and keeps its traceback. Text is printed as written: the consoles
read no rich markup or emoji codes, and help texts are escaped from markup once, here; a console
that cannot encode a character (``PYTHONIOENCODING=ascii``) prints ``?`` for it.

Ctrl-C has one path too: whenever it lands (start-up, compilation, a run, a write, a figure),
the command ends with exit code 130 and one line saying what is on disk at that moment, from the
files the command registered as it wrote them (:mod:`._kept`). A Ctrl-C while the package and
the commands are imported and the command line is parsed is held (:mod:`stickslip._startup`)
and reported the same way.
"""

from __future__ import annotations

import contextlib
import errno
import math
import os
import sys
import warnings
from pathlib import Path
from typing import Callable

import rich
import typer
from rich.console import Console
from rich.markup import escape
from rich.text import Text
from typer.core import TyperGroup

from .. import _startup
from .._version import __version__
from ..errors import StickSlipError
from ._kept import forget_outputs, on_disk, on_interrupt
from ._lazy import LazyCommands, runs_kernels

console = Console(markup=False, emoji=False, highlight=False)
err_console = Console(stderr=True, markup=False, emoji=False, highlight=False, soft_wrap=True)

#: The click base class of usage errors (typer re-exports only its subclass BadParameter; recent
#: typer versions carry their own copy of click).
_ClickException = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException")

#: errno values of operating-system errors about a path the user gave or can fix.
_PATH_ERRNOS = {getattr(errno, name) for name in ("EACCES", "EPERM", "EROFS", "ENOENT", "EISDIR", "ENOTDIR", "EEXIST",
                                                  "ENOSPC", "EDQUOT", "ENAMETOOLONG", "ELOOP", "EFBIG")
                if hasattr(errno, name)}


class CLIError(StickSlipError, ValueError):
    """An option value the command line refuses: out of range, conflicting, or an output that
    must not be replaced. The message names the option and the fix."""


def exact(value) -> str:
    """A number given on the command line as the shortest text that reads back as it (``50``,
    ``0.1``, ``1.0000001``, ``1e+300``): what a message quotes of an option's value (``:g`` would
    round it to six digits)."""
    if isinstance(value, int) and not isinstance(value, bool):
        return str(value)
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def as_typed(flag: str, value) -> str:
    """Option ``flag``'s ``value`` as the user typed it where the float lost it (a number beyond
    the float range reads as ``inf``: its 400 digits are quoted, not ``inf``), else :func:`exact`."""
    if isinstance(value, float) and not math.isfinite(value):
        args = sys.argv[1:]
        for i, arg in enumerate(args):
            text = arg[len(flag) + 1:] if arg.startswith(flag + "=") else (
                args[i + 1] if arg == flag and i + 1 < len(args) else None)
            try:
                typed = float(text) if text is not None else None
            except ValueError:
                continue
            if typed is not None and (typed == value or math.isnan(typed) and math.isnan(value)):
                return text
    return exact(value)


def error_line(message: str) -> None:
    """Print ``error: message`` as one line on stderr, exactly as written: what the user typed is
    quoted as typed, however many digits it has."""
    err_console.print(Text.assemble(("error:", "bold red"), " ", " ".join(str(message).split())))


def warning_line(message: str) -> None:
    """Print ``warning: message`` as one line on stderr (stdout stays clean for --json)."""
    err_console.print(Text.assemble(("warning:", "yellow"), " ", " ".join(str(message).split())))


def note_line(message: str) -> None:
    """Print one informative line on stderr."""
    err_console.print(Text(" ".join(str(message).split()), style="dim"))


def resumable_holds(what: str) -> Callable[[Path], str]:
    """What a resumable command's output holds, read from its ``complete`` attribute when it was
    written: the finished ``what``, or part of it with the journal that keeps the rest."""
    def holds(path: Path) -> str:
        import h5py  # the attributes alone, without opening the dataset (h5py is already loaded by then)
        import numpy as np

        with h5py.File(path, "r") as fh:
            complete = int(np.ravel(fh.attrs.get("complete", 1))[0])  # netCDF attributes are arrays
        if complete:
            return f"the finished {what} is in {path}"
        return (f"{path} holds part of the {what} and {journal_of(path)} the finished work; run the same command "
                "again to resume")
    return holds


#: Whether the running command has printed its ``interrupted:`` line.
_reported = [False]


def report_interrupt() -> None:
    """Print the one ``interrupted: ...`` line (once per command), from what is on disk now."""
    if not _reported[0]:
        _reported[0] = True
        err_console.print(Text(f"interrupted: {on_disk()}"))


def _end_interrupted() -> None:
    """End the process now, exit status 130, after a Ctrl-C was reported. What the command keeps is
    written and closed by then. Ending through the interpreter's shutdown instead would finalise what
    the interrupt left half built (numba's compiler objects, when it came during a compilation: the
    process could crash at exit) and could deliver a Ctrl-C that a finaliser had swallowed
    (:mod:`stickslip._startup` delivers it again a moment later) a second time, ending the process
    by the signal after its one line."""
    patches = sys.modules.get("stickslip.model.numba_patches")  # loaded with numba, if the command got that far
    if patches is not None:
        patches.end_run()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(130)


def _interrupted_by_ctrl_c(exc: BaseException) -> bool:
    """A SystemError that a Ctrl-C caused: raised while a compiled kernel returned its result."""
    while exc is not None:
        if isinstance(exc, KeyboardInterrupt):
            return True
        exc = exc.__cause__ or exc.__context__
    return False


def _path_error_message(exc: OSError) -> str:
    where = exc.filename or ""
    what = exc.strerror or str(exc)
    return (f"cannot write or read {where}: {what}" if where else str(exc)) + \
        "; check the path and its permissions, or choose another path"


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Python warnings of the library, as one ``warning:`` line each."""
    warning_line(str(message))


def _escape_help(command) -> None:
    """Escape the help texts of a command tree from rich markup, so that they print as written
    (units such as [s] and [rad/s] included)."""
    if getattr(command, "help", None):
        command.help = escape(command.help)
    for param in getattr(command, "params", []):
        if getattr(param, "help", None):
            param.help = escape(param.help)
    for sub in getattr(command, "commands", {}).values():
        _escape_help(sub)


class _Application(LazyCommands, TyperGroup):
    """The ``stickslip`` group: the one place where errors become a line and an exit code. Its
    commands are imported when asked for (:class:`._lazy.LazyCommands`)."""

    #: What the running command is inside of (:meth:`invoke`): the compile notice joins it once the
    #: command is known to run kernels (:meth:`resolve_command`).
    _scope = None

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        _escape_help(self)

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True, **extra):
        forget_outputs()
        _reported[0] = False
        _use_replacement_characters()
        try:
            if _startup.release(raise_pending=False):  # a Ctrl-C held since the imports
                raise KeyboardInterrupt
            code = super().main(args=args, prog_name=prog_name, complete_var=complete_var, standalone_mode=False,
                                **extra)
        except KeyboardInterrupt:  # before the command ran (the parser's own turns into exit code 130)
            code = 130
        except _ClickException as exc:  # the parser's: unknown, missing or mistyped options
            code = exc.exit_code
            if type(exc).__name__ != "NoArgsIsHelpError":  # that one has printed the help
                ctx = getattr(exc, "ctx", None)
                error_line(exc.format_message() + (f" (see '{ctx.command_path} --help')" if ctx else ""))
        except typer.Abort:
            error_line("aborted")
            code = 1
        code = code if isinstance(code, int) else 0
        if code == 130:
            report_interrupt()  # unless the command has
        if not standalone_mode:
            return code
        sys.exit(code)

    def invoke(self, ctx):
        from ..integrate.interrupt import forget_ctrl_c, on_ctrl_c

        forget_ctrl_c()
        try:
            _check_environment()
            # a run is one of many (sweep points, shooting, continuation): Ctrl-C stops the command;
            # `simulate` keeps its one interrupted run instead
            with warnings.catch_warnings(), on_ctrl_c(partial=False), contextlib.ExitStack() as self._scope:
                warnings.showwarning = _show_warning
                return super().invoke(ctx)
        except StickSlipError as exc:
            error_line(str(exc))
        except OSError as exc:
            if exc.errno not in _PATH_ERRNOS:
                raise
            error_line(_path_error_message(exc))
        except KeyboardInterrupt:
            report_interrupt()
            raise typer.Exit(130) from None
        except SystemError as exc:
            if not _interrupted_by_ctrl_c(exc):
                raise
            report_interrupt()
            raise typer.Exit(130) from None
        finally:
            release_outputs()
            self._scope = None
        raise typer.Exit(2)

    def resolve_command(self, ctx, args):
        if args and self._scope is not None and runs_kernels(args[0]):
            # before the command's module is imported: a kernel compiled from then on is counted
            self._scope.enter_context(_compile_notice())
        return super().resolve_command(ctx, args)


class _Typer(typer.Typer):
    """The typer application whose start-up (building the command tree, until
    :meth:`_Application.main` runs) holds Ctrl-C as the imports before it did (:mod:`stickslip._startup`)."""

    def __call__(self, *args, **kwargs):
        _startup.hold()
        try:
            return super().__call__(*args, **kwargs)
        except SystemExit as exc:
            if exc.code == 130:  # the command line's own process, after a Ctrl-C
                _end_interrupted()
            raise
        finally:
            _startup.release(raise_pending=False)  # main has released it, unless it never ran


def _use_replacement_characters() -> None:
    """Let stdout and stderr print ``?`` for characters their encoding lacks (``PYTHONIOENCODING=ascii``,
    a C locale) instead of failing on the first ``–`` or ``φ``."""
    for stream in (sys.stdout, sys.stderr):
        encoding = getattr(stream, "encoding", None) or "utf-8"
        try:
            "–≈φ│".encode(encoding)
        except (UnicodeEncodeError, LookupError):
            try:
                stream.reconfigure(errors="replace")
            except (AttributeError, ValueError):  # not a text stream of the interpreter's (tests capture it)
                pass


def _compile_notice():
    """Compile time counted for the command (:mod:`._compiling`), and a line while numba compiles
    when stderr is a terminal, with a spinner below it where stdout is one too. The spinner is on
    rich's global console, the console of the studies' progress bars, so that rich shows both
    together instead of letting them overwrite each other; it is transient and leaves nothing in
    the output."""
    from ._compiling import compile_notice

    terminal = getattr(sys.stderr, "isatty", lambda: False)()
    return compile_notice(note_line if terminal else None, rich.get_console() if terminal else None)


def _check_environment() -> None:
    """Refuse an environment the kernels cannot run in; say what :mod:`stickslip._startup` changed."""
    if os.environ.get("NUMBA_DISABLE_JIT", "0").strip() not in ("", "0"):
        raise CLIError(f"NUMBA_DISABLE_JIT={os.environ['NUMBA_DISABLE_JIT']}: stickslip's kernels must be compiled "
                       "(interpreted, a run would take hours and some kernels cannot run at all); unset "
                       "NUMBA_DISABLE_JIT or set it to 0")
    if os.environ.get("STICKSLIP_COMPILE_PROCESSES", "").strip():  # unset or empty: the default, 2
        from ..parallel import compile_processes  # noqa: PLC0415 - the process pools' module, not needed otherwise

        compile_processes()  # a setting that is not a positive integer: one line, exit 2
    for note in _startup.notes:
        warning_line(note)


app = _Typer(
    name="stickslip",
    cls=_Application,
    help="Exact stick-slip simulation and analysis of friction-contact systems (default model: two rigid plates in frictional contact).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
_Application.build = staticmethod(lambda: typer.main.get_command(app))


# ----------------------------------------------------------------------------- option parsing
def parse_assignments(items: list[str] | None, option: str = "--set") -> dict:
    """``["N=50", "friction_law=coulomb"]`` → ``{"N": 50.0, "friction_law": "coulomb"}``.

    Raises
    ------
    CLIError
        For an item without ``=`` or a name given twice.
    """
    values: dict = {}
    for item in items or []:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise CLIError(f"{option} expects NAME=VALUE, got {item!r}; e.g. {option} "
                           + ("k_px=400" if option == "--set" else "dx=1"))
        if name in values:
            raise CLIError(f"{option} {name} is given twice; give each once")
        text = text.strip()
        try:
            values[name] = float(text)
        except ValueError:
            values[name] = text
            continue
        if not math.isfinite(values[name]) and text.lower().lstrip("+-") not in ("inf", "infinity", "nan"):
            raise CLIError(f"{option} {item.strip()}: {text} is beyond the range of a float (about ±1.8e308); "
                           "give a finite number")
    return values


#: The option of each parameter that has one of its own.
PARAMETER_FLAGS = {"N": "--N", "Omega": "--omega", "mu_k": "--mu-k", "delta_mu": "--delta-mu", "alpha": "--alpha"}


#: Largest ``--config`` file read [bytes]: it holds a table of parameters.
MAX_CONFIG_BYTES = 2**20


def _config_table(config) -> dict:
    """The TOML of a ``--config`` file, read bounded (a regular file of at most
    :data:`MAX_CONFIG_BYTES`: a folder, a pipe or a device is refused before it is read)."""
    # here, not at start-up: `--version`, `--help` and `models` need no files read or written
    from ..inputs import read_regular_file  # noqa: PLC0415

    if sys.version_info >= (3, 11):
        import tomllib  # noqa: PLC0415
    else:  # pragma: no cover - exercised only on Python 3.10
        import tomli as tomllib  # noqa: PLC0415

    data = read_regular_file(config, MAX_CONFIG_BYTES, "--config", CLIError,
                             "give a TOML file with a [parameters] table")
    try:
        return tomllib.loads(data.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise CLIError(f"--config {config} is not valid TOML ({exc}); fix the syntax") from None
    except RecursionError:
        raise CLIError(f"--config {config}: a value is nested too deeply to read; give a [parameters] table of "
                       "name = number") from None


def config_values(config) -> dict:
    """``{name: value}`` of the parameters a --config TOML file sets (validated; names it does
    not set are left out)."""
    from ..model.parameters import Parameters

    data = _config_table(config)
    table = data.get("parameters", data)
    if not isinstance(table, dict):
        raise CLIError(f"--config {config}: [parameters] must be a table of name = value")
    loaded = Parameters.from_dict(table)
    return {name: getattr(loaded, name) for name in table}


def build_system(model: str, config, assignments, *, base=None, swept: dict | None = None, **named):
    """The model a command runs on, from ``--model``, ``--config``, ``--set`` and the plates' named options.

    Parameters
    ----------
    model : str
        ``--model``: a library name, a model file path, or a variant of the two plates.
    config : path or None
        ``--config`` (a TOML file with a [parameters] table of names or paths).
    assignments : list of str or None
        ``--set`` items, ``PATH=VALUE``.
    base : FrictionModel, optional
        The model the options change (a continued run's) when ``model`` names it or a variant of
        the plates it is; default the one ``model`` names.
    swept : dict of parameter name → option, optional
        Parameters the command varies itself; setting one of them too is refused.
    **named
        The plates' named options by parameter name (``N=``, ``Omega=``, ...; None: not given).

    Returns
    -------
    system : FrictionModel
    given : list of str
        The options that set a parameter, in order.

    Raises
    ------
    CLIError, ModelError
        For an unknown model or parameter, a plates option given for another model, or two
        options that set the same parameter.
    """
    from ..model.library import load_model, plates_variant, two_plates
    from ..model.library.two_plates import is_plates
    from ..model.parameters import Parameters

    variant = plates_variant(model)
    if base is not None:  # a continued run: its own model (the caller checked that ``model`` names it)
        system = base
    else:
        system = two_plates(Parameters(), variant) if variant is not None else load_model(model)
    plates = is_plates(system)
    named = {k: v for k, v in named.items() if v is not None}
    if named and not plates:
        raise CLIError(f"{PARAMETER_FLAGS.get(next(iter(named)), '--' + next(iter(named)))} is a parameter of the two "
                       f"plates; model {system.name!r} takes its numbers as --set PATH=VALUE ('stickslip models "
                       f"{model}' lists the paths)")
    changes, given = {}, []
    if config is not None:
        changes.update(config_values(config) if plates else _config_parameters(config))
        given.append("--config")
    assigned = parse_assignments(assignments)
    setters = {item.partition("=")[0].strip(): [f"--set {item.strip()}"] for item in assignments or []}
    for name, value in named.items():
        setters.setdefault(name, []).append(f"{PARAMETER_FLAGS.get(name, '--' + name)} {exact(value)}")
    for name, sweeper in (swept or {}).items():
        setters.setdefault(name, []).insert(0, sweeper)
    for name, options in setters.items():
        if len(options) > 1:
            raise CLIError(f"{' and '.join(options)} both set {name}; give one of them")
    changes.update(assigned)
    changes.update(named)
    given += [f"--set {k}" for k in assigned] + [PARAMETER_FLAGS.get(k, f"--{k}") for k in named]
    return system.replace(**changes).with_slip_band(system.slip_band), given


def _config_parameters(config) -> dict:
    """The ``[parameters]`` table of a ``--config`` TOML file for a model's named parameters."""
    table = _config_table(config).get("parameters", {})
    if not isinstance(table, dict):
        raise CLIError(f"--config {config}: [parameters] must be a table of name = value")
    return dict(table)


def check_nc_path(out, flag: str = "--out") -> None:
    """A NetCDF output path must end in ``.nc``."""
    if Path(out).suffix != ".nc":
        raise CLIError(f"{flag} {out}: give a path ending in .nc")


def check_choice(flag: str, value, choices) -> None:
    """``value`` of option ``flag`` must be one of ``choices``."""
    if value not in choices:
        raise CLIError(f"{flag} {value}: choose one of {', '.join(choices)}")


def check_positive(flags: dict) -> None:
    """Every ``{flag: value}`` must be a finite number > 0 (``None``: not given, skipped)."""
    for flag, value in flags.items():
        if value is not None and not (math.isfinite(value) and value > 0):
            raise CLIError(f"{flag} must be a finite number > 0, got {as_typed(flag, value)}")


def check_below_one(flags: dict) -> None:
    """Every ``{flag: value}`` (a relative tolerance) must be < 1: at 1 or more any guess passes."""
    for flag, value in flags.items():
        if value is not None and not value < 1.0:
            raise CLIError(f"{flag} {exact(value)}: a relative tolerance must be < 1 (typical values 1e-6 … 1e-10)")


def executor_of(executor: str | None, scheduler: str | None) -> str:
    """The executor of ``--executor`` and ``--scheduler``: by default ``dask`` with a scheduler,
    else ``processes``; a scheduler with another executor is refused (the library would ignore it)."""
    if executor is None:
        return "dask" if scheduler else "processes"
    if scheduler and executor != "dask":
        raise CLIError(f"--scheduler needs --executor dask (got --executor {executor})")
    return executor


def check_finite(flags: dict) -> None:
    """Every ``{flag: value}`` must be a finite number (``None``: not given, skipped)."""
    for flag, value in flags.items():
        if value is not None and not math.isfinite(value):
            raise CLIError(f"{flag} must be a finite number, got {as_typed(flag, value)}")


# ----------------------------------------------------------------------------- outputs
#: Locks of the outputs of the running command, taken by the checks below and released when the
#: command ends (:meth:`_Application.invoke`).
_held_outputs: list = []


def hold_output(out: Path) -> None:
    """Take the lock of output ``out`` for the rest of the command: a second writer of it is
    refused now, before anything is computed, not after (:class:`stickslip.files.OutputLock`)."""
    from ..files import lock  # noqa: PLC0415 - see _config_table

    _held_outputs.append(lock(out))


def release_outputs() -> None:
    """Release the locks :func:`hold_output` took (the last release deletes each lock file)."""
    while _held_outputs:
        _held_outputs.pop().release()


def _check_folder(path: Path, flag: str) -> None:
    """The folder of ``path`` exists and is writable, or can be created."""
    folder = path.parent if str(path.parent) else Path(".")
    existing = folder
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        raise CLIError(f"{flag} {path}: {existing} is a file, not a folder; choose another {flag}")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise CLIError(f"{flag} {path}: the folder {existing} is not writable; choose another {flag}")


def check_output(path: Path, overwrite: bool, *, flag: str = "--out", inputs: dict | None = None,
                 what: str | None = None) -> None:
    """Refuse, before anything is computed, an output file that must not or cannot be written.

    Parameters
    ----------
    path : Path
        A file the command will write.
    overwrite : bool
        The command's ``--overwrite``: replace an existing file.
    flag : str
        The option that names it.
    inputs : dict of option → Path, optional
        Files the command reads; never overwritten, not even with ``--overwrite``.
    what : str, optional
        How the messages name the file (default ``"{flag} {path}"``).
    """
    from ..files import refuse_output  # noqa: PLC0415 - see _config_table

    refuse_output(path, overwrite=overwrite, inputs=inputs, flag=flag, what=what)
    _check_folder(path, flag)


def _check_figure(out: Path, overwrite: bool, flag: str = "--out", inputs: dict | None = None) -> None:
    """:func:`check_output` for the figure beside NetCDF output ``out`` (``OUT.png``)."""
    png = out.with_suffix(".png")
    check_output(png, overwrite, flag=flag, inputs=inputs, what=f"the figure {png} of {flag} {out}")


def check_outputs(out: Path, figure: bool, overwrite: bool, **kwargs) -> None:
    """:func:`check_output` for a NetCDF output and, with ``figure``, the .png beside it; then
    hold the output's lock until the command ends (:func:`hold_output`)."""
    check_nc_path(out, kwargs.get("flag", "--out"))
    check_output(out, overwrite, **kwargs)
    if figure:
        _check_figure(out, overwrite, **kwargs)
    hold_output(out)


def journal_of(out: Path) -> Path:
    """The journal a resumable command keeps beside its output (``OUT.nc.journal``)."""
    return out.with_name(out.name + ".journal")


def check_resumable_output(out: Path, figure: bool, overwrite: bool, inputs: dict | None = None) -> bool:
    """Outputs of a resumable command: the NetCDF file and its journal are the command's own
    (the library resumes them or refuses another run's); a figure is refused only when a
    fresh run would replace a file that is not the command's. No output may be an input. Holds
    the output's lock until the command ends (:func:`hold_output`).

    Returns
    -------
    bool
        Whether the figure may replace an existing file: with ``overwrite``, or when the run
        resumes (its figure is the command's own).
    """
    from ..files import refuse_output  # noqa: PLC0415 - see _config_table

    check_nc_path(out)
    refuse_output(out, overwrite=True, inputs=inputs)
    _check_folder(out, "--out")
    fresh = not out.exists() and not journal_of(out).exists()
    if figure:
        _check_figure(out, overwrite or not fresh, inputs=inputs)
    hold_output(out)
    on_interrupt(f"finished work is kept in {journal_of(out)}; run the same command again to resume", journal_of(out))
    return overwrite or not fresh


def check_output_folder(out: Path, overwrite: bool) -> None:
    """An output folder must not hold files already, unless ``overwrite``."""
    if out.exists() and not out.is_dir():
        raise CLIError(f"--out {out} is a file; give a folder")
    if out.is_dir() and any(out.iterdir()) and not overwrite:
        raise CLIError(f"--out {out} is not empty; pass --overwrite to replace its files, or give another --out")
    _check_folder(out / "x", "--out")


def given(ctx: typer.Context, name: str) -> bool:
    """Whether option ``name`` (its parameter name) was given, not left at its default."""
    source = ctx.get_parameter_source(name)
    return source is not None and source.name not in ("DEFAULT", "DEFAULT_MAP")


def _version(value: bool) -> None:
    if value:
        console.print(f"stickslip {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(False, "--version", callback=_version, is_eager=True, help="Print the version and exit."),
) -> None:
    """Exact stick-slip simulation and analysis of friction-contact systems (default model: two rigid plates in frictional contact)."""
