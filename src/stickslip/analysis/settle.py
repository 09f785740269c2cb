"""What a run settles to, and runs extended until they have settled.

:func:`attractor` gives the verdict on a trajectory's window from the evidence:

=================  ======================================================================
``equilibrium``    at rest, or a slip-only oscillation decaying in every free coordinate
                   (:func:`~.classify.classify_response`), where steady sliding is linearly
                   stable (:func:`stickslip.stability`)
``periodic``       the maxima of the coordinate repeat with k crossings per period and the
                   window shows no drift (:mod:`.period`); for k ≥ 2 only when the shot
                   k-periodic orbit confirms it (:func:`.confirm.confirm_period`)
``chaotic``        stationary, not periodic, largest Lyapunov exponent positive for two
                   initial separations (:func:`.confirm.lyapunov_sign`)
``quasiperiodic``  stationary, not periodic, largest exponent zero for both, and the
                   crossings unchanged over 1000 s (:func:`.confirm.span_change`)
``unbounded``      the state became non-finite
``unsettled``      anything else: a transient, an unconfirmed claim, a failed run, or samples
                   too sparse to resolve the motion (:func:`undersampled`)
=================  ======================================================================

``settled`` is True for every verdict but ``unsettled``. The evidence (spreads, drifts,
shooting and Lyapunov results, the reason a claim was not made) comes with the verdict.

:func:`simulate_until_settled` runs :func:`stickslip.simulate` for ``t_min`` seconds, then
extends the run from its final state in steps of ``step`` seconds (``simulate(..., ic=traj,
t0=traj.t[-1])``), judging the trailing ``window`` seconds after each, until the verdict is
settled or the run reaches ``cap`` seconds.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import StickSlipError
from .classify import STATIONARY_RTOL, Classification, classify
from .confirm import QUASI_RATE, QUASI_SPAN_S, confirm_period, lyapunov_sign, span_change

__all__ = ["ATTRACTORS", "Attractor", "attractor", "simulate_until_settled", "attractor_code", "jsonable",
           "DEFAULT_CAP_S", "DEFAULT_WINDOW_S", "DEFAULT_STEP_S", "DEFAULT_T_MIN_S"]

#: Verdicts; their index is the integer code stored in sweeps (−1: the run failed).
ATTRACTORS = ("equilibrium", "periodic", "quasiperiodic", "chaotic", "unbounded", "unsettled")

#: Defaults of :func:`simulate_until_settled` [s]. The paper's stick-slip orbits settle to the
#: period rule's 1e-5 within 500–700 s from rest (Model 1, N = 50–120 N, Ω = 0.5 and 5 rad/s:
#: slowest multipliers 0.994 per 0.65 s); the cap leaves a factor ~3 and bounds the samples
#: kept (2000 s at 1 kHz: 2·10⁶ samples, ~0.26 GB).
DEFAULT_CAP_S = 2000.0
DEFAULT_WINDOW_S = 100.0
DEFAULT_STEP_S = 100.0
DEFAULT_T_MIN_S = 200.0


def attractor_code(name: str) -> int:
    """Integer code of a verdict (index in :data:`ATTRACTORS`)."""
    return ATTRACTORS.index(name)


@dataclasses.dataclass(frozen=True)
class Attractor:
    """What a run's window settles to.

    Attributes
    ----------
    attractor : str
        One of :data:`ATTRACTORS`.
    settled : bool
        Whether the evidence shows the attractor itself (every verdict but ``unsettled``).
    period_count : int or None
        Maxima of the coordinate per period of a settled periodic orbit; None otherwise.
    period_s : float
        Period [s] of a settled periodic orbit; NaN otherwise.
    fundamental_frequency_hz : float or None
        1 / period of a settled periodic orbit [Hz]; None otherwise.
    dominant_frequency_hz : float or None
        Highest peak of the coordinate's spectrum in the window [Hz]; None at rest (peak-to-peak
        below :data:`~stickslip.analysis.steady.REST_AMPLITUDE`).
    settle_time_s : float or None
        Simulated time by which the run was seen settled: the end of the window judged [s];
        None when unsettled.
    classification : Classification or None
        The signal's verdict (:func:`~.classify.classify`); None when the run stopped early.
    evidence : dict
        What was measured (the classification's evidence, plus ``shooting`` or ``lyapunov``
        results and a ``reason`` when a claim was not made).
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

    @property
    def code(self) -> int:
        """Integer code (:func:`attractor_code`)."""
        return attractor_code(self.attractor)

    @property
    def kind(self) -> str:
        """The steady-state kind (:data:`~.classify.KINDS`) that this verdict implies."""
        if self.attractor == "equilibrium":
            return "equilibrium"
        if self.attractor == "periodic":
            return "periodic-stick-slip" if self.classification.stick_fraction > 0.0 else "periodic-slip"
        return "non-periodic"

    def to_dict(self) -> dict:
        """JSON-ready dict of the verdict (without the classification)."""
        return {"settled": self.settled, "attractor": self.attractor, "period_count": self.period_count,
                "fundamental_frequency_hz": self.fundamental_frequency_hz,
                "dominant_frequency_hz": self.dominant_frequency_hz, "settle_time_s": self.settle_time_s,
                "evidence": jsonable(self.evidence)}


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
        name = "unbounded" if traj.status.startswith("state became non-finite") else "unsettled"
        return Attractor(name, name == "unbounded", None, math.nan, None, None, end if name == "unbounded" else None,
                         None, {"reason": f"the run stopped early: {traj.status}"})
    c = classify(traj, t_from, dof)
    evidence = dict(c.evidence)
    dominant = _finite(c.fft_frequency_hz)
    sparse = undersampled(traj)

    def verdict(name, k=None, period=math.nan, **more):
        evidence.update(more)
        settled = name != "unsettled"
        return Attractor(name, settled, k, period, 1.0 / period if settled and k else None, dominant,
                         end if settled else None, c, evidence)

    if sparse:
        return verdict("unsettled", reason=sparse)
    if c.attractor in ("equilibrium", "decaying"):
        if "stability" not in cache:
            cache["stability"] = _equilibrium_stability(traj)
        stab = cache["stability"]
        if stab.get("stable"):
            return verdict("equilibrium", stability=stab)
        seen = "at rest" if c.attractor == "equilibrium" else "a slip-only oscillation decays"
        why = stab.get("reason") or f"steady sliding is linearly unstable (max Re λ = {stab['max_real_part']:.3g} 1/s)"
        return verdict("unsettled", stability=stab, reason=f"{seen}, but {why}")
    if c.attractor == "periodic":
        k, period = c.multiplicity, c.period_s
        if k == 1:
            return verdict("periodic", 1, period)
        if not confirm:
            return verdict("unsettled", reason=f"a period of {k} maxima is claimed only when the shot orbit confirms it")
        key = ("shooting", k, round(period, 3))
        if key not in cache:
            cache[key] = confirm_period(traj, k, period, dof=dof, t_from=t_from)
        shot = cache[key]
        if shot["confirmed"]:
            return verdict("periodic", k, period, shooting=shot)
        return verdict("unsettled", shooting=shot, reason=f"period of {k} maxima not confirmed: {shot['reason']}")
    if c.attractor == "stationary":
        if not lyapunov:
            return verdict("unsettled", reason="stationary but not periodic; no Lyapunov exponent computed")
        if "lyapunov" not in cache:
            cache["lyapunov"] = lyapunov_sign(traj)
        lyap = cache["lyapunov"]
        if lyap["sign"] == "positive":
            return verdict("chaotic", lyapunov=lyap)
        if lyap["sign"] is None:
            return verdict("unsettled", lyapunov=lyap, reason=lyap["reason"])
        span = span_change(traj, end - max(t_from, float(traj.t[0])), dof=dof)
        if span is not None and span["rate"] <= QUASI_RATE and span["range_change"] <= STATIONARY_RTOL:
            return verdict("quasiperiodic", lyapunov=lyap, span=span)
        why = (f"the run is shorter than {QUASI_SPAN_S:g} s" if span is None else
               f"its crossings changed over {QUASI_SPAN_S:g} s (rate {span['rate']:.2g} 1/s, range "
               f"{span['range_change']:.2g} A)")
        return verdict("unsettled", lyapunov=lyap, span=span,
                       reason=f"largest Lyapunov exponent ≈ 0, but a torus is claimed only when the crossings stay "
                              f"unchanged over {QUASI_SPAN_S:g} s and {why}")
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
    from ..stability import stability

    try:
        res = stability(traj.system)
    except (StickSlipError, ArithmeticError, np.linalg.LinAlgError) as exc:
        return {"stable": False, "reason": f"the equilibrium's stability could not be computed ({exc})"}
    return {"stable": bool(res.stable), "max_real_part": float(res.max_real_part)}


