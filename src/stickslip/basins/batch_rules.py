"""The early-stopping classifier's tests (:mod:`.early`) compiled, on a run's record arrays.

The same formulas as the Python tests, in the same order of operations, so that the section
crossings (:func:`section`) are the ones :func:`.cycles.section_of` locates. Where a test's
outcome hangs on the last bits of a number that the compiled code may round differently (a
matrix product summed in another order, a mean summed pairwise by numpy), the test says
:data:`DOUBT` instead of deciding: the state is then classified by the Python classifier, so
that every state gets the label the Python tests give it. The period rule is compiled only as a
filter: where it might hold (a looser test, :func:`maybe_settled`), the state goes to the Python
classifier, which runs it with the window's verdict.
"""

from __future__ import annotations

import math

import numpy as np

from ..analysis.peaks import ROOT_SLACK
from ..analysis.period import DRIFT_FLOOR, MAX_MULTIPLICITY, MIN_PERIODS, SEPARATION_FACTOR, SETTLE_RTOL
from ..model.jit import loop
from .cycles import MATCH_PERIODS

__all__ = ["DOUBT", "NEAR", "LOOSE", "section", "matched_cycle", "linear_test", "maybe_settled", "recurs",
           "period_match", "minima_between"]

#: What a test gives where its outcome is not certain (compare :data:`NEAR`).
DOUBT = -1

#: Relative distance from a test's threshold within which the compiled test says :data:`DOUBT`:
#: far above the round-off of its quantities (~1e-13 of the threshold), so that a state decided
#: here is decided as the Python test decides it.
NEAR = 1e-9

#: Absolute slack of the compiled period-rule filter on the relative spread, drift and
#: separation (numpy's pairwise sums differ from the sums here by ~1e-15 of the values).
LOOSE = 1e-12


@loop
def _peaks(t, x, dx, sign, lo, hi, times, values):
    """:func:`stickslip.analysis.peaks.find_peaks` of ``sign`` · x on the samples lo ≤ i < hi,
    written into ``times`` and ``values``; returns their number."""
    count = 0
    for i in range(lo, hi - 1):
        d0 = sign * dx[i]
        d1 = sign * dx[i + 1]
        if not (d0 > 0 and d1 <= 0):
            continue
        h = t[i + 1] - t[i]
        x0 = sign * x[i]
        x1 = sign * x[i + 1]
        m0 = d0 * h
        m1 = d1 * h
        a = 6 * x0 + 3 * m0 - 6 * x1 + 3 * m1
        b = -6 * x0 - 4 * m0 + 6 * x1 - 2 * m1
        c = m0
        disc = b * b - 4 * a * c
        if not disc >= 0:
            continue
        sq = math.sqrt(disc)
        qq = -0.5 * (b + math.copysign(sq, b))
        r1 = qq / a if a != 0 else math.nan
        r2 = c / qq if qq != 0 else math.nan
        s = math.nan
        for r in (r1, r2):
            slope = 2 * a * r + b
            if (math.isfinite(r) and r >= -ROOT_SLACK and r <= 1.0 + ROOT_SLACK and slope <= 0
                    and math.isnan(s)):
                s = min(max(r, 0.0), 1.0)
        if math.isnan(s):
            continue
        when = t[i] + s * h
        u = (when - t[i]) / h
        u2 = u * u
        u3 = math.pow(u, 3.0)
        h00 = 2 * u3 - 3 * u2 + 1
        h10 = u3 - 2 * u2 + u
        h01 = -2 * u3 + 3 * u2
        h11 = u3 - u2
        times[count] = when
        values[count] = h00 * x0 + h10 * h * d0 + h01 * x1 + h11 * h * d1
        count += 1
    return count


@loop
def section(t, x, dx, lo, hi, work, top_t, top_v, minima):
    """:func:`.cycles.section_of` of the samples lo ≤ i < hi: the maxima's times and values into
    ``top_t``, ``top_v`` and the minima between them into ``minima``; returns their number.
    ``work``: (2, hi − lo) scratch for the located minima."""
    m = _peaks(t, x, dx, 1.0, lo, hi, top_t, top_v)
    low_t = work[0]
    low_v = work[1]
    n_low = _peaks(t, x, dx, -1.0, lo, hi, low_t, low_v)
    for i in range(m):
        minima[i] = math.nan
    for i in range(m - 1):
        a = np.searchsorted(low_t[:n_low], top_t[i], side="right")
        b = np.searchsorted(low_t[:n_low], top_t[i + 1], side="right")
        smallest = math.inf
        if b > a:
            for q in range(a, b):
                smallest = min(smallest, -low_v[q])
        else:
            ilo = lo + np.searchsorted(t[lo:hi], top_t[i], side="right")
            ihi = lo + np.searchsorted(t[lo:hi], top_t[i + 1], side="right")
            for q in range(ilo, max(ihi, ilo + 1)):
                smallest = min(smallest, x[q])
        minima[i + 1] = smallest
    return m


