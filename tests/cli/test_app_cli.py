"""The application around every command: one error line (exit 2) for what the user can fix,
exit 130 and one line on Ctrl-C, text that is printed as written (no rich markup), and units in
every --help."""

import os
import re
import signal
import subprocess
import sys
import threading
import time

import importlib
import inspect
import json
import typing

import pytest
import typer
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.cli._lazy import import_all

runner = CliRunner()


def invoke(*args, **kwargs):
    return runner.invoke(app, list(args), **kwargs)


def one_error_line(res, code=2, prefix="error:") -> str:
    """The single line of a refused command (exit ``code``, no traceback)."""
    assert res.exit_code == code, res.output
    assert res.exception is None or isinstance(res.exception, SystemExit), res.exception
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith(prefix), res.output
    return lines[0]


def commands(typer_app=app, path=()):
    """(command path, callback) of every command (each command's module imported: they register when asked for)."""
    import_all()
    for info in typer_app.registered_commands:
        yield [*path, info.name or info.callback.__name__.replace("_", "-")], info.callback
    for group in typer_app.registered_groups:
        yield from commands(group.typer_instance, (*path, group.name))


def options(callback):
    """(flag, type, help) of every option of a command: declared as the parameter's default, or in
    its ``Annotated`` type (the shared options of ``stickslip.cli._options``)."""
    hints = typing.get_type_hints(callback, include_extras=True)
    for name, parameter in inspect.signature(callback).parameters.items():
        hint, info, decls = hints.get(name), parameter.default, ()
        if typing.get_origin(hint) is typing.Annotated:
            hint, *extras = typing.get_args(hint)
            info = next((x for x in extras if isinstance(x, typer.models.OptionInfo)), info)
            decls = () if info.default is ... else (info.default,)  # in Annotated, the first name comes as default
        if isinstance(info, typer.models.OptionInfo):
            decls += tuple(info.param_decls or ())
            yield (decls[0] if decls else f"--{name}"), hint, info.help or ""


def test_options_are_read_from_defaults_and_annotated_types():
    """The two tests below see every option: an inline one and a shared one, with their types."""
    found = {(" ".join(path), flag): kind for path, callback in commands() for flag, kind, _ in options(callback)}
    assert found[("simulate", "--cap")] is float  # declared inline
    assert found[("sweep", "--t-end")] is float and found[("orbit", "--slip-band")] == typing.Optional[float]


# ----------------------------------------------------------------------------- usage errors
@pytest.mark.parametrize("args, words", [
    (["simulate", "--N", "abc"], "Invalid value for '--N'"),
    (["simulate", "--bogus", "1"], "No such option: --bogus"),
    (["continue", "--param", "Omega"], "Missing option '--from'"),
    (["stability-map", "--N-points", "2.5"], "Invalid value for '--N-points'"),
    (["no-such-command"], "No such command"),
])
def test_usage_errors_are_one_line(args, words):
    line = one_error_line(invoke(*args))
    assert words in line and "--help" in line, line


# ----------------------------------------------------------------------------- markup
@pytest.mark.parametrize("text", ["[red]a:b:c", "[bold]x[/]", ":smile:"])
def test_user_input_in_an_error_is_printed_as_given(text):
    line = one_error_line(invoke("simulate", "--model", text, "--t-end", "1", "--json"))
    assert text in line, line


def test_user_input_in_a_summary_is_printed_as_given(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = invoke("simulate", "--t-end", "1", "--no-plot", "--out", "[red]a:b:c.nc")
    assert res.exit_code == 0, res.output
    assert "[red]a:b:c.nc" in res.output and (tmp_path / "[red]a:b:c.nc").is_file()


#: Options without a unit (counts, names, flags, and dimensionless numbers).
DIMENSIONLESS = {"--mu-k", "--delta-mu", "--rtol", "--atol", "--tol", "--step", "--max-step", "--match-rtol"}


def test_every_float_option_states_its_unit():
    missing = []
    for path, callback in commands():
        for flag, kind, text in options(callback):
            if kind in (float, typing.Optional[float]) and flag not in DIMENSIONLESS:
                if not re.search(r"\[[^\]]+\]", text):
                    missing.append(f"{' '.join(path)} {flag}")
    assert not missing, missing


@pytest.mark.parametrize("name", [" ".join(path) for path, _ in commands()])
def test_help_shows_every_bracket_as_written(name):
    path, callback = next((p, c) for p, c in commands() if " ".join(p) == name)
    res = invoke(*path, "--help")
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.replace("│", " ").split())  # the words, without the panel's borders
    for flag, _, help_text in options(callback):
        for token in re.findall(r"\[[^\]]*\]", help_text):
            assert token in text, f"{name} {flag}: {token} missing from --help"


# ----------------------------------------------------------------------------- paths
def test_a_directory_as_output_is_one_line(tmp_path):
    (tmp_path / "d.nc").mkdir()
    line = one_error_line(invoke("simulate", "--t-end", "1", "--out", str(tmp_path / "d.nc")))
    assert "directory" in line and "--out" in line


