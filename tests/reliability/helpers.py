"""Shared pieces of the fault suite: small commands, running them as real processes, comparing outputs."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from stickslip.parallel import default_workers
from stickslip.sweep.spec import TIMING_COLUMNS

#: The console script of this environment (a real process that can be killed with SIGKILL).
STICKSLIP = str(Path(sys.executable).with_name("stickslip"))

#: Two workers where the machine has them (the pool and its journal batches are exercised).
WORKERS = str(min(2, default_workers()))

_QUIET = ["--no-plot", "--no-progress", "--json"]

#: Small instances of every resumable command, writing to ``OUT`` (replaced by the output path).
COMMANDS = {
    "sweep": ["sweep", "--grid", "N=30:70:5", "--grid", "Omega=0.5,5", "--t-end", "10", "--executor", "processes",
              "--workers", WORKERS, "--out", "OUT", *_QUIET],
    "bifurcation": ["bifurcation", "--param", "N", "--range", "30:70:6", "--omega", "0.5", "--t-end", "10",
                    "--executor", "serial", "--out", "OUT", *_QUIET],
    "regions": ["regions", "--N", "30,50", "--omega", "8.5,12", "--t-end", "20", "--t-from", "10",
                "--executor", "processes", "--workers", WORKERS, "--out", "OUT", *_QUIET],
    "continue": ["continue", "--param", "Omega", "--from", "3", "--to", "3.3", "--N", "50", "--model", "rotation",
                 "--search-time", "30", "--max-points", "6", "--slip-band", "1e-5", "--out", "OUT", *_QUIET],
}

#: Per command: variables that depend on the machine, not on the results.
MACHINE_DEPENDENT = {"sweep": TIMING_COLUMNS, "bifurcation": TIMING_COLUMNS, "regions": TIMING_COLUMNS,
                     "continue": ()}


def command(name: str, out: Path, *extra: str) -> list[str]:
    """The argv of command ``name`` writing to ``out``."""
    return [STICKSLIP] + [str(out) if a == "OUT" else a for a in COMMANDS[name]] + list(extra)


def run(argv, *, env=None, preexec_fn=None, cwd=None, timeout=600) -> subprocess.CompletedProcess:
    """Run ``argv`` to completion (text output captured)."""
    return subprocess.run(argv, capture_output=True, text=True, env=env, preexec_fn=preexec_fn, cwd=cwd,
                          timeout=timeout)


def start(argv, **kwargs) -> subprocess.Popen:
    return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)


def one_line_error(res, words: str) -> str:
    """Assert that ``res`` failed with exit code 2 and one stderr line containing ``words``; return it."""
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    assert len(lines) == 1 and lines[0].startswith("error:") and words in lines[0], res.stderr
    assert "Traceback" not in res.stderr + res.stdout
    return lines[0]


def read_output(name: str, path: Path):
    """The output of command ``name`` read back by its loader (fails on a corrupt file)."""
    if name == "continue":
        from stickslip.orbits.continuation import load_branch

        return load_branch(path)
    from stickslip.sweep import load_sweep

    return load_sweep(path)


def assert_same_results(name: str, a, b) -> None:
    """Every variable and coordinate identical (bit for bit, NaNs equal), machine timings aside."""
    skip = set(MACHINE_DEPENDENT[name])
    assert set(a.data_vars) == set(b.data_vars)
    for var in a.data_vars:
        if var not in skip:
            assert a[var].equals(b[var]), var
    for coord in a.coords:
        assert a[coord].equals(b[coord]), coord
    for key in ("digest", "points_done", "complete", "stop_reason"):
        assert a.attrs.get(key) == b.attrs.get(key), key


def leftovers(out: Path) -> list[Path]:
    """Files beside ``out`` other than the output and its figure (a lock file is a leftover too)."""
    keep = {out.name, out.with_suffix(".png").name}
    return sorted(p for p in out.parent.iterdir() if p.name not in keep)


def wait_for(predicate, timeout: float, interval: float = 0.02) -> bool:
    """Poll ``predicate()`` until true or ``timeout`` seconds pass; its last value."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(interval)
    return bool(predicate())


def environ(**extra) -> dict:
    env = dict(os.environ)
    env.update(extra)
    return env


def same_arrays(a, b) -> bool:
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)
