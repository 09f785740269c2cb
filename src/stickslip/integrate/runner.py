"""One runner of the compiled loops: chunks, transition buffers, stop conditions, one result.

A run is a *stepper* advanced chunk by chunk into one :class:`Record`, until the stepper reaches
its end or a *stop condition* ends it:

:class:`EventStepper`
    The ``event`` integrator (:func:`.event_loop.integrate_event`) from its own state: each chunk
    integrates in local time from the previous chunk's end (absolute time never enters a step or
    an event tolerance, so runs of any length keep their resolution) and ends at the first
    accepted step past its planned end that is not inside an approach to stick, so chunked and
    unchunked runs take the same steps.
:class:`Record`
    The samples of the run at its uniform sample times (allocated once) and its transitions (the
    most recent :data:`KEEP_TRANSITIONS`, so memory stays bounded however long the run).
:class:`StopCondition`
    Where each chunk ends and whether the run stops after it: :class:`ToTheEnd` aims chunks at
    :data:`CHUNK_STEPS` steps (Ctrl-C is answered between them); basin studies stop a state as
    soon as its attractor is known (:class:`stickslip.basins.early.EarlyStop`).

Every compiled loop writes transitions into buffers sized for the chunk
(:func:`transition_room`); a chunk ends early where its log is nearly full
(:func:`.event_loop.next_step_size`), and one whose last step outgrew the room left is run again
from its start with room for all of them, which gives the same result.
"""

from __future__ import annotations

import contextlib
import dataclasses
import time

import numpy as np

from ..errors import SimulationError
from ..model.bundle import contact_state
from ..model.system_model import FrictionModel
from . import contacts as E
from .bundles import Samples, TransitionLog, transition_log
from .event_loop import N_EXTRA, controls, integrate_event
from .interrupt import interruptible
from .loop_split import start_callees
from ..analysis.modes import contact_index_dtype, mode_words
from .result import ImpactTally, Transitions, impact_speeds, mode_array
from .status import CHUNK_END, Status

__all__ = ["EventStepper", "Record", "Chunk", "RunOutput", "StopCondition", "ToTheEnd", "run_chunks",
           "transition_room", "CHUNK_STEPS", "FIRST_CHUNK", "TRANSITIONS_PER_SECOND", "MIN_TRANSITION_ROOM",
           "KEEP_TRANSITIONS", "KEEP_TRANSITION_STATES", "NO_STEP_CAP"]

#: Steps (accepted and rejected) a chunk of the compiled loop aims at: Ctrl-C is answered between
#: chunks, after about 0.1 s (the plates take ~1 µs a step). Chunk lengths follow from step
#: counts, not from wall time, so a run's chunks, and with them the round-off of its local
#: times, are the same however loaded the machine is: the same inputs give the same result.
CHUNK_STEPS = 100_000
#: Simulated time [s] of the first chunk, before its speed is known.
FIRST_CHUNK = 20.0
#: Numbers a chunk writes into its samples at most (each sample holds 2n + 2 states, a mode and
#: 2 per contact): a model of many DOFs sampled densely spends its time in the samples (measured
#: 2.6 µs a sample of a 60-DOF model, about 20 ns a number), so this too bounds a chunk to about
#: 0.1 s and with it the wait for Ctrl-C.
CHUNK_SAMPLE_NUMBERS = 5_000_000

#: Initial room for transitions per simulated second of a chunk (stick-slip cycles have 2 per
#: period); a chunk with more is run again from its start with room for all (same result).
TRANSITIONS_PER_SECOND = 64
MIN_TRANSITION_ROOM = 1024

#: Transitions a run keeps: the most recent ones (earlier ones are counted in
#: ``Transitions.dropped``), so that memory stays bounded however long the run: 10^6 transitions
#: × (instant, kind, contact) plus the states of the last :data:`KEEP_TRANSITION_STATES`.
KEEP_TRANSITIONS = 1_000_000
KEEP_TRANSITION_STATES = 100_000

#: "No cap" on the steps of a run (int64 for the compiled loops).
NO_STEP_CAP = 2**62

