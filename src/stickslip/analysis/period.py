"""Period detection on one Poincaré section with the evidence that the response has settled.

Section: the peaks of the response, Σ = {ẋ = 0, ẍ < 0}, located as events on the cubic Hermite
interpolant of the samples (x, ẋ) (:func:`~stickslip.analysis.peaks.find_peaks`). The crossings
give the sequence of peak values p_i at times τ_i over the window.

A matching return map is not enough: a slowly converging transient repeats to any fixed
tolerance after a while, and a transient whose slowest Floquet multipliers lie near −1 repeats
better every second crossing than every crossing (it passes for period 2). So for each
candidate multiplicity k (crossings per period) these are measured, relative to the
peak-to-peak amplitude A of x in the window (values) and to the period T (times):

* **spread**: max_i |p_{i+k} − p_i| and max_i |(τ_{i+k} − τ_i) − T|, T the mean of τ_{i+k} − τ_i;
* **drift**: the trend across the window: for each of the k branches (p_j, p_{j+k}, ...), the
  mean of its last third minus the mean of its first third (and the same for τ_{i+k} − τ_i);
  a settled orbit drifts by no more than its noise, a converging one by many return steps;
* **separation** (k ≥ 2): the smallest spread of the multiplicities below k.

The response is **periodic and settled** with multiplicity k for the smallest k ≤
:data:`MAX_MULTIPLICITY` with at least :data:`MIN_PERIODS` periods in the window, spread ≤
:data:`SETTLE_RTOL`, drift ≤ spread (or ≤ :data:`DRIFT_FLOOR`) and separation ≥
:data:`SEPARATION_FACTOR` × spread: a period of k ≥ 2 crossings needs distinct branches. Below
:data:`~stickslip.analysis.signal.REST_AMPLITUDE` the response is at rest and not periodic.

This is the rule of the signal alone; :mod:`stickslip.attractors` adds what the dynamics
must confirm (a period-k claim with k ≥ 2 by shooting, chaos by a Lyapunov exponent). Every
consumer (classification, ``Trajectory.steady``, sweeps) calls :func:`detect_period`.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .peaks import Peaks, find_peaks
from .signal import REST_AMPLITUDE

__all__ = ["SETTLE_RTOL", "DRIFT_FLOOR", "DECAY_FACTOR", "SEPARATION_FACTOR", "MAX_MULTIPLICITY", "MIN_PERIODS",
           "REST_AMPLITUDE", "ReturnMap", "Periodicity", "return_map", "evidence_at", "decay_ratio", "detect_period"]

#: Spread allowed for a settled period, relative to the amplitude A (values) and to
#: the period T (times). The integration and peak-location noise of a settled orbit is
#: 1e-9 … 1e-8 A in values and 2e-7 T in times at rtol = 1e-8 and 200 samples per second
#: (Model 1, N = 50 N, Ω = 0.5 and 5 rad/s, measured in 100 s windows of a 1500 s run; 4e-7 T
#: at N = 70 N); 1e-5 leaves a factor ≥ 25 over it and is 100 times finer than a bifurcation
#: diagram resolves.
SETTLE_RTOL = 1e-5

#: Drift across the window accepted whatever the spread (relative, like SETTLE_RTOL): above the
#: noise of the means of a third of the returns (timing noise 2e-7 T at 200 samples per second:
#: on a settled orbit the drift is ~1e-7, as large as the spread) and 10 times below the
#: settle tolerance.
DRIFT_FLOOR = 0.1 * SETTLE_RTOL

#: Ratio of the median return difference of the window's first third to its last third above
#: which the differences count as decaying (a converging transient, not a stationary response:
#: :mod:`~stickslip.analysis.classify`).
DECAY_FACTOR = 3.0

#: A period of k ≥ 2 crossings needs its branches distinct: every multiplicity below k must
#: miss by at least this factor times the spread at k. A transient whose multipliers rotate by
#: nearly 2π/k per crossing matches at k a few times better than at 1; a true period-k orbit
#: separates its branches by orders of magnitude more than its noise.
SEPARATION_FACTOR = 100.0

#: What was seen when nothing settled: the smallest multiplicity whose spread comes within this
#: factor of the best one (a transient matches at many k nearly equally well).
BEST_FACTOR = 10.0

#: Largest number of peaks per period searched for.
MAX_MULTIPLICITY = 16

#: Periods that must fit in the window before a period is claimed (three per third, so that
#: the drift compares means of ≥ 3 returns).
MIN_PERIODS = 9


@dataclasses.dataclass(frozen=True)
class ReturnMap:
    """Evidence of the return map at one multiplicity k (all relative: values to A, times to T).

    Attributes
    ----------
    multiplicity : int
        k, crossings per candidate period (0 when no k could be tested).
    period_s : float
        Mean of τ_{i+k} − τ_i [s].
    spread : float
        max of the value and time spreads [-].
    drift : float
        max of the branch-value and period drifts across the window [-].
    separation : float
        Smallest spread of the multiplicities below k [-] (inf for k = 1): how distinct the
        k branches are.
    settled : bool
        Whether the k-periodic match holds and the window shows no drift (module docstring).
    """

    multiplicity: int
    period_s: float
    spread: float
    drift: float
    separation: float
    settled: bool

    def to_dict(self) -> dict:
        """Plain dict."""
        return dataclasses.asdict(self)


@dataclasses.dataclass(frozen=True)
class Periodicity:
    """Result of :func:`detect_period` over one window.

    Attributes
    ----------
    periodic : bool
        Whether the peak sequence repeats and has settled (module docstring).
    multiplicity : int
        Peaks (section crossings) per period; 0 when not periodic.
    period_s : float
        Period T [s]; NaN when not periodic.
    amplitude : float
        Peak-to-peak amplitude A of the response in the window [unit of x].
    peaks : Peaks
        The section crossings (event-located peaks).
    evidence : ReturnMap
        The settled multiplicity's measurements, or, when none settled, those of the
        simplest multiplicity that matches nearly best (what was seen; :func:`return_map`).
    """

    periodic: bool
    multiplicity: int
    period_s: float
    amplitude: float
    peaks: Peaks
    evidence: ReturnMap

    @property
    def frequency_hz(self) -> float:
        """1 / period [Hz]; NaN when not periodic."""
        return 1.0 / self.period_s if self.periodic else math.nan


def _thirds(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    m = max(x.size // 3, 1)
    return x[:m], x[-m:]


def decay_ratio(d: np.ndarray) -> float:
    """Median of the first third of ``d`` over that of its last third (1 when too short)."""
    if d.size < 3:
        return 1.0
    first, last = _thirds(np.abs(d))
    lo = float(np.median(last))
    return float(np.median(first)) / lo if lo > 0.0 else math.inf


def evidence_at(p: np.ndarray, tau: np.ndarray, k: int, amplitude: float, separation: float = math.inf) -> ReturnMap:
    """The measurements of the return map at multiplicity ``k`` (module docstring).

    Parameters
    ----------
    p, tau : ndarray (n,)
        Crossing values [unit of x] and times [s], n > k.
    k : int
        Multiplicity.
    amplitude : float
        Peak-to-peak amplitude A of the response.
    separation : float
        Smallest spread of the multiplicities below k [-] (inf for k = 1).
    """
    dp = p[k:] - p[:-k]
    dtau = tau[k:] - tau[:-k]
    period = float(np.mean(dtau))
    spread = max(float(np.max(np.abs(dp))) / amplitude, float(np.max(np.abs(dtau - period))) / period)
    drift = 0.0
    for j in range(k):
        first, last = _thirds(p[j::k])
        drift = max(drift, abs(float(np.mean(last) - np.mean(first))) / amplitude)
    first, last = _thirds(dtau)
    drift = max(drift, abs(float(np.mean(last) - np.mean(first))) / period)
    settled = (spread <= SETTLE_RTOL and (drift <= spread or drift <= DRIFT_FLOOR)
               and separation >= SEPARATION_FACTOR * max(spread, DRIFT_FLOOR))
    return ReturnMap(k, period, spread, drift, separation, bool(settled))


def return_map(peaks: Peaks, amplitude: float) -> tuple[ReturnMap | None, ReturnMap]:
    """(settled evidence or None, best evidence seen) of a peak sequence.

    Parameters
    ----------
    peaks : Peaks
        Section crossings in time order.
    amplitude : float
        Peak-to-peak amplitude A of the response (scale of the value tolerance).

    Returns
    -------
    (ReturnMap or None, ReturnMap)
        The smallest settled multiplicity's evidence (None if none settled), and what was seen:
        the evidence of the smallest k whose spread is within :data:`BEST_FACTOR` of the
        smallest spread of every k tested (``multiplicity`` 0 if none could be tested).
    """
    p, tau = peaks.value, peaks.time
    seen = []
    separation = math.inf
    for k in range(1, MAX_MULTIPLICITY + 1):
        if p.size < MIN_PERIODS * k + 1:
            break
        ev = evidence_at(p, tau, k, amplitude, separation)
        if ev.settled:
            return ev, ev
        seen.append(ev)
        separation = min(separation, ev.spread)
    if not seen:
        return None, ReturnMap(0, math.nan, math.inf, math.inf, math.inf, False)
    return None, next(ev for ev in seen if ev.spread <= BEST_FACTOR * separation)


def detect_period(t, x, dx) -> Periodicity:
    """Whether a sampled response repeats on the peak section and has settled.

    Parameters
    ----------
    t : ndarray (n,)
        Sample times of the window [s], increasing.
    x, dx : ndarray (n,)
        The response (e.g. φ [rad]) and its rate (φ̇ [rad/s]) at the samples.

    Returns
    -------
    Periodicity
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    dx = np.asarray(dx, dtype=float)
    amp = float(np.max(x) - np.min(x)) if x.size else 0.0
    pk = find_peaks(t, x, dx)
    if amp < REST_AMPLITUDE:
        return Periodicity(False, 0, math.nan, amp, pk, ReturnMap(0, math.nan, 0.0, 0.0, math.inf, False))
    settled, best = return_map(pk, amp)
    if settled is None:
        return Periodicity(False, 0, math.nan, amp, pk, best)
    return Periodicity(True, settled.multiplicity, settled.period_s, amp, pk, settled)
