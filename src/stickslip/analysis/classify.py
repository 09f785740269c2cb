"""Classification of the steady state: equilibrium, periodic slip, periodic stick-slip, non-periodic.

The decision uses the window t ≥ t_from (the transient before it is discarded):

1. **At rest** – peak-to-peak φ below :data:`~stickslip.analysis.steady.REST_AMPLITUDE`:
   ``equilibrium``.
2. **Return map of the peaks** – :func:`~stickslip.analysis.period.detect_period`, the one
   period detection shared with the steady-state summary (``Trajectory.steady``): the peaks of φ
   (events φ̇ = 0, φ̈ < 0) form the sequence p_i at times τ_i; the response is periodic with
   multiplicity k (peaks per period) for the smallest k ≤ :data:`MAX_MULTIPLICITY` with
   |p_{i+k} − p_i| ≤ :data:`PEAK_RTOL` · A and |(τ_{i+k} − τ_i) − T| ≤ :data:`PEAK_RTOL` · T for
   all i, A the peak-to-peak amplitude of φ and T the period; at least :data:`MIN_REPEATS`
   periods must fit. Periodic: ``periodic-stick-slip`` if any stick occurs in the window, else
   ``periodic-slip``.
3. **Decay** – not periodic, no stick, and the peak-to-peak amplitude in the last quarter of the
   window below :data:`DECAY_RATIO` times that of the first quarter, in φ and in every other free
   DOF: ``equilibrium`` (converging to steady sliding, Eq. 14). A slip-only response that grows
   in any DOF is not an equilibrium.
4. Otherwise ``non-periodic``.

``settled`` says whether the attractor has stopped drifting: periodic and equilibrium
classifications are settled by construction; for a non-periodic response the range of the
peaks in the two halves of the window must agree to :data:`SETTLE_RTOL` · A.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .peaks import Peaks
from .period import MAX_MULTIPLICITY, MIN_REPEATS, PEAK_RTOL, detect_period
from .steady import REST_AMPLITUDE, _spectral_peak, stick_time

__all__ = ["KINDS", "Classification", "classify_response", "classify", "kind_code",
           "PEAK_RTOL", "MAX_MULTIPLICITY", "MIN_REPEATS"]

#: Steady-state kinds; their index is the integer code stored in sweeps (−1: the run failed).
KINDS = ("equilibrium", "periodic-slip", "periodic-stick-slip", "non-periodic")

#: A slip-only, non-periodic oscillation whose last-quarter amplitude is below this fraction of
#: the first quarter's is decaying onto the equilibrium (a settled slip limit cycle is caught as
#: periodic before this test). The slowest free decay of Table 1 (time constant 2 m_d / c_dx =
#: 200 s) gives e^(−0.75 W / 200) < 0.99 for any window W > 2.7 s.
DECAY_RATIO = 0.99

#: Relative agreement of the peak ranges of the two window halves for a settled non-periodic
#: response (1 % of A: chaotic peak sets fill their range to that level within ~50 peaks).
SETTLE_RTOL = 1e-2


def kind_code(kind: str) -> int:
    """Integer code of a kind (index in :data:`KINDS`); −1 for ``failed``."""
    return KINDS.index(kind) if kind in KINDS else -1


@dataclasses.dataclass(frozen=True)
class Classification:
    """Steady-state classification of φ over [t_from, t_to].

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    multiplicity : int
        Peaks per period of a periodic response (the period multiplicity); 0 otherwise.
    period_s : float
        Period from the return map [s]; NaN unless periodic.
    frequency_hz : float
        1/period when periodic; otherwise the mean rate of peaks [Hz]; NaN without peaks.
    fft_frequency_hz : float
        Highest peak of the Hann-windowed amplitude spectrum of φ [Hz]; NaN at rest.
    stick_fraction : float
        Fraction of the window in stick [-].
    settled : bool
        Whether the attractor has stopped drifting (see module docstring).
    amplitude : float
        Peak-to-peak φ in the window [rad].
    peaks : Peaks
        Event-located peaks of φ in the window.
    t_from, t_to : float
        The window [s].
    """

    kind: str
    multiplicity: int
    period_s: float
    frequency_hz: float
    fft_frequency_hz: float
    stick_fraction: float
    settled: bool
    amplitude: float
    peaks: Peaks
    t_from: float
    t_to: float

    @property
    def code(self) -> int:
        """Integer code (:func:`kind_code`)."""
        return kind_code(self.kind)

    @property
    def is_stick_slip(self) -> bool:
        """Stick-slip oscillation (periodic or not) with stick in the window."""
        return self.kind != "equilibrium" and self.stick_fraction > 0.0

    def to_dict(self) -> dict:
        """Flat dict without the peak arrays."""
        d = dataclasses.asdict(self)
        d.pop("peaks")
        d["n_peaks"] = len(self.peaks)
        return d


def _ptp(x):
    return float(np.max(x) - np.min(x)) if x.size else 0.0


def _decaying(t, x, t0, t1):
    """Whether the peak-to-peak of x in the last quarter is below DECAY_RATIO × the first's."""
    q = (t1 - t0) / 4.0
    first, last = _ptp(x[t <= t0 + q]), _ptp(x[t >= t1 - q])
    return last < REST_AMPLITUDE or last < DECAY_RATIO * first


