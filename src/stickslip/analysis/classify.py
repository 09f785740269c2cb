"""Classification of a response window from the signal alone: at rest, periodic, decaying,
stationary or still drifting.

The decision uses the window t ≥ t_from (the transient before it is discarded); the outcome is
named in the one vocabulary of :mod:`.outcome`, the signal's own finding in ``signal``:

1. **At rest** (``at-rest``) – peak-to-peak x below
   :data:`~stickslip.analysis.signal.REST_AMPLITUDE`: ``equilibrium``, settled.
2. **Settled period** (``periodic``) – :func:`~stickslip.analysis.period.detect_period` (the
   one period rule, shared with ``Trajectory.steady``): the peaks repeat with multiplicity k and
   the window shows no drift and no decaying return differences: ``periodic``, settled; a
   stick-slip orbit when any stick occurs in the window (``stick_fraction`` > 0), else a
   pure-slip orbit.
3. **Decay** (``decaying``) – no settled period, no stick, each quarter of the window holding
   at least :data:`DECAY_MIN_PEAKS` maxima of x (so that a quarter's peak-to-peak is an
   amplitude, not a part of one oscillation), the peak-to-peak amplitude falling from each
   quarter to the next and in the last quarter below :data:`DECAY_RATIO` times that of the first,
   in x and in every other given response: ``equilibrium`` (converging to steady sliding). A
   conservative oscillation (undamped, slip only) does not decay: its quarters' amplitudes stay
   or go up and down (a beat between modes), or its quarters are shorter than its period. The signal
   cannot tell a decay onto the equilibrium from one onto a small slip limit cycle or a mode
   growing unseen below it, so this is not settled here: :mod:`stickslip.attractors` confirms
   it with the linear stability of the equilibrium. A slip-only response that grows in any
   response is not an equilibrium.
4. Otherwise ``unsettled``: **stationary** when the window holds enough peaks for every
   multiplicity to have been tried (:data:`STATIONARY_MIN_PEAKS`), the return differences of
   the best multiplicity seen are far from a match (spread ≥ :data:`STATIONARY_MIN_SPREAD`),
   and they show neither decay (:func:`~stickslip.analysis.period.decay_ratio` at most
   :data:`~stickslip.analysis.period.DECAY_FACTOR`) nor trend (their drift is no larger than
   their spread): no sign of a transient, a candidate for chaos or a torus that only the
   dynamics can confirm (:mod:`stickslip.attractors`); else **drifting**. The range of
   the peaks is not required to repeat between the window halves: a chaotic attractor's
   100-s windows differ in range by 3–25 % (docs/settling.md).

``settled`` is True only for cases 1 and 2. ``signal`` names what the signal shows
(:data:`SIGNALS`): ``at-rest``, ``periodic``, ``decaying``, ``stationary`` or ``drifting``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .modes import sample_flags
from .outcome import is_stick_slip, outcome_code
from .peaks import Peaks
from .period import DECAY_FACTOR, MAX_MULTIPLICITY, MIN_PERIODS, SETTLE_RTOL, decay_ratio, detect_period
from .signal import REST_AMPLITUDE, spectral_peak, stick_time

__all__ = ["SIGNALS", "Classification", "classify_response", "classify", "SETTLE_RTOL", "MAX_MULTIPLICITY",
           "MIN_PERIODS", "STATIONARY_MIN_PEAKS"]

#: What the signal of a window shows (module docstring): the evidence behind its outcome.
SIGNALS = ("at-rest", "periodic", "decaying", "stationary", "drifting")

#: A slip-only, non-periodic oscillation whose last-quarter amplitude is below this fraction of
#: the first quarter's is decaying onto the equilibrium (a settled slip limit cycle is caught as
#: periodic before this test). The slowest free decay of Table 1 (time constant 2 m_d / c_dx =
#: 200 s) gives e^(−0.75 W / 200) < 0.99 for any window W > 2.7 s.
DECAY_RATIO = 0.99

#: Maxima of x each quarter of the window must hold before the quarters' amplitudes are compared
#: (in a quarter without one, the peak-to-peak depends on where the oscillation's phase cuts it: an
#: undamped cosine whose period is 0.7 of the window has quarter amplitudes 0.57 of each other).
#: One is enough with the amplitudes falling quarter by quarter (a beat goes up and down); two
#: would refuse a decay whose window holds fewer than eight periods (the belt's 30 s window at
#: period 2π holds 4.8, and steady sliding was then called unsettled).
DECAY_MIN_PEAKS = 1

#: Smallest return spread (relative to A) of a stationary non-periodic window: a window that
#: nearly repeats (spread 1e-5 … 1e-3) is a slow approach to a periodic orbit until shown
#: otherwise (Model 3, N = 50 N, Ω = 0.677 rad/s: spread 1.1e-5 at 100–200 s, period 1 by 400 s).
STATIONARY_MIN_SPREAD = 1e-3

#: Agreement of the peak ranges of two windows of a stationary response, relative to A (the
#: range change of a torus's windows; :func:`range_change`).
STATIONARY_RTOL = 1e-2

#: Peaks a window needs before "no period" is a finding rather than a lack of data: every
#: multiplicity up to :data:`~stickslip.analysis.period.MAX_MULTIPLICITY` then fits
#: :data:`~stickslip.analysis.period.MIN_PERIODS` periods plus one (with fewer, a short window
#: in which only k = 1 can be tried would pass as stationary, a candidate for chaos).
STATIONARY_MIN_PEAKS = (MIN_PERIODS + 1) * MAX_MULTIPLICITY


@dataclasses.dataclass(frozen=True)
class Classification:
    """Classification of a response over [t_from, t_to] from the signal alone.

    Parameters
    ----------
    outcome : str
        ``equilibrium``, ``periodic`` or ``unsettled`` (of :data:`~.outcome.OUTCOMES`; the signal
        alone names no other).
    multiplicity : int
        Peaks per period of a settled periodic response; 0 otherwise.
    period_s : float
        Period from the return map [s]; NaN unless periodic.
    frequency_hz : float
        1/period when periodic [Hz]; NaN otherwise (a run without a period has no frequency of its
        own: see ``fft_frequency_hz`` and ``peak_rate_hz``).
    fft_frequency_hz : float
        Highest peak of the Hann-windowed amplitude spectrum of x [Hz]; NaN at rest.
    stick_fraction : float
        Fraction of the window in stick [-]: the stick character beside the outcome.
    settled : bool
        Whether the window shows the attractor itself, not a transient (module docstring).
    amplitude : float
        Peak-to-peak x in the window [unit of x].
    peaks : Peaks
        Event-located peaks of x in the window.
    peak_rate_hz : float
        Mean rate of the peaks in the window [Hz]; NaN with fewer than two.
    t_from, t_to : float
        The window [s].
    signal : str
        What the signal shows, one of :data:`SIGNALS` (module docstring).
    evidence : dict
        What was measured: ``multiplicity``, ``period_s``, ``spread``, ``drift``,
        ``separation`` of the settled or best return map
        (:class:`~stickslip.analysis.period.ReturnMap`); when not periodic also
        ``amplitude_ratio`` (last quarter's peak-to-peak over the first's) and, when not
        decaying, ``range_change`` (of the peak ranges between the window halves, relative to
        A) and ``return_decay`` (:func:`~stickslip.analysis.period.decay_ratio` of the return
        differences).
    """

    outcome: str
    multiplicity: int
    period_s: float
    frequency_hz: float
    fft_frequency_hz: float
    stick_fraction: float
    settled: bool
    amplitude: float
    peaks: Peaks = dataclasses.field(repr=False)
    t_from: float
    t_to: float
    signal: str = "drifting"
    evidence: dict = dataclasses.field(default_factory=dict, repr=False)
    peak_rate_hz: float = math.nan

    @property
    def code(self) -> int:
        """Integer code of the outcome (:func:`~.outcome.outcome_code`)."""
        return outcome_code(self.outcome)

    @property
    def is_stick_slip(self) -> bool:
        """Stick-slip oscillation (periodic or not) with stick in the window."""
        return is_stick_slip(self.outcome, self.stick_fraction)

    def to_dict(self) -> dict:
        """Flat dict without the peak arrays."""
        d = dataclasses.asdict(self)
        d.pop("peaks")
        d["n_peaks"] = len(self.peaks)
        return d


def _ptp(x):
    return float(np.max(x) - np.min(x)) if x.size else 0.0


def _quarters(t, x, t0, t1):
    """Peak-to-peak of x in the four quarters of [t0, t1]."""
    edges = np.linspace(t0, t1, 5)
    return np.array([_ptp(x[(t >= a) & (t <= b)]) for a, b in zip(edges[:-1], edges[1:])])


def _decaying(q):
    """Whether the quarters' amplitudes fall from each quarter to the next, the last below
    DECAY_RATIO × the first's (or whether the last is at rest)."""
    return q[-1] < REST_AMPLITUDE or (bool(np.all(np.diff(q) < 0.0)) and q[-1] < DECAY_RATIO * q[0])