@loop
def _at_most(value, limit):
    """value ≤ limit: 1, 0, or :data:`DOUBT` within :data:`NEAR` · |limit| of it (NaN: 0)."""
    if not value <= limit and not value > limit:
        return 0
    if abs(value - limit) <= NEAR * abs(limit):
        return DOUBT
    return 1 if value <= limit else 0


@loop
def _matches(k, period, amplitude, peaks, top_t, top_v, minima, m, rtol):
    """:func:`.cycles.run_matches` of the cycle (k, T, A, its k maxima) and the section's m
    crossings: 1, 0 or :data:`DOUBT`."""
    need = MATCH_PERIODS * k + 1
    if m < need:
        return 0
    highest = -math.inf
    for i in range(m - need, m):
        highest = max(highest, top_v[i])
    lowest = math.inf
    for i in range(m - need + 1, m):
        v = minima[i]
        lowest = math.nan if math.isnan(v) or math.isnan(lowest) else min(lowest, v)
    verdict = _at_most(abs((highest - lowest) - amplitude), rtol * amplitude)
    if verdict != 1:
        return verdict
    worst = 0.0
    for i in range(m - need + k, m):
        worst = max(worst, abs((top_t[i] - top_t[i - k]) - period))
    spread = _at_most(worst, rtol * period)
    if spread != 1:
        return spread
    best = math.inf
    for s in range(k):
        d = 0.0
        for i in range(need):
            d = max(d, abs(top_v[m - need + i] - peaks[(i + s) % k]))
        best = min(best, d)
    return _at_most(best, rtol * amplitude)


@loop
def matched_cycle(cycles, top_t, top_v, minima, m, rtol):
    """Index of the first cycle whose crossings the section's last ones recur on (−2: none;
    :data:`DOUBT`: a test too near its threshold before one matched)."""
    k_of, periods, amplitudes, peaks = cycles[0], cycles[1], cycles[2], cycles[3]
    for c in range(k_of.size):
        verdict = _matches(k_of[c], periods[c], amplitudes[c], peaks[c], top_t, top_v, minima, m, rtol)
        if verdict == 1:
            return c
        if verdict == DOUBT:
            return DOUBT
    return -2


@loop
def recurs(s1, s2, factor, atol, rtol):
    """Whether the states s1, s2 (2n,) at two breakaways recur (:func:`.recurrence.recurs`):
    1, 0 or :data:`DOUBT`."""
    doubt = False
    for i in range(s1.size):
        limit = factor * (atol + rtol * max(abs(s1[i]), abs(s2[i])))
        v = _at_most(abs(s2[i] - s1[i]), limit)
        if v == 0:
            return 0
        doubt = doubt or v == DOUBT
    return DOUBT if doubt else 1


@loop
def minima_between(t, x, dx, lo, hi, t1, t2, work):
    """The minima of x located on the samples lo ≤ i < hi (as :func:`section` locates them) with
    times in (t1, t2], written from ``work[1, 0]`` on; returns their number."""
    a = lo + np.searchsorted(t[lo:hi], t1, side="right") - 1
    b = lo + np.searchsorted(t[lo:hi], t2, side="right") + 1
    count = _peaks(t, x, dx, -1.0, max(a, lo), min(b, hi), work[0], work[1])
    kept = 0
    for q in range(count):
        if work[0, q] > t1 and work[0, q] <= t2:
            work[1, kept] = -work[1, q]
            kept += 1
    return kept


