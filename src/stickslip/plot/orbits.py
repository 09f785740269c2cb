"""Plots of periodic orbits and Lyapunov-exponent convergence (matplotlib only; no simulation)."""

from __future__ import annotations

import numpy as np

__all__ = ["plot_lyapunov_convergence"]


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
