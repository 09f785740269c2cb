"""Intensity of oscillation, paper Eq. (16), and the relative-motion angle of Fig. 11."""

from __future__ import annotations

import math

import numpy as np

from ..errors import EquilibriumError
from ..stability.equilibrium import equilibrium, sliding_speeds

__all__ = ["ANGLE_SPEED_FRACTION", "intensity", "trajectory_intensities", "relative_motion_angle", "angle_range"]


def _trapezoid(y, t):
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))


def intensity(t, x, x_e=0.0, *, t_from: float | None = None) -> float:
    """Intensity index of paper Eq. (16), I = √(∫_T (X − X_e)² dt) / T.

    Parameters
    ----------
    t : ndarray (n,)
        Sample times [s].
    x : ndarray (n,) or (n, d)
        The response X; with d columns the integrand is the squared Euclidean distance
        Σ_j (X_j − X_e,j)² (e.g. the translation (x1, y1) of the upper plate, Fig. 16(c)).
    x_e : float or ndarray (d,)
        The equilibrium value X_e (Eq. 14).
    t_from : float, optional
        Start of the steady window [s]; T = t[-1] − t_from. Default: the whole record.

    Returns
    -------
    float
        I in [unit of X · s^(-1/2)], exactly as Eq. (16) is printed (it is not an RMS: for
        X − X_e = A sin ωt over whole periods, I = A / √(2T), so compare values at equal T).
        The integral is the trapezoidal rule on the samples (second order in the step).
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if t_from is not None:
        sel = t >= t_from
        t, x = t[sel], x[sel]
    if t.size < 2:
        raise ValueError("intensity needs at least 2 samples in the window; choose an earlier t_from")
    d = x - np.asarray(x_e, dtype=float)
    sq = d * d if d.ndim == 1 else np.sum(d * d, axis=1)
    T = float(t[-1] - t[0])
    return math.sqrt(_trapezoid(sq, t)) / T


def trajectory_intensities(traj, t_from: float | None = None, equilibrium_q=None) -> dict:
    """Eq. (16) for the responses of Fig. 16 over t ≥ ``t_from`` [s] (a run of the two plates: its
    coordinates are found by their names, phi, x1, y1, and r among its parameters).

    Parameters
    ----------
    traj : Trajectory
    t_from : float, optional
        Default the trajectory's ``steady_from``.
    equilibrium_q : ndarray (n,), optional
        The equilibrium q_e (Eq. 14); computed with :func:`stickslip.equilibrium` when omitted.
        NaNs are returned when it cannot be found.

    Returns
    -------
    dict
        ``r_phi`` [m s^-1/2] (Figs. 16(a), (b)), ``x1``, ``y1`` and ``translation``
        (‖(x1, y1) − (x1e, y1e)‖, Fig. 16(c)) [m s^-1/2].
    """
    t_from = traj.steady_from if t_from is None else float(t_from)
    system = traj.system
    if equilibrium_q is None:
        try:
            equilibrium_q = equilibrium(system)
        except EquilibriumError:
            equilibrium_q = np.full(system.n, np.nan)
    qe = np.asarray(equilibrium_q, dtype=float)
    r = system.parameters["r"]
    s = traj.states
    phi, x1, y1 = (system.dofs.index(name) for name in ("phi", "x1", "y1"))
    return {
        "r_phi": intensity(traj.t, r * s[:, phi], r * qe[phi], t_from=t_from),
        "x1": intensity(traj.t, s[:, x1], qe[x1], t_from=t_from),
        "y1": intensity(traj.t, s[:, y1], qe[y1], t_from=t_from),
        "translation": intensity(traj.t, s[:, [x1, y1]], qe[[x1, y1]], t_from=t_from),
    }


def relative_motion_angle(traj, t_from: float | None = None):
    """Angle of v_r against the gross circumferential direction (Fig. 11) over t ≥ ``t_from``.

    Returns
    -------
    t : ndarray (k,)
        Sample times [s].
    angle : ndarray (k,)
        Angle [deg] between v_r and −e_n2 (the lower plate surface's direction of motion
        relative to the upper plate, Eq. 8); NaN in stick, where v_r = 0 has no direction.
    """
    t_from = traj.steady_from if t_from is None else float(t_from)
    sel = traj.t >= t_from
    return traj.t[sel], traj.sliding_angle_deg[sel]


#: Default speed floor of :func:`angle_range` as a fraction of the contact's sliding speed at rest
#: (for the plates Ω r):
#: within 1 % of v_r = 0 the direction of v_r turns through all angles on the approach to and
#: departure from stick (it is the direction of a vanishing vector), which would swamp the
#: variation of the sliding direction that Fig. 11 shows.
ANGLE_SPEED_FRACTION = 0.01


def angle_range(traj, t_from: float | None = None, min_speed: float | None = None) -> tuple[float, float]:
    """(min, max) of the relative-motion angle in slip [deg] over samples with |v_r| ≥ ``min_speed``.

    ``min_speed`` [m/s] defaults to :data:`ANGLE_SPEED_FRACTION` × the first contact's sliding
    speed at rest at q = 0 (for the plates |Ω| r). NaNs when no sample qualifies (all stick).
    """
    t_from = traj.steady_from if t_from is None else float(t_from)
    if min_speed is None:
        min_speed = ANGLE_SPEED_FRACTION * sliding_speeds(traj.system, np.zeros(traj.system.n))[0]
    _, ang = relative_motion_angle(traj, t_from)
    vr = traj.relative_velocity[traj.t >= t_from]
    ang = ang[np.isfinite(ang) & (np.hypot(vr[:, 0], vr[:, 1]) >= min_speed)]
    if ang.size == 0:
        return math.nan, math.nan
    return float(ang.min()), float(ang.max())
