"""Peaks of a response located as events (ẋ = 0, ẍ < 0) instead of sampled maxima.

The samples carry both x and ẋ (φ and φ̇ are states), so on each sample interval the response
is represented by the cubic Hermite interpolant of (x, ẋ) at its ends, which is fourth-order
accurate in the step. A peak is a root of the interpolant's derivative where it changes sign
from + to − (ẋ = 0 with ẍ < 0); its value is the interpolant there. With the accelerations
ẍ at the samples as well, the root is located on the Hermite interpolant of (ẋ, ẍ) by
:func:`stickslip.analysis.signal.hermite_crossings` and the value read off the (x, ẋ) cubic.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .signal import hermite_crossings

__all__ = ["Peaks", "find_peaks", "hermite_value", "trajectory_peaks"]

#: Slack on the unit interval for a root of the Hermite derivative [-]: 1e-9 of a sample
#: interval is far below any physical timing and far above the round-off of the quadratic.
ROOT_SLACK = 1e-9


@dataclasses.dataclass(frozen=True)
class Peaks:
    """Local maxima of a response.

    Attributes
    ----------
    time : ndarray (k,)
        Instants of ẋ = 0 with ẍ < 0 [s].
    value : ndarray (k,)
        x at those instants [unit of x].
    """

    time: np.ndarray
    value: np.ndarray

    def __len__(self) -> int:
        return int(self.time.size)


def hermite_value(t, x, dx, index, when):
    """Cubic Hermite interpolant of samples (x, ẋ) at ``when`` inside intervals ``index``.

    Parameters
    ----------
    t, x, dx : ndarray (n,)
        Sample times [s], values and rates.
    index : ndarray (k,) int
        Interval i means [t[i], t[i+1]].
    when : ndarray (k,)
        Times inside those intervals [s].
    """
    index = np.asarray(index, dtype=np.intp)
    h = t[index + 1] - t[index]
    s = (np.asarray(when, dtype=float) - t[index]) / h
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    return h00 * x[index] + h10 * h * dx[index] + h01 * x[index + 1] + h11 * h * dx[index + 1]


def _quadratic_roots(x0, x1, m0, m1):
    """Roots s in [0, 1] of the derivative of the unit-interval Hermite cubic where it falls
    through zero. Returns (s, valid) arrays; H'(s) = a s² + b s + c."""
    a = 6 * x0 + 3 * m0 - 6 * x1 + 3 * m1
    b = -6 * x0 - 4 * m0 + 6 * x1 - 2 * m1
    c = m0
    s = np.full(x0.shape, np.nan)
    disc = b * b - 4 * a * c
    ok = disc >= 0
    sq = np.sqrt(np.where(ok, disc, 0.0))
    # numerically stable pair of roots; a → 0 degenerates to the linear root −c/b
    qq = -0.5 * (b + np.copysign(sq, b))
    with np.errstate(divide="ignore", invalid="ignore"):
        r1 = np.where(a != 0, qq / a, np.nan)
        r2 = np.where(qq != 0, c / qq, np.nan)
    for r in (r1, r2):
        slope = 2 * a * r + b  # H''(s): negative for a maximum
        # a root on a sample (ẋ = 0 there to round-off) may land a few ulps outside [0, 1]
        take = ok & np.isfinite(r) & (r >= -ROOT_SLACK) & (r <= 1.0 + ROOT_SLACK) & (slope <= 0) & np.isnan(s)
        s = np.where(take, np.clip(r, 0.0, 1.0), s)
    return s, np.isfinite(s)


def find_peaks(t, x, dx, ddx=None) -> Peaks:
    """Local maxima of x(t) as events ẋ = 0, ẍ < 0.

    Parameters
    ----------
    t : ndarray (n,)
        Sample times [s], increasing.
    x, dx : ndarray (n,)
        The response and its time derivative at the samples.
    ddx : ndarray (n,), optional
        Second derivative at the samples. When given, ẋ = 0 is located on the Hermite
        interpolant of (ẋ, ẍ); otherwise on the derivative of the (x, ẋ) cubic.

    Returns
    -------
    Peaks
        Times and values (value from the (x, ẋ) cubic in both cases).
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    dx = np.asarray(dx, dtype=float)
    if t.size < 2:
        return Peaks(np.empty(0), np.empty(0))
    if ddx is not None:
        # up-crossings of −ẋ through 0 are the instants where ẋ falls through zero
        times, idx = hermite_crossings(t, -dx, -np.asarray(ddx, dtype=float), 0.0)
        # a crossing that lands exactly on a sample belongs to the interval before it
        return Peaks(times, hermite_value(t, x, dx, idx, times))
    # ẋ ≥ 0 at the left end and ≤ 0 at the right end, not both zero (plateaus are not peaks)
    i = np.flatnonzero((dx[:-1] > 0) & (dx[1:] <= 0))
    if i.size == 0:
        return Peaks(np.empty(0), np.empty(0))
    h = t[i + 1] - t[i]
    s, ok = _quadratic_roots(x[i], x[i + 1], dx[i] * h, dx[i + 1] * h)
    i, s, h = i[ok], s[ok], h[ok]
    times = t[i] + s * h
    return Peaks(times, hermite_value(t, x, dx, i, times))


def trajectory_peaks(traj, t_from: float | None = None, dof: str | None = None) -> Peaks:
    """Peaks of one DOF of a :class:`~stickslip.Trajectory` for t ≥ ``t_from`` [s].

    ``t_from`` defaults to the trajectory's ``steady_from``; ``dof`` is a name of the model's
    dofs, default its observed one (the plates' φ).
    """
    system = traj.system
    dof = system.dofs[system.observed_index] if dof is None else dof
    if dof not in system.dofs:
        raise ValueError(f"unknown DOF {dof!r}; choose one of {', '.join(system.dofs)}")
    j = system.dofs.index(dof)
    t_from = traj.steady_from if t_from is None else float(t_from)
    sel = traj.t >= t_from
    return find_peaks(traj.t[sel], traj.states[sel, j], traj.states[sel, system.n + j])
