"""Figures of the model library (matplotlib only; the numbers come from :mod:`stickslip.studies.models`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..analysis.modes import flag_bits
from ._common import agg_figure, save_figure
from .trajectory import stick_intervals

__all__ = ["plot_hoffmann", "plot_belt", "plot_popp_stelter", "save_hoffmann_figure", "save_belt_figure",
           "save_popp_stelter_figure"]

#: Colours of the two contacts of a model (stick shading and phase-portrait segments).
CONTACT_COLOURS = ("tab:orange", "tab:purple")


def _damping_label(damping) -> str:
    return "no damping" if damping == (0.0, 0.0) else f"damping c = {damping[0]:g}, {damping[1]:g}"


def plot_hoffmann(sweeps, fig=None):
    """Frequencies |Im λ| and growth rates Re λ of steady sliding of ``hoffmann`` against μ.

    Parameters
    ----------
    sweeps : sequence of HoffmannSweep
        One per damping; markers are the eigenvalues of ``stability``, lines the roots of the
        characteristic polynomial, dashed verticals the onsets found by bisection.
    fig : matplotlib Figure, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = fig or agg_figure((9.0, 3.8))
    ax_f, ax_g = fig.subplots(1, 2, sharex=True)
    colours = ("tab:blue", "tab:red", "tab:green")
    for sweep, colour in zip(sweeps, colours):
        label = _damping_label(sweep.damping)
        mu = np.repeat(sweep.mu, 4)
        upper = sweep.eigenvalues.imag.ravel() >= 0.0
        ax_f.plot(mu[upper], sweep.eigenvalues.imag.ravel()[upper], ".", color=colour, ms=3, label=f"stability(): {label}")
        ax_g.plot(mu, sweep.eigenvalues.real.ravel(), ".", color=colour, ms=3)
        # branches by rank: the k-th largest frequency and the k-th largest real part at each μ
        freq = np.sort(np.abs(sweep.polynomial_eigenvalues.imag), axis=1)
        growth = np.sort(sweep.polynomial_eigenvalues.real, axis=1)
        for j in range(4):
            ax_f.plot(sweep.mu, freq[:, j], "-", color=colour, lw=0.7, alpha=0.7)
            ax_g.plot(sweep.mu, growth[:, j], "-", color=colour, lw=0.7, alpha=0.7)
        for ax in (ax_f, ax_g):
            ax.axvline(sweep.onset, color=colour, ls="--", lw=0.9)
        ax_g.annotate(f"onset μ = {sweep.onset:.4f}", (sweep.onset, 0.0), xytext=(4, 8 + 14 * colours.index(colour)),
                      textcoords="offset points", color=colour, fontsize=8)
    ax_f.set_ylabel("frequency |Im λ| [rad / time unit]")
    ax_g.set_ylabel("growth rate Re λ [1 / time unit]")
    ax_g.axhline(0.0, color="k", lw=0.6)
    for ax in (ax_f, ax_g):
        ax.set_xlabel("friction coefficient μ [-]")
        ax.grid(alpha=0.3)
    ax_f.plot([], [], "-", color="0.4", lw=0.6, label="roots of det(λ²M + λC + K(μ))")
    ax_f.legend(fontsize=7, loc="lower left")
    fig.suptitle("hoffmann: the two frequencies merge and a pair of eigenvalues leaves the imaginary axis",
                 fontsize=10)
    return fig


def plot_belt(attractors, window=40.0, fig=None):
    """``belt`` from bSTAB's templates: phase portrait (FP and LC) and the LC's displacement.

    Parameters
    ----------
    attractors : BeltAttractors
    window : float
        Length of the time history shown (the end of the LC run) [time units].
    fig : matplotlib Figure, optional
    """
    fig = fig or agg_figure((9.0, 3.8))
    ax_p, ax_t = fig.subplots(1, 2, width_ratios=(1.0, 1.3))
    V = attractors.runs["LC"].system.contacts[0].drive[0]
    for label, colour in (("FP", "tab:blue"), ("LC", "tab:red")):
        run = attractors.runs[label]
        x0, v0 = run.states[0, :2]
        late = run.t >= attractors.t_star
        ax_p.plot(run.states[:, 0], run.states[:, 1], "-", color=colour, lw=0.4, alpha=0.35)
        ax_p.plot(run.states[late, 0], run.states[late, 1], "-", color=colour, lw=1.4,
                  label=f"{label} template ({x0:g}, {v0:g}): max|x'| after t = {attractors.t_star:g}: "
                        f"{attractors.feature[label]:.3g}")
        ax_p.plot([x0], [v0], "o", color=colour, ms=4)
    ax_p.plot([attractors.steady_sliding], [0.0], "k*", ms=9, label=f"steady sliding x = μ(V) N / k = "
                                                                     f"{attractors.steady_sliding:.4f}")
    ax_p.axhline(V, color="0.5", lw=0.8, ls=":", label=f"belt speed V = {V:g} (stick)")
    ax_p.axvline(attractors.breakaway, color="tab:orange", lw=0.8, ls="--",
                 label=f"breakaway x = (μs N − c V) / k = {attractors.breakaway:g}")
    ax_p.set_xlabel("x [-]")
    ax_p.set_ylabel("x' [-]")
    ax_p.set_ylim(-2.4, 4.2)  # room for the legend above the cycle
    ax_p.legend(fontsize=6.5, loc="upper left")
    ax_p.grid(alpha=0.3)
    run = attractors.runs["LC"]
    shown = run.t >= run.t[-1] - window
    for a, b in stick_intervals(run.t[shown], flag_bits(run.mode[shown], 0, run.system.n_contacts).any(axis=1)):
        ax_t.axvspan(a, b, color="tab:orange", alpha=0.25, lw=0)
    ax_t.plot(run.t[shown], run.states[shown, 0], color="tab:red", lw=1.2, label="x (LC)")
    ax_t.axhline(attractors.breakaway, color="tab:orange", lw=0.8, ls="--")
    ax_t.plot([], [], "s", color="tab:orange", alpha=0.4, label="stick (x' = V, x linear in t)")
    ax_t.set_xlabel("time [-]")
    ax_t.set_ylabel("x [-]")
    ax_t.legend(fontsize=7, loc="lower right")
    ax_t.grid(alpha=0.3)
    fig.suptitle("belt (bSTAB friction case): steady sliding and the stick-slip cycle coexist", fontsize=10)
    return fig


