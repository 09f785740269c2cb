"""The basin-stability driver: models → initial states → batches → executor → journal → NetCDF.

Per parameter value the model's context (steady sliding, its stability, the linear flow;
:mod:`.context`) and initial states are made here once. States go to the executor in batches
(``serial`` in this process, ``processes`` in a pool of worker processes, ``dask`` on a
LocalCluster or a scheduler, from :mod:`stickslip.parallel`); each batch carries the
cycles found so far for its parameter value, so that later states stop as soon as they reach
one. Outcomes are journaled as batches arrive; the dataset is assembled from the journal
(:func:`.result.assemble`), so a study killed at any moment and started again computes only the
missing states and gives the same labels. Ctrl-C stops handing out batches, waits for those
running (each about :data:`TARGET_BATCH_S` of work), writes the partial result and keeps the
journal for the next run; a Ctrl-C while the result is written lets the write finish (the file
is then whole, complete or not). Either way the result says it was interrupted
(``timings["interrupted"]``), and a caller learns it from
:func:`~stickslip.integrate.interrupt.ctrl_c_taken`.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

from ..analysis.outcome import outcome_code
from ..errors import BasinError, StickSlipError
from ..integrate.initial import refused_rigid_starts, rigid_gaps
from ..integrate.interrupt import interruptible
from ..journal import finished_output, output_path
from ..memory import check_memory, format_bytes, largest_count, param_bytes, state_bytes
from ..model.library import load_model
from ..parallel import EXECUTORS, check_executor, check_workers, map_unordered
from .batch import classify_batch, compiled_batch_applies
from .context import Context, make_context, model_of, register_model
from .cycles import find_cycle
from .early import DECIDED, Options, Outcome, classify_state, row_column
from .result import BasinResult, assemble
from .spec import BasinSpec, build_spec
from .states import StateSpec
from .store import Journal, load_basins, write_dataset

__all__ = ["basin_stability", "EXECUTORS", "TARGET_BATCH_S", "evaluate_batch"]

#: Wall time aimed at per batch [s]: small enough that cycles found by one worker reach the
#: others soon and that Ctrl-C is answered within about this long, large enough that a task's
#: overhead (~1 ms in a pool, ~5–20 ms in dask) stays near 1 %.
TARGET_BATCH_S = {"serial": 0.25, "processes": 0.5, "dask": 1.0}
MIN_BATCHES_PER_WORKER = 4
MAX_BATCH_STATES = 4096
#: States classified in this process after the first (which compiles or loads the kernels) to
#: time a state for the automatic batch size.
TIMED_STATES = 8
#: Fewest states of a batch that the compiled batch classifies: it saves ~1 ms·core a state but
#: costs a first call ~15 s of CPU to compile, so a small study (or a large one's first and timed
#: states) keeps the per-state path, whose outcome rows are the same state by state.
MIN_COMPILED_BATCH = 32


def evaluate_batch(task):
    """Classify a batch of states; module-level so that executors can pickle it.

    ``task`` = (context, flat indices (m,), initial states (m, 2n), cycles, options); returns
    (flat indices, outcome rows (m, width)).
    """
    ctx, indices, states, cycles, opts = task
    model = model_of(ctx.key)
    if len(states) >= MIN_COMPILED_BATCH and compiled_batch_applies(model):  # one compiled call for many states
        return indices, classify_batch(ctx, model, states, cycles, opts)[0]
    cycles = list(cycles)
    rows = []
    for s0 in states:
        o = classify_state(ctx, model, s0, cycles, opts)
        if o.verdict == "periodic" and find_cycle(cycles, o.cycle, opts.match_rtol) < 0:
            cycles.append(o.cycle)
        rows.append(o.to_row())
    return indices, np.array(rows)


def _refuse_inside_stops(models, initial: np.ndarray) -> None:
    """Refuse states that start inside a rigid contact's stop or at it moving into it (no motion
    starts there), in one line that says how many and how to keep them out.

    Raises
    ------
    BasinError
    """
    for m, states in zip(models, initial):
        refused = refused_rigid_starts(m, states)
        if refused.any():
            first = int(np.flatnonzero(refused)[0])
            names = ", ".join(m.contact_names[c] for c, *_ in rigid_gaps(m, states[first]))
            raise BasinError(f"{int(refused.sum())} of {refused.size} states of model {m.name!r} start inside a rigid "
                             f"contact's stop ({names}: gap < 0) or at it moving into it (the first: state {first}); "
                             "choose states with gap > 0 (the range of the dofs that open the gap above 0)")


def _state_units(model) -> dict:
    """The unit of each state and parameter of ``model`` (where it says), for the figures' axes."""
    return {**model.units, **dict(zip(model.state_names, model.state_units))}


