"""The state layout the orbit tools assume, in one place: the two plates' 12 states.

The orbit tools (sections, shooting, continuation, Lyapunov exponents) work on a state
s = [q, q̇] of :data:`N_DOFS` generalised coordinates followed by their velocities, as
:data:`stickslip.STATE_NAMES` orders them; a model variant frees some of the DOFs. Everything
they need to know about that layout — its size, where a velocity sits, which states are free,
where φ and φ̇ are, the units, the steady-sliding state, the projection onto the stick
constraint — is here, so that a model that describes its own states can replace this module.
"""

from __future__ import annotations

import numpy as np

from ..model import kernels as K
from ..model.variants import DOF_NAMES, STATE_NAMES

__all__ = ["N_DOFS", "N_STATES", "PHI", "PHI_DOT", "STATE_UNITS", "STATE_NAMES", "free_states",
           "velocity_of", "equilibrium_state", "stick_projected", "kernel_state", "KERNEL_STATE"]

#: Generalised coordinates q (x1, y1, x2, y2, φ, ψ) and states s = [q, q̇].
N_DOFS = len(DOF_NAMES)
N_STATES = len(STATE_NAMES)

#: Indices of φ (the upper plate's rotation) and of φ̇ in the state.
PHI = STATE_NAMES.index("phi")
PHI_DOT = STATE_NAMES.index("dphi")

#: Units of the states, in state order.
STATE_UNITS = ("m", "m", "m", "m", "rad", "rad", "m/s", "m/s", "m/s", "m/s", "rad/s", "rad/s")

#: Length of the integrator kernels' work vector: the states and two stick-multiplier slots.
KERNEL_STATE = N_STATES + 2


def velocity_of(index: int) -> int:
    """State index of the velocity of coordinate ``index`` (< :data:`N_DOFS`)."""
    return index + N_DOFS


def free_states(system) -> np.ndarray:
    """Indices (2 n_free,) of the free states of the system's variant: positions, then velocities."""
    dofs = system.variant.free_indices
    return np.concatenate([dofs, dofs + N_DOFS])


def equilibrium_state(params, model) -> np.ndarray:
    """The steady-sliding state (N_STATES,) of paper Eq. (14): q at the equilibrium, q̇ = 0."""
    from ..stability import equilibrium

    s = np.zeros(N_STATES)
    s[:N_DOFS] = equilibrium(params, model)
    return s


def kernel_state(s: np.ndarray) -> np.ndarray:
    """The kernels' work vector (N_STATES + 2,) holding state ``s``."""
    y = np.zeros(KERNEL_STATE)
    y[:N_STATES] = s[:N_STATES]
    return y


def stick_projected(system, s: np.ndarray) -> np.ndarray:
    """The state with q̇ projected onto v_r = 0 in the mass metric (:func:`kernels.project_velocity`)."""
    y = kernel_state(s)
    K.project_velocity(y, system.minv, system.p)
    return y[:N_STATES].copy()
