"""Figures of the complex eigenvalue analysis of sparse models: the mode-coupling diagram and mode shapes."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["plot_mode_coupling", "plot_mode_shape", "cell_edges"]

#: The edges of each element type (pairs of its corner nodes, VTK's order; mid-side nodes left out).
_EDGES = {
    "line": [(0, 1)], "line3": [(0, 1)],
    "triangle": [(0, 1), (1, 2), (2, 0)], "triangle6": [(0, 1), (1, 2), (2, 0)],
    "quad": [(0, 1), (1, 2), (2, 3), (3, 0)], "quad8": [(0, 1), (1, 2), (2, 3), (3, 0)],
    "tetra": [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)],
    "pyramid": [(0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (1, 4), (2, 4), (3, 4)],
    "wedge": [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)],
    "hexahedron": [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)],
}
_EDGES["tetra10"], _EDGES["wedge15"], _EDGES["hexahedron20"] = _EDGES["tetra"], _EDGES["wedge"], _EDGES["hexahedron"]


def cell_edges(cells) -> np.ndarray:
    """The distinct edges (e, 2) of a mesh's elements (:attr:`~stickslip.model.sparse_form.NodeMap.cells`)
    as pairs of node indices."""
    pairs = [block[:, list(edge)] for kind, block in cells for edge in _EDGES.get(kind, [])]
    if not pairs:
        return np.zeros((0, 2), dtype=np.int64)
    return np.unique(np.sort(np.vstack(pairs), axis=1), axis=0)


def _onset_labels(onsets) -> list[tuple[float, str]]:
    """One label per distinct onset μ (as printed, 4 digits), in increasing μ: onsets of several
    branch pairs at one μ share a label, and the caller staggers neighbours' heights so that close
    labels do not overlap."""
    labels: dict[str, float] = {}
    for onset in sorted(onsets, key=lambda o: o["mu"]):
        labels.setdefault(f"μ = {onset['mu']:.4g}", float(onset["mu"]))
    return [(mu, text) for text, mu in labels.items()]


def plot_mode_coupling(result, *, hz: bool = False, ax=None):
    """Frequencies (top) and real parts (bottom) of the band's eigenvalues against μ, each branch a
    line, the instabilities' onsets (coalescences) marked.

    Parameters
    ----------
    result : ModeCoupling
    hz : bool
        Frequencies in Hz (Im λ / 2π) instead of rad/s.
    ax : pair of Axes, optional
    """
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(2, 1, sharex=True, figsize=(6.4, 6.0), constrained_layout=True)
    else:
        fig = ax[0].figure
    scale = 1 / (2 * math.pi) if hz else 1.0
    lam = result.eigenvalues
    unstable = result.unstable
    for j in range(lam.shape[1]):
        ax[0].plot(result.mu, lam[:, j].imag * scale, color="0.35", lw=1.0)
        ax[1].plot(result.mu, lam[:, j].real, color="0.35", lw=1.0)
        for axis, values in ((ax[0], lam[:, j].imag * scale), (ax[1], lam[:, j].real)):
            axis.plot(result.mu, np.where(unstable[:, j], values, np.nan), color="tab:red", lw=2.0)
    for onset in result.onsets:
        ax[0].plot(onset["mu"], onset["angular_frequency"] * scale, "o", mfc="none", mec="tab:red", ms=9)
        ax[1].plot(onset["mu"], 0.0, "o", mfc="none", mec="tab:red", ms=9)
    for row, label in enumerate(_onset_labels(result.onsets)):
        ax[1].annotate(label[1], (label[0], 0.0), textcoords="offset points", xytext=(4, 6 + 11 * (row % 3)),
                       fontsize=8, color="tab:red")
    ax[1].axhline(0.0, color="k", lw=0.6)
    ax[0].set_ylabel("frequency [Hz]" if hz else "Im λ [rad/s]")
    ax[1].set_ylabel("Re λ [1/s]")
    ax[1].set_xlabel("friction coefficient μ")
    ax[0].set_title(f"mode coupling: model {result.model}")
    return fig


def plot_mode_shape(result, mode: int | None = None, *, scale: float = 0.1, ax=None):
    """The real part of a mode's shape on the model's nodes (x, y; displaced by ``scale`` × the
    model's size), the undeformed nodes grey; where the model gives its elements, their edges
    too (the mesh, undeformed and displaced). ``mode``: an index of ``result.eigenvalues``
    (default the most unstable)."""
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    nodes = result.form.nodes
    if nodes is None:
        raise ValueError(f"model {result.model!r} gives no node coordinates to draw its mode shapes on")
    j = int(np.argmax(result.eigenvalues.real + 1e-300 * (result.eigenvalues.imag >= 0))) if mode is None else mode
    if result.eigenvalues[j].imag < 0:
        j = int(np.argmin(np.abs(result.eigenvalues - np.conj(result.eigenvalues[j]))))
    u = nodes.displacement(result.mode_shapes[j]).real
    xyz = nodes.coordinates
    on = np.unique(nodes.node[nodes.node >= 0])
    size = float(np.ptp(xyz[on, :2], axis=0).max()) or 1.0
    amp = np.max(np.abs(u[on])) or 1.0
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.4, 3.6), constrained_layout=True)
    else:
        fig = ax.figure
    moved = xyz[on, :2] + scale * size / amp * u[on, :2]
    edges = cell_edges(nodes.cells)
    if edges.size:
        displaced = xyz[:, :2] + scale * size / amp * u[:, :2]
        ax.add_collection(LineCollection(xyz[edges, :2], colors="0.85", linewidths=0.6))
        ax.add_collection(LineCollection(displaced[edges], colors="0.45", linewidths=0.6))
    ax.plot(xyz[on, 0], xyz[on, 1], ".", color="0.8", ms=3)
    ax.scatter(moved[:, 0], moved[:, 1], c=np.linalg.norm(u[on], axis=1), s=6, cmap="viridis")
    lam = result.eigenvalues[j]
    ax.set_title(f"mode {j}: Re λ = {lam.real:.4g} 1/s, {lam.imag / (2 * math.pi):.5g} Hz")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return fig