def _models(model, param, values):
    """The models of the parameter values (the model itself without a parameter)."""
    if param is None:
        return [model]
    try:
        return [model.replace(**{param: v}) for v in values]
    except StickSlipError as exc:  # the model names the path as --set does
        text = str(exc)
        raise BasinError("--param " + text[len("--set "):] if text.startswith("--set ") else f"--param {param}: {text}") \
            from None


#: How each kind of states names its count, for the setting that fits.
_STATE_COUNT = {"box": "--n {k}", "grid": "a --grid of at most {k} points", "ics": "at most {k} rows in --ics"}


def _check_memory(model, spec: BasinSpec) -> None:
    """Refuse, before a model is rebuilt or a state drawn, a study whose states and models would
    not fit in memory (:func:`stickslip.memory.state_bytes`, :func:`~stickslip.memory.param_bytes`)."""
    P, N = spec.n_params, spec.n_states
    per_state, per_param = state_bytes(model.n, spec.row_width), param_bytes(model.n)

    def fits(memory: float) -> str:
        fixes = []
        k = largest_count(P * per_state, memory, P * per_param)  # states per value, the values kept
        if k >= 1:
            fixes.append("give " + _STATE_COUNT[spec.states.kind].format(k=k))
        p = largest_count(N * per_state + per_param, memory)  # values, the states kept
        if spec.param is not None and p >= 2:
            fixes.append(f"give at most {p} parameter values (--param PATH=LO:HI:K)")
        return " or ".join(fixes) or (f"give fewer states and parameter values ({format_bytes(per_state)} a state "
                                      f"and {format_bytes(per_param)} a parameter value)")

    values = f" × {P:.3g} parameter values" if spec.param is not None else ""
    check_memory(float(P) * N * per_state + float(P) * per_param,
                 f"a basin study of {N:.3g} states{values} of model {model.name!r} ({format_bytes(per_state)} a state)",
                 fits)


def _contexts(models, keys):
    ctxs = [make_context(m, key=k) for m, k in zip(models, keys)]
    info = [{"equilibrium": c.equilibrium, "stable": c.stable, "max_real_part": c.max_real_part, "period": c.period,
             "unilateral": bool(m.unilateral), "open_at_equilibrium": bool(c.open_contacts)}
            for c, m in zip(ctxs, models)]
    return ctxs, info


def _progress(total, done, label):
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    bar = Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                   TextColumn("{task.fields[rate]}"), TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn())
    bar.start()
    return bar, bar.add_task(label, total=total, completed=done, rate="")


