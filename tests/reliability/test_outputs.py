"""Every command writes its outputs through one path (stickslip.files.write_output): it takes the
output's lock before computing, never writes an input (with or without --overwrite), never
replaces a file it was not told to, says in one line when a folder takes no files, and leaves no
lock file beside a finished output."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from stickslip import files
from stickslip.cli import app
from stickslip.files import OutputLock, lock_path

runner = CliRunner()

_HOLDER = """
import sys, time
from stickslip.files import lock
held = lock(sys.argv[1])
print("held", flush=True)
time.sleep(120)
"""

#: A CSV of two belt states, for --ics.
STATES = "x,dx\n1,0\n0.5,1\n"

_BASINS = ["basins", "--model", "belt", "--executor", "serial", "--no-progress"]


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def one_line(res, code: int = 2) -> str:
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert res.exit_code == code, res.output
    assert len(lines) == 1 and lines[0].startswith("error:") and "Traceback" not in res.output, res.output
    return lines[0]


@pytest.fixture
def holder(tmp_path):
    """Another process holding the lock of ``tmp_path / "o.nc"`` (as a running command would)."""
    out = tmp_path / "o.nc"
    proc = subprocess.Popen([sys.executable, "-c", _HOLDER, str(out)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "held"
    yield out, proc.pid
    proc.kill()
    proc.wait()


#: One command of each kind writing ``OUT`` (refused before anything is computed).
WRITERS = {
    "simulate": ["simulate", "--model", "belt", "--t-end", "1", "--overwrite", "--out", "OUT"],
    "orbit": ["orbit", "--model", "belt", "--ic", "x=0,dx=1.5", "--overwrite", "--out", "OUT"],
    "lyapunov": ["lyapunov", "--model", "belt", "--ic", "x=0,dx=1.5", "--overwrite", "--out", "OUT"],
    "stability-map": ["stability-map", "--N-points", "3", "--omega-points", "3", "--overwrite", "--out", "OUT"],
    "basins": [*_BASINS, "--box", "x=-2:2", "--n", "4", "--overwrite", "--out", "OUT"],
    "sweep": ["sweep", "--model", "belt", "--grid", "contact.0.drive=0.5,1", "--t-end", "5", "--overwrite",
              "--out", "OUT"],
    "continue": ["continue", "--model", "belt", "--param", "contact.0.drive", "--from", "1.5", "--to", "1.6",
                 "--ic", "x=0,dx=1.5", "--overwrite", "--out", "OUT"],
}


@pytest.mark.parametrize("name", list(WRITERS))
def test_a_writer_is_refused_while_another_process_writes_its_output(name, holder):
    """Before, `simulate --overwrite` and `orbit --overwrite` on the output of a running `basins`
    computed, reported "wrote" and were then replaced by the basins result."""
    out, pid = holder
    out.write_bytes(b"the running command's snapshot")
    line = one_line(invoke(*[out if a == "OUT" else a for a in WRITERS[name]]))
    assert f"o.nc is being written by process {pid}" in line
    assert out.read_bytes() == b"the running command's snapshot"
    assert not out.with_suffix(".png").exists()


@pytest.mark.parametrize("args", [
    ["simulate", "--model", "belt", "--ic", "x=1,dx=1", "--t-end", "5", "--no-plot"],
    ["sweep", "--model", "belt", "--grid", "contact.0.drive=0.5,1", "--t-end", "5", "--executor", "serial",
     "--no-plot", "--no-progress"],
])
def test_no_lock_file_is_left_beside_a_finished_output(args, tmp_path):
    out = tmp_path / "o.nc"
    res = invoke(*args, "--out", out)
    assert res.exit_code == 0, res.output
    assert [p.name for p in tmp_path.iterdir()] == ["o.nc"]  # before: o.nc.lock too (resumable commands)


def test_a_lock_on_a_file_no_longer_at_its_name_is_not_kept(tmp_path):
    """A holder deletes its lock file while it still holds it, then unlocks. A writer that had
    opened that file just before gets its flock, but must let go and lock the file now at the
    name, or two writers could hold two different files: the check run on every acquisition."""
    out = tmp_path / "o.nc"
    path = lock_path(out)
    stale = os.open(path, os.O_RDWR | os.O_CREAT)
    os.unlink(path)
    current = os.open(path, os.O_RDWR | os.O_CREAT)
    try:
        with pytest.raises(files._Stale):
            files._take_current(path)(stale)
        files._take_current(path)(current)  # the file at the name: kept, the holder recorded
        assert json.loads(path.read_text())["pid"] == os.getpid()
    finally:
        os.close(stale)
        os.close(current)


def test_a_stale_acquisition_is_taken_again(tmp_path, monkeypatch):
    out = tmp_path / "o.nc"
    real, made = files.FileLock, []

    class FirstStale(real):
        def acquire(self, *args, **kwargs):
            made.append(self)
            if len(made) == 1:
                raise files._Stale
            return super().acquire(*args, **kwargs)

    monkeypatch.setattr(files, "FileLock", FirstStale)
    with OutputLock(out, timeout=10) as taken:
        assert taken.held and len(made) == 2 and lock_path(out).exists()
    assert not lock_path(out).exists()  # the last release deletes it


# ----------------------------------------------------------------------------- inputs and existing files
def test_basins_does_not_replace_an_existing_figure_without_overwrite(tmp_path):
    (tmp_path / "o.png").write_text("my figure")
    line = one_line(invoke(*_BASINS, "--box", "x=-2:2", "--n", "4", "--out", tmp_path / "o.nc"))
    assert "o.png exists; pass --overwrite" in line
    assert (tmp_path / "o.png").read_text() == "my figure" and not (tmp_path / "o.nc").exists()


@pytest.mark.parametrize("ics, out", [("states.nc", "states.nc"), ("pic.png", "pic.nc")])
@pytest.mark.parametrize("overwrite", [False, True])
def test_basins_never_writes_its_input(ics, out, overwrite, tmp_path):
    """Before: `--ics states.nc --out states.nc --overwrite` replaced the CSV by the result, and
    `--ics pic.png --out pic.nc` replaced the CSV by the figure."""
    (tmp_path / ics).write_text(STATES)
    args = [*_BASINS, "--ics", tmp_path / ics, "--out", tmp_path / out] + (["--overwrite"] if overwrite else [])
    line = one_line(invoke(*args))
    assert "is the file given to --ics; an input is never overwritten" in line
    assert (tmp_path / ics).read_text() == STATES


def test_the_basins_library_never_writes_its_input(tmp_path):
    from stickslip.basins import basin_stability, from_csv
    from stickslip.files import OutputError
    from stickslip.model.library import load_model

    csv = tmp_path / "states.nc"
    csv.write_text(STATES)
    belt = load_model("belt")
    with pytest.raises(OutputError, match="an input is never overwritten"):
        basin_stability(belt, from_csv(belt, csv), out=csv, overwrite=True, executor="serial")
    assert csv.read_text() == STATES


# ----------------------------------------------------------------------------- folders that take no files
@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs /proc")
@pytest.mark.parametrize("args", [
    ["sweep", "--model", "belt", "--grid", "contact.0.drive=0.5,1", "--t-end", "5", "--out", "/proc/sw.nc"],
    ["continue", "--model", "belt", "--param", "contact.0.drive", "--from", "1.5", "--to", "1.6", "--ic",
     "x=0,dx=1.5", "--out", "/proc/sw.nc"],
    ["simulate", "--model", "belt", "--t-end", "1", "--out", "/proc/sw.nc"],
])
def test_a_folder_that_takes_no_files_is_one_honest_line(args):
    """Before: sweep and continue said "/proc/sw.nc is being written by another process";
    simulate computed, then printed h5py's text with the temporary's name."""
    line = one_line(invoke(*args))
    assert "/proc/sw.nc" in line and "choose another" in line
    assert "being written" not in line and ".tmp" not in line


def test_a_result_written_from_python_never_silently_replaces_a_file(tmp_path):
    """``Trajectory.to_netcdf`` and ``StabilityMap.to_netcdf`` refuse an existing file unless told
    ``overwrite=True``, in the Python API's words, and leave the first file as it was."""
    import numpy as np

    import stickslip
    from stickslip.errors import OutputError

    belt = stickslip.load_model("belt")
    first, second = stickslip.simulate(belt, 1.0), stickslip.simulate(belt, 2.0)
    path = tmp_path / "run.nc"
    first.to_netcdf(path)
    with pytest.raises(OutputError, match=r"run\.nc exists; pass overwrite=True to replace it, or give another path"):
        second.to_netcdf(path)
    assert stickslip.load_trajectory(path).t[-1] == first.t[-1]
    second.to_netcdf(path, overwrite=True)
    assert stickslip.load_trajectory(path).t[-1] == second.t[-1]
    assert not lock_path(path).exists()

    smap = stickslip.stability_map(belt, np.linspace(0.5, 2.0, 3), np.linspace(0.5, 1.0, 2),
                                   axes=("contact.0.normal_force", "contact.0.drive"))
    with pytest.raises(OutputError, match="overwrite=True"):
        smap.to_netcdf(path)
    smap.to_netcdf(tmp_path / "map.nc")
    assert stickslip.load_stability_map(tmp_path / "map.nc").to_xarray().identical(smap.to_xarray())
