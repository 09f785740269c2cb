"""Period detection on one Poincaré section, shared by :func:`~stickslip.analysis.classify.classify`
and the steady-state summary (:func:`~stickslip.analysis.steady.summarize`, ``Trajectory.steady``).

Section: the peaks of the response, Σ = {ẋ = 0, ẍ < 0}, located as events on the cubic Hermite
interpolant of the samples (x, ẋ) (:func:`~stickslip.analysis.peaks.find_peaks`). The crossings
give the sequence of peak values p_i at times τ_i. The response is periodic with multiplicity k
(section crossings, i.e. peaks, per period) for the smallest k ≤ :data:`MAX_MULTIPLICITY` with

    |p_{i+k} − p_i| ≤ PEAK_RTOL · A    and    |(τ_{i+k} − τ_i) − T| ≤ PEAK_RTOL · T    for all i,

A the peak-to-peak amplitude of x in the window and T the mean of τ_{i+k} − τ_i (the period).
At least :data:`MIN_REPEATS` periods must fit in the window. Below
:data:`~stickslip.analysis.steady.REST_AMPLITUDE` the response is at rest and not periodic.

Both consumers call :func:`detect_period`, so they cannot disagree on whether a window is
periodic, on its multiplicity or on its period.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .peaks import Peaks, find_peaks
from .steady import REST_AMPLITUDE

__all__ = ["PEAK_RTOL", "MAX_MULTIPLICITY", "MIN_REPEATS", "REST_AMPLITUDE", "Periodicity", "return_map_period",
           "detect_period"]

#: Tolerance of the return map relative to the peak-to-peak amplitude A (values) and to the
#: period T (times). 1e-3 · A is the resolution at which a bifurcation diagram (Figs. 12–14) can
#: show distinct peak values; the lightly damped translation modes (decay time 2 m_d / c_dx =
#: 200 s) leave drifts of that order after 100–200 s, so a tighter value reports settled periodic
#: orbits as non-periodic within the paper's run lengths. The timing condition keeps slowly
#: modulated responses (whose peak values may repeat by chance) from passing as periodic.
PEAK_RTOL = 1e-3

#: Largest number of peaks per period searched for.
MAX_MULTIPLICITY = 16

#: Periods that must repeat inside the window before a response counts as periodic.
MIN_REPEATS = 3


@dataclasses.dataclass(frozen=True)
class Periodicity:
    """Result of :func:`detect_period` over one window.

    Attributes
    ----------
    periodic : bool
        Whether the peak sequence repeats (module docstring).
    multiplicity : int
        Peaks (section crossings) per period; 0 when not periodic.
    period_s : float
        Period T [s]; NaN when not periodic.
    amplitude : float
        Peak-to-peak amplitude A of the response in the window [unit of x].
    peaks : Peaks
        The section crossings (event-located peaks).
    """

    periodic: bool
    multiplicity: int
    period_s: float
    amplitude: float
    peaks: Peaks

    @property
    def frequency_hz(self) -> float:
        """1 / period [Hz]; NaN when not periodic."""
        return 1.0 / self.period_s if self.periodic else math.nan


def return_map_period(peaks: Peaks, amplitude: float) -> tuple[int, float]:
    """(multiplicity, period [s]) of a peak sequence by the return-map rule, or (0, NaN).

    Parameters
    ----------
    peaks : Peaks
        Section crossings in time order.
    amplitude : float
        Peak-to-peak amplitude A of the response (scale of the value tolerance).
    """
    p, tau = peaks.value, peaks.time
    for k in range(1, MAX_MULTIPLICITY + 1):
        if p.size < MIN_REPEATS * k + 1:
            break
        dp = np.abs(p[k:] - p[:-k])
        dtau = tau[k:] - tau[:-k]
        period = float(np.mean(dtau))
        if np.max(dp) <= PEAK_RTOL * amplitude and np.max(np.abs(dtau - period)) <= PEAK_RTOL * period:
            return k, period
    return 0, math.nan


def detect_period(t, x, dx) -> Periodicity:
    """Whether a sampled response repeats on the peak section, with its multiplicity and period.

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
        return Periodicity(False, 0, math.nan, amp, pk)
    k, period = return_map_period(pk, amp)
    return Periodicity(bool(k), k, period, amp, pk)
