"""One worker pool for every campaign: tasks mapped over this process, a process pool or dask.

Sweeps, basin-stability studies and the Region II edge over N all hand independent tasks to
:func:`map_unordered`, which yields each task's result as it finishes:

``serial``     in this process.
``processes``  a :class:`concurrent.futures.ProcessPoolExecutor` (:func:`worker_pool`; ``fork``
               where available, so the workers inherit the kernels this process has already
               compiled).
``dask``       a ``dask.distributed`` client to a scheduler address, or to a LocalCluster with
               one single-threaded worker process per core when no address is given
               (:func:`local_cluster`); each worker runs the caller's warm-up once, before its
               first task.

At most ``2 × workers`` tasks are in flight, and the next task is drawn from the caller's
iterator only after a result has been handed back, so tasks may depend on the results seen so
far (basin studies pass the cycles found) and the pending work held in memory does not grow
with the campaign. ``workers`` may not exceed the CPUs this process may run on
(:func:`check_workers`): more would only time-share the cores and multiply memory. Pool workers
end within a second of their parent, also when it is killed with ``kill -9``
(:func:`watch_parent`), and so do dask's LocalCluster workers (:func:`dask_setup`, a worker
preload: dask's own watch, a thread that reads a pipe to the parent, waits for the GIL, which a
worker inside a compiled kernel holds for the whole kernel).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
import threading
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor
from concurrent.futures import wait as wait_futures
from typing import Callable, Iterable, Iterator

from .errors import SchedulerError, SweepError, WorkersError

__all__ = ["EXECUTORS", "default_workers", "check_workers", "check_executor", "watch_parent", "worker_pool",
           "connect", "local_cluster", "map_unordered", "POLL_S", "compile_processes"]

EXECUTORS = ("serial", "processes", "dask")

#: How often the pool and dask loops look at the caller's stop flag while tasks run [s] (Ctrl-C
#: is answered between).
POLL_S = 0.2


def default_workers() -> int:
    """CPUs this process may run on (its affinity mask where the platform has one, else all)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - macOS/Windows
        return os.cpu_count() or 1


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


def check_executor(executor: str, error: type[Exception] = SweepError) -> str:
    """``executor`` if it is one of :data:`EXECUTORS`, else ``error`` naming the choices."""
    if executor not in EXECUTORS:
        raise error(f"unknown executor {executor!r}; choose one of {', '.join(EXECUTORS)}")
    return executor


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
            import ctypes  # only where prctl exists

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


#: The setting of how many processes a cold start compiles in (``model/compile_ahead.py``).
COMPILE_PROCESSES_ENV = "STICKSLIP_COMPILE_PROCESSES"


def compile_processes() -> int:
    """How many processes a cold start may compile in: ``STICKSLIP_COMPILE_PROCESSES`` (default 2,
    also where it is empty; 1 compiles in this process alone).

    Raises
    ------
    WorkersError
        One line, where the setting is not a positive integer.
    """
    text = os.environ.get(COMPILE_PROCESSES_ENV, "").strip() or "2"
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise WorkersError(f"{COMPILE_PROCESSES_ENV}={os.environ[COMPILE_PROCESSES_ENV]!r} is not a positive integer; "
                           f"set it to 1 (compile in one process) or 2 (a cold start compiles in two), or unset it")
    return value


def _compile_alone() -> None:
    """In a pool or dask worker: the workers fill the cores, so a cold start in a worker compiles
    there alone, without the helper process of ``model/compile_ahead.py``."""
    os.environ[COMPILE_PROCESSES_ENV] = "1"


def _init_worker(parent: int, warm: Callable[[], object] | None) -> None:
    watch_parent(parent)
    _compile_alone()
    if warm is not None:
        warm()


def worker_pool(workers: int, warm: Callable[[], object] | None = None) -> ProcessPoolExecutor:
    """A :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` processes that end with this one.

    Forked where the platform can (the workers inherit the kernels this process has already
    compiled), else spawned, and then each runs ``warm()`` (a module-level function: compile or
    load the kernels its tasks need) as it starts. Each worker runs :func:`watch_parent`.
    """
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_init_worker,
                               initargs=(os.getpid(), None if ctx.get_start_method() == "fork" else warm))


#: Environment variables of dask's nanny (``distributed.nanny.pre-spawn-environ``) that the
#: LocalCluster's workers start without. Setting ``MALLOC_TRIM_THRESHOLD_`` turns off glibc's
#: dynamic mmap threshold, so every array of ≥ 128 kB (a run's samples: 4.5 MB at 200 s ×
#: 200 Hz) is mapped and unmapped again per point and its pages faulted in anew: measured
#: 20 % more CPU per point in dask workers than in pool processes, and equal without it
#: (40 runs of 200 s, Ω = 0.5 rad/s, 2 workers: 2.86 vs 2.37 s of point time; pool 2.40 s).
DROPPED_NANNY_ENVIRON = ("MALLOC_TRIM_THRESHOLD_",)


#: The pid of the process that started this process's LocalCluster: set before the cluster forks
#: its workers, which inherit it (:func:`dask_setup`). Not an environment variable: dask's nanny
#: copies those into its own process too, and its subprocesses would inherit a stale pid.
_cluster_parent: int | None = None


def dask_setup(worker=None) -> None:
    """dask's worker preload hook (this module is named in ``distributed.worker.preload`` by
    :func:`local_cluster`): the worker watches the process that started the cluster
    (:func:`watch_parent`), so that it ends when that process does, even after ``kill -9``.
    A worker that was spawned rather than forked watches its parent process."""
    watch_parent(_cluster_parent)
    _compile_alone()


