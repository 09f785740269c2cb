"""Executors: run batches of grid points and yield ``(indices, rows)`` as they finish.

``serial``     in this process.
``processes``  a :class:`concurrent.futures.ProcessPoolExecutor` (``fork`` where available, so
               the workers inherit the kernels this process has already compiled).
``dask``       a ``dask.distributed`` client to a scheduler address, or to a LocalCluster with
               one single-threaded worker process per core when no address is given; each worker
               loads the numba kernels from the on-disk cache (``cache=True``) once, before the
               first batch (:func:`~stickslip.sweep.spec.warm_up`). The LocalCluster's workers
               are forked where available and start without the ``MALLOC_TRIM_THRESHOLD_`` that
               dask's nanny sets by default (:func:`local_cluster`).

At most ``2 × workers`` batches are in flight, so the pending work held in memory does not grow
with the grid. ``workers`` may not exceed the CPUs this process may run on
(:func:`check_workers`): more would only time-share the cores and multiply memory. Pool workers
end within a second of their parent, also when it is killed with ``kill -9``
(:func:`watch_parent`); dask's LocalCluster workers already do (each watches a pipe to the
process that started it).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
import threading
import time
from typing import Iterator, Sequence

import numpy as np

from .spec import SweepError, SweepSpec, evaluate_batch, warm_up

__all__ = ["EXECUTORS", "default_workers", "check_workers", "watch_parent", "worker_pool", "connect", "local_cluster",
           "run_batches", "WorkersError", "SchedulerError"]

EXECUTORS = ("serial", "processes", "dask")


def default_workers() -> int:
    """CPUs this process may run on (its affinity mask where the platform has one, else all)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - macOS/Windows
        return os.cpu_count() or 1


class WorkersError(SweepError):
    """More worker processes than CPUs, or fewer than one."""


def check_workers(workers: int | None, *, address: str | None = None, option: str = "workers") -> int:
    """``workers`` (default :func:`default_workers`), checked to be between 1 and the available CPUs.

    Parameters
    ----------
    workers : int or None
    address : str, optional
        A dask scheduler address: its workers run elsewhere, so only ``workers >= 1`` is checked.
    option : str
        How the messages name the setting (``--workers`` on the command line).

    Raises
    ------
    WorkersError
        One line naming the limit.
    """
    limit = default_workers()
    if workers is None:
        return limit
    workers = int(workers)
    if workers < 1:
        raise WorkersError(f"{option} must be >= 1, got {workers}")
    if workers > limit and not address:
        raise WorkersError(f"{option} {workers} is more than the {limit} CPUs available to this process; give at "
                           f"most {limit} (more workers than CPUs only share the same cores), or use a dask "
                           "cluster (--scheduler) for more")
    return workers


#: How often a pool worker checks that its parent is alive [s] (where the platform cannot tell it).
PARENT_POLL_S = 0.5


def watch_parent(parent: int | None = None, interval: float = PARENT_POLL_S) -> None:
    """Make this process (a pool worker) end when its parent does, even after ``kill -9``.

    On Linux the kernel sends SIGKILL when the parent dies (``prctl(PR_SET_PDEATHSIG)``), which
    works while the worker is inside a compiled kernel that holds the GIL. (Strictly, when the
    thread that forked the worker ends: our pools are started and used by one thread for the
    whole run.) Everywhere, a daemon
    thread also polls the parent pid every ``interval`` seconds and ends the process with
    ``os._exit`` once the parent is gone (reparented: ``os.getppid()`` changed).
    """
    parent = os.getppid() if parent is None else parent
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            PR_SET_PDEATHSIG = 1
            libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError):  # pragma: no cover - no libc prctl: the thread below suffices
            pass
    if os.getppid() != parent:  # the parent died before the watch began
        os._exit(1)

    def poll():
        while True:
            time.sleep(interval)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=poll, name="stickslip-watch-parent", daemon=True).start()


def _init_worker(parent: int, warm: bool) -> None:
    watch_parent(parent)
    if warm:
        warm_up()


def worker_pool(workers: int):
    """A :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` processes that end with this one.

    Forked where the platform can (the workers inherit the kernels this process has already
    compiled), else spawned and warmed up (:func:`~stickslip.sweep.spec.warm_up`) as they start.
    Each worker runs :func:`watch_parent`.
    """
    from concurrent.futures import ProcessPoolExecutor

    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_init_worker,
                               initargs=(os.getpid(), ctx.get_start_method() != "fork"))


def _serial(spec, batches, info) -> Iterator:
    for b in batches:
        yield evaluate_batch(spec, b)


