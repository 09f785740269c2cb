"""fold_curve's worker processes: no more than the CPUs, refused before anything runs, and gone
within seconds of their parent, also after kill -9 (as the sweep executors' workers)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from reliability.helpers import wait_for  # the fault suite's helpers (tests/reliability; needs psutil)
from reliability.test_worker_processes import GRACE_S, _alive, _descendants_once_running
from stickslip.orbits import region_edge
from stickslip.orbits import continuation as C
from stickslip.errors import WorkersError
from stickslip.parallel import default_workers


def test_more_workers_than_cpus_is_refused_before_anything_runs(monkeypatch, tmp_path):
    calls = []
    monkeypatch.setattr(region_edge, "_edge_at", lambda *a: calls.append(a[0]))
    too_many = default_workers() + 1
    with pytest.raises(WorkersError, match=f"more than the {default_workers()} CPUs"):
        C.fold_curve([10.0, 20.0, 30.0], workers=too_many, out=tmp_path / "fc.nc")
    assert calls == [] and list(tmp_path.iterdir()) == []  # nothing computed, no journal, no lock
    with pytest.raises(WorkersError, match="must be >= 1"):
        C.fold_curve([10.0], workers=0)


_SLOW_CHILD = textwrap.dedent("""
    import time
    from stickslip.orbits import continuation as C
    from stickslip.orbits import region_edge

    def slow_edge(N, *args):  # one N that takes long: the parent is killed while the workers run
        time.sleep(300)

    region_edge._edge_at = slow_edge
    C.fold_curve([10.0, 20.0, 30.0, 40.0], workers=2)
""")


@pytest.mark.skipif(default_workers() < 2, reason="needs 2 CPUs for 2 workers")
def test_workers_end_after_the_parent_is_killed(tmp_path):
    with open(tmp_path / "log", "w") as log:  # orphaned workers would hold pipes open
        proc = subprocess.Popen([sys.executable, "-c", _SLOW_CHILD], stdout=log, stderr=log)
    children = []
    try:
        children = _descendants_once_running(proc, 2)
        time.sleep(1.0)  # the workers are inside slow_edge
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        t = time.monotonic()
        assert wait_for(lambda: not _alive(children), GRACE_S), \
            f"{len(_alive(children))} of {len(children)} workers still running {GRACE_S} s after kill -9 of the parent"
        print(f"fold_curve: {len(children)} worker processes gone {time.monotonic() - t:.2f} s after kill -9")
    finally:  # never leave processes of this test behind, whatever failed
        for pid in _alive([proc.pid] + children):
            os.kill(pid, signal.SIGKILL)
