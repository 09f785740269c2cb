"""Signal primitives on uniform samples: crossings of the cubic Hermite interpolant, the spectrum
and its peak, stick time from exact transition instants, and the rest threshold."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["REST_AMPLITUDE", "hermite_crossings", "spectrum", "spectral_peak", "stick_time", "open_time", "phase_time",
           "STICK", "SLIP", "OPEN", "CLOSE"]

#: Peak-to-peak of a coordinate below which the response counts as at rest (no oscillation) [unit of
#: the coordinate: rad for the plates' φ];
#: far below any stick-slip amplitude (~1e-2 rad in the paper) and above integration noise.
REST_AMPLITUDE = 1e-7


def hermite_crossings(t, x, dx, level):
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


def spectral_peak(t, x):
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


#: Transition kinds as the integrators record them: slip → stick (+1), stick → slip (−1), a
#: unilateral contact opening (2) and closing (3).
STICK, SLIP, OPEN, CLOSE = 1, -1, 2, 3


def phase_time(t_from, t_to, flags_at_start, transition_times, transition_kinds, transition_contacts,
               n_contacts: int, *, enter: int, leave: int, bit_offset: int = 0):
    """Time spent in one phase of the contacts (stick, or open) within [t_from, t_to] [s], from
    exact transition instants: by any contact (the union of their intervals), and by each.

    Parameters
    ----------
    t_from, t_to : float
        The window [s].
    flags_at_start : int
        The sampled mode just after ``t_from``: bit ``bit_offset + c`` set when contact c is in the phase.
    transition_times, transition_kinds, transition_contacts : array-like (k,)
        Transition instants [s], kinds (:data:`STICK`, :data:`SLIP`, :data:`OPEN`, :data:`CLOSE`)
        and contacts.
    n_contacts : int
    enter, leave : int
        The kinds that start and end the phase.
    bit_offset : int
        Where the phase's bits start in the mode (0 for stick, ``n_contacts`` for open).

    Returns
    -------
    total : float
        Time with some contact in the phase [s].
    each : ndarray (n_contacts,)
        Each contact's time in the phase [s].
    """
    inside = [bool(int(flags_at_start) >> (bit_offset + c) & 1) for c in range(n_contacts)]
    since = [t_from] * n_contacts
    each = np.zeros(n_contacts)
    start = t_from
    total = 0.0
    for tt, kind, c in zip(transition_times, transition_kinds, transition_contacts):
        if tt <= t_from or tt > t_to or (kind != enter and kind != leave):
            continue
        c = int(c)
        was = any(inside)
        if inside[c] and kind == leave:
            each[c] += tt - since[c]
            inside[c] = False
        elif not inside[c] and kind == enter:
            since[c] = tt
            inside[c] = True
        if was and not any(inside):
            total += tt - start
        elif not was and any(inside):
            start = tt
    for c in range(n_contacts):
        if inside[c]:
            each[c] += t_to - since[c]
    if any(inside):
        total += t_to - start
    return total, each


def stick_time(t_from, t_to, mode_at_start, transition_times, transition_kinds, transition_contacts=None,
               n_contacts: int = 1):
    """Time spent in stick within [t_from, t_to] [s] (:func:`phase_time`): by any contact, and by each.

    Parameters
    ----------
    t_from, t_to : float
        The window [s].
    mode_at_start : int
        The mode just after ``t_from``: bit c set when contact c sticks (one contact: 1 in stick).
    transition_times, transition_kinds : array-like (k,)
        Transition instants [s] and kinds (+1 slip → stick, −1 stick → slip; others ignored).
    transition_contacts : array-like (k,), optional
        The contact of each transition (default all contact 0).
    n_contacts : int

    Returns
    -------
    float, or (float, ndarray (n_contacts,)) when ``transition_contacts`` is given
        Time with some contact stuck [s] (and each contact's own).
    """
    contacts = np.zeros(len(transition_times), dtype=np.int64) if transition_contacts is None else transition_contacts
    total, each = phase_time(t_from, t_to, mode_at_start, transition_times, transition_kinds, contacts, n_contacts,
                             enter=STICK, leave=SLIP)
    return total if transition_contacts is None else (total, each)


def open_time(t_from, t_to, mode_at_start, transition_times, transition_kinds, transition_contacts, n_contacts: int):
    """Time unilateral contacts spend open within [t_from, t_to] [s] (:func:`phase_time`; the
    mode's bit ``n_contacts + c`` is set while contact c is open): by any contact, and by each."""
    return phase_time(t_from, t_to, mode_at_start, transition_times, transition_kinds, transition_contacts,
                      n_contacts, enter=OPEN, leave=CLOSE, bit_offset=n_contacts)
