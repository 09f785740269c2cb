"""Overview figure of one trajectory: coordinates with stick shaded, |F| against its stick limit (μs N,
or μs λ for a unilateral contact) per contact, the
phase plot and spectrum of the observed coordinate (the plates: φ, ψ and the φ spectrum)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..analysis.signal import spectrum
from ._common import param_text, save_figure, symbol

__all__ = ["plot_trajectory", "save_trajectory_figure", "stick_intervals", "shade_contacts", "shown_coordinates",
           "stick_limit_label", "friction_lines"]


def stick_intervals(t: np.ndarray, mode: np.ndarray) -> list[tuple[float, float]]:
    """Contiguous stick intervals (start, end) [s] of a sampled mode series (non-zero: a contact sticks)."""
    m = (np.asarray(mode) != 0).astype(np.int8)
    edges = np.diff(np.concatenate([[0], m, [0]]))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return [(float(t[a]), float(t[b])) for a, b in zip(starts, ends)]


def _shade_stick(ax, intervals, t_lo, t_hi, label="stick", color="tab:orange", hatch=None):
    first = True
    for a, b in intervals:
        if b < t_lo or a > t_hi:
            continue
        ax.axvspan(a, b, facecolor=color, alpha=0.25, lw=0, hatch=hatch, label=label if first and label else None)
        first = False


#: Shading colours of the contacts' stick phases, by contact (cycled).
STICK_COLORS = ("tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:olive")


def shade_contacts(ax, t, mode, system, t_lo, t_hi, labels: bool = True) -> None:
    """Shade the stick phases of each contact of ``system`` in the sampled ``mode`` (bit c: contact c),
    one colour per contact, labelled ``stick`` (one contact) or ``<contact name> sticks``; the open
    phases of unilateral contacts (bit nc + c) hatched grey, labelled ``open`` or ``<name> open``."""
    mode = np.asarray(mode).astype(np.int64)
    names = system.contact_names
    nc = len(names)
    for c, name in enumerate(names):
        label = ("stick" if nc == 1 else f"{name} sticks") if labels else None
        _shade_stick(ax, stick_intervals(t, (mode >> c) & 1), t_lo, t_hi, label=label,
                     color=STICK_COLORS[c % len(STICK_COLORS)])
        if system.contacts[c].unilateral:
            label = ("open" if nc == 1 else f"{name} open") if labels else None
            _shade_stick(ax, stick_intervals(t, (mode >> (nc + c)) & 1), t_lo, t_hi, label=label, color="0.5",
                         hatch="//")


def stick_limit_label(contact) -> str:
    """The legend's name of a contact's stick limit μs × normal force: ``μs N`` for a pressed
    contact (N its prescribed load), ``μs λ`` for a unilateral one, whose normal force is its
    contact force λ (a compliant law's, 0 while open), and ``μs λ (multiplier)`` for a rigid one,
    whose λ is the multiplier that keeps it closed."""
    if not contact.unilateral:
        return "μs N"
    return "μs λ (multiplier)" if contact.normal.law == "rigid" else "μs λ"


def friction_lines(traj) -> list[dict]:
    """What the friction panel draws, per contact: ``label`` and ``force`` (k,) of |F| [N], and
    ``limit_label`` and ``limit`` (k,) of the stick limit μs × normal force [N]
    (:func:`stick_limit_label`); with several contacts each label ends with the contact's name."""
    system = traj.system
    nc = system.n_contacts
    lines = []
    for c, contact in enumerate(system.contacts):
        tag = "" if nc == 1 else f" {contact.name or c}"
        lines.append({"label": f"|F|{tag}", "force": np.hypot(traj.friction[:, 2 * c], traj.friction[:, 2 * c + 1]),
                      "limit_label": stick_limit_label(contact) + tag,
                      "limit": contact.friction.mu_s * traj.normal_force[:, c]})
    return lines


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
    if fig is None:
        fig = plt.figure(figsize=(11, 8.4), constrained_layout=True)
    gs = fig.add_gridspec(3, 2)
    ax_phi = fig.add_subplot(gs[0, :])
    ax_F = fig.add_subplot(gs[1, :], sharex=ax_phi)
    ax_phase = fig.add_subplot(gs[2, 0])
    ax_spec = fig.add_subplot(gs[2, 1])
    above = {"loc": "lower right", "bbox_to_anchor": (1.0, 1.0), "frameon": False, "fontsize": 9}  # hides no data

    system = traj.system
    shown, unit = shown_coordinates(system)
    for j in shown:
        ax_phi.plot(t[show], traj.states[show, j], lw=1.0, label=symbol(system.dofs[j]))
    shade_contacts(ax_phi, t, traj.mode, system, t_lo, t_hi)
    ax_phi.set_xlim(t_lo, t_hi)
    ax_phi.set_ylabel(("angle" if unit == "rad" else "coordinate") + (f" [{unit}]" if unit else ""))
    whole = t_lo <= t_first
    span = f"{_g(t_lo)}–{_g(t_hi)} s"
    ax_phi.set_title(f"the whole run, {span}" if whole else f"last {_g(t_hi - t_lo)} s of the run ({span} of "
                     f"{_g(t_first)}–{_g(t_hi)} s)", fontsize=10, loc="left")
    ax_phi.legend(ncol=3, **above)

    nc = system.n_contacts
    for drawn in friction_lines(traj):
        line, = ax_F.plot(t[show], drawn["force"][show], lw=1.0, color="tab:green" if nc == 1 else None,
                          label=drawn["label"])
        ax_F.plot(t[show], drawn["limit"][show], color="k" if nc == 1 else line.get_color(), ls="--", lw=0.8,
                  label=drawn["limit_label"])
    shade_contacts(ax_F, t, traj.mode, system, t_lo, t_hi, labels=False)
    ax_F.set_xlabel("t [s]")
    ax_F.set_ylabel("friction force [N]")
    ax_F.legend(ncol=2 * nc, **above)

    steady_span = f"steady window {_g(t_steady)}–{_g(t_hi)} s"
    k = traj.observed
    sym = symbol(system.dofs[k])
    unit = system.units.get(system.dofs[k], "").strip("-")
    phi, dphi = traj.states[steady, k], traj.states[steady, system.n + k]
    ax_phase.plot(phi, dphi, lw=0.6)
    ax_phase.set_xlabel(sym + (f" [{unit}]" if unit else ""))
    ax_phase.set_ylabel(f"d{sym}/dt" + (f" [{unit}/s]" if unit else ""))
    ax_phase.set_title(f"phase plot ({steady_span})", fontsize=10)

    f, a = spectrum(t[steady], phi)
    ax_spec.semilogy(f, np.maximum(a, 1e-12), lw=0.8)
    s = traj.steady
    if np.isfinite(s.frequency_hz):
        # the fundamental only when the coordinate repeats; otherwise the highest peak
        name = "fundamental" if s.periodic else "dominant (not periodic)"
        ax_spec.axvline(s.frequency_hz, color="tab:red", ls=":", lw=1, label=f"{name} {s.frequency_hz:.4g} Hz")
        ax_spec.legend(loc="best")
        ax_spec.set_xlim(0, min(f[-1], 10 * s.frequency_hz + 1))
    ax_spec.set_xlabel("frequency [Hz]")
    ax_spec.set_ylabel(f"amplitude of {sym}" + (f" [{unit}]" if unit else ""))
    ax_spec.set_title(f"spectrum of {sym} ({steady_span})", fontsize=10)
    p = traj.params
    if p is not None:
        fig.suptitle(f"model {traj.model}: " + ", ".join(param_text(k, getattr(p, k)) for k in
                                                         ("N", "Omega", "mu_k", "delta_mu", "alpha")) + f" ({traj.method})")
    else:
        fig.suptitle(f"model {system.name} ({system.source}; {traj.method})")
    return fig


#: Most coordinates drawn in a time history.
MAX_SHOWN = 4


def shown_coordinates(system) -> tuple[list[int], str]:
    """Indices of the coordinates a time history shows and their common unit: the observed one
    and the other free DOFs in its unit (the plates' φ and ψ), at most :data:`MAX_SHOWN`."""
    j0 = system.observed_index
    unit = system.units.get(system.dofs[j0], "").strip("-")
    same = [j for j in range(system.n) if system.free[j] and j != j0
            and system.units.get(system.dofs[j], "").strip("-") == unit]
    return ([j0] + same)[:MAX_SHOWN], unit


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
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path
