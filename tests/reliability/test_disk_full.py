"""A full disk (a file size limit, RLIMIT_FSIZE) while a command writes: one line, exit 2, no torn
or lost file and no temporary left; the same command without the limit then finishes to the
clean result. HDF5 cannot survive a failed write in the process that made it (it crashed with a
segmentation fault, exit 139, after dozens of "Exception ignored" tracebacks): NetCDF files are
written by a child process, so the crash is the child's and the command reports one line."""

from __future__ import annotations

import resource
import subprocess
import sys

import pytest

from stickslip.basins import load_basins
from stickslip.sweep import load_sweep

from .helpers import STICKSLIP, assert_same_results, command, leftovers, one_line_error, read_output, run


def limited(max_bytes: int):
    """``preexec_fn`` giving the child a file size limit of ``max_bytes``."""
    return lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (max_bytes, max_bytes))


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    runs = {}
    for name in ("sweep", "continue"):
        out = tmp_path_factory.mktemp(f"clean-{name}") / f"{name}.nc"
        res = run(command(name, out))
        assert res.returncode == 0, res.stderr
        runs[name] = read_output(name, out)
    return runs


# 2 kB: the sweep journal fills after 2 points; 16 kB: the journal holds every point, the NetCDF does not fit.
@pytest.mark.parametrize("name, max_bytes", [("sweep", 2_000), ("sweep", 16_000), ("continue", 4_000)])
def test_full_disk_is_one_line_and_the_run_resumes(name, max_bytes, clean, tmp_path):
    out = tmp_path / f"{name}.nc"
    res = run(command(name, out), preexec_fn=limited(max_bytes))
    one_line_error(res, "the disk or the file size limit is full")
    assert not out.exists() or read_output(name, out) is not None  # never a torn output
    again = run(command(name, out))
    assert again.returncode == 0, again.stderr
    assert_same_results(name, clean[name], read_output(name, out))
    assert leftovers(out) == []


def test_full_disk_keeps_the_previous_output(clean, tmp_path):
    # a finished sweep, then another grid --overwrite on it with no room for the new NetCDF
    out = tmp_path / "sweep.nc"
    assert run(command("sweep", out)).returncode == 0
    res = run(command("sweep", out, "--grid", "alpha=4,6", "--overwrite"), preexec_fn=limited(16_000))
    one_line_error(res, "is left as it was")
    assert_same_results("sweep", clean["sweep"], load_sweep(out))


# ----------------------------------------------------------------------------- HDF5 cut short
#: A NetCDF of 800 kB written through stickslip.files to a relative path under a 64 kB file size limit.
_HDF5_WRITER = """
import resource
import numpy as np, xarray as xr
from stickslip.files import WriteError, atomic_write
resource.setrlimit(resource.RLIMIT_FSIZE, (65536, 65536))
ds = xr.Dataset({f"v{i}": ("t", np.arange(20000.0)) for i in range(5)})
try:
    atomic_write("r.nc", lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf"))
except WriteError as exc:
    print(exc)
"""


def test_a_netcdf_write_cut_by_a_full_disk_raises_one_error_instead_of_crashing(tmp_path):
    res = subprocess.run([sys.executable, "-c", _HDF5_WRITER], cwd=tmp_path, capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, (res.returncode, res.stderr[-2000:])  # before: -11, a segmentation fault
    assert res.stdout.startswith("cannot write r.nc: the disk or the file size limit is full (File too large)")
    assert res.stderr == ""  # before: "Exception ignored in ... ObjectID.__dealloc__" tracebacks
    assert list(tmp_path.iterdir()) == []  # no temporary, no output


#: Small belt commands whose NetCDF output does not fit under the limit while their journal does.
BELT = {
    # 800 kB of samples under a 64 kB limit (the case that crashed 10 of 10 times)
    "simulate": (["simulate", "--model", "belt", "--ic", "x=1,dx=1", "--t-end", "100", "--no-plot", "--json"],
                 65_536),
    # 4 points: a 1.4 kB journal, a 36 kB NetCDF
    "sweep": (["sweep", "--model", "belt", "--grid", "contact.0.drive=0.5:2:4", "--t-end", "50", "--executor",
               "serial", "--no-plot", "--no-progress", "--json"], 16_384),
    # 10 states: a 14 kB journal, a 32 kB NetCDF
    "basins": (["basins", "--model", "belt", "--box", "x=-2:2", "--box", "dx=-2:2", "--n", "10", "--executor",
                "serial", "--no-plot", "--no-progress", "--json"], 24_000),
}


def _belt(name: str, out, *extra) -> list:
    args, _ = BELT[name]
    return [STICKSLIP, *args, "--out", str(out), *extra]


#: What must agree between the clean run and the resumed one (machine timings aside).
COMPARED = {"simulate": ("x", "dx", "mode"), "sweep": ("done", "attractor", "frequency", "peaks"),
            "basins": ("label", "fraction", "count")}


def _load(name: str, path):
    if name == "simulate":
        from stickslip import load_trajectory

        return load_trajectory(path).to_xarray()
    return (load_sweep if name == "sweep" else load_basins)(path)


@pytest.mark.parametrize("name", list(BELT))
def test_a_netcdf_output_cut_by_a_full_disk_is_one_line_and_the_command_resumes(name, tmp_path):
    clean = tmp_path / "clean" / "o.nc"  # also compiles the kernels: a cache write under the limit would fail
    clean.parent.mkdir()
    res = run(_belt(name, clean))
    assert res.returncode == 0, res.stderr
    work = tmp_path / "work"
    work.mkdir()
    out = work / "o.nc"
    res = run(_belt(name, "o.nc"), cwd=work, preexec_fn=limited(BELT[name][1]))  # a relative --out, as typed
    one_line_error(res, "cannot write o.nc: the disk or the file size limit is full")  # before: exit 139
    assert "Exception ignored" not in res.stderr
    assert not out.exists() and [p.name for p in leftovers(out)] == ([] if name == "simulate" else ["o.nc.journal"])
    res = run(_belt(name, "o.nc"), cwd=work)  # room again: the journal is resumed (simulate: run again)
    assert res.returncode == 0, res.stderr
    a, b = _load(name, clean), _load(name, out)
    for var in COMPARED[name]:
        assert a[var].equals(b[var]), var
    assert leftovers(out) == []


def test_a_full_disk_keeps_the_previous_netcdf_output(tmp_path):
    out = tmp_path / "o.nc"
    assert run(_belt("simulate", "o.nc"), cwd=tmp_path).returncode == 0
    before = out.read_bytes()
    res = run(_belt("simulate", "o.nc", "--overwrite", "--t-end", "120"), cwd=tmp_path, preexec_fn=limited(65_536))
    one_line_error(res, "o.nc is left as it was")  # before: that line, then exit 139
    assert out.read_bytes() == before and leftovers(out) == []
