"""Worker processes: bounded by the CPUs, gone within seconds of their parent (also after kill -9),
and an unreachable dask scheduler is one line, not a traceback."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.sweep import SweepError, sweep
from stickslip.parallel import default_workers

from .helpers import STICKSLIP, one_line_error, run, wait_for

psutil = pytest.importorskip("psutil")  # installed with dask.distributed

#: Seconds within which the workers of a killed parent must be gone.
GRACE_S = 10.0

#: A sweep long enough to be killed while its workers compute (20 points of 100 s).
LONG = ["sweep", "--grid", "N=30:70:20", "--grid", "Omega=0.5", "--t-end", "100", "--no-plot", "--no-progress"]


def test_more_workers_than_cpus_is_refused_before_anything_runs(tmp_path):
    too_many = default_workers() + 1
    with pytest.raises(SweepError, match=f"more than the {default_workers()} CPUs"):
        sweep({"N": [30.0, 50.0]}, out=tmp_path / "s.nc", workers=too_many, t_end=1.0)
    assert list(tmp_path.iterdir()) == []  # nothing computed, no journal, no lock
    res = run([STICKSLIP, "sweep", "--grid", "N=30,50", "--t-end", "1", "--workers", "100000",
               "--out", str(tmp_path / "c.nc")])
    one_line_error(res, f"give at most {default_workers()}")
    assert list(tmp_path.iterdir()) == []


def _alive(pids) -> list[int]:
    alive = []
    for pid in pids:
        try:
            if psutil.Process(pid).status() != psutil.STATUS_ZOMBIE:
                alive.append(pid)
        except psutil.NoSuchProcess:
            pass
    return alive


def _descendants_once_running(proc, count: int) -> list[int]:
    parent = psutil.Process(proc.pid)
    assert wait_for(lambda: len(parent.children(recursive=True)) >= count, 120), "the workers never started"
    return [c.pid for c in parent.children(recursive=True)]


@pytest.mark.parametrize("executor", ["processes", "dask"])
def test_workers_end_after_the_parent_is_killed(executor, tmp_path):
    workers = min(2, default_workers())
    # output to files: orphaned workers would hold pipes open and block reading them
    with open(tmp_path / "stdout", "w") as log:
        proc = subprocess.Popen([STICKSLIP, *LONG, "--executor", executor, "--workers", str(workers),
                                 "--out", str(tmp_path / "s.nc")], stdout=log, stderr=log)
    children = []
    try:
        children = _descendants_once_running(proc, workers)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        t = time.monotonic()
        assert wait_for(lambda: not _alive(children), GRACE_S), \
            f"{len(_alive(children))} of {len(children)} workers still running {GRACE_S} s after kill -9 of the parent"
        print(f"{executor}: {len(children)} worker processes gone {time.monotonic() - t:.2f} s after kill -9")
    finally:  # never leave processes of this test behind, whatever failed
        for pid in _alive([proc.pid] + children):
            os.kill(pid, signal.SIGKILL)


#: A dask LocalCluster whose one worker holds the GIL in one long C call (as a compiled kernel does),
#: after writing its pid to the file named by argv[1].
_GIL_HOLDING_CLUSTER = """
import os, sys
from distributed import Client
from stickslip.parallel import local_cluster

def hold_the_gil(path):
    with open(path + ".tmp", "w") as f:
        f.write(str(os.getpid()))
    os.replace(path + ".tmp", path)
    exponent = 60_000_000
    return pow(3, exponent).bit_length()  # one C call of ~30 s that never releases the GIL

if __name__ == "__main__":
    client = Client(local_cluster(1))
    client.submit(hold_the_gil, sys.argv[1]).result()
"""


def test_a_dask_worker_inside_a_long_call_ends_with_its_killed_parent(tmp_path):
    """dask's own watch (a thread reading a pipe to the parent) needs the GIL; the worker must end
    without it, as the kernel ends it (PR_SET_PDEATHSIG) where it can."""
    if not sys.platform.startswith("linux"):
        pytest.skip("the parent's death signal is Linux's")
    script = tmp_path / "cluster.py"
    script.write_text(_GIL_HOLDING_CLUSTER)
    marker = tmp_path / "worker.pid"
    with open(tmp_path / "log", "w") as log:
        proc = subprocess.Popen([sys.executable, str(script), str(marker)], stdout=log, stderr=log)
    worker = None
    try:
        assert wait_for(marker.exists, 120), (tmp_path / "log").read_text()
        worker = int(marker.read_text())
        time.sleep(0.5)  # inside the long call
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        assert wait_for(lambda: not _alive([worker]), 5.0), "the worker outlived its parent's kill -9 by 5 s"
    finally:
        for pid in _alive([proc.pid] + ([worker] if worker else [])):
            os.kill(pid, signal.SIGKILL)


def test_unreachable_scheduler_is_one_line(tmp_path):
    import dask
    import distributed  # noqa: F401  (its defaults join dask's config now, not inside the block below,
    # whose exit would take them out again for every later test of this process)

    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        res = CliRunner().invoke(app, ["sweep", "--grid", "N=30,50", "--t-end", "1", "--no-plot", "--no-progress",
                                       "--scheduler", "tcp://127.0.0.1:9", "--out", str(tmp_path / "s.nc")])
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and "cannot connect to the dask scheduler at 'tcp://127.0.0.1:9'" in lines[0], res.output