def test_an_unwritable_output_is_one_line(tmp_path):
    line = one_error_line(invoke("simulate", "--t-end", "1", "--out", "/proc/stickslip-test/x.nc"))
    assert "/proc" in line


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_folder_is_one_line(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir(mode=0o555)
    line = one_error_line(invoke("simulate", "--t-end", "1", "--out", str(ro / "x.nc")))
    assert "not writable" in line and "--out" in line


def test_an_os_error_while_writing_is_one_line(tmp_path, monkeypatch):
    import stickslip.cli.simulate as command

    def full_disk(path):
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr(command, "netcdf_writer", lambda ds: full_disk)
    line = one_error_line(invoke("simulate", "--t-end", "1", "--no-plot", "--out", str(tmp_path / "x.nc")))
    assert "No space left on device" in line


# ----------------------------------------------------------------------------- bugs stay visible
def test_a_bug_keeps_its_traceback(tmp_path, monkeypatch):
    import stickslip.cli.simulate as command

    def broken(*args, **kwargs):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(command, "run_simulation", broken)
    res = invoke("simulate", "--t-end", "1", "--out", str(tmp_path / "x.nc"))
    assert isinstance(res.exception, ZeroDivisionError)


# ----------------------------------------------------------------------------- Ctrl-C
def test_ctrl_c_is_one_line_and_exit_130(tmp_path, monkeypatch):
    import stickslip.cli.simulate as command

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(command, "run_simulation", interrupted)
    res = invoke("simulate", "--t-end", "1", "--out", str(tmp_path / "x.nc"))
    line = one_error_line(res, code=130, prefix="interrupted:")
    assert "nothing was written" in line
    assert not (tmp_path / "x.nc").exists()


@pytest.mark.parametrize("target, args, journal, kept", [
    ("stickslip.cli.continue_.start_run", ["continue", "--from", "5", "--to", "6", "--out", "b.nc"], "b.nc.journal",
     "finished work is kept in b.nc.journal; run the same command again to resume"),
    ("stickslip.cli.sweep.run_sweep", ["sweep", "--grid", "N=30,50", "--out", "s.nc"], "s.nc.journal",
     "finished work is kept in s.nc.journal; run the same command again to resume"),
    ("stickslip.cli.sweep.run_sweep", ["sweep", "--grid", "N=30,50", "--out", "s.nc"], None, "nothing was written"),
    ("stickslip.cli.reproduce.run_reproduce", ["reproduce", "--only", "fig3", "--out", "paper"], None,
     "the figures finished so far are listed in paper/report.md"),
    ("stickslip.cli.orbit.lyapunov_spectrum", ["lyapunov", "--out", "l.nc"], None, "nothing was written"),
])
def test_ctrl_c_says_what_each_command_keeps(target, args, journal, kept, tmp_path, monkeypatch):
    """A resumable command names its journal when one was started, and only then."""
    module, _, name = target.rpartition(".")

    def interrupted(*a, **k):
        if journal is not None:
            (tmp_path / journal).mkdir()
        raise KeyboardInterrupt

    monkeypatch.setattr(importlib.import_module(module), name, interrupted)
    monkeypatch.chdir(tmp_path)
    line = one_error_line(invoke(*args), code=130, prefix="interrupted:")
    assert line == f"interrupted: {kept}"


def _size(path) -> int:
    """Bytes in a journal (a file, or a folder of files); -1 when there is none."""
    if path.is_dir():
        return sum(f.stat().st_size for f in path.iterdir())
    return path.stat().st_size if path.exists() else -1


def _journaled_orbits(path) -> int:
    """Points of the branch in a continuation's journal: its ``JSON<TAB>crc`` lines after the
    header whose record holds a ``"point"`` (the start orbit is recorded before the first of them)."""
    if not path.is_file():
        return 0
    count = 0
    for line in path.read_bytes().splitlines()[1:]:
        try:
            record = json.loads(line.rpartition(b"\t")[0])
        except ValueError:  # a line being written
            continue
        count += isinstance(record, dict) and "point" in record
    return count


def _stickslip(*args, prelude: str = "") -> list:
    # faulthandler: a command that Ctrl-C did not end shows where it was (SIGABRT, _interrupt_when)
    return [sys.executable, "-X", "faulthandler", "-c", f"{prelude}\nfrom stickslip.cli import app; app()", *args]


#: Run before the command line: the first chunk of a run touches the file named by
#: ``STICKSLIP_TEST_CHUNK_DONE`` once recorded. The test presses Ctrl-C on that evidence, whatever
#: the imports and the kernels (compiled on a cold cache: a minute or more) took before it.
_MARK_FIRST_CHUNK = """
import os, pathlib
from stickslip.integrate import runner
_add = runner.Record.add
def _add_and_mark(self, chunk):
    _add(self, chunk)
    if self.n > 0:
        pathlib.Path(os.environ["STICKSLIP_TEST_CHUNK_DONE"]).touch()
runner.Record.add = _add_and_mark
"""


def _interrupt_when(proc, ready, deadline_s=900.0) -> tuple:
    """Send SIGINT to ``proc`` once ``ready(stderr lines so far)`` is true (or ``deadline_s`` has
    passed, or it has ended); its (returncode, stdout, stderr lines). A command still running 60 s
    after the SIGINT fails the test with the stacks of its threads."""
    streams = {"out": [], "err": []}

    def read(stream, into: list) -> None:  # line by line, so that ``ready`` sees each as it comes
        for line in stream:
            into.append(line)

    readers = [threading.Thread(target=read, args=(proc.stdout, streams["out"]), daemon=True),
               threading.Thread(target=read, args=(proc.stderr, streams["err"]), daemon=True)]
    for reader in readers:
        reader.start()
    deadline = time.monotonic() + deadline_s
    while not ready(list(streams["err"])) and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    try:
        proc.wait(timeout=60)
    except subprocess.TimeoutExpired:
        proc.send_signal(signal.SIGABRT)  # faulthandler prints every thread's stack, then the process ends
        proc.wait(timeout=60)
        for reader in readers:
            reader.join(timeout=10)
        pytest.fail(f"Ctrl-C did not end the command within 60 s; where it was:\n{''.join(streams['err'])[-6000:]}")
    finally:
        proc.kill()  # if Ctrl-C did not end it
    for reader in readers:
        reader.join(timeout=60)
    stderr = "".join(streams["err"])
    return proc.returncode, "".join(streams["out"]), [ln for ln in stderr.splitlines() if ln.strip()]


@pytest.mark.parametrize("command", [
    ["sweep", "--grid", "N=20:80:8", "--grid", "Omega=0.5", "--t-end", "2", "--executor", "serial", "--no-progress"],
    ["continue", "--from", "5", "--to", "30", "--max-points", "100000", "--step", "1e-4",
     "--max-step", "2e-4", "--search-time", "20", "--no-progress"],
])
def test_ctrl_c_stops_resumable_work_keeps_its_journal_and_the_same_command_resumes(command, tmp_path):
    out, journal = tmp_path / "r.nc", tmp_path / "r.nc.journal"
    if command[0] == "continue":
        # compile (or load) every kernel a continuation step uses before the timed run: Ctrl-C
        # during a first compilation waits for numba to finish it (a minute on a cold cache)
        short = [("3" if prev == "--max-points" else arg) for prev, arg in zip([None, *command], command)]
        warm = subprocess.run(_stickslip(*short, "--no-plot", "--out", str(tmp_path / "warm.nc")),
                              capture_output=True, text=True, timeout=900)
        assert warm.returncode == 0, warm.stderr
    cmd = _stickslip(*command, "--no-plot", "--out", str(out), "--json")
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def first_work_journaled(_) -> bool:
        if command[0] == "sweep":  # a finished point recorded (the manifest is written first)
            return _size(journal / "rows.f64") > 0
        return _journaled_orbits(journal) > 0  # not only the start orbit: a point of the branch

    code, _, lines = _interrupt_when(proc, first_work_journaled)
    assert code == 130, lines
    assert len(lines) == 1 and lines[0].startswith("interrupted:") and "resume" in lines[0], lines
    assert not out.exists() and _size(journal) > 0
    if command[0] == "continue":
        again = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        code, _, lines = _interrupt_when(again, lambda said: len(said) > 0)  # Ctrl-C once it has said its first line
        assert code == 130 and lines[0].startswith("resuming from "), lines
        assert len(lines) == 2 and lines[1].startswith("interrupted:") and "resume" in lines[1], lines
        return
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr
    summary = json.loads(again.stdout.strip().splitlines()[-1])
    assert summary["points_resumed"] >= 1 and summary["points_resumed"] + summary["points_computed"] == 8


def test_ctrl_c_keeps_the_part_of_a_run_done(tmp_path):
    from stickslip import load_trajectory

    out, chunk_done = tmp_path / "x.nc", tmp_path / "first-chunk-done"
    proc = subprocess.Popen(_stickslip("simulate", "--t-end", "100000", "--sample-rate", "10", "--no-plot",
                                       "--out", str(out), prelude=_MARK_FIRST_CHUNK),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "STICKSLIP_TEST_CHUNK_DONE": str(chunk_done)})
    code, _, lines = _interrupt_when(proc, lambda _: chunk_done.exists())
    assert chunk_done.exists(), lines  # the run had started when Ctrl-C was pressed
    assert code == 130, lines
    assert len(lines) == 1 and lines[0].startswith("interrupted: the run up to t = ") and str(out) in lines[0], lines
    kept = load_trajectory(out)
    assert 0 < kept.t[-1] < 100000 and kept.status.startswith("interrupted at t = ")
    assert f"t = {kept.t[-1]:g} s" in lines[0]  # the line says what the file holds


def test_the_command_line_starts_without_scipys_solvers():
    """scipy's optimisers and integrators (0.3 s of a start) are imported by what uses them."""
    code = ("import sys, stickslip.cli; "
            "print(sorted(m for m in ('scipy.optimize', 'scipy.integrate') if m in sys.modules))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "[]"
