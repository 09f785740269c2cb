"""Steady-state summary of a trajectory: fundamental frequency, stick and open fractions, extrema."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .modes import sample_flags
from .period import detect_period
from .signal import REST_AMPLITUDE, SLIP, STICK, open_time, spectral_peak, stick_time

__all__ = ["SteadyState", "fundamental_frequency", "summarize"]


@dataclasses.dataclass(frozen=True)
class SteadyState:
    """Summary of the steady part of a run (t ≥ ``t_from``), following one coordinate.

    Attributes
    ----------
    t_from, t_to : float
        Window analysed [s].
    fundamental_frequency_hz : float
        1 / (smallest period) of the coordinate [Hz] when it repeats on its peak section and has
        settled (:func:`stickslip.analysis.period.detect_period`); NaN otherwise. This is the
        signal's rule alone: :func:`stickslip.attractors.attractor` confirms periods of more than
        one peak by shooting before it reports them.
    dominant_frequency_hz : float
        Highest peak of the coordinate's amplitude spectrum in the window [Hz]; NaN at rest.
    periodic : bool
        Whether the coordinate repeats on the section and has settled (the same decision as
        :func:`stickslip.analysis.classify.classify`).
    period_multiplicity : int
        Section crossings (peaks) per period (0 when not periodic).
    stick_fraction : float
        Fraction of the window in which some contact sticks [-]. When the motion is periodic, of
        the whole periods that end the window (the largest number of periods that fits it), so
        that it is the orbit's own fraction rather than one biased by a part period.
    contact_stick_fractions : tuple of float
        Fraction of the window (whole periods when periodic) in which each contact sticks [-], in
        the model's contact order.
    n_transitions : int
        Stick↔slip transitions inside the window.
    coordinate : str
        The dof followed (the model's observed one: the plates' φ).
    minimum, maximum : float
        Extremes of the coordinate in the window [its unit] (from the uniform samples).
    open_fraction : float or None
        Fraction of the window (whole periods when periodic, as ``stick_fraction``) in which some
        unilateral contact is open [-] (None for a model whose contacts are all pressed).
    contact_open_fractions : tuple of float
        Fraction of the window (whole periods when periodic) in which each contact is open [-]
        (empty for a model whose contacts are all pressed).
    impacts : int or None
        Impacts of rigid contacts in the window (None for a model without rigid contacts).
    max_impact_speed : float or None
        Largest normal speed |ġ⁻| at those impacts [m/s] (0 without impacts; None for a model
        without rigid contacts; NaN where the states of some of the window's impacts were not
        kept: :attr:`max_impact_speed_reason` then says so).
    max_impact_speed_reason : str
        Why :attr:`max_impact_speed` is undefined (empty where it is defined).
    """

    t_from: float
    t_to: float
    fundamental_frequency_hz: float
    dominant_frequency_hz: float
    periodic: bool
    period_multiplicity: int
    stick_fraction: float
    contact_stick_fractions: tuple
    n_transitions: int
    coordinate: str
    minimum: float
    maximum: float
    open_fraction: float | None = None
    contact_open_fractions: tuple = ()
    impacts: int | None = None
    max_impact_speed: float | None = None
    max_impact_speed_reason: str = ""

    @property
    def frequency_hz(self) -> float:
        """The fundamental frequency when periodic, else the dominant one [Hz] (NaN at rest)."""
        return self.fundamental_frequency_hz if self.periodic else self.dominant_frequency_hz

    def to_dict(self) -> dict:
        """Plain dict (NaN kept as float NaN), the extremes named after the coordinate
        (``phi_min``, ``phi_max`` for the plates, ``x_min``, ``x_max`` for the belt)."""
        d = dataclasses.asdict(self)
        if self.open_fraction is None:  # all contacts pressed: nothing opens
            del d["open_fraction"], d["contact_open_fractions"]
        if self.impacts is None:  # no rigid contacts: no impacts
            del d["impacts"], d["max_impact_speed"]
        if not self.max_impact_speed_reason:
            del d["max_impact_speed_reason"]
        d[f"{self.coordinate}_min"] = d.pop("minimum")
        d[f"{self.coordinate}_max"] = d.pop("maximum")
        return d


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


def summarize(t, states, mode, transitions, t_from, *, n_contacts: int, coordinate: int, rate: int, name: str,
              unilateral: bool = False, impacts=None) -> SteadyState:
    """Steady-state summary of samples with t ≥ ``t_from`` (see :class:`SteadyState`), following the
    state column ``coordinate`` (its rate in column ``rate``), the dof called ``name``, of a model
    with ``n_contacts`` contacts (``unilateral``: some of them open and close; ``impacts``: the
    instants [s] and normal speeds ġ⁻ [m/s] of its rigid contacts' impacts, or their tally of the
    window counted during the run (an object with ``count`` and ``max_speed``), None without them).
    ``transitions`` has the run's transitions as arrays ``time``, ``kind`` and ``contact`` (a
    :class:`stickslip.integrate.result.Transitions`)."""
    t = np.asarray(t)
    sel = t >= t_from
    if sel.sum() < 2:
        raise ValueError(f"steady_from = {t_from} s leaves fewer than 2 samples; choose an earlier time")
    ts = t[sel]
    phi = states[sel, coordinate]
    dphi = states[sel, rate]
    t0, t1 = float(ts[0]), float(ts[-1])
    # mode just after t0: the sample's mode unless a transition sits exactly on t0
    mode0 = sample_flags(mode[sel][0])
    tt = np.asarray(transitions.time)
    kinds = np.asarray(transitions.kind)
    window = (tt > t0) & (tt <= t1) & ((kinds == STICK) | (kinds == SLIP))
    per = detect_period(ts, phi, dphi)
    at_rest = per.amplitude < REST_AMPLITUDE
    periodic = per.periodic and not at_rest
    contacts = np.asarray(transitions.contact)
    # the fractions: over whole periods ending at t1 when periodic (a part period biases them)
    f0 = t1 - (t1 - t0) // per.period_s * per.period_s if periodic else t0
    j = int(np.searchsorted(ts, f0, side="right")) - 1  # the last sample at or before f0

    def phase(time_in):
        """Time in a phase within [f0, t1]: within [ts[j], t1] less within [ts[j], f0] (the mode
        is known at samples)."""
        after = time_in(float(ts[j]), t1, int(mode[sel][j]), tt, kinds, contacts, n_contacts)
        before = time_in(float(ts[j]), f0, int(mode[sel][j]), tt, kinds, contacts, n_contacts)
        return after[0] - before[0], np.asarray(after[1], float) - np.asarray(before[1], float)

    stick, each = phase(stick_time) if periodic else stick_time(t0, t1, mode0, tt, kinds, contacts, n_contacts)
    opened, each_open = (None, ()) if not unilateral else (
        phase(open_time) if periodic else open_time(t0, t1, mode0, tt, kinds, contacts, n_contacts))
    span = t1 - f0
    return SteadyState(
        t_from=t0,
        t_to=t1,
        fundamental_frequency_hz=1.0 / per.period_s if periodic else math.nan,
        dominant_frequency_hz=math.nan if at_rest else spectral_peak(ts, phi),
        periodic=bool(periodic),
        period_multiplicity=int(per.multiplicity) if periodic else 0,
        stick_fraction=stick / span,
        contact_stick_fractions=tuple(float(x) / span for x in each),
        n_transitions=int(window.sum()),
        coordinate=name,
        minimum=float(phi.min()),
        maximum=float(phi.max()),
        open_fraction=None if opened is None else opened / span,
        contact_open_fractions=tuple(float(x) / span for x in each_open),
        **_impacts_in(impacts, t0, t1),
    )


def _impacts_in(impacts, t0: float, t1: float) -> dict:
    """``impacts`` and ``max_impact_speed`` of the impacts in (t0, t1] (nothing without rigid
    contacts). An impact whose state before was not kept has speed NaN: the maximum is then
    unknown (NaN, with the reason), not the maximum of the others."""
    if impacts is None:
        return {}
    if hasattr(impacts, "max_speed"):  # counted during the run (an integrate.result.ImpactTally): exact
        return {"impacts": int(impacts.count), "max_impact_speed": float(impacts.max_speed)}
    times, speeds = (np.asarray(a, dtype=float) for a in impacts)
    inside = (times > t0) & (times <= t1)
    unknown = int(np.isnan(speeds[inside]).sum())
    if unknown:
        return {"impacts": int(inside.sum()), "max_impact_speed": math.nan,
                "max_impact_speed_reason": f"the states of {unknown} of the window's {int(inside.sum())} impacts "
                                           "were not kept (a run keeps the states of its most recent transitions "
                                           "only); move the steady window later or run shorter"}
    return {"impacts": int(inside.sum()),
            "max_impact_speed": float(np.abs(speeds[inside]).max()) if inside.any() else 0.0}
