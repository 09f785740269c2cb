"""The ``simulate()`` driver: resolve the model, validate options, build the initial state, run a
method in chunks, wrap the result."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Mapping

import numpy as np

from ..errors import SimulationError
from ..model.bundle import contact_state
from ..model.library import resolve_system
from ..model.library.two_plates import NAME as TWO_PLATES
from ..model.system_model import FrictionModel
from . import contacts as E
from .event_loop import N_EXTRA, integrate_event
from .fixed_step import run_aeom, run_naeom
from .initial import initial_state
from .interrupt import interruptible, partial_on_ctrl_c
from .result import Stats, Trajectory, Transitions
from .status import CHUNK_END, Status

__all__ = ["simulate", "METHODS", "MAX_SAMPLES"]

#: Largest number of uniform samples a run may keep (each ~ (2n + 2 + 2 nc) float64 and a flag byte).
MAX_SAMPLES = 20_000_000

#: Integration methods by name; ``aeom`` and ``naeom`` are the paper's fixed-step methods for the
#: two plates only.
METHODS = ("event", "aeom", "naeom")

#: Steps (accepted and rejected) a chunk of the compiled loop aims at: Ctrl-C is answered between
#: chunks, after about 0.1 s (the plates take ~1 µs a step). Chunk lengths follow from step
#: counts, not from wall time, so a run's chunks, and with them the round-off of its local
#: times, are the same however loaded the machine is: the same inputs give the same result.
CHUNK_STEPS = 100_000
#: Simulated time [s] of the first chunk, before its speed is known.
FIRST_CHUNK = 20.0

#: Initial room for transitions per simulated second of a chunk (stick-slip cycles have 2 per
#: period); a chunk with more is run again from its start with room for all (same result).
TRANSITIONS_PER_SECOND = 64
MIN_TRANSITION_ROOM = 1024

#: Transitions a run keeps: the most recent ones (earlier ones are counted in
#: ``Transitions.dropped``), so that memory stays bounded however long the run: 10^6 transitions
#: × (instant, kind, contact) plus the states of the last :data:`KEEP_TRANSITION_STATES`.
KEEP_TRANSITIONS = 1_000_000
KEEP_TRANSITION_STATES = 100_000


#: "No cap" on the steps of a run (int64 for the compiled loop).
NO_STEP_CAP = 2**62


def _check_positive(name: str, value, hint: str) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise SimulationError(f"{name} must be a number, got {value!r}; {hint}") from None
    if not math.isfinite(value) or value <= 0.0:
        raise SimulationError(f"{name} = {value} must be a finite number > 0; {hint}")
    return value


class _Buffers:
    """Output arrays of a run: samples (allocated once) and per-chunk transition buffers."""

    def __init__(self, system: FrictionModel, sample_times: np.ndarray):
        n = sample_times.size
        ns = 2 * system.n + N_EXTRA
        self.out_s = np.empty((n, ns))
        self.out_mode = np.empty(n, dtype=np.int8)
        self.out_F = np.empty((n, 2 * system.n_contacts))
        self.tr_t: list[np.ndarray] = []
        self.tr_kind: list[np.ndarray] = []
        self.tr_contact: list[np.ndarray] = []
        self.tr_s: list[np.ndarray] = []
        self.kept = 0
        self.dropped = 0

    def add_transitions(self, tr, n_tr: int) -> None:
        """Keep the first ``n_tr`` transitions of a chunk's buffers, dropping the oldest beyond the caps."""
        for store, buf in zip((self.tr_t, self.tr_kind, self.tr_contact, self.tr_s), tr):
            store.append(buf[:n_tr].copy())
        self.kept += n_tr
        if self.kept > 2 * KEEP_TRANSITIONS or sum(len(s) for s in self.tr_s) > 2 * KEEP_TRANSITION_STATES:
            drop = max(self.kept - KEEP_TRANSITIONS, 0)
            for store in (self.tr_t, self.tr_kind, self.tr_contact):
                joined = np.concatenate(store)[drop:]
                store[:] = [joined]
            states = np.concatenate(self.tr_s)
            self.tr_s[:] = [states[max(len(states) - KEEP_TRANSITION_STATES, 0):]]
            self.kept -= drop
            self.dropped += drop

    def transitions(self, ns: int) -> Transitions:
        """The kept transitions; states of the earliest kept ones beyond the state cap are NaN."""
        if not self.tr_t:
            return Transitions(np.empty(0), np.empty(0, np.int8), np.empty((0, ns)), np.empty(0, np.int8))
        time_, kind, contact = (np.concatenate(s) for s in (self.tr_t, self.tr_kind, self.tr_contact))
        states = np.concatenate(self.tr_s)
        if len(states) < len(time_):
            states = np.concatenate([np.full((len(time_) - len(states), ns), np.nan), states])
        return Transitions(time_, kind, states, contact, dropped=self.dropped)

    @staticmethod
    def transition_room(duration: float, ns: int, capacity: int | None = None):
        cap = capacity or MIN_TRANSITION_ROOM + int(TRANSITIONS_PER_SECOND * max(duration, 0.0))
        return np.empty(cap), np.empty(cap, dtype=np.int8), np.empty(cap, dtype=np.int8), np.empty((cap, ns))