#: Preparation of a run (packing the model, compiling or loading its kernels) shorter than this
#: [s] is not reported as compile time: loading cached kernels once per process takes longer, a
#: run whose kernels are loaded takes microseconds.
COMPILE_REPORT_S = 0.05


def transition_room(duration: float, ns: int, capacity: int | None = None, n_contacts: int = 1) -> TransitionLog:
    """Transition buffers (times, kinds, contacts, states (·, ns)) for a chunk of ``duration`` [s]:
    ``capacity`` entries, default :data:`MIN_TRANSITION_ROOM` + :data:`TRANSITIONS_PER_SECOND` per second;
    the contacts' indices int8, wider for a model of more than 127 contacts."""
    cap = capacity or MIN_TRANSITION_ROOM + int(TRANSITIONS_PER_SECOND * max(duration, 0.0))
    return transition_log(cap, ns, contact_index_dtype(n_contacts))


@dataclasses.dataclass(frozen=True)
class Chunk:
    """What one chunk of a compiled loop did.

    Attributes
    ----------
    status : int
        :mod:`.status` code; ``CHUNK_END`` when the chunk stopped at its planned end.
    tau : float
        Time advanced [s].
    idx : int
        Next sample index of the record after the chunk.
    stats : ndarray (6,) int64
        Accepted and rejected steps, rhs calls, re-taken steps, slip → stick and stick → slip
        transitions of the chunk.
    lost : int
        Contact whose normal force reached 0 (status ``CONTACT_LOST``), else −1.
    transitions : tuple of ndarray
        The chunk's transitions: times (k,), kinds (k,), contacts (k,), states (k, ns).
    """

    status: int
    tau: float
    idx: int
    stats: np.ndarray
    lost: int
    transitions: tuple

    @property
    def steps(self) -> int:
        """Accepted plus rejected steps of the chunk."""
        return int(self.stats[0] + self.stats[1])


