"""Figures of the step-size study (paper Figs. 5 and 6): steady-state φ and |F| per Δt."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._common import save_figure

__all__ = ["plot_timestep_method", "plot_timestep_errors", "save_timestep_figures"]

_PAPER_FIG = {"aeom": "Fig. 5", "naeom": "Fig. 6"}


def plot_timestep_method(study, method: str, fig=None):
    """Steady-state φ and |F| of ``method`` for each Δt (one row per Δt), converged ``event``
    reference dashed. The last seconds of each run are shown against time since the last
    up-crossing of the reference's mid level, so the runs are aligned in phase.

    Returns the matplotlib Figure.
    """
    import matplotlib.pyplot as plt

    runs = study.fixed(method)
    ref = study.reference
    if fig is None:
        fig, axes = plt.subplots(len(runs), 2, figsize=(10, 1.9 * len(runs) + 1.2), sharex=True, squeeze=False,
                                 layout="constrained")
    else:
        axes = np.array(fig.subplots(len(runs), 2, sharex=True, squeeze=False))
    level = 0.5 * (ref.phi_min + ref.phi_max)
    static = (study.params.mu_k + study.params.delta_mu) * study.params.N

    def aligned(run):
        t, phi = run.window_t, run.window_phi
        up = np.flatnonzero((phi[:-1] < level) & (phi[1:] >= level))
        t_start = t[up[0]] if up.size else t[0]
        return t - t_start

    tr = aligned(ref)
    for row, run in zip(axes, runs):
        tt = aligned(run)
        for ax, y_run, y_ref, unit in ((row[0], run.window_phi, ref.window_phi, "φ [rad]"),
                                       (row[1], run.window_F, ref.window_F, "|F| [N]")):
            ax.plot(tr, y_ref, "k--", lw=0.9, label=f"event, rtol {ref.rtol:g} (reference)")
            ax.plot(tt, y_run, color="tab:blue", lw=1.1, label=f"{method.upper()} (Δt of the row)")
            ax.set_ylabel(unit)
            ax.grid(alpha=0.3)
        row[1].axhline(static, color="tab:red", lw=0.7, ls=":", label="μs N")
        err = run.errors
        row[0].set_title(f"Δt = {run.dt:g} s: relative errors of f {err['freq_error']:.1e}, of φ peak-to-peak "
                         f"{err['phi_pp_error']:.1e}; {run.stick_phases} stick phases", fontsize=9, loc="left")
    fig.legend(handles=axes[0, 1].get_lines(), loc="outside lower center", ncol=3, fontsize=9, frameon=False)
    for ax in axes[-1]:
        ax.set_xlim(0.0, min(tr[-1], 1.5))
        ax.set_xlabel("time since an up-crossing of the mid level of φ [s]")
    fig.suptitle(f"{_PAPER_FIG.get(method, '')}: steady-state φ and |F| by {method.upper()} for various Δt "
                 f"(Ω = {study.params.Omega:g} rad/s, N = {study.params.N:g} N)", fontsize=10)
    return fig


def plot_timestep_errors(study, fig=None):
    """Error of the steady state against wall time, all methods: the cost at equal accuracy."""
    import matplotlib.pyplot as plt

    if fig is None:
        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    else:
        axes = fig.subplots(1, 2)
    styles = {"aeom": ("tab:blue", "o"), "naeom": ("tab:orange", "s"), "event": ("k", "^")}
    floor = 1e-12  # plotted instead of an exact 0 on the log axis
    for method, (color, marker) in styles.items():
        runs = study.fixed(method) if method != "event" else study.event_runs()
        if not runs:
            continue
        wall = [max(r.wall_time_s, 1e-6) for r in runs]
        for ax, key, title in ((axes[0], "phi_shape_error", "φ waveform error / Δφ_ref"),
                               (axes[1], "F_shape_error", "|F| waveform error / μs N")):
            err = [max(r.errors[key], floor) for r in runs]
            ax.loglog(wall, err, marker=marker, color=color, label=method.upper() if method != "event" else "event")
            for w, e, r in zip(wall, err, runs):
                ax.annotate(f"{r.dt:g}" if r.dt is not None else f"{r.rtol:g}", (w, e), fontsize=7,
                            textcoords="offset points", xytext=(4, 3))
            ax.set_xlabel(f"wall time for 0–{study.t_end:g} s [s]")
            ax.set_title(title, fontsize=10)
            ax.grid(alpha=0.3, which="both")
    axes[0].legend()
    fig.suptitle("Cost against accuracy (labels: Δt [s] or event rtol)", fontsize=10)
    fig.tight_layout()
    return fig


def save_timestep_figures(study, out_dir) -> dict:
    """Write ``fig5_aeom.png``, ``fig6_naeom.png`` and ``timestep_errors.png``; returns the paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {}
    for method, name in (("aeom", "fig5_aeom.png"), ("naeom", "fig6_naeom.png")):
        if study.fixed(method):
            fig = plot_timestep_method(study, method)
            paths[method] = out / name
            save_figure(fig, paths[method], dpi=120)
            plt.close(fig)
    fig = plot_timestep_errors(study)
    paths["errors"] = out / "timestep_errors.png"
    save_figure(fig, paths["errors"], dpi=120)
    plt.close(fig)
    return paths
