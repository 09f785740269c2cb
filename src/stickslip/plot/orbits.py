"""Plots of periodic orbits and Lyapunov-exponent convergence (matplotlib only; no simulation)."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_lyapunov_convergence", "plot_lyapunov_spectrum"]


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
    import matplotlib.pyplot as plt

    if not isinstance(results, (list, tuple)):
        results = [results]
    labels = labels or [f"{r.model}, N = {r.params.N:g} N, Ω = {r.params.Omega:g} rad/s" for r in results]
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.4, 3.6), constrained_layout=True)
    else:
        fig = ax.figure
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
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(6.4, 3.8), constrained_layout=True)
    else:
        fig = ax.figure
    order = np.argsort(-spectrum.exponents)
    if n_show is None:
        order = [i for i in order if spectrum.exponents[i] > -10.0]
    else:
        order = order[:n_show]
    for rank, i in enumerate(order, start=1):
        ax.plot(spectrum.time, spectrum.estimate[:, i], lw=1.0,
                label=f"λ{rank} = {spectrum.exponents[i]:+.4f} 1/s")
    if reference is not None:
        for v in np.asarray(reference, dtype=float):
            if v > -10.0:
                ax.axhline(v, color="0.4", lw=0.6, ls="--")
    ax.axhline(0.0, color="k", lw=0.6)
    p = spectrum.params
    ax.set_title(f"{spectrum.model}, N = {p.N:g} N, Ω = {p.Omega:g} rad/s", fontsize=9)
    ax.set_xlabel("averaging time [s]")
    ax.set_ylabel("Lyapunov exponent estimate [1/s]")
    ax.legend(fontsize=6, ncol=2)
    ax.grid(alpha=0.3)
    return fig