def basin_stability(model, states: StateSpec, *, param: str | None = None, values=(), out=None,
                    t_end: float = 500.0, executor: str = "processes", workers: int | None = None,
                    address: str | None = None, batch_size: int | str = "auto", progress: bool = False,
                    overwrite: bool = False, snapshot_interval: float = 60.0, keep_journal: bool = False,
                    **options) -> BasinResult:
    """Which attractor each initial state reaches, and the basin stability (fraction) of each.

    Parameters
    ----------
    model : FrictionModel or str
        The model (a library name such as ``belt`` or ``two-plates``, a model file, or a model).
    states : StateSpec
        The initial states (:func:`.states.box`, :func:`.states.grid`, :func:`.states.from_csv`).
    param : str, optional
        A parameter path of the model (``contact.0.drive``, the plates' ``N``): the study is
        repeated for each of ``values``.
    values : sequence of float
        The parameter's values.
    out : path, optional
        NetCDF output (``.nc``); classified states are journaled beside it and a study killed and
        started again with the same arguments resumes. Default: a temporary file.
    t_end : float
        Longest run of a state [s].
    executor : {"serial", "processes", "dask"}
    workers : int, optional
        Worker processes (default all CPUs available to this process, also the most allowed);
        with ``dask`` and no ``address``, the LocalCluster's size.
    address : str, optional
        A dask scheduler address (``tcp://host:8786``).
    batch_size : int or "auto"
        States per task; ``auto`` times the first state here and aims at :data:`TARGET_BATCH_S`.
    progress : bool
        Show a progress bar.
    overwrite : bool
        Discard an output or journal of a different study instead of refusing.
    snapshot_interval : float
        Seconds between snapshots of the partial result [s].
    keep_journal : bool
        Keep the journal after the result is written.
    **options
        ``rtol``, ``atol``, ``match_rtol``, ``confirm``, ``lyapunov``, ``max_steps``
        (:class:`.early.Options`).

    Returns
    -------
    BasinResult
        ``complete`` is False when the study was interrupted (Ctrl-C) before every state was
        classified; the journal is then kept. ``timings["interrupted"]``: whether Ctrl-C was pressed.

    Raises
    ------
    BasinError
        Invalid states, parameter or options, or an output of a different study.
    stickslip.files.LockError
        Another process is writing the same output.
    stickslip.files.WriteError
        The disk is full (the journal keeps every classified state).
    """
    t_start = time.perf_counter()
    check_executor(executor, BasinError)
    model = load_model(model)
    unknown = set(options) - {"rtol", "atol", "match_rtol", "confirm", "lyapunov", "max_steps"}
    if unknown:
        raise BasinError(f"unknown option(s) {', '.join(sorted(unknown))}")
    opts = Options(t_end=t_end, **options)
    key = register_model(model)
    spec = build_spec(model, states, param=param, values=values, options=opts, key=key)
    workers = check_workers(workers, address=address)
    _check_memory(model, spec)
    models = _models(model, param, spec.values)
    keys = [register_model(m) for m in models]
    ctxs, info_models = _contexts(models, keys)
    period = max(c.period for c in ctxs)
    if t_end < period:
        raise BasinError(f"--t-end {t_end:g} is shorter than the characteristic period T_c = {period:.4g} of model "
                         f"{model.name!r} (its slowest oscillation); give several periods, e.g. --t-end {100 * period:.3g}")
    initial = np.stack([states.states(m, None if c.equilibrium is None else c.equilibrium[:m.n])
                        for m, c in zip(models, ctxs)])
    if model.rigid:
        _refuse_inside_stops(models, initial)
    out, tmpdir = output_path(out, "basins.nc", BasinError)
    ds = finished_output(out, spec.digest, load_basins, what="basin study", error=BasinError, overwrite=overwrite)
    if ds is not None and int(ds.attrs.get("complete", 0)):
        return BasinResult(out, ds, {"total_s": time.perf_counter() - t_start, "states_computed": 0,
                                     "states_resumed": spec.size, "executor": executor, "workers": workers,
                                     "interrupted": False})
    journal = Journal(out, spec, overwrite=overwrite)
    timing = {"executor": executor, "workers": workers, "interrupted": False}
    try:
        result = _run(spec, ctxs, info_models, initial, journal, out, timing, _state_units(model), executor=executor,
                      workers=workers,
                      address=address, batch_size=batch_size, progress=progress,
                      snapshot_interval=snapshot_interval)
        if not result.complete or keep_journal:
            journal.close()
        else:
            journal.remove()
    except BaseException:
        journal.close()
        raise
    if tmpdir is not None:
        tmpdir.cleanup()
        result = BasinResult(None, result.dataset, result.timings)
    result.timings["total_s"] = time.perf_counter() - t_start
    return result


