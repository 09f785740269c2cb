"""The early-stopping classifier: one initial state, integrated in pieces until its attractor is known.

Each state runs with the exact ``event`` integrator, piece by piece
(:func:`stickslip.integrate.runner.run_chunks` with the stop condition :class:`EarlyStop`, so the
run takes the same steps as one long call) for at most ``t_end``. After each piece of one
characteristic period T_c (:func:`test_interval` samples), in this order:

1. **Steady sliding reached** (only where it is linearly stable). The deviation δ = s − s_e at
   the end of a chunk of :data:`~.context.CHUNK_PERIODS` T_c is compared with the linear flow
   from its start, Φ δ0. In the norm of the Lyapunov function V = δᵀPδ the linear flow contracts
   by c = |δ0| − |Φ δ0| per chunk; the chunk counts as linear when no contact stuck and
   |δ − Φ δ0| ≤ :data:`LINEAR_MARGIN` · c. Near an unstable cycle around the equilibrium the
   nonlinear terms cancel the contraction and the test fails; in the linear regime they are a
   vanishing fraction of it, V keeps falling and the run converges. The last
   :data:`LINEAR_CHUNKS` consecutive chunks (ending at the piece's end) all linear, or |δ| below
   the context's rest level, decide ``equilibrium``.
2. **A known cycle reached**: the window's section crossings recur on a cycle already found
   (:func:`.cycles.run_matches`).
3. **A known cycle recurred** (:mod:`.recurrence`): the state at the run's latest breakaway
   (stick → slip) equals, to :data:`~.recurrence.RECURRENCE_FACTOR` times the integration
   tolerances, the breakaway state of a known cycle (:func:`~.recurrence.cycle_point`), or the
   state at an earlier breakaway of the same contact with the one period between them matching
   a known cycle (:func:`.cycles.period_matches`): the run repeats from there. A contact that
   sticks fixes its slip velocity, so runs onto a stick-slip cycle pass through the cycle's
   breakaway state itself (the belt's every time, to the last bit): the cycle is recognised at
   the first breakaway on it instead of after :data:`~.cycles.MATCH_PERIODS` periods of crossings.
4. **A new cycle** (after every chunk of :data:`~.context.CHUNK_PERIODS` T_c): the maxima of
   the last :data:`RULE_PERIODS` T_c repeat by the package's period rule
   (:func:`stickslip.analysis.period.return_map`); the window's verdict
   (:func:`stickslip.attractors.attractor`, which for k ≥ 2 maxima per period needs the shot
   orbit to confirm it) then decides ``periodic`` and gives the cycle's features.
5. At ``t_end``: the verdict of :func:`~stickslip.attractors.attractor` on the window
   (``equilibrium``, ``periodic``, ``quasiperiodic``, ``chaotic`` or ``unsettled``); a run that
   stops early is ``unbounded`` (non-finite state), ``contact-lost`` (a normal force reached 0)
   or ``failed`` (step size underflow, step cap).

The outcome is a fixed-length row of numbers (:class:`Outcome`), journaled by the study.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np

from ..analysis.outcome import OUTCOMES, outcome_code
from ..analysis.peaks import Peaks
from ..analysis.period import MIN_PERIODS, return_map
from ..attractors import attractor, stopped_outcome
from ..integrate.contacts import TRANSITION_TO_SLIP
from ..integrate.result import Stats, Trajectory, Transitions
from ..integrate.runner import Chunk, EventStepper, Record, StopCondition, run_chunks
from ..integrate.status import CHUNK_END, SUCCESS
from .context import CHUNK_PERIODS, Context
from .cycles import KMAX, MATCH_PERIODS, MATCH_RTOL, Cycle, Section, cycle_from_section, run_matches, section_of
from .recurrence import cycle_point, earlier_recurrence, period_cycle, recurs

__all__ = ["Options", "Outcome", "classify_state", "EarlyStop", "DECIDED", "LINEAR_MARGIN", "LINEAR_CHUNKS",
           "RULE_PERIODS", "row_width", "row_column", "DEFAULT_MAX_STEPS", "test_interval"]

#: How the verdict was reached (``matched-at-end``: set when the study is assembled, for a run
#: unsettled at t_end whose last crossings recur on a cycle found from another state;
#: ``recurred``: the state at a breakaway recurred and that period matched a known cycle).
DECIDED = ("linear", "at-rest", "matched", "period-rule", "end-verdict", "stopped", "matched-at-end", "recurred")

#: Fraction of the linear flow's contraction (in the Lyapunov norm) that the nonlinear part of a
#: chunk may reach for the chunk to count as linear.
LINEAR_MARGIN = 0.05

#: Consecutive linear chunks that decide the equilibrium.
LINEAR_CHUNKS = 2

#: Trailing span of the window, in T_c, on which the period rule is tried during the run (the
#: rule needs nine periods).
RULE_PERIODS = 16

#: Default cap on the integration steps of one state (a state that stalls ends as ``failed``).
DEFAULT_MAX_STEPS = 10_000_000

#: Section crossings an outcome keeps (enough to match a cycle of KMAX maxima per period).
N_CROSSINGS = MATCH_PERIODS * KMAX + 1

_HEAD = ("verdict", "decided_by", "t_decided", "period", "multiplicity", "amplitude", "stick_fraction",
         "open_fraction", "steps", "wall_time")


def row_width(n: int) -> int:
    """Numbers per outcome row of a model with n coordinates."""
    return len(_HEAD) + KMAX + 2 * n + 3 * N_CROSSINGS


def row_column(name: str) -> int:
    """The column of an outcome row that holds ``name`` (``verdict``, ``decided_by``, ``t_decided``,
    ``steps``, ``wall_time``, …; ``state``: the first of the state's 2n)."""
    return len(_HEAD) + KMAX if name == "state" else _HEAD.index(name)


@dataclasses.dataclass(frozen=True)
class Options:
    """Integration and decision options of a study (the same for every state).

    Attributes
    ----------
    t_end : float
        Longest run of a state [s].
    rtol, atol : float
        Tolerances of the event integrator.
    match_rtol : float
        Tolerance of the cycle matches (:mod:`.cycles`).
    confirm : bool
        Shoot the orbit of a period claim of k ≥ 2 maxima (:func:`stickslip.attractors.attractor`).
    lyapunov : bool
        Compute Lyapunov exponents for a stationary non-periodic window at t_end (chaos or torus).
    max_steps : int
        Cap on the integration steps of one state.
    """

    t_end: float = 500.0
    rtol: float = 1e-8
    atol: float = 1e-10
    match_rtol: float = MATCH_RTOL
    confirm: bool = True
    lyapunov: bool = False
    max_steps: int = DEFAULT_MAX_STEPS


@dataclasses.dataclass(frozen=True)
class Outcome:
    """What one state reached.

    Attributes
    ----------
    verdict : str
        The outcome, one of :data:`~stickslip.analysis.outcome.OUTCOMES`.
    decided_by : str
        One of :data:`DECIDED`.
    t_decided : float
        Simulated time at which the verdict was reached [s].
    cycle : Cycle or None
        The cycle's features (``periodic``).
    state : ndarray (2n,)
        The state it ended in (a state on the cycle for ``periodic``).
    section : Section or None
        The run's last :data:`N_CROSSINGS` section crossings (kept for matching at the end).
    steps : int
        Integration steps taken.
    wall_time : float
        Seconds spent on this state.
    """

    verdict: str
    decided_by: str
    t_decided: float
    cycle: Cycle | None
    state: np.ndarray
    section: Section | None = None
    steps: int = 0
    wall_time: float = 0.0

    def to_row(self) -> np.ndarray:
        """The outcome as a row of :func:`row_width` numbers."""
        n2 = self.state.size
        row = np.full(row_width(n2 // 2), np.nan)
        c = self.cycle
        row[:len(_HEAD)] = (outcome_code(self.verdict), DECIDED.index(self.decided_by), self.t_decided,
                            math.nan if c is None else c.period, 0 if c is None else c.multiplicity,
                            math.nan if c is None else c.amplitude, math.nan if c is None else c.stick_fraction,
                            math.nan if c is None or c.open_fraction is None else c.open_fraction,
                            self.steps, self.wall_time)
        o = len(_HEAD)
        if c is not None:
            row[o:o + c.multiplicity] = c.peaks
        o += KMAX
        row[o:o + n2] = self.state
        o += n2
        if self.section is not None:
            s = self.section.last(min(len(self.section), N_CROSSINGS))
            m = len(s)
            for j, values in enumerate((s.times, s.maxima, s.minima)):
                row[o + j * N_CROSSINGS + N_CROSSINGS - m:o + (j + 1) * N_CROSSINGS] = values
        return row

    @classmethod
    def from_row(cls, row: np.ndarray, n: int) -> "Outcome":
        """The outcome written by :meth:`to_row` (n: the model's coordinates)."""
        verdict, decided, t, period, k, amp, stick, opened, steps, wall = row[:len(_HEAD)]
        o = len(_HEAD)
        k = int(k)
        state = row[o + KMAX:o + KMAX + 2 * n].copy()
        cycle = Cycle(k, float(period), float(amp), row[o:o + k].copy(), float(stick), state,
                      float(opened) if math.isfinite(opened) else None) if k > 0 else None
        o += KMAX + 2 * n
        times, maxima, minima = (row[o + j * N_CROSSINGS:o + (j + 1) * N_CROSSINGS] for j in range(3))
        keep = np.isfinite(times)
        section = Section(times[keep], maxima[keep], minima[keep]) if np.any(keep) else None
        return cls(OUTCOMES[int(verdict)], DECIDED[int(decided)], float(t), cycle, state, section, int(steps),
                   float(wall))


def _window_start(record: Record, limit: int) -> int:
    """Index in ``record.chunks`` of the first chunk of the window: the chunks with samples from the
    latest one on whose later chunks hold fewer than ``limit`` samples (the window holds at least
    ``limit`` samples, whole chunks, once the run has that many)."""
    later, start = 0, 0
    for k in range(len(record.chunks) - 1, -1, -1):
        size = record.chunks[k][2]
        if size and later < limit:
            start = k
        later += size
    return start


def _trajectory(model, opts: Options, record: Record, first_chunk: int, t_end: float, steps: int) -> Trajectory:
    """The window (the samples and transitions of ``record`` from chunk ``first_chunk`` on, without
    a last chunk that wrote no samples) as a :class:`~stickslip.integrate.result.Trajectory`, for the verdict."""
    n2 = 2 * model.n
    first_sample, first_tr, _ = record.chunks[first_chunk]
    last_tr = record.chunks[-1][1] if record.chunks[-1][2] == 0 else record.transition_count
    t, states, mode, friction = record.samples(first_sample)
    tr = record.transitions(first_tr, last_tr)
    return Trajectory(t=t.copy(), states=np.ascontiguousarray(states[:, :n2]), mode=mode.copy(),
                      friction=friction.copy(), work=np.zeros((t.size, 2)),
                      transitions=Transitions(tr.time, tr.kind, np.ascontiguousarray(tr.state[:, :n2]), tr.contact),
                      stats=Stats(accepted_steps=steps), status="success", system=model, method="event",
                      options={"rtol": opts.rtol, "atol": opts.atol, "dt": None,
                               "sample_rate": 1.0 / (record.sample_times[1] - record.sample_times[0]),
                               "ic": "explicit", "perturbation": None, "t0": float(t[0]), "t_end": t_end,
                               "slip_band": model.slip_band},
                      steady_from=float(t[0]))


def _linear(ctx: Context, d0: np.ndarray, d1: np.ndarray) -> tuple[bool, bool]:
    """(at rest, linear) for the deviations from s_e at a chunk's start and end (free states)."""
    P = ctx.lyapunov

    def norm(d):
        return math.sqrt(max(float(d @ P @ d), 0.0))

    n1 = norm(d1)
    if n1 <= ctx.rest:
        return True, True
    lin = ctx.flow @ d0
    contraction = norm(d0) - norm(lin)
    return False, contraction > 0.0 and norm(d1 - lin) <= LINEAR_MARGIN * contraction


def test_interval(ctx: Context) -> int:
    """Samples per piece of a run: the tests run after each (one T_c)."""
    return max(ctx.chunk // CHUNK_PERIODS, 1)


class EarlyStop(StopCondition):
    """The stop condition of one state (module docstring): pieces of :func:`test_interval` samples,
    each followed by the tests that may decide the state's :class:`Outcome` (in :attr:`outcome`).

    Parameters
    ----------
    ctx : Context
    model : FrictionModel
    cycles : sequence of Cycle
        Cycles already found for this model.
    opts : Options
    record : Record
        The run's record (its samples before the window are dropped as the run goes on).
    start : float
        ``time.perf_counter()`` when the state was taken up (for the outcome's wall time).
    """

    def __init__(self, ctx: Context, model, cycles, opts: Options, record: Record, start: float):
        self.ctx, self.model, self.cycles, self.opts, self.record, self.start = ctx, model, cycles, opts, record, start
        self.target = 0
        self.next_rule = ctx.chunk  # the period rule is tried once per chunk, from the first chunk's end
        self.cache: dict = {}
        self.outcome: Outcome | None = None

    def chunk_length(self, stepper) -> float:
        m, record = self.ctx.chunk, self.record
        if record.room < 2 * m + 2 and record.chunks:  # drop the samples before the window
            record.keep_from(record.chunks[_window_start(record, self.ctx.window)][0])
        g = test_interval(self.ctx)
        self.target = max(record.n + g - 1, g)  # the piece ends at this sample
        return self.target * self.ctx.dt - stepper.t

    def stop(self, stepper, record: Record, chunk: Chunk) -> bool:
        self.outcome = self._decide(stepper, record, chunk)
        return self.outcome is not None

    def _steady(self, record: Record, first: int, tw, sw, mw) -> str | None:
        """Test 1 (module docstring): ``at-rest``, ``linear`` or None."""
        ctx, m, target = self.ctx, self.ctx.chunk, self.target
        window_first = record.chunks[first][0]
        b = target - window_first
        if not (ctx.stable and b - m >= 0 and b < tw.size):
            return None
        trw = record.transitions(record.chunks[first][1]).time
        for j in range(LINEAR_CHUNKS):
            a, b = target - (j + 1) * m - window_first, target - j * m - window_first
            if a < 0:
                return None
            rest, linear = _linear(ctx, sw[a, ctx.free] - ctx.equilibrium[ctx.free],
                                   sw[b, ctx.free] - ctx.equilibrium[ctx.free])
            if rest and j == 0:
                return "at-rest"
            if bool(np.any(mw[a:b + 1])) or bool(np.any((trw > tw[a]) & (trw <= tw[b]))) or not linear:
                return None
        return "linear"

    def _recurred(self, record: Record, first: int, tw, sw, section: Section) -> Cycle | None:
        """Test 3 (module docstring): the known cycle the run's latest breakaway recurs on, or None."""
        if not self.cycles:
            return None
        n, n2, j, opts = self.model.n, 2 * self.model.n, self.model.observed_index, self.opts
        tr = record.transitions(record.chunks[first][1])
        slips = np.flatnonzero(tr.kind == TRANSITION_TO_SLIP)
        if slips.size == 0:
            return None
        last = slips[-1]
        for cycle in self.cycles:  # the cycle's own breakaway state
            p = cycle_point(self.ctx, self.model, cycle, opts)
            if p is not None and p.contact == tr.contact[last] and recurs(p.state, tr.state[last, :n2], opts.atol,
                                                                          opts.rtol):
                return cycle
        found = earlier_recurrence(tr, n2, opts.atol, opts.rtol)  # one period of the run's own
        if found is None:
            return None
        c = period_cycle(self.cycles, tr.time[found[0]], tr.time[found[1]], tw, sw[:, j], sw[:, n + j], section,
                         opts.match_rtol)
        return self.cycles[c] if c >= 0 else None

    def _decide(self, stepper, record: Record, chunk: Chunk) -> Outcome | None:
        ctx, model, opts = self.ctx, self.model, self.opts
        n, n2, j = model.n, 2 * model.n, model.observed_index
        t, steps = stepper.t, int(stepper.stats[0] + stepper.stats[1])
        first = _window_start(record, ctx.window)
        window_first = record.chunks[first][0]
        tw, sw, mw, _ = record.samples(window_first)
        sw = sw[:, :n2]

        def outcome(verdict, decided, cycle=None, state=None, section=None):
            last = sw[-1].copy() if record.chunks[-1][2] else stepper.y[:n2].copy()
            return Outcome(verdict, decided, t, cycle, last if state is None else state, section, steps,
                           time.perf_counter() - self.start)

        if chunk.status not in (CHUNK_END, SUCCESS):
            return outcome(stopped_outcome(chunk.status), "stopped")
        # 1. steady sliding reached: the last chunks against the linear flow
        steady = self._steady(record, first, tw, sw, mw)
        if steady is not None:
            return outcome("equilibrium", steady)
        rule_due = self.target >= self.next_rule
        if not (self.cycles or rule_due or chunk.status == SUCCESS):
            return None  # tests 2 to 5 have nothing to test
        section = section_of(tw, sw[:, j], sw[:, n + j])
        # 2. a known cycle reached
        for cycle in self.cycles:
            if run_matches(cycle, section, opts.match_rtol):
                return outcome("periodic", "matched", cycle, cycle.state)
        # 3. a known cycle recurred
        cycle = self._recurred(record, first, tw, sw, section)
        if cycle is not None:
            return outcome("periodic", "recurred", cycle, cycle.state)
        # 5. the verdict at t_end
        if chunk.status == SUCCESS:
            traj, v = self._verdict(record, first, float(tw[0]), steps)
            if v.attractor == "periodic":
                cyc = _cycle(section, traj, v)
                return outcome("periodic", "period-rule", cyc, cyc.state)
            return outcome(v.attractor, "end-verdict", section=section)
        # 4. a new cycle, once per chunk: the period rule on the last RULE_PERIODS T_c, then the window's verdict
        if not rule_due:
            return None
        self.next_rule = self.target + ctx.chunk
        t_from = t - RULE_PERIODS * ctx.period
        recent = section.times >= t_from
        if np.count_nonzero(recent) > MIN_PERIODS and tw[0] <= t_from:
            x = sw[tw >= t_from, j]
            settled, _ = return_map(Peaks(section.times[recent], section.maxima[recent]), float(np.ptp(x)))
            if settled is not None:
                traj, v = self._verdict(record, first, t_from, steps)
                if v.attractor == "periodic":
                    cyc = _cycle(section, traj, v)
                    return outcome("periodic", "period-rule", cyc, cyc.state)
        return None

    def _verdict(self, record: Record, first_chunk: int, t_from: float, steps: int):
        """The verdict of :func:`stickslip.attractors.attractor` on the window from ``t_from``."""
        traj = _trajectory(self.model, self.opts, record, first_chunk, float(self.opts.t_end), steps)
        return traj, attractor(traj, t_from, confirm=self.opts.confirm, lyapunov=self.opts.lyapunov,
                               cache=self.cache)


def classify_state(ctx: Context, model, s0: np.ndarray, cycles, opts: Options) -> Outcome:
    """Integrate one state until its attractor is known (module docstring) or ``opts.t_end``.

    Parameters
    ----------
    ctx : Context
        The model's context (:func:`.context.make_context`).
    model : FrictionModel
    s0 : ndarray (2n,)
        The initial state.
    cycles : sequence of Cycle
        Cycles already found for this model.
    opts : Options

    Returns
    -------
    Outcome
    """
    start = time.perf_counter()
    m, dt, t_end = ctx.chunk, ctx.dt, float(opts.t_end)
    # a step never passes more than one chunk of samples
    stepper = EventStepper(model, s0, 0.0, t_end, rtol=opts.rtol, atol=opts.atol, h_max=m * dt,
                           max_steps=opts.max_steps)
    if stepper.open_contact >= 0:
        return Outcome("contact-lost", "stopped", 0.0, None, np.array(s0, dtype=float),
                       wall_time=time.perf_counter() - start)
    # samples t_i = i dt up to t_end; the record holds the window and room for two chunks (a chunk
    # writes at most 2m + 2 samples: it ends within one step of h_max = m dt past its target)
    times = np.arange(int(math.floor(t_end / dt)) + 2) * dt
    record = Record(model, times, capacity=ctx.window + 3 * (2 * m + 2))
    stop = EarlyStop(ctx, model, cycles, opts, record, start)
    run_chunks(stepper, record, stop, interrupt=False)
    return stop.outcome
def _cycle(section: Section, traj, verdict) -> Cycle:
    """The features of the window's settled periodic verdict."""
    window = verdict.classification
    # the stick and open fractions over the whole periods that end the window, from the located
    # transitions (exact for a settled cycle, wherever the window starts in it)
    whole = math.floor((window.t_to - window.t_from) / verdict.period_s) * verdict.period_s
    steady = traj.steady_state(window.t_to - whole)
    return cycle_from_section(section, traj.t, traj.states, verdict.period_count, verdict.period_s,
                              steady.stick_fraction, steady.open_fraction)