def plot_popp_stelter(traj, periods_shown=3.0, period=None, fig=None):
    """The stick-slip orbit of ``popp-stelter``: each mass's displacement with the stick phases of
    its contact shaded, and each mass's phase portrait with its stick segment highlighted.

    Parameters
    ----------
    traj : Trajectory
        A run of ``popp-stelter`` long enough to be on its orbit at the end.
    periods_shown : float
        Window of the time histories, in periods of the orbit.
    period : float, optional
        The orbit's period; default the mean spacing of contact 0's last stick entries.
    fig : matplotlib Figure, optional
    """
    fig = fig or agg_figure((9.0, 5.2))
    axes = fig.subplots(2, 2, width_ratios=(1.6, 1.0))
    tr = traj.transitions
    if period is None:
        entries = tr.time[(tr.kind == 1) & (tr.contact == 0)]
        period = float(np.mean(np.diff(entries[-4:])))
    shown = traj.t >= traj.t[-1] - periods_shown * period
    t = traj.t[shown]
    n = traj.system.n
    sticks = flag_bits(traj.mode[shown], 0, traj.system.n_contacts)  # (k, nc): any width of mode word
    for c, colour in enumerate(CONTACT_COLOURS[:traj.system.n_contacts]):
        stuck = sticks[:, c]
        V = traj.system.contacts[c].drive[0]
        ax_t, ax_p = axes[c]
        for other, other_colour in enumerate(CONTACT_COLOURS[:traj.system.n_contacts]):
            for a, b in stick_intervals(t, sticks[:, other]):
                ax_t.axvspan(a, b, color=other_colour, alpha=0.25 if other == c else 0.08, lw=0)
        x, v = traj.states[shown, c], traj.states[shown, n + c]
        ax_t.plot(t, x, color="k", lw=1.0)
        ax_t.set_ylabel(f"{traj.system.dofs[c]} [-]")
        ax_t.grid(alpha=0.3)
        ax_p.plot(x, v, color="0.3", lw=0.8)
        ax_p.plot(np.where(stuck, x, np.nan), np.where(stuck, v, np.nan), color=colour, lw=3.0,
                  label=f"contact {c} ({traj.system.contacts[c].name}) sticks: x{c + 1}' = V = {V:g}")
        ax_p.set_xlabel(f"{traj.system.dofs[c]} [-]")
        ax_p.set_ylabel(f"{traj.system.dofs[c]}' [-]")
        ax_p.legend(fontsize=7, loc="lower left")
        ax_p.grid(alpha=0.3)
    axes[1][0].set_xlabel("time [-]")
    axes[0][0].set_title("shaded: stick of contact 0 (orange) and contact 1 (purple)", fontsize=8)
    stuck_both = np.count_nonzero(sticks[:, :2].all(axis=1))
    fig.suptitle(f"popp-stelter: stick-slip orbit, period {period:.4f}; the contacts stick in turn"
                 + ("" if stuck_both == 0 else " and together"), fontsize=10)
    return fig


def _save(fig, path) -> Path:
    path = Path(path)
    save_figure(fig, path, dpi=120)
    return path


def save_hoffmann_figure(sweeps, path, **kwargs) -> Path:
    """Draw :func:`plot_hoffmann` into a PNG file and return its path."""
    return _save(plot_hoffmann(sweeps, **kwargs), path)


def save_belt_figure(attractors, path, **kwargs) -> Path:
    """Draw :func:`plot_belt` into a PNG file and return its path."""
    return _save(plot_belt(attractors, **kwargs), path)


def save_popp_stelter_figure(traj, path, **kwargs) -> Path:
    """Draw :func:`plot_popp_stelter` into a PNG file and return its path."""
    return _save(plot_popp_stelter(traj, **kwargs), path)