class Record:
    """The samples and transitions of one run.

    Parameters
    ----------
    system : FrictionModel
    sample_times : ndarray (k,)
        Uniform sample times [s], absolute; written from index 0 as the run passes them.
    capacity : int, optional
        Rows of the sample arrays (default k: every sample). With fewer, samples before a kept
        window are dropped by :meth:`keep_from` (memory stays flat however long the run).

    Attributes
    ----------
    n : int
        Samples written so far (absolute index of the next).
    base : int
        Absolute index of the first sample still held (row 0 of the arrays).
    chunks : list of (int, int, int)
        For each chunk: its first sample, its first transition (as counted by
        :attr:`transition_count`) and its number of samples.
    tally : ImpactTally or None
        With ``impact_window`` (a model with rigid contacts): the number and largest speed of the
        impacts in (impact_window, last sample time], exact however many transitions are dropped.
    """

    def __init__(self, system: FrictionModel, sample_times: np.ndarray, capacity: int | None = None,
                 impact_window: float | None = None):
        k = sample_times.size if capacity is None else min(int(capacity), sample_times.size)
        self.system = system
        self.sample_times = sample_times
        #: The impacts after ``impact_window`` [s] up to the last sample time, counted chunk by
        #: chunk from the states the chunk logged (before older states are dropped): None unless asked
        self.tally = None if impact_window is None or not system.rigid or sample_times.size == 0 else \
            ImpactTally(float(impact_window), float(sample_times[-1]))
        self.ns = 2 * system.n + N_EXTRA
        self.capacity = k
        self._states = np.empty((k, self.ns))
        self._mode = mode_array(k, system.n_contacts, system.unilateral)
        self._friction = np.empty((k, 2 * system.n_contacts))
        self.base = 0
        self.n = 0
        self.chunks: list[tuple[int, int, int]] = []
        self._tr: list[tuple] = []
        self.kept = 0
        self.dropped = 0
        self.transition_count = 0

    # ------------------------------------------------------------------ samples
    def loop_arrays(self) -> tuple[Samples, int]:
        """(samples, next row) for a compiled loop that writes the next samples in place: the held
        arrays, their times from :attr:`base` on."""
        times = self.sample_times[self.base:self.base + self.capacity]
        return Samples(times, self._states, self._mode, self._friction), self.n - self.base

    @property
    def room(self) -> int:
        """Rows still free in the sample arrays."""
        return self.capacity - (self.n - self.base)

    def samples(self, first: int = 0, last: int | None = None):
        """(t, states (·, 2n + 2), mode, friction) of the samples ``first`` ≤ i < ``last`` (absolute
        indices, default: all written), as views."""
        last = self.n if last is None else last
        a, b = first - self.base, last - self.base
        if a < 0:
            raise IndexError(f"sample {first} was dropped (the record holds samples from {self.base} on)")
        return self.sample_times[first:last], self._states[a:b], self._mode[a:b], self._friction[a:b]

    def keep_from(self, first: int) -> None:
        """Drop the samples before the absolute index ``first``, moving the rest to the arrays' start."""
        shift = first - self.base
        if shift <= 0:
            return
        held = self.n - first
        for a in (self._states, self._mode, self._friction):
            a[:held] = a[shift:shift + held]
        self.base = first

    # ------------------------------------------------------------------ chunks and transitions
    def add(self, chunk: Chunk) -> None:
        """Take a chunk's samples (already written in place) and its transitions, dropping the
        oldest transitions beyond :data:`KEEP_TRANSITIONS` (states beyond :data:`KEEP_TRANSITION_STATES`)."""
        self.chunks.append((self.n, self.transition_count, chunk.idx - self.n))
        self.n = chunk.idx
        n_tr = chunk.transitions[0].size
        if self.tally is not None and n_tr:
            times, kinds, contacts, states = chunk.transitions
            rows, speeds = impact_speeds(self.system, kinds, contacts, states)
            self.tally = self.tally.add(times[rows], speeds)
        self.transition_count += n_tr
        self._tr.append(tuple(a.copy() for a in chunk.transitions))
        self.kept += n_tr
        if self.kept > 2 * KEEP_TRANSITIONS or sum(len(t[3]) for t in self._tr) > 2 * KEEP_TRANSITION_STATES:
            drop = max(self.kept - KEEP_TRANSITIONS, 0)
            times, kinds, contacts = (np.concatenate([t[i] for t in self._tr])[drop:] for i in range(3))
            states = np.concatenate([t[3] for t in self._tr])
            states = states[max(len(states) - KEEP_TRANSITION_STATES, 0):]
            self._tr = [(times, kinds, contacts, states)]
            self.kept -= drop
            self.dropped += drop

    def transitions(self, first: int = 0, last: int | None = None) -> Transitions:
        """The kept transitions numbered ``first`` ≤ i < ``last`` in the run (default: all); states
        of the earliest kept ones beyond the state cap are NaN."""
        if not self._tr:
            return Transitions(np.empty(0), np.empty(0, np.int8), np.empty((0, self.ns)), np.empty(0, np.int8))
        times, kinds, contacts = (np.concatenate([t[i] for t in self._tr]) for i in range(3))
        states = np.concatenate([t[3] for t in self._tr])
        if len(states) < len(times):
            states = np.concatenate([np.full((len(times) - len(states), self.ns), np.nan), states])
        a = max(first - self.dropped, 0)
        b = len(times) if last is None else last - self.dropped
        return Transitions(times[a:b], kinds[a:b], states[a:b], contacts[a:b], dropped=self.dropped + a)


