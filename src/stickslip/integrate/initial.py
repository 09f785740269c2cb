"""The initial state of a run: named starts, states by name, a saved run's end, or numbers.

Every model has the starts of :data:`NAMED_STARTS`; a model may define more of its own
(``FrictionModel.starts``: the plates' ``far``, carried along by the lower plate's surface).
"""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np

from ..errors import EquilibriumError, SimulationError
from ..model.matrices import dense_array
from ..model.system_model import FrictionModel
from ..stability.equilibrium import steady_sliding
from .result import Trajectory, load_trajectory

__all__ = ["initial_state", "NAMED_STARTS", "NEAR_PERTURBATION", "start_names", "start_description", "check_rigid_start", "rigid_gaps", "refused_rigid_starts"]

#: Perturbation of the observed coordinate added to steady sliding by the ``near`` start [unit of
#: the coordinate; rad for the plates' φ]: 5 % of φ_e ≈ 0.0197 rad at N = 50 N (Eq. 14), small
#: enough to stay in the basin of a stable equilibrium and large enough that an unstable one
#: departs within a few seconds.
NEAR_PERTURBATION = 1e-3

#: The starts every model has (Sect. 4.2.2 of the paper uses one far from and one near the
#: equilibrium; a model's own, such as the plates' ``far``, are in ``FrictionModel.starts``).
NAMED_STARTS = {
    "zero": "at rest, springs undeformed (q = 0, q̇ = 0)",
    "near": f"steady sliding with the observed coordinate raised by {NEAR_PERTURBATION:g}",
    "equilibrium": "steady sliding exactly (the plates: Eq. 14)",
}


def start_names(system: FrictionModel) -> tuple[str, ...]:
    """The named starts of ``system``: :data:`NAMED_STARTS`, then the model's own."""
    return tuple(NAMED_STARTS) + tuple(k for k in system.starts if k not in NAMED_STARTS)


def start_description(system: FrictionModel, name: str) -> str:
    """One line on the named start ``name`` of ``system``."""
    if name in system.starts:
        return system.starts[name].description
    return NAMED_STARTS[name]


def _named_state(system: FrictionModel, name: str) -> np.ndarray:
    s = np.zeros(2 * system.n)
    if name in system.starts:
        return np.array(system.starts[name].state, dtype=float)
    if name in ("equilibrium", "near"):
        try:
            s[:system.n] = steady_sliding(system)
        except EquilibriumError as exc:
            raise SimulationError(f"ic={name!r}: {exc}") from exc
        if name == "near":
            s[system.observed_index] += NEAR_PERTURBATION
    return s