def _join(a, b):
    """Trajectory ``a`` followed by ``b`` (which starts at a's last sample, dropped from b)."""
    from ..integrate.result import Stats, Transitions

    stats = Stats(**{f.name: getattr(a.stats, f.name) + getattr(b.stats, f.name)
                     for f in dataclasses.fields(Stats)})
    tr = Transitions(np.concatenate([a.transitions.time, b.transitions.time]),
                     np.concatenate([a.transitions.kind, b.transitions.kind]),
                     np.concatenate([a.transitions.state, b.transitions.state]),
                     np.concatenate([a.transitions.contact, b.transitions.contact]),
                     a.transitions.dropped + b.transitions.dropped)
    return dataclasses.replace(
        b, t=np.concatenate([a.t, b.t[1:]]), states=np.concatenate([a.states, b.states[1:]]),
        mode=np.concatenate([a.mode, b.mode[1:]]), friction=np.concatenate([a.friction, b.friction[1:]]),
        work=np.concatenate([a.work, b.work[1:] + a.work[-1]]), transitions=tr, stats=stats,
        options=dict(a.options, t_end=b.options["t_end"]))


def _tail(traj, t_from: float):
    """The part of ``traj`` from ``t_from`` on (transitions before it dropped)."""
    from ..integrate.result import Transitions

    sel = traj.t >= t_from
    keep = traj.transitions.time > t_from
    tr = Transitions(traj.transitions.time[keep], traj.transitions.kind[keep], traj.transitions.state[keep],
                     traj.transitions.contact[keep], traj.transitions.dropped + int(np.count_nonzero(~keep)))
    return dataclasses.replace(traj, t=traj.t[sel], states=traj.states[sel], mode=traj.mode[sel],
                               friction=traj.friction[sel], work=traj.work[sel], transitions=tr)


