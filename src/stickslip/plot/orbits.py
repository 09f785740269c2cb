"""Plots of periodic orbits and Lyapunov-exponent convergence (matplotlib only; no simulation)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..orbits.problem import stick_summary
from ._common import save_figure, symbol
from .trajectory import shade_contacts, shown_coordinates

#: Exponents at or below this [1/s] are left out of :func:`plot_lyapunov_spectrum` by default:
#: the directions a stick phase collapses, −∞ in exact arithmetic.
SHOWN_ABOVE = -10.0

__all__ = ["plot_lyapunov_convergence", "plot_lyapunov_spectrum", "plot_orbit", "plot_multipliers",
           "save_orbit_figure", "save_lyapunov_spectrum_figure"]


def _figure_axes(ax, figsize):
    """(figure, axes): those of ``ax``, or a new constrained-layout figure of ``figsize`` [in]."""
    if ax is not None:
        return ax.figure, ax
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=figsize, constrained_layout=True)


def _model_text(result) -> str:
    """The model of an orbit result: the plates' variant with N and Ω, or the model's name."""
    p = result.params
    return result.model if p is None else f"{result.model}, N = {p.N:g} N, Ω = {p.Omega:g} rad/s"


def plot_lyapunov_convergence(results, labels=None, ax=None):
    """Running estimate of λ_max against averaging time, one curve per result.

    Parameters
    ----------
    results : LyapunovResult or sequence of them
    labels : sequence of str, optional
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not isinstance(results, (list, tuple)):
        results = [results]
    labels = labels or [_model_text(r) for r in results]
    fig, ax = _figure_axes(ax, (6.4, 3.6))
    for r, lab in zip(results, labels):
        ax.plot(r.time, r.estimate, label=f"{lab}: λ = {r.exponent:.4f} ± {r.standard_error:.4f} 1/s")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("averaging time [s]")
    ax.set_ylabel("λ_max estimate [1/s]")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    return fig


def plot_lyapunov_spectrum(spectrum, reference=None, n_show=None, ax=None):
    """Running estimates of every Lyapunov exponent against averaging time.

    Parameters
    ----------
    spectrum : LyapunovSpectrum
    reference : array-like, optional
        Reference exponents drawn as dashed lines [1/s] (e.g. ln|μ_i|/T of a periodic orbit).
    n_show : int, optional
        Show only the n largest (by final value); default all above −10 1/s (the stick-collapsed
        directions, −∞ in exact arithmetic, are left out).
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _figure_axes(ax, (6.4, 3.8))
    order = np.argsort(-spectrum.exponents)
    if n_show is None:
        order = [i for i in order if spectrum.exponents[i] > SHOWN_ABOVE]
        left_out = f"{spectrum.exponents.size - len(order)} exponents below {SHOWN_ABOVE:g} 1/s not shown".replace("-", "−")
    else:
        order = order[:n_show]
        left_out = f"{spectrum.exponents.size - len(order)} smallest exponents not shown"
    for rank, i in enumerate(order, start=1):
        ax.plot(spectrum.time, spectrum.estimate[:, i], lw=1.0,
                label=f"λ{rank} = {spectrum.exponents[i]:+.4f} 1/s")
    if reference is not None:
        for v in np.asarray(reference, dtype=float):
            if v > SHOWN_ABOVE:
                ax.axhline(v, color="0.4", lw=0.6, ls="--")
    ax.axhline(0.0, color="k", lw=0.6)
    title = (f"model {_model_text(spectrum)}: averaged over "
             f"{spectrum.time[-1]:g} s after a {spectrum.t_transient:g} s transient")
    if len(order) < spectrum.exponents.size:
        title += f"\n({left_out})"
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("averaging time [s]")
    ax.set_ylabel("Lyapunov exponent estimate [1/s]")
    ax.legend(fontsize=6, ncol=2)
    ax.grid(alpha=0.3)
    return fig


def plot_orbit(orbit, traj, ax=None):
    """The observed coordinate (the plates' φ) over one period of a periodic orbit, stick phases shaded.

    Parameters
    ----------
    orbit : PeriodicOrbit
    traj : Trajectory
        The orbit simulated over one period from its section state (``orbit.trajectory(1.0)``).
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _figure_axes(ax, (6.4, 3.6))
    system = orbit.system
    shade_contacts(ax, traj.t, traj.mode, system, traj.t[0], traj.t[-1])
    shown, unit = shown_coordinates(system)
    for j in shown:
        ax.plot(traj.t, traj.states[:, j], lw=1.2, label=symbol(system.dofs[j]))
    ax.set_xlim(0.0, orbit.period)
    ax.set_xlabel("time from the section [s]")
    ax.set_ylabel(("coordinates" if len(shown) > 1 else symbol(system.dofs[shown[0]])) + (f" [{unit}]" if unit else ""))
    contacts = stick_summary(traj, orbit.period)["contacts"]
    phases = ", ".join(f"{c['stick_phases']} of {name}" for name, c in contacts.items()) if len(contacts) > 1 else \
        str(orbit.stick_phases)
    ax.set_title(f"T = {orbit.period:.6g} s ({orbit.frequency:.6g} Hz), stick phases: {phases}", fontsize=9)
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)
    return fig


