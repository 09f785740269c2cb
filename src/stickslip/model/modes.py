"""Linear mode frequencies of the plates without friction, from the mass and stiffness diagonals."""

from __future__ import annotations

import math

import numpy as np

from .parameters import Parameters
from .system import assemble

__all__ = ["natural_frequencies"]


def natural_frequencies(params: Parameters, model="full") -> np.ndarray:
    """Undamped natural frequencies of the free DOFs without friction.

    Each DOF has its own mass (or inertia) and spring, so the modes are uncoupled:
    f_i = sqrt(k_i / m_i) / (2π). Friction couples them, but a stick constraint only moves the
    frequencies inside this range, so the largest is the highest linear frequency a run
    resolves; sampling below twice it aliases the spectrum (Nyquist).

    Parameters
    ----------
    params : Parameters
    model : str or iterable of DOF names
        The variant whose free DOFs count (see :func:`stickslip.model.resolve_variant`).

    Returns
    -------
    ndarray, shape (k,)
        Frequencies [Hz] of the k free DOFs, ascending (0 for a DOF without a spring).
    """
    system = assemble(params, model)
    free = system.minv > 0
    return np.sort(np.sqrt(system.stiff[free] * system.minv[free]) / (2.0 * math.pi))