def _warm_up(system: FrictionModel, y: np.ndarray, rtol, atol) -> None:
    """Compile (or load from cache) the event loop for this kinematics class on a 1 µs run."""
    ns = y.size
    cst = contact_state(system.data.m)
    st = np.array([0.0])
    tr = _Buffers.transition_room(0.0, ns, 1)
    integrate_event(y.copy(), cst, 0.0, 1e-6, 1e-6, system.data, rtol, atol, 1e-7, 1e-6, 10, st, 0,
                    np.empty((1, ns)), np.empty(1, dtype=np.int8), np.empty((1, 2 * system.n_contacts)),
                    tr[0], tr[1], tr[2], tr[3], 0)


def _run_event(system: FrictionModel, y0: np.ndarray, t0: float, t_end: float, sample_times: np.ndarray,
               rtol: float, atol: float, dt: float | None, max_steps: int):
    """The ``event`` method, in chunks of about :data:`CHUNK_STEPS` steps.

    Each chunk integrates in its own local time from the previous chunk's end (absolute time
    never enters a step or an event tolerance, so runs of any length keep their resolution) and
    ends at the first accepted step past its planned end that is not inside an approach to stick,
    so the chunks take the same steps as one long call. A KeyboardInterrupt between chunks ends
    the run with what is done (status INTERRUPTED).
    """
    prepared = time.perf_counter()
    md = system.data
    ns = 2 * system.n + N_EXTRA
    y = np.zeros(ns)
    y[:2 * system.n] = y0
    F = np.empty(2 * system.n_contacts)
    N = np.empty(system.n_contacts)
    cst = contact_state(md.m)
    lost = E.contact_lost(y, md)
    if lost >= 0:
        raise SimulationError(f"the normal force of contact {lost} is ≤ 0 at the initial state: the contact is open; "
                              "start from a state where every contact is pressed")
    _warm_up(system, y, rtol, atol)
    E.initial_modes(y, cst, md, rtol, atol, F, N)
    # everything before the loop (packing the model, compiling or loading the kernels) when it is
    # the first run of a process (seconds; numba's own start is ~0.4 s of it), else microseconds
    compile_time = time.perf_counter() - prepared
    compile_time = compile_time if compile_time > 0.05 else 0.0
    h_max = dt if dt is not None else (t_end - t0)
    h = min(1e-3, h_max)  # a fraction of the mechanical periods of interest; the controller adapts it
    buffers = _Buffers(system, sample_times)
    stats = np.zeros(6, dtype=np.int64)
    t = t0
    idx = 0
    chunk = min(FIRST_CHUNK, t_end - t0)
    status = CHUNK_END
    lost = -1
    steps_left = max_steps
    interrupted = False
    with interruptible() as stop:
        while status == CHUNK_END and not stop.requested:
            tau_end = t_end - t
            tau_stop = min(chunk, tau_end)
            start_state = (y.copy(), cst.copy(), h, idx)
            capacity = None
            while True:
                tr = _Buffers.transition_room(tau_stop, ns, capacity)
                res = integrate_event(y, cst, t, tau_stop, tau_end, md, rtol, atol, h, h_max, steps_left, sample_times,
                                      idx, buffers.out_s, buffers.out_mode, buffers.out_F, tr[0], tr[1], tr[2], tr[3], 0)
                n_tr = res[5]
                if n_tr <= tr[0].size:
                    break
                capacity = n_tr  # rerun this chunk from its start with room for all its transitions
                y, cst, h, idx = start_state[0].copy(), start_state[1].copy(), start_state[2], start_state[3]
            status, tau, y, h, idx, _, st, lost = res
            buffers.add_transitions(tr, n_tr)
            stats += st
            steps_left = max_steps - int(stats[0] + stats[1])
            t = t + tau
            taken = int(st[0] + st[1])
            if tau > 0.0 and taken > 0:  # aim the next chunk at CHUNK_STEPS steps
                chunk = min(max(tau * CHUNK_STEPS / taken, 1e-3), 10.0 * max(tau, 1e-3))
        interrupted = stop.requested and status == CHUNK_END
    if stop.requested and not partial_on_ctrl_c():  # also when the run had just finished: the caller stops
        raise KeyboardInterrupt
    code = Status.INTERRUPTED if interrupted else Status(status)
    transitions = buffers.transitions(ns)
    stats_out = dict(accepted_steps=int(stats[0]), rejected_steps=int(stats[1]), rhs_calls=int(stats[2]),
                     retaken_steps=int(stats[3]), slip_to_stick=int(stats[4]), stick_to_slip=int(stats[5]),
                     compile_time_s=compile_time)
    return code, t, lost, idx, buffers, transitions, stats_out