class EventStepper:
    """The ``event`` integrator of ``system`` from the state ``s0`` at ``t0``, advanced chunk by chunk.

    Parameters
    ----------
    system : FrictionModel
    s0 : ndarray (2n,)
    t0, t_end : float
        Start and end of the run [s].
    rtol, atol : float
        Local error tolerances.
    h_max : float
        Largest step [s].
    max_steps : int
        Cap on the steps (accepted and rejected) of the whole run.

    Attributes
    ----------
    y : ndarray (2n + 2,)
        The state (and the work of friction and damping) at :attr:`t`.
    open_contact : int
        A contact whose normal force is ≤ 0 at the start (−1: none). Such a run cannot start; the
        caller says so.
    prepare_s : float
        Seconds spent preparing the run (packing the model, compiling or loading the kernels)
        when that took more than :data:`COMPILE_REPORT_S`, else 0.
    """

    def __init__(self, system: FrictionModel, s0: np.ndarray, t0: float, t_end: float, *, rtol: float,
                 atol: float, h_max: float, max_steps: int):
        start = time.perf_counter()
        md = self.md = system.data
        n2 = 2 * system.n
        self.ns = n2 + N_EXTRA
        self.y = np.zeros(self.ns)
        self.y[:n2] = s0
        self.cst = contact_state(md.m)
        self.t, self.t_end = float(t0), float(t_end)
        self.rtol, self.atol, self.h_max = rtol, atol, h_max
        self.h = min(1e-3, h_max)  # a fraction of the mechanical periods of interest; the controller adapts it
        self.steps_left = int(max_steps)
        self.stats = np.zeros(6, dtype=np.int64)
        self.n_contacts = system.n_contacts
        # on a cold start the loop's callees compile in two processes (:mod:`.loop_split`): the
        # helper starts before the check of the contacts' loads, which compiles meanwhile
        with start_callees(md) or contextlib.nullcontext() as cold:
            self.open_contact = int(E.contact_lost(self.y, md))
            if self.open_contact < 0:
                if cold is not None:
                    cold.finish()
                self._warm_up(system)
        prepared = time.perf_counter() - start
        self.prepare_s = prepared if prepared > COMPILE_REPORT_S else 0.0

    def _warm_up(self, system: FrictionModel) -> None:
        """Compile (or load from cache) the event loop for this kinematics class and set the modes
        the state starts in (the loop's ``start_modes`` call: no time passes, it may project q̇)."""
        nc = system.n_contacts
        samples = Samples(np.empty(0), np.empty((1, self.ns)), mode_array(1, nc, system.unilateral),
                          np.empty((1, 2 * nc)))
        self.y = integrate_event(self.md, self.cst, self.y, controls(0.0, 0.0, 0.0, self.rtol, self.atol, 1e-6, 10),
                                 1e-7, samples, 0, transition_room(0.0, self.ns, 1, nc), start_modes=True)[2]

    def advance(self, tau_stop: float, record: Record) -> Chunk:
        """Integrate about ``tau_stop`` seconds more (to the first accepted step past it outside an
        approach to stick, or to the end), writing samples into ``record`` from its next index."""
        start = (self.y.copy(), self.cst.copy(), self.h)
        tau_end = self.t_end - self.t
        capacity = None
        while True:
            tr = transition_room(tau_stop, self.ns, capacity, self.n_contacts)
            samples, row = record.loop_arrays()
            chunk = controls(self.t, tau_stop, tau_end, self.rtol, self.atol, self.h_max, self.steps_left)
            status, tau, y, h, idx, n_tr, st, lost = integrate_event(self.md, self.cst, self.y, chunk, self.h,
                                                                     samples, row, tr)
            if n_tr <= tr.times.size:
                break
            capacity = n_tr  # again from the chunk's start with room for all its transitions
            self.y, self.cst, self.h = start[0].copy(), start[1].copy(), start[2]
        self.y, self.h = y, h
        self.t = self.t + tau
        self.stats += st
        self.steps_left -= int(st[0] + st[1])
        return Chunk(int(status), float(tau), record.base + int(idx), st, int(lost), tuple(a[:n_tr] for a in tr))


class StopCondition:
    """Where the chunks of a run end and whether the run stops after one.

    Subclasses give :meth:`chunk_length` and, optionally, :meth:`stop`, which sees every chunk
    (also the last one, whatever its status).
    """

    def chunk_length(self, stepper) -> float:
        """Simulated time [s] the next chunk aims at."""
        raise NotImplementedError

    def stop(self, stepper, record: Record, chunk: Chunk) -> bool:
        """Whether the run ends after ``chunk`` (it ends anyway unless the chunk's status is ``CHUNK_END``)."""
        return False


class ToTheEnd(StopCondition):
    """Run to the end, in chunks of about :data:`CHUNK_STEPS` steps (the first :data:`FIRST_CHUNK` s)
    and at most ``max_length`` seconds [s] (default: no bound)."""

    def __init__(self, max_length: float = float("inf")) -> None:
        self.length = FIRST_CHUNK
        self.max_length = max_length

    def chunk_length(self, stepper) -> float:
        return min(self.length, self.max_length, stepper.t_end - stepper.t)

    def stop(self, stepper, record: Record, chunk: Chunk) -> bool:
        if chunk.tau > 0.0 and chunk.steps > 0:  # aim the next chunk at CHUNK_STEPS steps
            self.length = min(max(chunk.tau * CHUNK_STEPS / chunk.steps, 1e-3), 10.0 * max(chunk.tau, 1e-3))
        return False


