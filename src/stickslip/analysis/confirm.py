"""What the dynamics must confirm before a run's verdict is reported: a period of k ≥ 2 section
crossings by shooting the k-periodic orbit, chaos (or a torus) by the largest Lyapunov exponent.

Period k ≥ 2 (:func:`confirm_period`): :func:`stickslip.periodic_orbit` is started from the
run's last crossings of the first section that the window crosses only in slip (shooting needs
that), tried on the analysed coordinate first and then on the other free ones: its maxima, its
minima, or crossings of a level of it (:data:`LEVELS`), with the number of crossings per period
counted in the window. The claim stands when Newton converges, every non-trivial Floquet
multiplier lies inside the unit circle, and a run of :data:`ORBIT_PERIODS` periods started on
the orbit shows, by the same period rule as the signal (:func:`~.period.detect_period`), the
same k and the same period to :data:`PERIOD_RTOL`: a transient near a period-1 orbit shot with
multiplicity 2 converges onto that orbit, whose own run then shows k = 1.

Non-periodic but stationary (:func:`confirm_stationary`): the largest Lyapunov exponent λ
(:func:`stickslip.lyapunov_exponent`, Benettin, started from the run's final state) decides:
``chaotic`` when λ > :data:`LAMBDA_ZERO` and λ > 3 standard errors; ``quasiperiodic`` when
|λ| ≤ :data:`LAMBDA_ZERO` and the stationary window was long enough that any contraction at a
rate above :data:`LAMBDA_ZERO` would have shown as decaying returns
(:data:`QUASI_WINDOW_S`); otherwise no claim.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import StickSlipError
from .period import DECAY_FACTOR, detect_period

__all__ = ["ORBIT_PERIODS", "PERIOD_RTOL", "LAMBDA_ZERO", "QUASI_WINDOW_S", "LYAPUNOV_TIME_S",
           "confirm_period", "confirm_stationary"]

#: Periods of the run from the shot orbit on which its own multiplicity is measured (the period
#: rule needs nine; thirty average the noise of its drift test).
ORBIT_PERIODS = 30

#: Agreement of the shot orbit's period with the run's [-]; the run's period has settled to
#: 1e-5 (:data:`~.period.SETTLE_RTOL`).
PERIOD_RTOL = 1e-4

#: Largest Lyapunov exponents within ±LAMBDA_ZERO of 0 count as zero [1/s]. The slowest
#: contraction of the paper's stick-slip orbits is ln 0.994 / 0.65 s = −0.009 1/s; Benettin
#: estimates of periodic orbits are within ±0.002 1/s of their limit after 500–1500 s.
LAMBDA_ZERO = 5e-3

#: Shortest stationary window for a torus claim [s]: over it a contraction at LAMBDA_ZERO
#: shrinks the return differences by DECAY_FACTOR between the window's first and last thirds.
QUASI_WINDOW_S = 1.5 * math.log(DECAY_FACTOR) / LAMBDA_ZERO

#: Averaging time of the Lyapunov exponent [s] (after a 20 s start that sets the norm's scales).
LYAPUNOV_TIME_S = 500.0


#: Levels of the coordinate, as fractions of its range in the window, whose up- and
#: down-crossings are tried as sections after its maxima and minima.
LEVELS = (0.5, 0.25, 0.75, 0.1, 0.9)


def _sections_in_slip(traj, dof: str, t_from: float, period: float):
    """Sections crossed only in slip in the window, with their crossings per period: on ``dof``
    first, then on the model's other free coordinates; on each, its maxima, its minima, then
    up- and down-crossings of :data:`LEVELS` of its range in the window."""
    from ..model.system import assemble
    from ..model.variants import DOF_NAMES
    from ..orbits.section import Section, section_crossings

    system = assemble(traj.params, traj.model, traj.options.get("slip_band", 1e-3))
    sel = traj.t >= t_from
    t, states, mode = traj.t[sel], traj.states[sel], traj.mode[sel]
    span = float(t[-1] - t[0])
    first = DOF_NAMES.index(dof)
    for j in [first] + [int(i) for i in system.variant.free_indices if i != first]:
        name = DOF_NAMES[j]
        lo, hi = float(states[:, j].min()), float(states[:, j].max())
        candidates = [Section(6 + j, 0.0, -1, f"{name}_max"), Section(6 + j, 0.0, 1, f"{name}_min")]
        for frac in LEVELS:
            level = lo + frac * (hi - lo)
            candidates += [Section(j, level, 1, f"{name}={level:.6g} up"),
                           Section(j, level, -1, f"{name}={level:.6g} down")]
        for section in candidates:
            times, idx = section_crossings(system, section, t, states, mode)
            if times.size and not np.any(mode[idx] | mode[idx + 1]):
                yield section, int(round(times.size * period / span))


def confirm_period(traj, k: int, period: float, *, dof: str = "phi", t_from: float | None = None) -> dict:
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
        The coordinate analysed (a name of :data:`stickslip.DOF_NAMES`).
    t_from : float, optional
        Start of the window [s]; default ``traj.steady_from``.

    Returns
    -------
    dict
        ``confirmed`` (bool), ``section``, ``period_s``, ``multiplicity`` (maxima per period
        in the orbit's own run), ``stable``, ``stick_phases`` (per period), ``max_multiplier``
        (largest non-trivial modulus), ``residual``; ``reason`` when not confirmed.
    """
    from ..orbits import periodic_orbit

    t_from = traj.steady_from if t_from is None else float(t_from)
    reasons = []
    for section, mult in _sections_in_slip(traj, dof, t_from, period):
        try:
            orbit = periodic_orbit(traj.params, traj, section=section, period_multiplicity=mult)
            run = orbit.trajectory(periods=ORBIT_PERIODS, sample_rate=max(200.0, 100.0 * k / orbit.period))
        except (StickSlipError, ArithmeticError, np.linalg.LinAlgError) as exc:
            reasons.append(f"{section.name}: {exc}")
            continue
        j = _dof_index(dof)
        own = detect_period(run.t, run.states[:, j], run.states[:, 6 + j])
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


