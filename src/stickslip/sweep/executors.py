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
with the grid.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from typing import Iterator, Sequence

import numpy as np

from .spec import SweepError, SweepSpec, evaluate_batch, warm_up

__all__ = ["EXECUTORS", "default_workers", "local_cluster", "run_batches"]

EXECUTORS = ("serial", "processes", "dask")


def default_workers() -> int:
    """Cores available to this process."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - macOS/Windows
        return os.cpu_count() or 1


def _serial(spec, batches, info) -> Iterator:
    for b in batches:
        yield evaluate_batch(spec, b)


def _processes(spec, batches, workers, info) -> Iterator:
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        if ctx.get_start_method() != "fork":
            list(pool.map(warm_up, [None] * workers))
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


def _dask(spec, batches, workers, address, info) -> Iterator:
    try:
        from distributed import Client, as_completed
    except ImportError as exc:  # pragma: no cover - dask is a dependency
        raise SweepError("the dask executor needs `pip install 'dask[distributed]'`") from exc
    start = time.perf_counter()
    cluster = None
    if address:
        client = Client(address)
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
    workers = default_workers() if workers is None else int(workers)
    if workers < 1:
        raise SweepError(f"workers must be >= 1, got {workers}")
    if executor == "serial":
        return _serial(spec, batches, info)
    if executor == "processes":
        return _processes(spec, batches, workers, info)
    if executor == "dask":
        return _dask(spec, batches, workers, address, info)
    raise SweepError(f"unknown executor {executor!r}; choose one of {', '.join(EXECUTORS)}")