def plot_multipliers(orbit, ax=None):
    """Floquet multipliers of a periodic orbit in the complex plane with the unit circle.

    Parameters
    ----------
    orbit : PeriodicOrbit
        The trivial multiplier (closest to 1) is drawn as an open circle, the others as crosses.
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _figure_axes(ax, (4.0, 4.0))
    angle = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(np.cos(angle), np.sin(angle), color="k", lw=0.6)
    mu = np.asarray(orbit.nontrivial_multipliers)
    triv = orbit.trivial_multiplier
    ax.plot(mu.real, mu.imag, "x", color="tab:red" if not orbit.stable else "tab:blue", ms=7,
            label=f"μ (max |μ| = {np.max(np.abs(mu)):.6g})" if mu.size else "μ")
    ax.plot([triv.real], [triv.imag], "o", mfc="none", color="0.3", ms=8, label=f"trivial μ = {triv.real:.6g}")
    reach = max(1.1, 1.05 * float(np.max(np.abs(orbit.multipliers))))
    ax.set_xlim(-reach, reach)
    ax.set_ylim(-reach, reach)
    ax.set_aspect("equal")
    ax.axhline(0.0, color="0.7", lw=0.5)
    ax.axvline(0.0, color="0.7", lw=0.5)
    ax.set_xlabel("Re μ")
    ax.set_ylabel("Im μ")
    ax.set_title(f"Floquet multipliers ({orbit.options.get('monodromy', 'finite-difference')}): "
                 f"{'stable' if orbit.stable else 'unstable'}", fontsize=9)
    ax.legend(fontsize=7, loc="lower left")
    return fig


def save_orbit_figure(orbit, traj, path, *, dpi: int = 110) -> Path:
    """:func:`plot_orbit` and :func:`plot_multipliers` side by side into a PNG file (Agg backend).

    Parameters
    ----------
    orbit : PeriodicOrbit
    traj : Trajectory
        One period of the orbit (``orbit.trajectory(1.0)``).
    path : str or Path
    dpi : int

    Returns
    -------
    Path
    """
    plt = _pyplot_agg()
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.2), layout="constrained", width_ratios=(1.6, 1.0))
    plot_orbit(orbit, traj, axes[0])
    plot_multipliers(orbit, axes[1])
    fig.suptitle(f"Periodic orbit, model {_model_text(orbit)}, section {orbit.section.name}", fontsize=10)
    return _save(fig, path, dpi)


def save_lyapunov_spectrum_figure(spectrum, path, *, dpi: int = 110) -> Path:
    """:func:`plot_lyapunov_spectrum` (the running estimate of every exponent) into a PNG file.

    Parameters
    ----------
    spectrum : LyapunovSpectrum
    path : str or Path
    dpi : int

    Returns
    -------
    Path
    """
    _pyplot_agg()
    return _save(plot_lyapunov_spectrum(spectrum), path, dpi)


def _pyplot_agg():
    """pyplot on the Agg backend (files only, no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path, dpi: int) -> Path:
    """Write ``fig`` to ``path`` and close it; returns the path."""
    import matplotlib.pyplot as plt

    path = Path(path)
    save_figure(fig, path, dpi=dpi)
    plt.close(fig)
    return path
