"""A full disk (a file size limit, RLIMIT_FSIZE) while a command writes: one line, exit 2, no torn
or lost file; the same command without the limit then finishes to the clean result."""

from __future__ import annotations

import resource

import pytest

from stickslip.sweep import load_sweep

from .helpers import assert_same_results, command, leftovers, one_line_error, read_output, run


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
