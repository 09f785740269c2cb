"""Periodic attractors by phase-independent features, and the matching that makes the same cycle
reached from different states one attractor.

A cycle's features are those that do not depend on where along it a run is: its period T, the
number k of maxima of the observed coordinate per period, the peak-to-peak amplitude A of that
coordinate and the k maxima themselves (section points on Σ = {ẋ = 0, ẍ < 0}) as a cyclic
sequence (rotated to start at the largest). Two cycles are the same when k agrees, T and A
agree to ``rtol`` and the maxima agree to ``rtol`` A under some cyclic shift.

A run has **reached** a known cycle when its last :data:`MATCH_PERIODS` periods of maxima match
the cycle's maxima (one shift for all of them) to ``rtol`` A, the intervals between maxima one
period apart match T to ``rtol`` T, and its amplitude over those periods (largest maximum minus
smallest minimum between them) matches A: its section crossings recur on the cycle's (as
Attractors.jl's recurrence test: a trajectory that keeps returning to an attractor's cells
belongs to it). Maxima and minima are located as events on the cubic Hermite interpolant of the
samples (:func:`stickslip.analysis.peaks.find_peaks`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..analysis.peaks import find_peaks

__all__ = ["Cycle", "Section", "MATCH_PERIODS", "MATCH_RTOL", "KMAX", "cycles_equal", "run_matches", "find_cycle",
           "section_of", "cycle_from_section", "period_matches"]

#: Largest number of maxima per period a cycle's features hold (the period rule searches up to 16).
KMAX = 16

#: Periods of section crossings that must recur on a known cycle before a run counts as on it.
MATCH_PERIODS = 3

#: Default tolerance of the matches, relative to the cycle's amplitude (values) and period (times).
#: On the plates' Region II grid (20 × 20 states, docs/basins.md) 1e-2 and 1e-3 gave the same
#: labels; 1e-3 let the runs onto the cycle go 30 % longer (mean 299 s instead of 226 s) and keeps
#: a run that passes near a cycle without converging from being taken for it.
MATCH_RTOL = 1e-3


@dataclasses.dataclass(frozen=True)
class Cycle:
    """The phase-independent features of a periodic attractor.

    Attributes
    ----------
    multiplicity : int
        k, maxima of the observed coordinate per period.
    period : float
        T [s].
    amplitude : float
        Peak-to-peak amplitude A of the observed coordinate [its unit].
    peaks : ndarray (k,)
        The k maxima in time order, starting at the largest [unit of the coordinate].
    stick_fraction : float
        Fraction of a period in stick (of any contact) [-].
    state : ndarray (2n,)
        A state on the cycle: the sample nearest to its largest maximum.
    open_fraction : float or None
        Fraction of a period with some unilateral contact open [-]; None for a model whose contacts
        are all pressed.
    """

    multiplicity: int
    period: float
    amplitude: float
    peaks: np.ndarray
    stick_fraction: float
    state: np.ndarray
    open_fraction: float | None = None

    @property
    def frequency(self) -> float:
        """1 / T [Hz]."""
        return 1.0 / self.period


def _shift_distance(a: np.ndarray, ref: np.ndarray) -> float:
    """Smallest max |a_i − ref_{(i+s) mod k}| over the cyclic shifts s (len(a) a multiple of k allowed)."""
    k = ref.size
    idx = np.arange(a.size)
    return min(float(np.max(np.abs(a - ref[(idx + s) % k]))) for s in range(k))


def cycles_equal(a: Cycle, b: Cycle, rtol: float) -> bool:
    """Whether two cycles' features agree (module docstring)."""
    if a.multiplicity != b.multiplicity:
        return False
    scale = max(a.amplitude, b.amplitude)
    return (abs(a.period - b.period) <= rtol * max(a.period, b.period)
            and abs(a.amplitude - b.amplitude) <= rtol * scale
            and _shift_distance(a.peaks, b.peaks) <= rtol * scale)


@dataclasses.dataclass(frozen=True)
class Section:
    """A run's crossings of the section: its maxima, and the smallest minimum between each pair.

    Attributes
    ----------
    times, maxima : ndarray (m,)
        Instants [s] and values of the maxima of the observed coordinate, in time order.
    minima : ndarray (m,)
        ``minima[i]``: the smallest value of the coordinate between maxima i − 1 and i (NaN for i = 0).
    """

    times: np.ndarray
    maxima: np.ndarray
    minima: np.ndarray

    def __len__(self) -> int:
        return int(self.times.size)

    def amplitude(self, m: int) -> float:
        """Largest of the last ``m`` maxima minus the smallest minimum between them."""
        if m < 2 or self.times.size < m:
            return math.nan
        return float(np.max(self.maxima[-m:]) - np.min(self.minima[-m + 1:]))

    def last(self, m: int) -> "Section":
        """The last ``m`` crossings (the first minimum kept: it precedes the first kept maximum)."""
        return Section(self.times[-m:], self.maxima[-m:], self.minima[-m:])