def _run(spec: BasinSpec, ctxs: list[Context], info_models, initial, journal: Journal, out: Path, timing: dict, units, *,
         executor, workers, address, batch_size, progress, snapshot_interval) -> BasinResult:
    """Classify the states the journal lacks, journaling each batch, and write the result."""
    N, n = spec.n_states, spec.n_dofs
    indices, rows = journal.read()
    registry: list[list] = [[] for _ in range(spec.n_params)]

    def learn(idx, rws):
        # a matched or recurred outcome's cycle is one the registry holds: only the others can be new
        rws = np.asarray(rws).reshape(-1, spec.row_width)
        known = np.isin(rws[:, row_column("decided_by")], [DECIDED.index("matched"), DECIDED.index("recurred")])
        new = (rws[:, row_column("verdict")] == outcome_code("periodic")) & ~known
        for flat, row in zip(np.asarray(idx)[new], rws[new]):
            o = Outcome.from_row(row, n)
            reg = registry[int(flat) // N]
            if o.verdict == "periodic" and find_cycle(reg, o.cycle, spec.options.match_rtol) < 0:
                reg.append(o.cycle)

    learn(indices, rows)
    done = np.zeros(spec.size, dtype=bool)
    done[indices] = True
    todo = np.flatnonzero(~done)
    timing.update(states_resumed=int(done.sum()), states_computed=int(todo.size))
    store = {"idx": [indices], "rows": [rows]}
    last_snapshot = time.perf_counter()

    def dataset(extra=None):
        idx = np.concatenate(store["idx"])
        rws = np.concatenate(store["rows"]) if idx.size else np.empty((0, spec.row_width))
        return assemble(spec, info_models, initial, idx, rws,
                        attrs={"executor": timing["executor"], "state_units": json.dumps(units), **(extra or {})})

    bar = task_id = None
    if progress:
        bar, task_id = _progress(spec.size, int(done.sum()), f"basins {spec.size} states")
    compute_start = time.perf_counter()
    n_new = 0
    sizing = {"size": 1, "floor": 0}

    def record(idx, rws):
        nonlocal last_snapshot, n_new
        journal.append(idx, rws)
        store["idx"].append(np.asarray(idx, dtype=np.int64))
        store["rows"].append(rws)
        learn(idx, rws)
        n_new += len(idx)
        if batch_size == "auto" and len(idx) >= MIN_COMPILED_BATCH:  # batches sized by the path they take
            t = float(np.mean(np.asarray(rws)[:, row_column("wall_time")]))
            sizing["size"] = _batch_size(batch_size, t, todo.size - n_new, workers, executor, sizing["floor"])
            timing["batch_size"] = max(timing["batch_size"], sizing["size"])
        if bar is not None:
            bar.update(task_id, advance=len(idx), rate=f"{n_new / max(time.perf_counter() - compute_start, 1e-9):.1f} st/s")
        if time.perf_counter() - last_snapshot > snapshot_interval:
            write_dataset(dataset(), out, journal)
            last_snapshot = time.perf_counter()

    def task(flat):
        p = int(flat[0]) // N
        return (ctxs[p], flat, initial[p, flat % N], tuple(registry[p]), spec.options)

    try:
        with interruptible() as stop:  # also while the result is written: a Ctrl-C then lets the write finish
            if todo.size:
                record(*evaluate_batch(task(todo[:1])))  # compiles or loads the kernels
                timed, rest = todo[1:1 + TIMED_STATES], todo[1 + TIMED_STATES:]
                t = time.perf_counter()
                if timed.size:
                    record(*evaluate_batch(task(timed)))  # times a state
                t_state = (time.perf_counter() - t) / max(timed.size, 1)
                sizing["floor"] = _compiled_floor(ctxs, rest.size, workers, executor)
                sizing["size"] = _batch_size(batch_size, t_state, rest.size, workers, executor, sizing["floor"])
                timing.update(batch_size=sizing["size"], first_state_s=t_state)
                tasks = (task(b) for b in _batches(rest, lambda: sizing["size"], N))
                for idx, rws in map_unordered(evaluate_batch, tasks, executor=executor, workers=workers,
                                              address=address, stop=stop, info=timing):
                    record(idx, rws)
            if bar is not None:
                bar.stop()
                bar = None
            timing["compute_s"] = time.perf_counter() - compute_start
            timing["states_computed"] = n_new
            ds = dataset({"compute_s": timing["compute_s"]})
            write_dataset(ds, out, journal)
            timing["interrupted"] = bool(stop.requested)
    finally:
        if bar is not None:
            bar.stop()
    return BasinResult(out, ds, timing)


def _compiled_floor(ctxs, remaining: int, workers: int, executor: str) -> int:
    """The fewest states of an ``auto`` batch: :data:`MIN_COMPILED_BATCH` where the compiled batch
    takes the models' states and the study is large enough to give each worker
    :data:`MIN_BATCHES_PER_WORKER` such batches (the states timed first ran the per-state path,
    several times slower a state, and would make the batches too small for it), else 0."""
    share = remaining // (MIN_BATCHES_PER_WORKER * (1 if executor == "serial" else workers))
    compiled = all(compiled_batch_applies(model_of(c.key)) for c in ctxs)
    return MIN_COMPILED_BATCH if compiled and share >= MIN_COMPILED_BATCH else 0


def _batch_size(batch_size, t_state: float, remaining: int, workers: int, executor: str, floor: int) -> int:
    """States per batch: ``batch_size``, or for ``auto`` :data:`TARGET_BATCH_S` of work at
    ``t_state`` seconds a state (the first states timed, then each returned batch's), at most a
    share of the ``remaining`` states per worker, at least ``floor`` while that many remain."""
    if batch_size != "auto":
        try:
            size = int(batch_size)
        except (TypeError, ValueError):
            size = 0
        if size < 1:
            raise BasinError(f"batch_size must be >= 1 or 'auto', got {batch_size!r}")
        return size
    size = min(MAX_BATCH_STATES, max(1, math.ceil(TARGET_BATCH_S[executor] / max(t_state, 1e-6))))
    if executor != "serial":
        size = min(size, max(1, remaining // (MIN_BATCHES_PER_WORKER * workers)))
    return max(size, floor) if remaining >= floor else size


def _batches(flat: np.ndarray, size, per_param: int):
    """Consecutive runs of at most ``size()`` flat indices (asked before each batch), never across
    parameter values."""
    p = flat // per_param
    breaks = np.flatnonzero(np.diff(p)) + 1
    for group in np.split(flat, breaks):
        i = 0
        while i < group.size:
            n = max(int(size()), 1)
            yield group[i:i + n]
            i += n


def load_result(path) -> BasinResult:
    """A :class:`BasinResult` from a file written by :func:`basin_stability`."""
    return BasinResult(Path(path), load_basins(path), {})
