"""Steady-state summary of a trajectory: fundamental frequency, stick fraction, extrema."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .period import detect_period
from .signal import REST_AMPLITUDE, spectral_peak, stick_time

__all__ = ["SteadyState", "fundamental_frequency", "summarize"]


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
    return spectral_peak(t, phi), False, 0


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
