"""The state layout of a model as the orbit tools use it: states, free states, units, projections.

Every model's state is s = [q, q̇] (:attr:`FrictionModel.state_names`: the dofs, then ``d`` + each
dof); a model frees some of its dofs (:attr:`FrictionModel.free`). Everything the orbit tools need
to know about that layout — which states are free, the units, the steady-sliding state, the
projection onto the stick constraint of the contacts at rest, the states a rigid contact lets a
motion start from — is here.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.linalg

from ..errors import EquilibriumError
from ..integrate.contacts import STICK_SPEED_TOL
from ..integrate.initial import refused_rigid_starts, rigid_gaps
from ..model import physics as P
from ..model.bundle import CST, contact_state
from ..model.matrices import dense_array
from ..stability.equilibrium import steady_sliding

__all__ = ["free_states", "equilibrium_state", "ORBIT_MIN_SIZE", "distance_from_steady_sliding", "is_steady_sliding",
           "stick_projected", "resting_contacts", "rigid_admissible", "Constraint", "independent_states"]

#: A solution of the shooting equations without stick phases whose state on the section lies closer
#: than this to the steady-sliding state (‖(s − s_eq)/σ‖ over the free states, σ the orbit's scales)
#: is the equilibrium, not an orbit: the finite differences of its Jacobian (steps of
#: DEFAULT_FD_STEP = 1e-5 σ) would straddle such a cycle, so nothing the shooting computes can tell
#: it from steady sliding. Measured: 1e-12 on the steady sliding the two-mass belt's start converged
#: onto, against ≥ 2.8e-3 on the Model 4 slip cycle down to its Hopf point (0.69 at its start).
ORBIT_MIN_SIZE = 1e-5


def free_states(system) -> np.ndarray:
    """Indices (2 n_free,) of the free states of ``system``: positions, then velocities."""
    dofs = np.flatnonzero(system.free)
    return np.concatenate([dofs, dofs + system.n])


def equilibrium_state(system) -> np.ndarray:
    """The steady-sliding state (2n,): q at the equilibrium, q̇ = 0."""
    s = np.zeros(2 * system.n)
    s[:system.n] = steady_sliding(system)
    return s


def distance_from_steady_sliding(system, state: np.ndarray, free: np.ndarray, sigma: np.ndarray) -> float:
    """‖(s − s_eq)/σ‖ on the ``free`` states (σ their scales): the size of a cycle about the
    steady-sliding state of ``system``.

    Raises
    ------
    EquilibriumError
        Where ``system`` has no steady sliding.
    """
    return float(np.linalg.norm((np.asarray(state) - equilibrium_state(system))[free] / sigma))


def is_steady_sliding(system, state: np.ndarray, free: np.ndarray, sigma: np.ndarray, stick_phases: int) -> bool:
    """Whether a solution of the shooting equations is steady sliding (which solves them for any
    period), not a cycle: it has no stick phase and lies within :data:`ORBIT_MIN_SIZE` of the
    steady-sliding state (a model without steady sliding has no such solution)."""
    if stick_phases > 0:
        return False
    try:
        return distance_from_steady_sliding(system, state, free, sigma) < ORBIT_MIN_SIZE
    except EquilibriumError:
        return False


def resting_contacts(system, s: np.ndarray) -> np.ndarray:
    """Contact states (CST nc,) with every contact whose |v_c| ≤ STICK_SPEED_TOL marked as sticking."""
    md = system.data
    cst = contact_state(md.m)
    y = np.ascontiguousarray(s[:2 * system.n], dtype=float)
    for c in range(system.n_contacts):
        v0, v1 = P.slip_velocity(y, c, md)
        if np.hypot(v0, v1) <= STICK_SPEED_TOL:
            cst[CST * c] = P.MODE_STICK
    return cst


def stick_projected(system, s: np.ndarray, cst: np.ndarray | None = None) -> np.ndarray:
    """The state with q̇ projected onto v_c = 0 (mass metric) for the sticking contacts of ``cst``
    (default: the contacts at rest in ``s``, :func:`resting_contacts`)."""
    y = np.ascontiguousarray(s[:2 * system.n], dtype=float).copy()
    cst = resting_contacts(system, y) if cst is None else cst
    P.project_velocities(y, cst, np.int64(-1), system.data)
    return y


def rigid_admissible(system, s: np.ndarray, sp: np.ndarray) -> np.ndarray:
    """``sp``, a state near ``s``, where the rigid contacts let a motion start.

    The deviation sp − s is projected (Euclidean) onto W δq = 0, W δq̇ = 0 of the rigid contacts
    closed at ``s`` (g = 0: a perturbed closed contact stays closed, as the constrained linear
    flow has it), and mirrored through ``s`` (2s − sp) where it would start inside the stop of one
    open at ``s``, or at it moving into it (a flight near its landing). Returns a new array (2n,).
    """
    n = system.n
    out = np.array(sp, dtype=float)
    closed = [dense_array(system.contacts[c].gap_gradient).reshape(-1)
              for c, g, _, tol in rigid_gaps(system, s) if g[0] <= tol[0]]
    if closed:
        W = np.array(closed)
        for part in (slice(0, n), slice(n, 2 * n)):
            d = out[part] - s[part]
            out[part] = s[part] + d - W.T @ np.linalg.lstsq(W @ W.T, W @ d, rcond=None)[0]
    if refused_rigid_starts(system, out)[0]:
        out = 2.0 * np.asarray(s, dtype=float) - out
    return out


@dataclasses.dataclass(frozen=True, eq=False)
class Constraint:
    """The rigid contacts closed at a state, whose normal coordinates the orbit tools eliminate.

    A closed rigid contact holds g = g0 + W·q = 0 and ġ = W·q̇ = 0 (its gap is affine in q), so a
    state on the constraint is fixed by the other free states: for each closed contact one free
    dof (a pivot of a column-pivoted QR of W on the free dofs: the largest independent entries) is
    *dependent*, its position and velocity solved from the others. Shooting takes the other free
    states as its unknowns (``free``), so every iterate lies on the constraint, and its monodromy
    is the flow's linearisation restricted to the constraint's tangent space, 2(k − m) square for k
    free dofs and m closed contacts.

    Attributes
    ----------
    contacts : tuple of int
        The closed rigid contacts.
    free : ndarray (2 (k − m),)
        State indices of the independent free states: positions, then velocities.
    dependent : ndarray (m,)
        The dependent dofs (their positions; their velocities are at n + dependent).
    W : ndarray (m, n)
        The contacts' gap gradients.
    g0 : ndarray (m,)
        Their gaps at q = 0 [m].
    """

    contacts: tuple
    free: np.ndarray
    dependent: np.ndarray
    W: np.ndarray
    g0: np.ndarray

    def complete(self, s: np.ndarray) -> np.ndarray:
        """``s`` (2n,) with the dependent positions and velocities solved from the others (a copy)."""
        n = self.W.shape[1]
        out = np.array(s, dtype=float)
        J = self.dependent
        others = np.setdiff1d(np.arange(n), J)
        WJ, Wo = self.W[:, J], self.W[:, others]
        out[J] = np.linalg.solve(WJ, -self.g0 - Wo @ out[others])
        out[n + J] = np.linalg.solve(WJ, -Wo @ out[n + others])
        return out

    def embedding(self) -> np.ndarray:
        """∂s/∂s_free (2n × free.size): how a variation of the independent states moves every state."""
        n = self.W.shape[1]
        E = np.zeros((2 * n, self.free.size))
        E[self.free, np.arange(self.free.size)] = 1.0
        solve = np.linalg.solve(self.W[:, self.dependent], self.W)  # (m, n): rows of W_J⁻¹ W
        for k, j in enumerate(self.free):
            part = 0 if j < n else n
            E[part + self.dependent, k] = -solve[:, j - part]
        return E


def independent_states(system, s: np.ndarray) -> tuple[np.ndarray, Constraint | None]:
    """The free states that shooting from ``s`` takes as unknowns (with the section's), and the
    :class:`Constraint` of the rigid contacts closed at ``s`` (None where none is: then every free
    state, :func:`free_states`)."""
    closed = [c for c, g, _, tol in rigid_gaps(system, s) if g[0] <= tol[0]] if system.rigid else []
    if not closed:
        return free_states(system), None
    n = system.n
    W = np.array([dense_array(system.contacts[c].gap_gradient).reshape(-1) for c in closed])
    g0 = np.array([float(system.contacts[c].gap) for c in closed])
    dofs = np.flatnonzero(system.free)
    pivots = scipy.linalg.qr(W[:, dofs], pivoting=True)[2][:len(closed)]
    dependent = np.sort(dofs[pivots])
    kept = np.setdiff1d(dofs, dependent)
    free = np.concatenate([kept, kept + n])
    return free, Constraint(tuple(closed), free, dependent, W, g0)