def local_cluster(workers: int):
    """A ``distributed.LocalCluster`` of ``workers`` single-threaded worker processes, without the
    nanny environment of :data:`DROPPED_NANNY_ENVIRON`, no dashboard and quiet logs. Each worker
    ends with this process (:func:`dask_setup`).

    Workers are forked where the platform can (as the ``processes`` executor's): they inherit
    this process's imports and loaded kernels. Measured on 2 workers: cluster start 0.16 s and
    worker warm-up 0.44 s forked, 0.87 s and 0.7–1.1 s spawned (dask's default), which on the
    10 s Fig. 12(a) benchmark is the difference between 1.35× and ≥ 1.6× the serial speed.
    """
    global _cluster_parent
    import dask  # dask is imported only by campaigns that use it (~1 s of imports)
    from distributed import LocalCluster

    environ = dict(dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {})
    for name in DROPPED_NANNY_ENVIRON:
        environ.pop(name, None)
    _cluster_parent = os.getpid()
    preload = list(dask.config.get("distributed.worker.preload", default=[]) or [])
    config = {"distributed.nanny.pre-spawn-environ": environ, "distributed.worker.preload": [*preload, __name__]}
    if "fork" in multiprocessing.get_all_start_methods():
        config["distributed.worker.multiprocessing-method"] = "fork"
    with dask.config.set(config):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            dashboard_address=None, silence_logs=40)


def connect(address: str):
    """A ``distributed.Client`` of the scheduler at ``address``.

    Waits up to dask's connect timeout (``distributed.comm.timeouts.connect``, 30 s by default).

    Raises
    ------
    SchedulerError
        One line, if the address is malformed or nothing answers there.
    """
    from distributed import Client  # dask is imported only by campaigns that use it

    try:
        return Client(address)
    except (OSError, ValueError, TypeError) as exc:
        raise SchedulerError(f"cannot connect to the dask scheduler at {address!r} ({exc}); check the address "
                             "(tcp://HOST:PORT, as `dask scheduler` prints it) and that the scheduler runs and is "
                             "reachable from here, or leave out --scheduler to use this machine's cores") from None


class _NoStop:
    requested = False


def _serial(fn, tasks, stop) -> Iterator:
    for task in tasks:
        if stop.requested:
            return
        yield fn(task)


def _processes(fn, tasks, workers, stop, warm, info) -> Iterator:
    start = time.perf_counter()
    with worker_pool(workers, warm) as pool:
        info["pool_start_s"] = time.perf_counter() - start
        pending = set()
        for task in tasks:
            pending.add(pool.submit(fn, task))
            if len(pending) >= 2 * workers:
                break
        while pending:
            done, pending = wait_futures(pending, timeout=POLL_S, return_when=FIRST_COMPLETED)
            for fut in done:
                yield fut.result()
                task = None if stop.requested else next(tasks, None)
                if task is not None:
                    pending.add(pool.submit(fn, task))


def _dask(fn, tasks, workers, address, stop, warm, info) -> Iterator:
    import asyncio  # its TimeoutError (not the builtin one before Python 3.11); imported with dask, not at start-up

    from distributed import Client, wait  # dask is imported only by campaigns that use it

    start = time.perf_counter()
    cluster = None
    client = connect(address) if address else Client(cluster := local_cluster(workers))
    try:
        info["cluster_start_s"] = time.perf_counter() - start
        if warm is not None:
            t = time.perf_counter()
            client.run(warm)
            info["worker_warm_s"] = time.perf_counter() - t
        n_workers = max(1, len(client.scheduler_info().get("workers", {})))
        pending = {client.submit(fn, t, pure=False) for _, t in zip(range(2 * n_workers), tasks)}
        while pending:
            try:
                done = wait(pending, timeout=POLL_S, return_when="FIRST_COMPLETED").done
            except (TimeoutError, asyncio.TimeoutError):  # dask's wait raises when nothing finished in time
                continue
            for fut in done:
                pending.discard(fut)
                result = fut.result()
                fut.release()
                yield result
                task = None if stop.requested else next(tasks, None)
                if task is not None:
                    pending.add(client.submit(fn, task, pure=False))
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def map_unordered(fn: Callable, tasks: Iterable, *, executor: str = "processes", workers: int | None = None,
                  address: str | None = None, stop=None, warm: Callable[[], object] | None = None,
                  info: dict | None = None) -> Iterator:
    """Yield ``fn(task)`` for each task as it finishes (order not guaranteed).

    Parameters
    ----------
    fn : callable
        A module-level function (or ``functools.partial`` of one) of one task, so that worker
        processes can unpickle it.
    tasks : iterable
        Drawn lazily: the next task is taken after a result has been yielded.
    executor : {"serial", "processes", "dask"}
    workers : int, optional
        Worker processes (default all CPUs available; :func:`check_workers`); with ``dask`` and
        no ``address``, the LocalCluster's size.
    address : str, optional
        A dask scheduler address (``tcp://host:8786``).
    stop : object with a ``requested`` attribute, optional
        When it turns true no further task is handed out; the tasks running finish and are yielded.
    warm : callable, optional
        Run once in each worker before its first task where the worker does not inherit this
        process's compiled kernels (spawned pool workers, dask workers).
    info : dict, optional
        Receives start-up timings (``pool_start_s``, ``cluster_start_s``, ``worker_warm_s``).
    """
    info = {} if info is None else info
    stop = _NoStop() if stop is None else stop
    tasks = iter(tasks)
    check_executor(executor)
    workers = check_workers(workers, address=address)
    if executor == "serial":
        return _serial(fn, tasks, stop)
    if executor == "processes":
        return _processes(fn, tasks, workers, stop, warm, info)
    return _dask(fn, tasks, workers, address, stop, warm, info)