def simulate_until_settled(params=None, *, cap: float = DEFAULT_CAP_S, t_min: float = DEFAULT_T_MIN_S,
                           window: float = DEFAULT_WINDOW_S, step: float = DEFAULT_STEP_S, dof: str | None = None,
                           keep: str = "all", confirm: bool = True, lyapunov: bool = True, t0: float = 0.0,
                           **simulate_options):
    """Simulate until the run has settled (module docstring) or reaches ``cap``.

    Parameters
    ----------
    params : FrictionModel, Parameters or str, optional
        The model, as the first argument of :func:`stickslip.simulate`.
    cap : float
        Longest run [s] (measured from ``t0``).
    t_min : float
        Length of the first run [s].
    window : float
        Trailing window judged after each run [s].
    step : float
        Length of each extension [s].
    dof : str, optional
        Coordinate whose maxima form the section (default the model's observed one).
    keep : {"all", "window"}
        Keep every sample of the run, or only the last max(window, QUASI_SPAN_S) seconds
        (memory stays flat however long the run; for sweeps).
    confirm, lyapunov : bool
        See :func:`attractor`.
    t0 : float
        Initial time [s].
    **simulate_options
        ``model``, ``ic``, ``perturbation``, ``method``, ``rtol``, ``atol``, ``dt``,
        ``sample_rate``, ``max_steps``, ``slip_band`` of :func:`stickslip.simulate`.

    Returns
    -------
    Trajectory
        The run, with ``steady_from`` at the start of the last window judged and
        ``options["settle"]``: ``cap_s``, ``window_s``, ``step_s``, ``t_min_s``, ``settled``,
        ``attractor``, ``settle_time_s``, ``extensions``. Its :attr:`attractor` is the verdict
        already reached (not recomputed).
    """
    from ..integrate.driver import SimulationError, simulate

    for name, value in (("cap", cap), ("t_min", t_min), ("window", window), ("step", step)):
        if not (math.isfinite(value) and value > 0):
            raise SimulationError(f"{name} = {value} s must be a finite number > 0")
    if window > t_min:
        raise SimulationError(f"window = {window} s is longer than the first run (t_min = {t_min} s); "
                              "give t_min ≥ window")
    if keep not in ("all", "window"):
        raise SimulationError(f"keep = {keep!r}: choose 'all' or 'window'")
    if "steady_from" in simulate_options or "t_end" in simulate_options:
        raise SimulationError("simulate_until_settled sets the run length and window itself; "
                              "give cap, t_min, window and step instead of t_end and steady_from")
    t0 = float(t0)
    end = t0 + min(t_min, cap)
    traj = simulate(params, end, t0=t0, **simulate_options)
    simulate_options.pop("ic", None)
    simulate_options.pop("perturbation", None)
    cache: dict = {}
    extensions = 0
    while True:
        t_from = max(float(traj.t[-1]) - window, float(traj.t[0]))
        verdict = attractor(traj, t_from, dof=dof, confirm=confirm, lyapunov=lyapunov, cache=cache)
        if verdict.settled or traj.status != "success" or traj.t[-1] >= t0 + cap - 1e-9:
            break
        more = simulate(traj.system, min(float(traj.t[-1]) + step, t0 + cap), ic=traj, t0=float(traj.t[-1]),
                        **simulate_options)
        traj = _join(traj, more)
        if keep == "window":
            traj = _tail(traj, float(traj.t[-1]) - max(window, QUASI_SPAN_S))
        extensions += 1
    settle = {"cap_s": float(cap), "window_s": float(window), "step_s": float(step), "t_min_s": float(t_min),
              "settled": verdict.settled, "attractor": verdict.attractor,
              "settle_time_s": verdict.settle_time_s, "extensions": extensions}
    traj = dataclasses.replace(traj, steady_from=t_from, options=dict(traj.options, settle=settle))
    traj.__dict__["attractor"] = verdict  # the verdict reached, as Trajectory.attractor caches it
    return traj
