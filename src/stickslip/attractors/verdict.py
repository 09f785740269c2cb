"""What a run settles to: the verdict on a trajectory's window, from the evidence.

:func:`attractor` names it in the one vocabulary of outcomes
(:data:`~stickslip.analysis.outcome.OUTCOMES`):

=================  ======================================================================
``equilibrium``    at rest, or a slip-only oscillation decaying in every free coordinate
                   (:func:`~stickslip.analysis.classify.classify_response`), where steady
                   sliding is linearly stable (:func:`stickslip.stability`; a marginal centre,
                   Re λ = 0 within the solver's accuracy, leaves the run unsettled)
``periodic``       the maxima of the coordinate repeat with k crossings per period and the
                   window shows no drift (:mod:`stickslip.analysis.period`); for k ≥ 2 only
                   when the shot k-periodic orbit confirms it (:func:`.confirm.confirm_period`)
``chaotic``        stationary, not periodic, largest Lyapunov exponent positive for two
                   initial separations (:func:`.confirm.lyapunov_sign`)
``quasiperiodic``  stationary, not periodic, largest exponent zero for both, and the
                   crossings unchanged over 1000 s (:func:`.confirm.span_change`)
``unbounded``      the state became non-finite
``contact-lost``   the run stopped where a pressed contact's normal force reached 0
``failed``         the run stopped otherwise before its end (step size underflow, step cap,
                   no consistent contact force)
``unsettled``      anything else: a transient, an unconfirmed claim, a run cut short (Ctrl-C),
                   or samples too sparse to resolve the motion (:func:`undersampled`)
=================  ======================================================================

``settled`` is True for every verdict but ``unsettled`` and ``failed``. Whether the motion
sticks is the window's stick fraction beside the verdict (:attr:`Attractor.is_stick_slip`).
The evidence (spreads, drifts, shooting and Lyapunov results, the reason a claim was not made)
comes with the verdict.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..analysis.classify import STATIONARY_MIN_PEAKS, STATIONARY_RTOL, Classification, classify
from ..analysis.outcome import is_stick_slip, outcome_code
from ..errors import StickSlipError
from ..integrate.status import Status
from ..stability.verdict import verdict_text

# The confirmations (.confirm: shooting and Lyapunov exponents, the orbits layer and scipy.linalg)
# and the stability analysis are imported on the paths of a verdict that needs them: a run whose
# window decides alone (the default run of the command line) loads neither.

__all__ = ["Attractor", "attractor", "stopped_outcome", "jsonable", "undersampled"]


def stopped_outcome(status: Status) -> str:
    """The outcome of a run that ended with ``status`` before its end time: ``unbounded``
    (non-finite state), ``contact-lost``, ``unsettled`` (interrupted: only cut short) or
    ``failed``."""
    return {Status.NOT_FINITE: "unbounded", Status.CONTACT_LOST: "contact-lost",
            Status.INTERRUPTED: "unsettled"}.get(Status(status), "failed")


@dataclasses.dataclass(frozen=True)
class Attractor:
    """What a run's window settles to.

    Parameters
    ----------
    attractor : str
        The outcome, one of :data:`~stickslip.analysis.outcome.OUTCOMES`.
    settled : bool
        Whether the evidence shows what the run settles to (every verdict but ``unsettled`` and
        ``failed``).
    period_count : int or None
        Maxima of the coordinate per period of a settled periodic orbit; None otherwise.
    period_s : float
        Period [s] of a settled periodic orbit; NaN otherwise.
    fundamental_frequency_hz : float or None
        1 / period of a settled periodic orbit [Hz]; None otherwise.
    dominant_frequency_hz : float or None
        Highest peak of the coordinate's spectrum in the window [Hz]; None at rest (peak-to-peak
        below :data:`~stickslip.analysis.signal.REST_AMPLITUDE`).
    settle_time_s : float or None
        Simulated time by which the run was seen settled: the end of the window judged [s];
        None when unsettled.
    classification : Classification or None
        The signal's verdict (:func:`~stickslip.analysis.classify.classify`); None when the run stopped early.
    evidence : dict
        What was measured (the classification's evidence, plus ``shooting`` or ``lyapunov``
        results and a ``reason`` when a claim was not made).
    confirmed_by : str or None
        The computation past the window that confirmed the verdict, in words (a shot orbit and
        its own run, or Lyapunov runs continued from the run's end, with their simulated time);
        None when the window alone decided.
    """

    attractor: str
    settled: bool
    period_count: int | None
    period_s: float
    fundamental_frequency_hz: float | None
    dominant_frequency_hz: float | None
    settle_time_s: float | None
    classification: Classification | None
    evidence: dict
    confirmed_by: str | None = None

    @property
    def code(self) -> int:
        """Integer code of the outcome (:func:`~stickslip.analysis.outcome.outcome_code`)."""
        return outcome_code(self.attractor)

    @property
    def stick_fraction(self) -> float:
        """Fraction of the window in stick [-] (NaN when the run stopped early)."""
        return self.classification.stick_fraction if self.classification is not None else math.nan

    @property
    def is_stick_slip(self) -> bool:
        """Whether the run is a stick-slip oscillation (it moves and sticks in its window)."""
        return is_stick_slip(self.attractor, self.stick_fraction)

    def to_dict(self) -> dict:
        """JSON-ready dict of the verdict (without the classification)."""
        return {"settled": self.settled, "attractor": self.attractor, "period_count": self.period_count,
                "fundamental_frequency_hz": self.fundamental_frequency_hz,
                "dominant_frequency_hz": self.dominant_frequency_hz, "settle_time_s": self.settle_time_s,
                "confirmed_by": self.confirmed_by, "evidence": jsonable(self.evidence)}


def jsonable(x):
    """``x`` with numpy scalars as Python ones and non-finite floats as None (for JSON)."""
    if isinstance(x, dict):
        return {str(k): jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [jsonable(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return float(x) if math.isfinite(float(x)) else None
    if isinstance(x, (np.integer, np.bool_)):
        return x.item()
    return x


def _finite(x) -> float | None:
    return float(x) if x is not None and math.isfinite(x) else None


def attractor(traj, t_from: float | None = None, *, dof: str | None = None, confirm: bool = True,
              lyapunov: bool = True, cache: dict | None = None) -> Attractor:
    """The verdict on a trajectory's window t ≥ ``t_from`` (module docstring).

    Parameters
    ----------
    traj : Trajectory
    t_from : float, optional
        Start of the window [s]; default ``traj.steady_from``.
    dof : str, optional
        Coordinate whose maxima form the section (a dof of the model; default its observed one,
        the plates' φ).
    confirm : bool
        Shoot the orbit of a period claim with k ≥ 2 (without it no such claim is made).
    lyapunov : bool
        Compute the largest Lyapunov exponent of a stationary non-periodic window (without it
        no chaos or torus claim is made).
    cache : dict, optional
        Confirmations already computed for this run (:func:`simulate_until_settled` passes one
        so that a refuted claim is not shot again at every extension).

    Returns
    -------
    Attractor
    """
    t_from = traj.steady_from if t_from is None else float(t_from)
    cache = {} if cache is None else cache
    end = float(traj.t[-1])
    if traj.status != "success":
        name = stopped_outcome(traj.status_code)
        settled = name not in ("unsettled", "failed")
        return Attractor(name, settled, None, math.nan, None, None, end if settled else None, None,
                         {"reason": f"the run stopped early: {traj.status}"})
    c = classify(traj, t_from, dof)
    evidence = dict(c.evidence)
    dominant = _finite(c.fft_frequency_hz)
    sparse = undersampled(traj)

    def verdict(name, k=None, period=math.nan, confirmed_by=None, **more):
        evidence.update(more)
        settled = name != "unsettled"
        return Attractor(name, settled, k, period, 1.0 / period if settled and k else None, dominant,
                         end if settled else None, c, evidence, confirmed_by if settled else None)

    if sparse:
        return verdict("unsettled", reason=sparse)
    if c.signal in ("at-rest", "decaying"):
        if "stability" not in cache:
            cache["stability"] = _equilibrium_stability(traj)
        stab = cache["stability"]
        if stab.get("stable"):
            return verdict("equilibrium", stability=stab)
        seen = "at rest" if c.signal == "at-rest" else (
            f"a slip-only oscillation's amplitude fell in the window (last quarter / first "
            f"{evidence.get('amplitude_ratio', math.nan):.4g})")
        why = stab.get("reason") or f"steady sliding is {verdict_text(stab['max_real_part'], stab['tolerance'])}"
        return verdict("unsettled", stability=stab, reason=f"{seen}, but {why}")
    if c.signal == "periodic":
        k, period = c.multiplicity, c.period_s
        if k == 1:
            return verdict("periodic", 1, period)
        if not confirm:
            return verdict("unsettled", reason=f"a period of {k} maxima is claimed only when the shot orbit confirms it")
        from .confirm import ORBIT_PERIODS, confirm_period  # noqa: PLC0415 - see the module's imports

        key = ("shooting", k, round(period, 3))
        if key not in cache:
            cache[key] = confirm_period(traj, k, period, dof=dof, t_from=t_from)
        shot = cache[key]
        if shot["confirmed"]:
            return verdict("periodic", k, period, shooting=shot,
                           confirmed_by=f"the shot orbit and its own run of {ORBIT_PERIODS} periods "
                                        f"({ORBIT_PERIODS * shot['period_s']:.4g} s) past the run")
        return verdict("unsettled", shooting=shot, reason=f"period of {k} maxima not confirmed: {shot['reason']}")
    if c.signal == "stationary":
        if not lyapunov:
            return verdict("unsettled", reason="stationary but not periodic; no Lyapunov exponent computed")
        from .confirm import LYAPUNOV_START_S, QUASI_RATE, QUASI_SPAN_S, lyapunov_sign, span_change  # noqa: PLC0415

        if "lyapunov" not in cache:
            cache["lyapunov"] = lyapunov_sign(traj)
        lyap = cache["lyapunov"]
        past = (f"largest Lyapunov exponents over {len(lyap.get('exponents', []))} runs of "
                f"{LYAPUNOV_START_S + lyap.get('averaging_s', 0.0):g} s continued from the run's end")
        if lyap["sign"] == "positive":
            return verdict("chaotic", lyapunov=lyap, confirmed_by=past)
        if lyap["sign"] is None:
            return verdict("unsettled", lyapunov=lyap, reason=lyap["reason"])
        span = span_change(traj, end - max(t_from, float(traj.t[0])), dof=dof)
        if span is not None and span["rate"] <= QUASI_RATE and span["range_change"] <= STATIONARY_RTOL:
            return verdict("quasiperiodic", lyapunov=lyap, span=span, confirmed_by=past)
        why = (f"the run is shorter than {QUASI_SPAN_S:g} s" if span is None else
               f"its crossings changed over {QUASI_SPAN_S:g} s (rate {span['rate']:.2g} 1/s, range "
               f"{span['range_change']:.2g} A)")
        return verdict("unsettled", lyapunov=lyap, span=span,
                       reason=f"largest Lyapunov exponent ≈ 0, but a torus is claimed only when the crossings stay "
                              f"unchanged over {QUASI_SPAN_S:g} s and {why}")
    peaks = c.evidence.get("peaks", STATIONARY_MIN_PEAKS)
    if peaks < STATIONARY_MIN_PEAKS:
        return verdict("unsettled", reason=f"the window holds {peaks} peaks of the coordinate; a claim that it has no "
                                           f"period needs at least {STATIONARY_MIN_PEAKS} (every multiplicity up to "
                                           "16 over 9 periods): run longer")
    return verdict("unsettled", reason="the window still drifts")


def undersampled(traj) -> str | None:
    """Why the samples of ``traj`` cannot carry a verdict, or None when they can.

    Samples slower than twice the model's highest linear mode frequency (Nyquist) alias the
    motion: a stick-slip cycle sampled once per period looks at rest, one sampled at an
    incommensurate rate looks like a torus, and section crossings read off the interpolant are
    not the motion's. No verdict is drawn from such samples.
    """
    rate = traj.options.get("sample_rate") if traj.options else None
    if rate is None and traj.t.size > 1:
        rate = 1.0 / float(traj.t[1] - traj.t[0])
    system = getattr(traj, "system", None)
    if rate is None or system is None:
        return None
    highest = float(system.natural_frequencies().max(initial=0.0))
    if rate >= 2.0 * highest:
        return None
    return (f"the samples ({rate:g} per unit time) are slower than twice the highest linear mode frequency "
            f"({highest:.4g}), so they alias the motion; run with a sample rate of at least "
            f"{math.ceil(2.0 * highest)} for a verdict")


def _equilibrium_stability(traj) -> dict:
    """Linear stability of steady sliding for the run's parameters and model."""
    from ..stability import stability  # noqa: PLC0415 - see the module's imports

    try:
        res = stability(traj.system)
    except (StickSlipError, ArithmeticError, np.linalg.LinAlgError) as exc:
        return {"stable": False, "reason": f"the equilibrium's stability could not be computed ({exc})"}
    return {"stable": bool(res.stable), "verdict": res.verdict, "max_real_part": float(res.max_real_part),
            "tolerance": res.tolerance}
