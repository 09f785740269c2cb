"""The sweep driver: grid → batches → executor → journal → NetCDF (:class:`SweepResult`)."""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ..analysis.outcome import outcome_names
from ..errors import SweepError
from ..integrate.driver import check_samples
from ..journal import finished_output, output_path
from ..memory import check_memory, format_bytes, grid_point_bytes, largest_count, sample_bytes
from ..parallel import check_executor, check_workers, map_unordered
from .spec import SweepSpec, evaluate_batch, spec_system, warm_up
from .store import Journal, assemble, load_sweep

__all__ = ["SweepResult", "sweep", "TARGET_BATCH_S"]

#: Wall time aimed at per batch [s], by executor. A process-pool task costs ~1 ms of pickling
#: and IPC and a dask task ~5–20 ms of scheduling, so these keep the scheduler overhead below
#: 1–2 % of the work (the requirement is 5 %) while leaving ≥ 4 batches per worker for balance.
TARGET_BATCH_S = {"serial": 1.0, "processes": 1.0, "dask": 2.0}

#: Smallest number of batches per worker (load balance: the last batch finishes at most
#: ~1/4 of a worker's share after the others).
MIN_BATCHES_PER_WORKER = 4


@dataclasses.dataclass(frozen=True, eq=False)
class SweepResult:
    """A finished sweep.

    Parameters
    ----------
    path : Path
        The NetCDF file (``format = stickslip-sweep-1``).
    spec : SweepSpec
        The grid and the run options (:class:`stickslip.sweep.spec.SweepSpec`).
    dataset : xarray.Dataset
        Dimensions: the swept names in order (plus ``peak`` for ``peaks``); variables as listed in
        :data:`stickslip.sweep.spec.COLUMNS` with units and long names, and ``done``. Loaded into
        memory up to :data:`~stickslip.sweep.store.LOAD_LIMIT_POINTS` points (or without ``out``),
        opened lazily from ``path`` above.
    timings : dict
        ``total_s``, ``compute_s``, ``points_computed``, ``points_resumed``, ``batch_size``,
        ``batches``, ``executor``, ``workers`` and the executor's start-up times.
    """

    path: Path
    spec: SweepSpec
    dataset: object
    timings: dict

    def to_xarray(self):
        """The result as an ``xarray.Dataset``."""
        return self.dataset

    def outcomes(self) -> np.ndarray:
        """What each point's run settles to, by name (:data:`~stickslip.analysis.outcome.OUTCOMES`) over
        the grid; whether it sticks is the ``stick_fraction`` variable beside it."""
        return outcome_names(self.dataset["attractor"].values)


#: Most points per automatic batch: a batch's rows are held in memory until journaled, so this
#: bounds them (4096 × ~88 float64 = 2.9 MB) for very cheap points; any point costing ≥ 0.25 ms
#: still fills :data:`TARGET_BATCH_S`.
MAX_BATCH_POINTS = 4096