def _peaks_per_quarter(times, t0, t1) -> int:
    """The fewest maxima (at ``times``) in a quarter of [t0, t1]."""
    counts = np.histogram(times, bins=np.linspace(t0, t1, 5))[0]
    return int(counts.min())


def range_change(a: np.ndarray, b: np.ndarray, amplitude: float) -> float:
    """Largest change of the extreme peak values between two sets of peaks, relative to A."""
    if a.size < 2 or b.size < 2:
        return math.inf
    return max(abs(a.min() - b.min()), abs(a.max() - b.max())) / amplitude


def classify_response(t, x, dx, *, stick_fraction: float = 0.0, t_from: float | None = None,
                      others=None) -> Classification:
    """Classify a sampled response x(t) (see the module docstring for the rules).

    Parameters
    ----------
    t : ndarray (n,)
        Uniform sample times [s].
    x, dx : ndarray (n,)
        The response (e.g. φ [rad]) and its rate (e.g. φ̇ [rad/s]); any coordinate will do.
    stick_fraction : float
        Fraction of the window spent in stick [-] (0 for a slip-only or constructed signal).
    t_from : float, optional
        Start of the window [s]; default the first sample.
    others : ndarray (n, m), optional
        Other responses (e.g. the other free coordinates) that must decay too before a
        slip-only response counts as converging to the equilibrium: an unstable mode may grow
        in them while x still decays.
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    dx = np.asarray(dx, dtype=float)
    others = None if others is None else np.asarray(others, dtype=float).reshape(t.size, -1)
    if t_from is not None:
        sel = t >= t_from
        t, x, dx = t[sel], x[sel], dx[sel]
        others = None if others is None else others[sel]
    if t.size < 8:
        raise ValueError("classification needs at least 8 samples in the window; choose an earlier t_from")
    t0, t1 = float(t[0]), float(t[-1])
    per = detect_period(t, x, dx)
    amp, pk = per.amplitude, per.peaks
    rate = (len(pk) - 1) / (pk.time[-1] - pk.time[0]) if len(pk) >= 2 and pk.time[-1] > pk.time[0] else math.nan
    base = dict(stick_fraction=float(stick_fraction), amplitude=amp, peaks=pk, t_from=t0, t_to=t1,
                peak_rate_hz=float(rate))
    evidence = per.evidence.to_dict()
    if amp < REST_AMPLITUDE:  # at rest: no rate of peaks either
        return Classification("equilibrium", 0, math.nan, math.nan, math.nan, settled=True, signal="at-rest",
                              evidence=evidence, **{**base, "peak_rate_hz": math.nan})
    fft_f = spectral_peak(t, x)
    if per.periodic:
        return Classification("periodic", per.multiplicity, per.period_s, 1.0 / per.period_s, fft_f, settled=True,
                              signal="periodic", evidence=evidence, **base)
    quarters = [_quarters(t, x, t0, t1)] + ([] if others is None else [_quarters(t, y, t0, t1) for y in others.T])
    evidence["amplitude_ratio"] = float(quarters[0][-1] / quarters[0][0]) if quarters[0][0] > 0 else math.nan
    if stick_fraction == 0.0 and _peaks_per_quarter(pk.time, t0, t1) >= DECAY_MIN_PEAKS \
            and all(_decaying(q) for q in quarters):
        return Classification("equilibrium", 0, math.nan, math.nan, fft_f, settled=False, signal="decaying",
                              evidence=evidence, **base)
    mid = 0.5 * (t0 + t1)
    evidence["range_change"] = range_change(pk.value[pk.time < mid], pk.value[pk.time >= mid], amp)
    k = max(per.evidence.multiplicity, 1)
    evidence["return_decay"] = decay_ratio(pk.value[k:] - pk.value[:-k])
    best = per.evidence
    evidence["peaks"] = len(pk)
    stationary = (best.spread >= STATIONARY_MIN_SPREAD and evidence["return_decay"] <= DECAY_FACTOR
                  and not best.drift > best.spread and len(pk) >= STATIONARY_MIN_PEAKS)
    return Classification("unsettled", 0, math.nan, math.nan, fft_f, settled=False,
                          signal="stationary" if stationary else "drifting", evidence=evidence, **base)


def classify(traj, t_from: float | None = None, dof: str | None = None) -> Classification:
    """Classify the steady state of a :class:`~stickslip.Trajectory` over t ≥ ``t_from`` [s]
    from the signal of one DOF (the other free DOFs enter the decay test).

    The stick fraction comes from the exact transition instants. ``t_from`` defaults to the
    trajectory's ``steady_from`` (the last half of the run unless set). This is the signal's
    verdict; :func:`stickslip.attractors.attractor` adds the dynamical confirmations.
    ``dof`` defaults to the model's observed coordinate (the plates' φ).

    Parameters
    ----------
    traj : Trajectory
        A run of any model.
    t_from : float, optional
        Start of the window judged [s]; default ``traj.steady_from``.
    dof : str, optional
        The coordinate whose signal is classified (a name of ``traj.system.dofs``); default the
        model's observed coordinate.

    Returns
    -------
    Classification
    """
    system = traj.system
    j = dof_index(traj, dof)
    n = system.n
    t_from = traj.steady_from if t_from is None else float(t_from)
    sel = traj.t >= t_from
    ts = traj.t[sel]
    if ts.size < 8:
        raise ValueError(f"t_from = {t_from} s leaves fewer than 8 samples; choose an earlier time")
    tr = traj.transitions
    stick, _ = stick_time(float(ts[0]), float(ts[-1]), sample_flags(traj.mode[sel][0]), tr.time, tr.kind, tr.contact,
                          system.n_contacts)
    frac = stick / float(ts[-1] - ts[0])
    free = [int(i) for i in np.flatnonzero(system.free) if i != j]
    return classify_response(ts, traj.states[sel, j], traj.states[sel, n + j], stick_fraction=frac,
                             others=traj.states[sel][:, free] if free else None)


def dof_index(traj, dof: str | None = None) -> int:
    """Index in q of the coordinate ``dof`` of the trajectory's model (default its observed one)."""
    system = traj.system
    if dof is None:
        return system.observed_index
    if dof not in system.dofs:
        raise ValueError(f"unknown coordinate {dof!r} of model {system.name!r}; choose one of {', '.join(system.dofs)}")
    return system.dofs.index(dof)