def section_of(t: np.ndarray, x: np.ndarray, dx: np.ndarray) -> Section:
    """The :class:`Section` of a sampled coordinate x(t) with rate ẋ(t)."""
    top = find_peaks(t, x, dx)
    low = find_peaks(t, -x, -dx)
    m = len(top)
    minima = np.full(m, np.nan)
    if m >= 2:
        # located minima in (τ_{i−1}, τ_i]; where none was located (a flat stretch), the samples' minimum
        lo = np.searchsorted(low.time, top.time[:-1], side="right")
        hi = np.searchsorted(low.time, top.time[1:], side="right")
        ilo = np.searchsorted(t, top.time[:-1], side="right")
        ihi = np.searchsorted(t, top.time[1:], side="right")
        for i in range(m - 1):
            values = -low.value[lo[i]:hi[i]] if hi[i] > lo[i] else x[ilo[i]:max(ihi[i], ilo[i] + 1)]
            minima[i + 1] = float(np.min(values))
    return Section(top.time, top.value, minima)


def run_matches(cycle: Cycle, section: Section, rtol: float) -> bool:
    """Whether a run's last section crossings recur on ``cycle`` (module docstring)."""
    k = cycle.multiplicity
    need = MATCH_PERIODS * k + 1
    if len(section) < need:
        return False
    A, T = cycle.amplitude, cycle.period
    if not abs(section.amplitude(need) - A) <= rtol * A:
        return False
    tau = section.times[-need:]
    if np.max(np.abs((tau[k:] - tau[:-k]) - T)) > rtol * T:
        return False
    return _shift_distance(section.maxima[-need:], cycle.peaks) <= rtol * A


def period_matches(cycle: Cycle, period: float, maxima: np.ndarray, minima: np.ndarray, rtol: float) -> bool:
    """Whether one period of a run that provably repeats matches ``cycle``: the run's state recurs
    after ``period`` [s], and the maxima and the located minima of the coordinate inside that
    period (``maxima`` in time order) give the cycle's k maxima (one cyclic shift) to ``rtol`` A,
    its amplitude to ``rtol`` A and its period to ``rtol`` T, the tests of :func:`run_matches` on
    the one period that repeats."""
    k = cycle.multiplicity
    if maxima.size != k or minima.size == 0:
        return False
    A, T = cycle.amplitude, cycle.period
    if not abs((float(np.max(maxima)) - float(np.min(minima))) - A) <= rtol * A:
        return False
    if not abs(period - T) <= rtol * T:
        return False
    return _shift_distance(maxima, cycle.peaks) <= rtol * A


def find_cycle(cycles, candidate: Cycle, rtol: float) -> int:
    """Index of the first of ``cycles`` equal to ``candidate`` (:func:`cycles_equal`), or −1."""
    for i, c in enumerate(cycles):
        if cycles_equal(c, candidate, rtol):
            return i
    return -1


def cycle_from_section(section: Section, t: np.ndarray, states: np.ndarray, multiplicity: int, period: float,
                       stick_fraction: float, open_fraction: float | None = None) -> Cycle:
    """The features of a settled periodic window.

    Parameters
    ----------
    section : Section
        The window's crossings (at least k + 1 maxima).
    t : ndarray (m,)
        Sample times of the window [s].
    states : ndarray (m, 2n)
        States at the samples.
    multiplicity, period : int, float
        k and T of the settled period (:func:`stickslip.analysis.period.detect_period`).
    stick_fraction : float
        Fraction of the window in stick [-].
    open_fraction : float or None
        Fraction of the window with some contact open [-] (None: all contacts pressed).
    """
    k = int(multiplicity)
    top = int(np.argmax(section.maxima[-k:]))
    peaks = np.roll(section.maxima[-k:], -top)
    when = section.times[-k:][top]
    i = int(np.argmin(np.abs(t - when)))
    return Cycle(k, float(period), section.amplitude(k + 1), peaks.astype(float), float(stick_fraction),
                 states[i].copy(), None if open_fraction is None else float(open_fraction))
