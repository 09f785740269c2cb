"""Steady-state summary of a trajectory: fundamental frequency, stick fraction, extrema."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

__all__ = ["SteadyState", "fundamental_frequency", "stick_time", "summarize", "spectrum"]

#: Peak-to-peak φ below which the response counts as at rest (no oscillation) [rad];
#: far below any stick-slip amplitude (~1e-2 rad in the paper) and above integration noise.
REST_AMPLITUDE = 1e-7



@dataclasses.dataclass(frozen=True)
class SteadyState:
    """Summary of the steady part of a run (t ≥ ``t_from``).

    Attributes
    ----------
    t_from, t_to : float
        Window analysed [s].
    fundamental_frequency_hz : float
        1 / (smallest period) of φ [Hz] when periodic and settled (return map on the peak
        section, :func:`stickslip.analysis.period.detect_period`); otherwise the highest peak
        of the spectrum (dominant frequency); NaN at rest. ``Trajectory.summary()`` keeps the
        two apart and confirms periods of more than one peak.
    periodic : bool
        Whether φ repeats on the section and has settled (the signal rule of
        :mod:`stickslip.analysis.period`); the same decision as
        :func:`stickslip.analysis.classify.classify`.
    period_multiplicity : int
        Section crossings (peaks of φ) per period (0 when not periodic).
    stick_fraction : float
        Fraction of the window spent in stick [-].
    n_transitions : int
        Stick↔slip transitions inside the window.
    phi_min, phi_max : float
        Extremes of φ in the window [rad] (from the uniform samples).
    """

    t_from: float
    t_to: float
    fundamental_frequency_hz: float
    periodic: bool
    period_multiplicity: int
    stick_fraction: float
    n_transitions: int
    phi_min: float
    phi_max: float

    def to_dict(self) -> dict:
        """Plain dict (NaN kept as float NaN)."""
        return dataclasses.asdict(self)


def _hermite_crossings(t, x, dx, level):
    """Times where x crosses ``level`` upwards, on the cubic Hermite interpolant of (x, dx/dt).

    Returns (times, index of the sample interval).
    """
    i = np.flatnonzero((x[:-1] < level) & (x[1:] >= level))
    if i.size == 0:
        return np.empty(0), i
    h = t[i + 1] - t[i]
    x0, x1 = x[i] - level, x[i + 1] - level
    m0, m1 = dx[i] * h, dx[i + 1] * h
    lo = np.zeros(i.size)
    hi = np.ones(i.size)
    for _ in range(52):  # bisection to double precision on the unit interval
        s = 0.5 * (lo + hi)
        h00 = 2 * s**3 - 3 * s**2 + 1
        h10 = s**3 - 2 * s**2 + s
        h01 = -2 * s**3 + 3 * s**2
        h11 = s**3 - s**2
        val = h00 * x0 + h10 * m0 + h01 * x1 + h11 * m1
        below = val < 0
        lo = np.where(below, s, lo)
        hi = np.where(below, hi, s)
    return t[i] + 0.5 * (lo + hi) * h, i


def spectrum(t, x, *, detrend=True):
    """One-sided amplitude spectrum of a uniformly sampled signal (Hann window).

    Returns (frequencies [Hz], amplitudes [unit of x]), amplitudes corrected for the window's
    coherent gain so a sinusoid of amplitude a shows a peak ≈ a.
    """
    x = np.asarray(x, dtype=float)
    if detrend:
        x = x - x.mean()
    n = x.size
    if n < 4:
        return np.zeros(0), np.zeros(0)
    dt = (t[-1] - t[0]) / (n - 1)
    window = np.hanning(n)
    amp = 2.0 * np.abs(np.fft.rfft(x * window)) / window.sum()
    return np.fft.rfftfreq(n, dt), amp


def _spectral_peak(t, x):
    """Frequency of the highest spectral peak, refined by parabolic interpolation [Hz]."""
    f, a = spectrum(t, x)
    if a.size < 3:
        return math.nan
    k = int(np.argmax(a[1:])) + 1
    if 1 <= k < a.size - 1:
        y0, y1, y2 = np.log(a[k - 1 : k + 2] + 1e-300)
        denom = y0 - 2 * y1 + y2
        shift = 0.5 * (y0 - y2) / denom if denom != 0 else 0.0
        return float(f[k] + shift * (f[1] - f[0]))
    return float(f[k])


def fundamental_frequency(t, phi, dphi):
    """Fundamental frequency of φ(t) [Hz], whether it is periodic, and its multiplicity.

    Periodicity, multiplicity (peaks per period) and period come from
    :func:`stickslip.analysis.period.detect_period` (peak section, settled to
    :data:`~stickslip.analysis.period.SETTLE_RTOL`), the rule :func:`~stickslip.analysis.classify.classify`
    uses. Non-periodic responses get the highest peak of the Hann spectrum, refined by parabolic
    interpolation; at rest (peak-to-peak below :data:`REST_AMPLITUDE`) NaN.

    Returns
    -------
    (float, bool, int)
        Frequency [Hz], periodic, multiplicity.
    """
    from .period import detect_period  # period imports peaks, which imports this module

    t = np.asarray(t, dtype=float)
    phi = np.asarray(phi, dtype=float)
    dphi = np.asarray(dphi, dtype=float)
    per = detect_period(t, phi, dphi)
    if per.amplitude < REST_AMPLITUDE:
        return math.nan, False, 0
    if per.periodic:
        return 1.0 / per.period_s, True, per.multiplicity
    # not periodic: the dominant frequency. The mean rate of mid-level crossings is no
    # substitute: a waveform with two humps per cycle crosses the mid level twice (N = 120 N,
    # Ω = 0.5 rad/s: 1.59 Hz crossing rate against a 0.797 Hz spectral peak)
    return _spectral_peak(t, phi), False, 0


def stick_time(t_from, t_to, mode_at_start, transition_times, transition_kinds):
    """Total time spent in stick within [t_from, t_to] [s], from exact transition instants.

    ``mode_at_start`` is the mode (1 = stick) just after ``t_from``; kinds are +1 for
    slip → stick and −1 for stick → slip.
    """
    stick = bool(mode_at_start)
    start = t_from
    total = 0.0
    for tt, kind in zip(transition_times, transition_kinds):
        if tt <= t_from or tt > t_to:
            continue
        if stick and kind < 0:
            total += tt - start
            stick = False
        elif not stick and kind > 0:
            start = tt
            stick = True
    if stick:
        total += t_to - start
    return total


def summarize(t, states, mode, transition_times, transition_kinds, t_from, coordinate=4, rate=10):
    """Steady-state summary of samples with t ≥ ``t_from`` (see :class:`SteadyState`), following the
    state column ``coordinate`` (its rate in column ``rate``; default the plates' φ)."""
    t = np.asarray(t)
    sel = t >= t_from
    if sel.sum() < 2:
        raise ValueError(f"steady_from = {t_from} s leaves fewer than 2 samples; choose an earlier time")
    ts = t[sel]
    phi = states[sel, coordinate]
    dphi = states[sel, rate]
    t0, t1 = float(ts[0]), float(ts[-1])
    # mode just after t0: the sample's mode unless a transition sits exactly on t0
    mode0 = int(mode[sel][0])
    tt = np.asarray(transition_times)
    kinds = np.asarray(transition_kinds)
    window = (tt > t0) & (tt <= t1)
    freq, periodic, mult = fundamental_frequency(ts, phi, dphi)
    stick = stick_time(t0, t1, mode0, tt, kinds)
    return SteadyState(
        t_from=t0,
        t_to=t1,
        fundamental_frequency_hz=float(freq),
        periodic=bool(periodic),
        period_multiplicity=int(mult),
        stick_fraction=stick / (t1 - t0),
        n_transitions=int(window.sum()),
        phi_min=float(phi.min()),
        phi_max=float(phi.max()),
    )
