"""A constructed continuation problem with known special points (shared by the orbit tests).

The shooting map of a PeriodicOrbit of model ``rotation`` is replaced by an algebraic one with a
fold at alpha = 10, and its monodromy matrix by one whose multipliers are known functions of the
unknowns: the tests place real multipliers through +1 or −1, or complex pairs, where they want them.
"""

import types

import numpy as np

from stickslip import Parameters
from stickslip.model.library import two_plates
from stickslip.orbits import PeriodicOrbit, resolve_section
from stickslip.orbits import arclength

ROTATION = two_plates(Parameters(alpha=5.0), "rotation", 1e-12)

#: σ of the free states (phi, psi, phi_dot, psi_dot) of the constructed orbit.
SIGMA = np.array([0.01, 0.02, 0.3, 0.4])

#: One stick phase per period (kinds slip → stick, stick → slip), or none (a pure-slip orbit).
STICK = types.SimpleNamespace(kind=np.array([1, -1], dtype=np.int8), time=np.array([0.1, 0.2]))
SLIP = types.SimpleNamespace(kind=np.array([], dtype=np.int8), time=np.array([]))


def constructed_orbit(stick_phases: int = 1) -> PeriodicOrbit:
    """A PeriodicOrbit of model ``rotation`` whose shooting map is replaced by an algebraic one.

    Free states (phi, psi, phi_dot, psi_dot); the section fixes phi_dot, so the scaled unknowns are
    v = (phi/σ0, psi/σ1, psi_dot/σ3, T/T0, alpha/alpha0). With alpha0 = 5 the start is v = (1, 0.1, 0, 1, 1).
    """
    state = np.zeros(12)
    state[4], state[5] = SIGMA[0] * 1.0, SIGMA[1] * 0.1
    return PeriodicOrbit(state=state, period=0.5, multiplicity=1, stick_phases=stick_phases, residual=0.0,
                         iterations=0, residual_history=np.zeros(1), multipliers=np.ones(4, complex),
                         monodromy=np.eye(4), free_states=("phi", "psi", "phi_dot", "psi_dot"), scale=SIGMA,
                         system=ROTATION, section=resolve_section("phi_max", ROTATION),
                         options=dict(rtol=1e-10, atol=1e-13, slip_band=1e-12, tol=1e-8, fd_step=1e-5, max_iter=20))


def algebraic(v):
    """F(v): v0² + v4 − 2 (a fold at v4 = 2, i.e. alpha = 10), v1 = 0.1 v4, v2 = 0, v3 = 1."""
    return np.array([v[0] ** 2 + v[4] - 2.0, v[1] - 0.1 * v[4], v[2], v[3] - 1.0])


def fold_multiplier(v):
    """1 − v0/2: a real multiplier that crosses +1 at the fold (v0 = 0), inside the circle before it."""
    return 1.0 - 0.5 * v[0]


def fold_and_period_doubling(v):
    """diag(1, m, 1 − v0/2, 0.2), m = −0.5 − 0.75 (1 − v0): m = −1 at v0 = 1/3 (alpha = 5 (2 − 1/9)),
    and a real multiplier through +1 at the fold (alpha = 10)."""
    return np.diag([1.0, -0.5 - 0.75 * (1.0 - v[0]), fold_multiplier(v), 0.2])


def install(monkeypatch, monodromy=fold_and_period_doubling, transitions=STICK) -> None:
    """Replace the corrector's residual and Jacobian by the algebraic ones, with ``monodromy(v)``
    (4 × 4, the trivial multiplier 1 included) and the ``transitions`` of every flow map."""

    def residual(problem, v):
        return algebraic(v), np.zeros(12), transitions

    def jacobian(problem, v, end):
        J = np.array([[2 * v[0], 0, 0, 0, 1.0], [0, 1.0, 0, 0, -0.1], [0, 0, 1.0, 0, 0], [0, 0, 0, 1.0, 0]])
        return J, monodromy(v)

    monkeypatch.setattr(arclength, "_residual", residual)
    monkeypatch.setattr(arclength, "_jacobian", jacobian)