def _dof_index(dof: str) -> int:
    from ..model.variants import DOF_NAMES

    return DOF_NAMES.index(dof)


def confirm_stationary(traj, window_s: float, *, averaging: float = LYAPUNOV_TIME_S) -> dict:
    """Largest Lyapunov exponent from the run's final state, and the verdict it supports.

    Parameters
    ----------
    traj : Trajectory
        The run; its window showed a stationary, non-periodic response.
    window_s : float
        Length of the stationary window [s] (a torus claim needs :data:`QUASI_WINDOW_S`).
    averaging : float
        Averaging time of the exponent [s].

    Returns
    -------
    dict
        ``attractor`` (``chaotic``, ``quasiperiodic`` or None: no claim), ``lyapunov_exponent``
        [1/s], ``standard_error`` [1/s], ``averaging_s``; ``reason`` when no claim is made.
    """
    from ..orbits import lyapunov_exponent

    try:
        res = lyapunov_exponent(traj.params, traj.final_state, model=traj.model, t_transient=20.0,
                                t_average=averaging)
    except (StickSlipError, ArithmeticError) as exc:
        return {"attractor": None, "reason": f"Lyapunov exponent failed: {exc}"}
    lam, se = float(res.exponent), float(res.standard_error)
    out = {"lyapunov_exponent": lam, "standard_error": se, "averaging_s": float(averaging)}
    if lam > LAMBDA_ZERO and lam > 3.0 * se:
        return {"attractor": "chaotic", **out}
    if abs(lam) <= LAMBDA_ZERO and window_s >= QUASI_WINDOW_S:
        return {"attractor": "quasiperiodic", **out}
    reason = (f"λ = {lam:.3g} ± {se:.2g} 1/s is neither > {LAMBDA_ZERO:g} (and > 3 standard errors) nor "
              f"within ±{LAMBDA_ZERO:g} of 0 over a stationary window ≥ {QUASI_WINDOW_S:.0f} s "
              f"(window {window_s:.0f} s)")
    return {"attractor": None, "reason": reason, **out}