def classify_response(t, phi, dphi, *, stick_fraction: float = 0.0, t_from: float | None = None,
                      others=None) -> Classification:
    """Classify a sampled response φ(t) (see the module docstring for the rules).

    Parameters
    ----------
    t : ndarray (n,)
        Uniform sample times [s].
    phi, dphi : ndarray (n,)
        φ [rad] and φ̇ [rad/s] (any response and its rate will do).
    stick_fraction : float
        Fraction of the window spent in stick [-] (0 for a slip-only or constructed signal).
    t_from : float, optional
        Start of the window [s]; default the first sample.
    others : ndarray (n, k), optional
        Other responses (e.g. the free translations) that must decay too before a slip-only
        response counts as converging to the equilibrium: an unstable mode may grow in them
        while φ still decays.
    """
    t = np.asarray(t, dtype=float)
    phi = np.asarray(phi, dtype=float)
    dphi = np.asarray(dphi, dtype=float)
    others = None if others is None else np.asarray(others, dtype=float).reshape(t.size, -1)
    if t_from is not None:
        sel = t >= t_from
        t, phi, dphi = t[sel], phi[sel], dphi[sel]
        others = None if others is None else others[sel]
    if t.size < 8:
        raise ValueError("classification needs at least 8 samples in the window; choose an earlier t_from")
    t0, t1 = float(t[0]), float(t[-1])
    per = detect_period(t, phi, dphi)
    amp, pk = per.amplitude, per.peaks
    base = dict(stick_fraction=float(stick_fraction), amplitude=amp, peaks=pk, t_from=t0, t_to=t1)
    if amp < REST_AMPLITUDE:
        return Classification("equilibrium", 0, math.nan, math.nan, math.nan, settled=True, **base)
    fft_f = _spectral_peak(t, phi)
    k, period = per.multiplicity, per.period_s
    if k:
        kind = "periodic-stick-slip" if stick_fraction > 0.0 else "periodic-slip"
        return Classification(kind, k, period, 1.0 / period, fft_f, settled=True, **base)
    decaying = _decaying(t, phi, t0, t1) and (others is None or all(_decaying(t, x, t0, t1) for x in others.T))
    if stick_fraction == 0.0 and decaying:
        rate = (len(pk) - 1) / (pk.time[-1] - pk.time[0]) if len(pk) >= 2 else math.nan
        return Classification("equilibrium", 0, math.nan, float(rate), fft_f, settled=True, **base)
    rate = (len(pk) - 1) / (pk.time[-1] - pk.time[0]) if len(pk) >= 2 else math.nan
    mid = 0.5 * (t0 + t1)
    a, b = pk.value[pk.time < mid], pk.value[pk.time >= mid]
    settled = bool(a.size >= 2 and b.size >= 2
                   and abs(a.min() - b.min()) <= SETTLE_RTOL * amp and abs(a.max() - b.max()) <= SETTLE_RTOL * amp)
    return Classification("non-periodic", 0, math.nan, float(rate), fft_f, settled=settled, **base)


def classify(traj, t_from: float | None = None, dof: str = "phi") -> Classification:
    """Classify the steady state of a :class:`~stickslip.Trajectory` over t ≥ ``t_from`` [s].

    The stick fraction comes from the exact transition instants. ``t_from`` defaults to the
    trajectory's ``steady_from`` (the last half of the run unless set).
    """
    from ..model.variants import DOF_NAMES, resolve_variant

    j = DOF_NAMES.index(dof)
    t_from = traj.steady_from if t_from is None else float(t_from)
    sel = traj.t >= t_from
    ts = traj.t[sel]
    if ts.size < 8:
        raise ValueError(f"t_from = {t_from} s leaves fewer than 8 samples; choose an earlier time")
    stick = stick_time(float(ts[0]), float(ts[-1]), int(traj.mode[sel][0]), traj.transitions.time, traj.transitions.kind)
    frac = stick / float(ts[-1] - ts[0])
    free = [i for i, name in enumerate(DOF_NAMES) if name in resolve_variant(traj.model).free and i != j]
    return classify_response(ts, traj.states[sel, j], traj.states[sel, 6 + j], stick_fraction=frac,
                             others=traj.states[sel][:, free] if free else None)