def run_chunks(stepper, record: Record, stop: StopCondition, *, interrupt: bool = True) -> tuple[int, bool, int]:
    """Advance ``stepper`` chunk by chunk into ``record`` until it reaches its end, stops early
    (status), ``stop`` ends it, or Ctrl-C is pressed (when ``interrupt``: answered between chunks).

    Returns
    -------
    (status, interrupted, lost) : (int, bool, int)
        The last chunk's status (``CHUNK_END`` when ``stop`` or Ctrl-C ended the run), whether
        Ctrl-C did, and the contact lost (−1: none).
    """
    with (interruptible() if interrupt else _NoInterrupt()) as ctrl_c:
        while True:
            chunk = stepper.advance(stop.chunk_length(stepper), record)
            record.add(chunk)
            if stop.stop(stepper, record, chunk) or chunk.status != CHUNK_END or ctrl_c.requested:
                return chunk.status, bool(ctrl_c.requested), chunk.lost


class _NoInterrupt:
    requested = False

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        pass


@dataclasses.dataclass(frozen=True)
class RunOutput:
    """What a method's run gives the driver (the same for every method).

    Attributes
    ----------
    status : Status
    t_reached : float
        Time reached [s].
    lost : int
        Contact lost (status ``CONTACT_LOST``), else −1.
    record : Record
        Samples (the first :attr:`Record.n` are the run's) and transitions.
    stats : dict
        Keyword arguments of :class:`~.result.Stats` without the wall time.
    interrupted : bool
        Whether Ctrl-C was pressed during the run (also when the run had just finished).
    """

    status: Status
    t_reached: float
    lost: int
    record: Record
    stats: dict
    interrupted: bool = False


def stats_dict(st, prepare_s: float) -> dict:
    """The integrator counters (the first six of ``st``) as keyword arguments of :class:`~.result.Stats`."""
    return dict(accepted_steps=int(st[0]), rejected_steps=int(st[1]), rhs_calls=int(st[2]),
                retaken_steps=int(st[3]), slip_to_stick=int(st[4]), stick_to_slip=int(st[5]), compile_time_s=prepare_s)


def run_event(system: FrictionModel, s0: np.ndarray, t0: float, t_end: float, sample_times: np.ndarray, *,
              rtol: float, atol: float, dt: float | None, max_steps: int, impact_window: float | None = None
              ) -> RunOutput:
    """The ``event`` method from ``s0`` at ``t0`` to ``t_end``, to the end or Ctrl-C (:func:`run_chunks`);
    ``impact_window``: the start of the steady window whose impacts the record tallies (:class:`Record`).

    Raises
    ------
    SimulationError
        If a contact is open (normal force ≤ 0) at the start.
    """
    stepper = EventStepper(system, s0, t0, t_end, rtol=rtol, atol=atol,
                           h_max=dt if dt is not None else (t_end - t0), max_steps=max_steps)
    if stepper.open_contact >= 0:
        raise SimulationError(f"the normal force of contact {stepper.open_contact} is ≤ 0 at the initial state: the "
                              "contact is open; start from a state where every contact is pressed")
    record = Record(system, sample_times, impact_window=impact_window)
    rate = (sample_times.size - 1) / (sample_times[-1] - sample_times[0]) if sample_times.size > 1 else 0.0
    numbers = record.ns + 1 + 2 * system.n_contacts  # per sample: states, mode, friction
    stop = ToTheEnd(CHUNK_SAMPLE_NUMBERS / (numbers * rate) if rate > 0 else float("inf"))
    status, interrupted, lost = run_chunks(stepper, record, stop)
    code = Status.INTERRUPTED if interrupted and status == CHUNK_END else Status(status)
    return RunOutput(code, stepper.t, lost, record, stats_dict(stepper.stats, stepper.prepare_s), interrupted)
