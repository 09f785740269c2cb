"""What the dynamics must confirm before a run's verdict is reported: a period of k ≥ 2 section
crossings by shooting the k-periodic orbit, chaos (or a torus) by the largest Lyapunov exponent.

Period k ≥ 2 (:func:`confirm_period`): :func:`stickslip.periodic_orbit` is started from the
run's last crossings of the first section that the window crosses only in slip (shooting needs
that), tried on the analysed coordinate first and then on the other free ones: its maxima, its
minima, or crossings of a level of it (:data:`LEVELS`), with the number of crossings per period
counted in the window. The claim stands when Newton converges, every non-trivial Floquet
multiplier lies inside the unit circle, and a run of :data:`ORBIT_PERIODS` periods started on
the orbit shows, by the same period rule as the signal (:func:`~stickslip.analysis.period.detect_period`), the
same k and the same period to :data:`PERIOD_RTOL`: a transient near a period-1 orbit shot with
multiplicity 2 converges onto that orbit, whose own run then shows k = 1.

Non-periodic but stationary: the largest Lyapunov exponent λ (:func:`lyapunov_sign`,
Benettin from the run's final state, once for each initial separation of :data:`SEPARATIONS`)
decides. ``chaotic`` when every estimate is > :data:`LAMBDA_ZERO` and > 3 standard errors;
``quasiperiodic`` when every |λ| is within :data:`LAMBDA_ZERO` + 3 standard errors of 0 (a
torus's exponent converges like 1/t) **and** the crossings have not changed
over :data:`QUASI_SPAN_S` (:func:`span_change`); otherwise no claim.
"""

from __future__ import annotations

import math

import numpy as np

from ..analysis.classify import dof_index, range_change
from ..analysis.peaks import find_peaks
from ..analysis.period import detect_period, evidence_at, return_map
from ..errors import StickSlipError
from ..orbits import lyapunov_exponent, periodic_orbit
from ..orbits.section import Section, section_crossings

__all__ = ["ORBIT_PERIODS", "PERIOD_RTOL", "LAMBDA_ZERO", "SEPARATIONS", "QUASI_SPAN_S", "QUASI_RATE",
           "LYAPUNOV_TIME_S", "LYAPUNOV_START_S", "confirm_period", "lyapunov_sign", "span_change"]

#: Periods of the run from the shot orbit on which its own multiplicity is measured (the period
#: rule needs nine; thirty average the noise of its drift test).
ORBIT_PERIODS = 30

#: Agreement of the shot orbit's period with the run's [-]; the run's period has settled to
#: 1e-5 (:data:`~stickslip.analysis.period.SETTLE_RTOL`).
PERIOD_RTOL = 1e-4

#: A positive largest Lyapunov exponent must exceed this [1/s] (and 3 standard errors). Benettin
#: estimates of periodic orbits are within ±0.002 1/s of their limit (0) after 500–1500 s.
LAMBDA_ZERO = 5e-3

#: Initial separations of the two Benettin runs [-]: a chaotic exponent does not depend on d0
#: (docs/orbits.md: 1e-8 … 1e-6 agree), a spurious one does (Model 3, N = 50 N, Ω = 0.677 rad/s
#: after 200 s: 0.345 ± 0.029 1/s at 1e-7, −0.001 at 1e-6; the run is period 1 by 400 s).
SEPARATIONS = (1e-7, 1e-6)

#: A torus claim needs the crossings unchanged over this span [s]: the spreads of its first and
#: last windows may differ by a contraction rate of at most QUASI_RATE [1/s], and their peak
#: ranges by :data:`~stickslip.analysis.classify.STATIONARY_RTOL` of A. A λ ≈ 0 alone does not tell a torus from
#: a periodic orbit approached slowly (Model 1, N = 50 N, Ω = 0.5, Δμ = 0.0661: λ = −0.0004 …
#: 0.005 1/s, no visible decay in 330 s, but the spreads fall ×2.7 per 500 s, 0.5 → 5e-4 over
#: 4000 s).
QUASI_SPAN_S = 1000.0
QUASI_RATE = 1e-4