def _processes(spec, batches, workers, info) -> Iterator:
    from concurrent.futures import FIRST_COMPLETED, wait

    start = time.perf_counter()
    with worker_pool(workers) as pool:
        info["pool_start_s"] = time.perf_counter() - start
        it = iter(batches)
        pending = set()
        for b in it:
            pending.add(pool.submit(evaluate_batch, spec, b))
            if len(pending) >= 2 * workers:
                break
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                yield fut.result()
                nxt = next(it, None)
                if nxt is not None:
                    pending.add(pool.submit(evaluate_batch, spec, nxt))


#: Environment variables of dask's nanny (``distributed.nanny.pre-spawn-environ``) that the
#: LocalCluster's workers start without. Setting ``MALLOC_TRIM_THRESHOLD_`` turns off glibc's
#: dynamic mmap threshold, so every array of ≥ 128 kB (a run's samples: 4.5 MB at 200 s ×
#: 200 Hz) is mapped and unmapped again per point and its pages faulted in anew: measured
#: 20 % more CPU per point in dask workers than in pool processes, and equal without it
#: (40 runs of 200 s, Ω = 0.5 rad/s, 2 workers: 2.86 vs 2.37 s of point time; pool 2.40 s).
DROPPED_NANNY_ENVIRON = ("MALLOC_TRIM_THRESHOLD_",)


def local_cluster(workers: int):
    """A ``distributed.LocalCluster`` of ``workers`` single-threaded worker processes, without the
    nanny environment of :data:`DROPPED_NANNY_ENVIRON`, no dashboard and quiet logs.

    Workers are forked where the platform can (as the ``processes`` executor's): they inherit
    this process's imports and loaded kernels. Measured on 2 workers: cluster start 0.16 s and
    worker warm-up 0.44 s forked, 0.87 s and 0.7–1.1 s spawned (dask's default), which on the
    10 s Fig. 12(a) benchmark is the difference between 1.35× and ≥ 1.6× the serial speed.
    """
    import dask
    from distributed import LocalCluster

    environ = dict(dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {})
    for name in DROPPED_NANNY_ENVIRON:
        environ.pop(name, None)
    config = {"distributed.nanny.pre-spawn-environ": environ}
    if "fork" in multiprocessing.get_all_start_methods():
        config["distributed.worker.multiprocessing-method"] = "fork"
    with dask.config.set(config):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            dashboard_address=None, silence_logs=40)


class SchedulerError(SweepError):
    """The dask scheduler address is malformed or cannot be reached."""


def connect(address: str):
    """A ``distributed.Client`` of the scheduler at ``address``.

    Waits up to dask's connect timeout (``distributed.comm.timeouts.connect``, 30 s by default).

    Raises
    ------
    SchedulerError
        One line, if the address is malformed or nothing answers there.
    """
    from distributed import Client

    try:
        return Client(address)
    except (OSError, ValueError, TypeError) as exc:
        raise SchedulerError(f"cannot connect to the dask scheduler at {address!r} ({exc}); check the address "
                             "(tcp://HOST:PORT, as `dask scheduler` prints it) and that the scheduler runs and is "
                             "reachable from here, or leave out --scheduler to use this machine's cores") from None


def _dask(spec, batches, workers, address, info) -> Iterator:
    try:
        from distributed import Client, as_completed
    except ImportError as exc:  # pragma: no cover - dask is a dependency
        raise SweepError("the dask executor needs `pip install 'dask[distributed]'`") from exc
    start = time.perf_counter()
    cluster = None
    if address:
        client = connect(address)
    else:
        cluster = local_cluster(workers)
        client = Client(cluster)
    try:
        info["cluster_start_s"] = time.perf_counter() - start
        t = time.perf_counter()
        client.run(warm_up)
        info["worker_warm_s"] = time.perf_counter() - t
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
        it = iter(batches)
        futures = [client.submit(evaluate_batch, spec, b, pure=False) for _, b in zip(range(2 * n_workers), it)]
        ac = as_completed(futures)
        for fut in ac:
            result = fut.result()
            fut.release()
            yield result
            nxt = next(it, None)
            if nxt is not None:
                ac.add(client.submit(evaluate_batch, spec, nxt, pure=False))
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_batches(spec: SweepSpec, batches: Sequence[np.ndarray], *, executor: str = "processes",
                workers: int | None = None, address: str | None = None, info: dict | None = None) -> Iterator:
    """Yield ``(indices, rows)`` for each batch as it finishes (order not guaranteed).

    ``info`` receives start-up timings (``pool_start_s``, ``cluster_start_s``, ``worker_warm_s``).
    """
    info = {} if info is None else info
    workers = check_workers(workers, address=address)
    if executor == "serial":
        return _serial(spec, batches, info)
    if executor == "processes":
        return _processes(spec, batches, workers, info)
    if executor == "dask":
        return _dask(spec, batches, workers, address, info)
    raise SweepError(f"unknown executor {executor!r}; choose one of {', '.join(EXECUTORS)}")