def initial_state(system: FrictionModel, ic="zero", perturbation=None) -> np.ndarray:
    """The 2n-state initial condition of ``system``.

    Parameters
    ----------
    system : FrictionModel
    ic : str, array-like (2n,), mapping, path of a run's ``.nc`` file, or Trajectory
        A named start (:func:`start_names`): ``zero`` at rest, springs undeformed;
        ``equilibrium`` steady sliding; ``near`` steady sliding with the observed coordinate
        moved by :data:`NEAR_PERTURBATION`; or one of the model's own (``system.starts``, e.g.
        the plates' ``far``). A mapping ``{state name: value}`` sets those states (the others 0).
        A file or Trajectory: its final state (a continuation of that run).
    perturbation : float or array-like (2n,), optional
        Added to the state: a float perturbs the observed coordinate (the plates' φ), a vector
        every state.

    Raises
    ------
    SimulationError
        For an unknown string or state name, a wrong shape, a non-finite value, or a non-zero state
        of a locked DOF.
    """
    n2 = 2 * system.n
    names = system.state_names
    if isinstance(ic, Trajectory):
        s = ic.final_state
    elif isinstance(ic, Mapping):
        s = np.zeros(n2)
        for name, value in ic.items():
            if name not in names:
                raise SimulationError(f"initial state: unknown state {name!r} of model {system.name!r}; "
                                      f"states are {', '.join(names)}")
            s[names.index(name)] = float(value)
    elif isinstance(ic, str) and ic in start_names(system):
        s = _named_state(system, ic)
    elif isinstance(ic, Path) or (isinstance(ic, str) and ic.endswith(".nc")):
        s = load_trajectory(ic).final_state
    elif isinstance(ic, str):
        raise SimulationError(
            f"unknown initial condition {ic!r}; use {', '.join(repr(n) for n in start_names(system))}, a path to "
            f"a run .nc file, name=value pairs of states ({', '.join(names)}) or {n2} numbers"
        )
    else:
        s = np.asarray(ic, dtype=float).copy()
        if s.shape != (n2,):
            raise SimulationError(f"initial state must have {n2} entries ({', '.join(names)}), got shape {s.shape}")
    if s.shape != (n2,):
        raise SimulationError(f"initial state from {ic!r} has {s.size} entries, model {system.name!r} has {n2} states")
    if perturbation is not None:
        delta = np.asarray(perturbation, dtype=float)
        if delta.ndim == 0:
            s[system.observed_index] += float(delta)
        elif delta.shape == (n2,):
            s = s + delta
        else:
            raise SimulationError(f"perturbation must be a number (added to {system.dofs[system.observed_index]}) "
                                  f"or {n2} numbers, got shape {delta.shape}")
    if not np.all(np.isfinite(s)):
        raise SimulationError("initial state has a non-finite entry; give finite numbers")
    locked = ~np.concatenate([system.free, system.free])
    bad = [names[i] for i in np.flatnonzero(locked & (s != 0.0))]
    if bad:
        raise SimulationError(
            f"initial state sets {', '.join(bad)} but those DOFs are locked in this model; "
            "set them to 0 or choose a model that frees them"
        )
    return s


def rigid_gaps(system: FrictionModel, states: np.ndarray):
    """Gap and normal speed of every rigid contact at each of ``states``.

    Parameters
    ----------
    system : FrictionModel
    states : ndarray (k, 2n) or (2n,)
        States [q, q̇].

    Yields
    ------
    c : int
        The rigid contact.
    g, rate : ndarray (k,)
        Its gap g0 + W·q and normal speed W·q̇ [m, m/s].
    tol : ndarray (k,)
        Round-off of the gap: |g| below it counts as g = 0 [m].
    """
    n = system.n
    S = np.atleast_2d(np.asarray(states, dtype=float))
    for c, contact in enumerate(system.contacts):
        if not (contact.unilateral and contact.normal.law == "rigid"):
            continue
        W = dense_array(contact.gap_gradient).reshape(-1)
        g = contact.gap + S[:, :n] @ W
        tol = 1e-12 * (1.0 + abs(contact.gap) + np.abs(S[:, :n] * W).sum(axis=1))
        yield c, g, S[:, n:2 * n] @ W, tol


def refused_rigid_starts(system: FrictionModel, states: np.ndarray) -> np.ndarray:
    """Which of ``states`` (k, 2n) a rigid contact cannot start from (:func:`check_rigid_start`):
    bool (k,)."""
    refused = np.zeros(np.atleast_2d(states).shape[0], dtype=bool)
    for _, g, rate, tol in rigid_gaps(system, states):
        refused |= (g < -tol) | ((g <= tol) & (rate < 0.0))
    return refused


def check_rigid_start(system: FrictionModel, y0: np.ndarray) -> None:
    """Refuse a start that a rigid contact cannot take: inside its stop (g < 0), or at it and
    moving into it (g = 0, ġ < 0: an impact at the start; start just above it instead).

    Raises
    ------
    SimulationError
    """
    for c, g, rate, tol in rigid_gaps(system, y0):
        g, rate, tol = float(g[0]), float(rate[0]), float(tol[0])
        name = system.contact_names[c]
        if g < -tol:
            raise SimulationError(f"rigid contact {c} ({name}) starts inside its stop: gap {g:.6g} < 0; start with "
                                  "gap >= 0 (on it or above it)")
        if g <= tol and rate < 0.0:
            raise SimulationError(f"rigid contact {c} ({name}) starts at its stop moving into it (normal speed "
                                  f"{rate:.6g} < 0); start just above it (gap > 0) or at rest on it")