@loop
def period_match(cycles, period, top_v, first, last, minima, n_min, rtol):
    """:func:`.cycles.period_matches` of the maxima ``top_v[first:last]`` and the ``n_min`` minima of
    one period that recurs after ``period`` [s]: the index of the first known cycle it matches
    (−2: none; :data:`DOUBT`: a test too near its threshold before one matched)."""
    k_of, periods, amplitudes, peaks = cycles[0], cycles[1], cycles[2], cycles[3]
    p = last - first
    if n_min == 0:
        return -2
    highest = -math.inf
    for i in range(first, last):
        highest = max(highest, top_v[i])
    lowest = math.inf
    for i in range(n_min):
        lowest = min(lowest, minima[i])
    for c in range(k_of.size):
        k = k_of[c]
        if p != k:
            continue
        A, T = amplitudes[c], periods[c]
        verdict = _at_most(abs((highest - lowest) - A), rtol * A)
        if verdict == 1:
            verdict = _at_most(abs(period - T), rtol * T)
        if verdict == 1:
            best = math.inf
            for s in range(k):
                d = 0.0
                for i in range(k):
                    d = max(d, abs(top_v[first + i] - peaks[c, (i + s) % k]))
                best = min(best, d)
            verdict = _at_most(best, rtol * A)
        if verdict == 1:
            return c
        if verdict == DOUBT:
            return DOUBT
    return -2


@loop
def _lyapunov_norm(d, P):
    total = 0.0
    for i in range(d.size):
        row = 0.0
        for j in range(d.size):
            row += d[j] * P[j, i]
        total += row * d[i]
    return math.sqrt(max(total, 0.0))


@loop
def linear_test(linear, s0, s1):
    """:func:`.early._linear` of the states s0, s1 at a chunk's ends: (at rest, linear), each 1, 0
    or :data:`DOUBT`. ``linear``: (equilibrium (2n,), free (2k,), P, Φ, rest)."""
    equilibrium, free, P, flow, rest = linear
    k2 = free.size
    d0 = np.empty(k2)
    d1 = np.empty(k2)
    for i in range(k2):
        d0[i] = s0[free[i]] - equilibrium[free[i]]
        d1[i] = s1[free[i]] - equilibrium[free[i]]
    n1 = _lyapunov_norm(d1, P)
    at_rest = _at_most(n1, rest)
    if at_rest != 0:
        return at_rest, at_rest
    lin = np.zeros(k2)
    for i in range(k2):
        for j in range(k2):
            lin[i] += flow[i, j] * d0[j]
    n0 = _lyapunov_norm(d0, P)
    contraction = n0 - _lyapunov_norm(lin, P)
    if abs(contraction) <= NEAR * n0:
        return 0, DOUBT
    if contraction < 0.0:
        return 0, 0
    for i in range(k2):
        lin[i] = d1[i] - lin[i]
    off = _lyapunov_norm(lin, P)
    limit = 0.05 * contraction
    if abs(off - limit) <= NEAR * n0:
        return 0, DOUBT
    return 0, 1 if off <= limit else 0


@loop
def _third_drift(values, start, step, count):
    """|mean of the last third − mean of the first third| of values[start::step] (count of them)."""
    third = max(count // 3, 1)
    first = 0.0
    last = 0.0
    for i in range(third):
        first += values[start + i * step]
        last += values[start + (count - third + i) * step]
    return abs(last / third - first / third)


@loop
def maybe_settled(p, tau, amplitude):
    """Whether :func:`stickslip.analysis.period.return_map` of the crossings (p, τ) might find a
    settled multiplicity: its tests with :data:`LOOSE` slack (never False where it finds one)."""
    n = p.size
    separation = math.inf
    for k in range(1, MAX_MULTIPLICITY + 1):
        if n < MIN_PERIODS * k + 1:
            break
        period = 0.0
        for i in range(k, n):
            period += tau[i] - tau[i - k]
        period /= n - k
        spread = 0.0
        for i in range(k, n):
            spread = max(spread, abs(p[i] - p[i - k]) / amplitude, abs((tau[i] - tau[i - k]) - period) / period)
        drift = 0.0
        for j in range(k):
            drift = max(drift, _third_drift(p, j, k, (n - j + k - 1) // k) / amplitude)
        dtau = np.empty(n - k)
        for i in range(k, n):
            dtau[i - k] = tau[i] - tau[i - k]
        drift = max(drift, _third_drift(dtau, 0, 1, n - k) / period)
        slack = LOOSE + NEAR * spread
        if (spread <= SETTLE_RTOL + slack and (drift <= spread + slack or drift <= DRIFT_FLOOR + slack)
                and separation + slack >= SEPARATION_FACTOR * max(spread - slack, DRIFT_FLOOR)):
            return True
        if not math.isfinite(spread):  # NaN: numpy's test would be False; let Python decide
            return True
        separation = min(separation, spread)
    return False