#: Averaging time of the Lyapunov exponent [s], after a start of LYAPUNOV_START_S that sets the
#: norm's scales.
LYAPUNOV_TIME_S = 500.0
LYAPUNOV_START_S = 20.0

#: Levels of the coordinate, as fractions of its range in the window, whose up- and
#: down-crossings are tried as sections after its maxima and minima.
LEVELS = (0.5, 0.25, 0.75, 0.1, 0.9)


def _sections_in_slip(traj, dof: str, t_from: float, period: float):
    """Sections crossed only in slip in the window, with their crossings per period: on ``dof``
    first, then on the model's other free coordinates; on each, its maxima, its minima, then
    up- and down-crossings of :data:`LEVELS` of its range in the window."""
    system = traj.system
    n = system.n
    sel = traj.t >= t_from
    t, states, mode = traj.t[sel], traj.states[sel], traj.mode[sel]
    span = float(t[-1] - t[0])
    first = system.dofs.index(dof)
    for j in [first] + [int(i) for i in np.flatnonzero(system.free) if i != first]:
        name = system.dofs[j]
        lo, hi = float(states[:, j].min()), float(states[:, j].max())
        candidates = [Section(n + j, 0.0, -1, f"{name}_max"), Section(n + j, 0.0, 1, f"{name}_min")]
        for frac in LEVELS:
            level = lo + frac * (hi - lo)
            candidates += [Section(j, level, 1, f"{name}={level:.6g} up"),
                           Section(j, level, -1, f"{name}={level:.6g} down")]
        for section in candidates:
            times, idx = section_crossings(system, section, t, states, mode)
            if times.size and not np.any(mode[idx] | mode[idx + 1]):
                yield section, int(round(times.size * period / span))


def confirm_period(traj, k: int, period: float, *, dof: str | None = None, t_from: float | None = None) -> dict:
    """Shoot the k-periodic orbit the run shows and say whether it confirms the claim.

    Parameters
    ----------
    traj : Trajectory
        The run; its window t ≥ ``t_from`` showed a settled period of ``k`` maxima of ``dof``.
    k : int
        Section crossings (maxima of ``dof``) per period claimed by the signal.
    period : float
        Period claimed by the signal [s].
    dof : str
        The coordinate analysed (a dof of the run's model; default its observed one).
    t_from : float, optional
        Start of the window [s]; default ``traj.steady_from``.

    Returns
    -------
    dict
        ``confirmed`` (bool), ``section``, ``period_s``, ``multiplicity`` (maxima per period
        in the orbit's own run), ``stable``, ``stick_phases`` (per period), ``max_multiplier``
        (largest non-trivial modulus), ``residual``; ``reason`` when not confirmed.
    """
    dof = traj.system.dofs[dof_index(traj, dof)]
    t_from = traj.steady_from if t_from is None else float(t_from)
    reasons = []
    for section, mult in _sections_in_slip(traj, dof, t_from, period):
        try:
            orbit = periodic_orbit(None, traj, section=section, period_multiplicity=mult)
            run = orbit.trajectory(periods=ORBIT_PERIODS, sample_rate=max(200.0, 100.0 * k / orbit.period))
        except (StickSlipError, ArithmeticError, np.linalg.LinAlgError) as exc:
            reasons.append(f"{section.name}: {exc}")
            continue
        j = dof_index(traj, dof)
        own = detect_period(run.t, run.states[:, j], run.states[:, traj.system.n + j])
        out = {"section": section.name, "period_s": float(orbit.period), "multiplicity": int(own.multiplicity),
               "stable": bool(orbit.stable), "stick_phases": int(orbit.stick_phases), "residual": float(orbit.residual),
               "max_multiplier": float(np.max(np.abs(orbit.nontrivial_multipliers)))}
        same = own.periodic and own.multiplicity == k and abs(own.period_s / period - 1.0) <= PERIOD_RTOL
        if same and orbit.stable:
            return {"confirmed": True, **out}
        if not orbit.stable:
            why = f"the orbit is unstable (largest non-trivial multiplier {out['max_multiplier']:.6g})"
        elif own.periodic:
            why = f"the orbit repeats after {own.multiplicity} maxima ({own.period_s:.6g} s), not {k} ({period:.6g} s)"
        else:
            why = "a run on the orbit does not repeat"
        return {"confirmed": False, "reason": why, **out}
    return {"confirmed": False, "reason": "; ".join(reasons) or "no section is crossed only in slip"}