def _auto_batch(t_point: float, remaining: int, workers: int, executor: str) -> int:
    size = min(MAX_BATCH_POINTS, max(1, math.ceil(TARGET_BATCH_S[executor] / max(t_point, 1e-6))))
    if executor != "serial":
        size = min(size, max(1, remaining // (MIN_BATCHES_PER_WORKER * workers)))
    return size


def _settle_attrs(spec: SweepSpec) -> dict:
    """File attributes saying how each point's run length was chosen."""
    attrs = {"settle": int(spec.settle), "confirm": int(spec.confirm)}
    if spec.settle:
        attrs.update(cap=spec.cap, cap_units="s",
                     settle_comment="each run extended from its final state in steps of t_end - t_from until "
                                    "settled or cap; settle_time per point, window t_end - t_from at its end")
    return attrs


def _check_memory(spec: SweepSpec, runs: int) -> None:
    """Refuse, before anything runs, a sweep whose runs or grid would not fit in memory: one run
    (:func:`~stickslip.integrate.driver.check_samples`), then the grid's rows beside ``runs`` runs
    held at once in this machine's workers."""
    system = spec_system(spec)
    run = check_samples(system, spec.t_end, spec.sample_rate) * sample_bytes(system.n, system.n_contacts)
    points = math.prod(spec.shape)  # a Python int: no overflow for a huge grid
    per = grid_point_bytes(spec.row_width)

    def fits(memory: float) -> str:
        fixes = []
        if largest_count(per, memory, runs * run) >= 1:
            fixes.append(f"give at most {largest_count(per, memory, runs * run):.3g} points (fewer values)")
        others = spec.row_width - spec.n_peaks  # the numbers of a point besides its peaks
        per_peak = grid_point_bytes(1) - grid_point_bytes(0)
        peaks = largest_count(per_peak, (memory - runs * run) / points, grid_point_bytes(others))
        if peaks < spec.n_peaks:
            fixes.append(f"keep at most {peaks} peaks a point (n_peaks, --peaks)")
        return " or ".join(fixes)

    check_memory(points * per + runs * run, f"a sweep of {points:.3g} points ({format_bytes(per)} each, beside {runs} "
                 f"run(s) of {format_bytes(run)} at a time)", fits)


def _progress_bar():
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TaskProgressColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    return Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(), TaskProgressColumn(),
                    TextColumn("{task.fields[rate]}"), TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                    transient=False)


def sweep(grid: Mapping[str, Sequence] | SweepSpec, model=None, *, out=None,
          executor: str = "processes", workers: int | None = None, address: str | None = None,
          batch_size: int | str = "auto", progress: bool = False, overwrite: bool = False,
          snapshot_interval: float = 60.0, keep_journal: bool = False, t_end: float = 200.0,
          t_from: float | None = None, **options) -> SweepResult:
    """Simulate every point of a grid and keep its reductions, streaming them to disk.

    Parameters
    ----------
    grid : dict of name → values, or SweepSpec
        Swept dimensions in order: parameter names (for the plates ``N`` [N], ``Omega`` [rad/s],
        ``delta_mu``, ``alpha`` [s/m], any field of :class:`~stickslip.Parameters`; for another
        model its parameter paths, e.g. ``contact.0.drive``), ``model`` (the plates' variants),
        ``ic`` (named initial conditions, :data:`~stickslip.sweep.spec.NAMED_ICS`) or
        ``perturb_<state>``.
    model : FrictionModel, Parameters or str, optional
        The model, as :func:`stickslip.simulate` takes it: the plates' base parameters (default
        Table 1 with N = 50 N, Ω = 5 rad/s; in a variant: ``two_plates(params, "rotation")``), or
        any model stated as a model file (a FrictionModel read from one, a library name or a path).
    out : path, optional
        NetCDF output (``.nc``). Finished points are journaled beside it (``OUT.nc.journal``) as
        they arrive; a sweep killed and restarted with the same arguments recomputes nothing it
        had finished. Default: a temporary file (the dataset is returned loaded).
    executor : {"serial", "processes", "dask"}
    workers : int, optional
        Worker processes (default: all CPUs available to this process, also the most allowed). For
        ``dask`` without ``address``, the LocalCluster size.
    address : str, optional
        ``dask.distributed`` scheduler address (``tcp://host:8786``); default a LocalCluster.
    batch_size : int or "auto"
        Points per task. ``auto`` times the first point in this process (which also compiles the
        kernels) and aims at :data:`TARGET_BATCH_S` per batch.
    progress : bool
        Show a rich progress bar with rate and ETA.
    overwrite : bool
        Discard an existing output or journal of another sweep instead of refusing.
    snapshot_interval : float
        Seconds between NetCDF snapshots of the partial result while running [s].
    keep_journal : bool
        Keep the journal after the final NetCDF is written.
    t_end, t_from : float
        Run length and start of the steady window of every point [s] (default t_end/2).
    **options
        ``ic``, ``sample_rate`` [Hz] (default 200), ``rtol``, ``atol``, ``max_steps``,
        ``n_peaks``, ``method``, ``settle`` (extend every run until it has settled; then
        ``t_end`` is the first run's length), ``cap`` [s] (longest run when settling),
        ``confirm``: see :class:`~stickslip.sweep.spec.SweepSpec`.

    Returns
    -------
    SweepResult

    Raises
    ------
    SweepError
        For an invalid grid or option, more ``workers`` than CPUs, an unreachable scheduler, or an
        output that belongs to a different sweep.
    stickslip.files.LockError
        If another process is writing the same output.
    stickslip.files.WriteError
        If the disk is full (the journal keeps every finished point: run again to resume).
    """
    t_start = time.perf_counter()
    spec = grid if isinstance(grid, SweepSpec) else SweepSpec.build(grid, model, t_end=t_end, t_from=t_from, **options)
    check_executor(executor)
    workers = check_workers(workers, address=address)
    _check_memory(spec, 0 if address else 1 if executor == "serial" else workers)
    out, tmpdir = output_path(out, "sweep.nc", SweepError)
    ds = finished_output(out, spec.digest, lambda path: load_sweep(path, load="auto"), what="sweep", error=SweepError,
                         overwrite=overwrite)
    if ds is not None and int(ds.attrs.get("complete", 0)):
        return SweepResult(out, spec, ds, {"total_s": time.perf_counter() - t_start, "points_computed": 0,
                                           "points_resumed": spec.size, "executor": executor, "workers": workers})
    journal = Journal(out, spec, overwrite=overwrite)
    info: dict = {"executor": executor, "workers": workers}
    try:
        _compute(journal, out, info, batch_size=batch_size, address=address, progress=progress,
                 snapshot_interval=snapshot_interval)
        assemble(journal, out, extra_attrs={"executor": executor, **_settle_attrs(spec)})
        if not keep_journal:
            journal.remove()
        else:
            journal.close()
    except BaseException:
        journal.close()
        raise
    # a temporary output is deleted below, so its dataset must be in memory; otherwise large
    # grids stay on disk (opened lazily) so that memory does not grow with the grid
    ds = load_sweep(out, load=True if tmpdir is not None else "auto")
    info["total_s"] = time.perf_counter() - t_start
    result = SweepResult(out, spec, ds, info)
    if tmpdir is not None:
        tmpdir.cleanup()
    return result


def _compute(journal: Journal, out: Path, info: dict, *, batch_size, address, progress: bool,
             snapshot_interval: float) -> None:
    """Compute the points of ``journal``'s sweep that it does not hold, journaling each batch as it
    arrives (with ``info``'s executor and workers; its counts and times are added to ``info``) and
    writing a snapshot of ``out`` every ``snapshot_interval`` seconds."""
    spec, executor, workers = journal.spec, info["executor"], info["workers"]
    todo = np.flatnonzero(~journal.done_mask())
    info["points_resumed"] = int(spec.size - todo.size)
    info["points_computed"] = int(todo.size)
    bar = _progress_bar() if progress else None
    task = None
    if bar is not None:
        bar.start()
        task = bar.add_task(f"sweep {'×'.join(map(str, spec.shape))}", total=spec.size,
                            completed=spec.size - todo.size, rate="")
    compute_start = time.perf_counter()
    n_done = 0
    last_snapshot = time.perf_counter()

    def record(idx, rows):
        nonlocal n_done, last_snapshot
        journal.append(idx, rows)
        n_done += len(idx)
        if bar is not None:
            rate = n_done / max(time.perf_counter() - compute_start, 1e-9)
            bar.update(task, advance=len(idx), rate=f"{rate:.2f} pts/s")
        if time.perf_counter() - last_snapshot > snapshot_interval:
            assemble(journal, out, extra_attrs=_settle_attrs(spec))
            last_snapshot = time.perf_counter()

    if todo.size:
        # the first point runs here: it compiles/loads the kernels and times a point
        t = time.perf_counter()
        record(*evaluate_batch(spec, todo[:1]))
        t_point = time.perf_counter() - t
        rest = todo[1:]
        size = _auto_batch(t_point, rest.size, workers, executor) if batch_size == "auto" else int(batch_size)
        if size < 1:
            raise SweepError(f"batch_size must be >= 1 or 'auto', got {batch_size!r}")
        batches = [rest[i : i + size] for i in range(0, rest.size, size)]
        info.update(batch_size=size, batches=len(batches), first_point_s=t_point)
        if batches:
            for idx, rows in map_unordered(functools.partial(evaluate_batch, spec), batches, executor=executor,
                                           workers=workers, address=address, warm=warm_up, info=info):
                record(idx, rows)
    info["compute_s"] = time.perf_counter() - compute_start
    if bar is not None:
        bar.stop()