def _run_fixed_step(method: str, system: FrictionModel, y0: np.ndarray, t0: float, t_end: float,
                    sample_times: np.ndarray, rtol: float, atol: float, dt: float | None, max_steps: int):
    """The paper's fixed-step methods (two plates only)."""
    if system.name != TWO_PLATES:
        raise SimulationError(f"method {method!r} is the paper's fixed-step method for the two plates; "
                              f"model {system.name!r} runs with method='event' (CLI: --method event)")
    runner = run_aeom if method == "aeom" else run_naeom
    code, t_reached, keep, out_s, out_mode, out_F, transitions, stats = runner(system, y0, t0, t_end, sample_times,
                                                                            rtol, atol, dt, max_steps)
    buffers = _Buffers.__new__(_Buffers)
    buffers.out_s, buffers.out_mode, buffers.out_F = out_s, out_mode, out_F
    n_kept = int(np.count_nonzero(keep))
    ns = out_s.shape[1]
    transitions = Transitions(transitions.time, transitions.kind,
                              np.concatenate([transitions.state, np.zeros((len(transitions), ns - 12))], axis=1),
                              np.zeros(len(transitions), dtype=np.int8))
    return code, t_reached, -1, n_kept, buffers, transitions, stats


def simulate(
    system=None,
    t_end: float = 100.0,
    *,
    model=None,
    method: str = "event",
    ic="zero",
    perturbation=None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    dt: float | None = None,
    sample_rate: float = 1000.0,
    t0: float = 0.0,
    steady_from: float | None = None,
    max_steps: int | None = None,
    slip_band: float | None = None,
) -> Trajectory:
    """Simulate a friction-contact model with exact stick and slip.

    Parameters
    ----------
    system : FrictionModel, Parameters, str, optional
        The model: a :class:`FrictionModel`, a library name (``belt``, ...) or model file path, or
        the two plates' :class:`Parameters`; default the plates with Table 1 at N = 50 N, Ω = 5 rad/s.
    t_end : float
        Final time [s].
    model : str, iterable of DOF names, or FrictionModel, optional
        The plates' variant: ``full`` (Model 1, default), ``x`` (2), ``y`` (3), ``rotation`` (4), or
        the DOFs to free; a library name or model file here is the same as ``system``.
    method : str
        ``event`` (adaptive, exact transitions; default); ``aeom`` or ``naeom`` (the paper's fixed-step
        methods, two plates only).
    ic : see :func:`initial_state`
    perturbation : float or (2n,), optional
        Added to the initial state (a float perturbs the observed coordinate, the plates' φ).
    rtol, atol : float
        Local error tolerances of the adaptive method.
    dt : float, optional
        Largest step for ``event`` [s]; the fixed step of fixed-step methods.
    sample_rate : float
        Uniform output samples per second [Hz].
    t0 : float
        Initial time [s].
    steady_from : float, optional
        Start of the steady-state window [s]; default the last half of the run.
    max_steps : int, optional
        Cap on integration steps (default none: a run is stopped with Ctrl-C, which returns the
        part done).
    slip_band : float, optional
        Low-speed band [m/s] of the 2-D slip direction; default the model's (results converge as
        it → 0).

    Returns
    -------
    Trajectory
        Its ``status`` says how the run ended; an interrupted run (Ctrl-C) returns what was done.

    Raises
    ------
    SimulationError
        For invalid options (each message names the fix).
    """
    if method not in METHODS:
        raise SimulationError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    if slip_band is not None:
        slip_band = _check_positive("slip_band", slip_band, "give a speed in m/s, e.g. 1e-6")
    system = resolve_system(system, model, slip_band)
    t0 = float(t0)
    if not math.isfinite(t0):
        raise SimulationError("t0 must be finite")
    t_end = _check_positive("t_end - t0", float(t_end) - t0, "give t_end > t0 in seconds") + t0
    rtol = _check_positive("rtol", rtol, "typical values are 1e-6 … 1e-10")
    if not 1e-13 <= rtol <= 0.1:
        raise SimulationError(f"rtol = {rtol} is outside [1e-13, 0.1]: below 1e-13 round-off dominates; give a value in range")
    atol = _check_positive("atol", atol, "typical values are 1e-8 … 1e-12")
    sample_rate = _check_positive("sample_rate", sample_rate, "give samples per second, e.g. 1000")
    if dt is not None:
        dt = _check_positive("dt", dt, "give a step in seconds, e.g. 1e-4")
    n_samples = int(math.floor((t_end - t0) * sample_rate + 1e-9)) + 1
    if n_samples > MAX_SAMPLES:
        raise SimulationError(
            f"{n_samples} samples requested (t_end × sample_rate); lower sample_rate to keep ≤ {MAX_SAMPLES}"
        )
    y0 = initial_state(system, ic, perturbation)
    sample_times = t0 + np.arange(n_samples) / sample_rate

    start = time.perf_counter()
    runner = _run_event if method == "event" else (lambda *a: _run_fixed_step(method, *a))
    code, t_reached, lost, n_kept, buffers, transitions, stats = runner(
        system, y0, t0, t_end, sample_times, rtol, atol, dt, NO_STEP_CAP if max_steps is None else int(max_steps))
    wall = time.perf_counter() - start - stats.get("compile_time_s", 0.0)  # integration only
    if n_kept == 0:
        raise SimulationError(f"the run ended before its first sample ({code.message(t_reached, lost)})")

    ic_text = ic if isinstance(ic, str) else ("trajectory" if isinstance(ic, Trajectory) else str(Path(ic)) if isinstance(ic, Path)
                                              else "states" if isinstance(ic, Mapping) else "explicit")
    options = {"rtol": rtol, "atol": atol, "dt": dt, "sample_rate": sample_rate, "ic": ic_text,
               "perturbation": None if perturbation is None else np.asarray(perturbation, dtype=float).tolist(),
               "t0": t0, "t_end": t_end, "slip_band": system.slip_band}
    t_samples = sample_times[:n_kept]  # the samples up to the time reached: a prefix, so views
    if steady_from is None:
        steady_from = t0 + 0.5 * (t_samples[-1] - t0)
    n2 = 2 * system.n
    return Trajectory(
        t=t_samples,
        states=buffers.out_s[:n_kept, :n2],
        mode=buffers.out_mode[:n_kept],
        friction=buffers.out_F[:n_kept],
        work=buffers.out_s[:n_kept, n2:n2 + 2],
        transitions=Transitions(transitions.time, transitions.kind, transitions.state[:, :n2], transitions.contact,
                                transitions.dropped),
        stats=Stats(**stats, wall_time_s=wall),
        status=code.message(t_reached, lost),
        system=system,
        method=method,
        options=options,
        steady_from=float(steady_from),
        status_code=code,
    )
