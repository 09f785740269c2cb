"""Overview figure of one trajectory: φ, ψ with stick shaded, |F| against μs N, phase plot, spectrum."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..analysis.steady import spectrum
from ._common import param_text

__all__ = ["plot_trajectory", "save_trajectory_figure", "stick_intervals"]


def stick_intervals(t: np.ndarray, mode: np.ndarray) -> list[tuple[float, float]]:
    """Contiguous stick intervals (start, end) [s] of a sampled mode series (1 = stick)."""
    m = np.asarray(mode).astype(np.int8)
    edges = np.diff(np.concatenate([[0], m, [0]]))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return [(float(t[a]), float(t[b])) for a, b in zip(starts, ends)]


def _shade_stick(ax, intervals, t_lo, t_hi, label=True):
    first = True
    for a, b in intervals:
        if b < t_lo or a > t_hi:
            continue
        ax.axvspan(a, b, color="tab:orange", alpha=0.25, lw=0, label="stick" if (first and label) else None)
        first = False


def plot_trajectory(traj, *, window: float | None = None, fig=None):
    """Four-panel overview of a :class:`~stickslip.Trajectory`.

    Parameters
    ----------
    traj : Trajectory
    window : float, optional
        Length [s] of the time-history window shown (ending at the last sample); default
        ``min(10 s, steady window)``. Its title says which seconds of the run it shows. The
        phase plot and spectrum use the steady window, named in their titles.
    fig : matplotlib Figure, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    t = traj.t
    t_first, t_hi = float(t[0]), float(t[-1])
    steady = t >= traj.steady_from
    t_steady = float(t[steady][0]) if np.any(steady) else t_first
    if window is None:
        window = min(10.0, t_hi - traj.steady_from) if steady.sum() > 1 else t_hi - t_first
    t_lo = max(t_first, t_hi - window)
    show = t >= t_lo
    intervals = stick_intervals(t, traj.mode)
    if fig is None:
        fig = plt.figure(figsize=(11, 8.4), constrained_layout=True)
    gs = fig.add_gridspec(3, 2)
    ax_phi = fig.add_subplot(gs[0, :])
    ax_F = fig.add_subplot(gs[1, :], sharex=ax_phi)
    ax_phase = fig.add_subplot(gs[2, 0])
    ax_spec = fig.add_subplot(gs[2, 1])
    above = {"loc": "lower right", "bbox_to_anchor": (1.0, 1.0), "frameon": False, "fontsize": 9}  # hides no data

    ax_phi.plot(t[show], traj.states[show, 4], lw=1.0, label="φ")
    ax_phi.plot(t[show], traj.states[show, 5], lw=1.0, label="ψ")
    _shade_stick(ax_phi, intervals, t_lo, t_hi)
    ax_phi.set_xlim(t_lo, t_hi)
    ax_phi.set_ylabel("angle [rad]")
    whole = t_lo <= t_first
    span = f"{_g(t_lo)}–{_g(t_hi)} s"
    ax_phi.set_title(f"the whole run, {span}" if whole else f"last {_g(t_hi - t_lo)} s of the run ({span} of "
                     f"{_g(t_first)}–{_g(t_hi)} s)", fontsize=10, loc="left")
    ax_phi.legend(ncol=3, **above)

    ax_F.plot(t[show], traj.friction_magnitude[show], lw=1.0, color="tab:green", label="|F|")
    ax_F.axhline(traj.params.mu_s * traj.params.N, color="k", ls="--", lw=0.8, label="μs N")
    _shade_stick(ax_F, intervals, t_lo, t_hi, label=False)
    ax_F.set_xlabel("t [s]")
    ax_F.set_ylabel("friction force [N]")
    ax_F.legend(ncol=2, **above)

    steady_span = f"steady window {_g(t_steady)}–{_g(t_hi)} s"
    phi, dphi = traj.states[steady, 4], traj.states[steady, 10]
    ax_phase.plot(phi, dphi, lw=0.6)
    ax_phase.set_xlabel("φ [rad]")
    ax_phase.set_ylabel("dφ/dt [rad/s]")
    ax_phase.set_title(f"phase plot ({steady_span})", fontsize=10)

    f, a = spectrum(t[steady], phi)
    ax_spec.semilogy(f, np.maximum(a, 1e-12), lw=0.8)
    s = traj.steady
    if np.isfinite(s.fundamental_frequency_hz):
        # the summary's frequency is the fundamental only when φ repeats; otherwise the highest peak
        name = "fundamental" if getattr(s, "periodic", False) else "dominant (not periodic)"
        ax_spec.axvline(s.fundamental_frequency_hz, color="tab:red", ls=":", lw=1,
                        label=f"{name} {s.fundamental_frequency_hz:.4g} Hz")
        ax_spec.legend(loc="best")
        ax_spec.set_xlim(0, min(f[-1], 10 * s.fundamental_frequency_hz + 1))
    ax_spec.set_xlabel("frequency [Hz]")
    ax_spec.set_ylabel("amplitude of φ [rad]")
    ax_spec.set_title(f"spectrum of φ ({steady_span})", fontsize=10)
    p = traj.params
    fig.suptitle(f"model {traj.model}: " + ", ".join(param_text(k, getattr(p, k)) for k in
                                                     ("N", "Omega", "mu_k", "delta_mu", "alpha")) + f" ({traj.method})")
    return fig


def _g(value: float) -> str:
    """Seconds as printed in titles: ``90``, ``2.5``, ``12.35``."""
    return f"{value:.4g}"


def save_trajectory_figure(traj, path: str | Path, **kwargs) -> Path:
    """Draw :func:`plot_trajectory` into a PNG file (Agg backend) and return its path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plot_trajectory(traj, **kwargs)
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