def lyapunov_sign(traj, *, averaging: float = LYAPUNOV_TIME_S) -> dict:
    """Largest Lyapunov exponent from the run's final state, once per separation of
    :data:`SEPARATIONS`, and whether they agree on its sign.

    Parameters
    ----------
    traj : Trajectory
        The run; its window showed a stationary, non-periodic response.
    averaging : float
        Averaging time of each exponent [s].

    Returns
    -------
    dict
        ``sign`` (``positive``: every estimate > :data:`LAMBDA_ZERO` and > 3 standard errors;
        ``zero``: every |λ| ≤ :data:`LAMBDA_ZERO` + 3 standard errors, i.e. consistent with 0;
        None otherwise: the estimates disagree), ``exponents`` [1/s],
        ``standard_errors`` [1/s], ``separations``, ``averaging_s``; ``reason`` when None.
    """
    lams, ses = [], []
    for d0 in SEPARATIONS:
        try:
            res = lyapunov_exponent(traj.system, traj.final_state, t_transient=LYAPUNOV_START_S,
                                    t_average=averaging, d0=d0)
        except (StickSlipError, ArithmeticError) as exc:
            return {"sign": None, "reason": f"Lyapunov exponent failed: {exc}"}
        lams.append(float(res.exponent))
        ses.append(float(res.standard_error))
    out = {"exponents": lams, "standard_errors": ses, "separations": list(SEPARATIONS), "averaging_s": float(averaging)}
    if all(lam > LAMBDA_ZERO and lam > 3.0 * se for lam, se in zip(lams, ses)):
        return {"sign": "positive", **out}
    if all(abs(lam) <= LAMBDA_ZERO + 3.0 * se for lam, se in zip(lams, ses)):
        return {"sign": "zero", **out}
    text = ", ".join(f"{lam:.3g} ± {se:.2g}" for lam, se in zip(lams, ses))
    return {"sign": None, "reason": f"largest Lyapunov exponents {text} 1/s (d0 = {', '.join(map(str, SEPARATIONS))}) "
                                    f"are neither all > {LAMBDA_ZERO:g} (and > 3 standard errors) nor all consistent "
                                    "with 0", **out}


def span_change(traj, window: float, *, dof: str | None = None, span: float = QUASI_SPAN_S) -> dict | None:
    """How the crossings changed between the first and the last ``window`` seconds of the run's
    last ``span`` seconds; None when the run is shorter than ``span``.

    Returns
    -------
    dict or None
        ``span_s``, ``multiplicity`` (the last window's best), ``rate`` (|ln| of the ratio of the
        two windows' spreads at that multiplicity over the time between them [1/s]) and
        ``range_change`` (:func:`~stickslip.analysis.classify.range_change`).
    """
    end = float(traj.t[-1])
    if end - float(traj.t[0]) < span - 1e-9:
        return None
    j = dof_index(traj, dof)
    n = traj.system.n
    windows = []
    for a in (end - span, end - window):
        sel = (traj.t >= a) & (traj.t <= a + window)
        x = traj.states[sel, j]
        windows.append((find_peaks(traj.t[sel], x, traj.states[sel, n + j]), float(np.ptp(x))))
    (early, amp_e), (late, amp_l) = windows
    k = max(return_map(late, amp_l)[1].multiplicity, 1)
    if min(len(early), len(late)) <= k:
        return None
    s_e = evidence_at(early.value, early.time, k, amp_e).spread
    s_l = evidence_at(late.value, late.time, k, amp_l).spread
    rate = abs(math.log(s_e / s_l)) / (span - window) if s_e > 0 and s_l > 0 else math.inf
    return {"span_s": float(span), "multiplicity": int(k), "rate": float(rate),
            "range_change": float(range_change(early.value, late.value, amp_l))}
