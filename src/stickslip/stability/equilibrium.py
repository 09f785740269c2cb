"""Steady-sliding equilibrium of any friction model (for the plates: paper Eq. 14, Appendix A.1).

q̇ = 0 and f0 − K q + Σ_c G_cᵀ F_c(q, 0) = 0 with every contact slipping, solved by damped Newton
from q = 0 with the exact Jacobian of the simulator's own right-hand side (complex step), with a
continuation in the normal load as a fallback near the fold where steady sliding ceases to exist
(:mod:`stickslip.stability.steady`, compiled). The plates' functions (:func:`equilibrium`,
:func:`solve_equilibrium`, :func:`equilibrium_residual`) are this on the plates' model.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import EquilibriumError
from ..model.bundle import CST
from ..model.library.two_plates import NAME
from ..model.parameters import Parameters
from ..model.physics import MODE_SLIP_EXACT, rhs, slip_velocity
from ..model.system import System, assemble
from . import steady

__all__ = ["EquilibriumError", "equilibrium", "equilibrium_residual", "solve_equilibrium", "RESIDUAL_TOL",
           "steady_sliding", "steady_residual", "solve_steady", "plates_model", "point_text"]

#: Relative residual |K x − b| / max(|K x|, |b|) accepted as solved. Newton reaches ~1e-16
#: (round-off of the force balance); 1e-10 leaves room for ill-conditioned cases while still
#: pinning x far below any physical resolution.
RESIDUAL_TOL = 1e-10

#: Newton iterations allowed per solve. Converging cases take 3–8 from x = 0 (quadratic
#: convergence); 60 leaves room for the damped phase of strongly deflected cases.
MAX_ITER = 60

_REASONS = {
    steady.NEWTON_MAX_ITER: f"Newton did not converge in {MAX_ITER} iterations",
    steady.NEWTON_SINGULAR: "the Jacobian K_L became singular (is a free DOF without stiffness?)",
    steady.NEWTON_NOT_FINITE: "the iteration produced non-finite values",
    steady.NEWTON_NO_DESCENT: "Newton stalled (no step reduces the residual)",
}


def plates_model(system: System):
    """The :class:`~stickslip.model.FrictionModel` of an assembled plates :class:`System`."""
    return system.model()


def _is_plates(system) -> bool:
    return system.name == NAME


def point_text(system) -> str:
    """The point in words for messages: the plates' N, Ω and variant, else the model's name."""
    if _is_plates(system):
        p = system.parameters
        return f"N = {p['N']:g} N, Omega = {p['Omega']:g} rad/s, model {p['variant']!r}"
    return f"model {system.name!r}"


def _speeds(system, q: np.ndarray) -> list[float]:
    """Sliding speed of each contact at (q, q̇ = 0) [m/s]."""
    s = np.zeros(2 * system.n)
    s[:system.n] = q
    return [float(np.hypot(*slip_velocity(s, c, system.data))) for c in range(system.n_contacts)]


def _not_sliding_message(system, q: np.ndarray) -> str:
    plates = _is_plates(system)
    for c, (speed, contact) in enumerate(zip(_speeds(system, q), system.contacts)):
        if speed == 0.0:
            if plates:
                return ("no steady sliding at Omega = 0: the relative velocity vanishes at rest and the friction "
                        "direction is undefined; choose Omega != 0")
            return (f"no steady sliding: contact {c} does not slide at rest (its drive is 0); "
                    "give the contact a non-zero drive")
        if contact.dim == 2 and speed <= system.slip_band:
            fix = "increase |Omega|" if plates else "increase the drive"
            name = "|Omega| R" if plates else f"of contact {c}"
            return (f"sliding speed at equilibrium {name} = {speed:.3g} m/s is inside the simulator's low-speed band "
                    f"({system.slip_band:g} m/s), where its slip direction is not v/|v| and steady sliding is not an "
                    f"equilibrium of the simulated equations; {fix}")
    return "steady sliding is not an equilibrium of the simulated equations"


def _failure_message(system, q: np.ndarray, status: int, rel: float) -> str:
    reason = _REASONS.get(int(status), "the residual check failed")
    hint = ""
    if _is_plates(system) and np.all(np.isfinite(q)):
        r = system.parameters["r"]
        R = math.hypot(q[0] - q[2] + r * math.cos(q[4]), q[1] - q[3] + r * math.sin(q[4]))
        if R < 0.5 * r:
            hint = (f"; the iterate has the contact point at R = {R:.3g} m from the centre O2 (r = {r:g} m): the "
                    "friction load mu N drags the contact point onto the centre of the lower plate and steady "
                    "sliding does not exist beyond that load (a fold of Eq. 14); reduce N or mu")
    elif not _is_plates(system):
        hint = ("; steady sliding may not exist at these parameters (e.g. a friction load that drags the "
                "contact into a fold)")
    return (f"no steady-sliding equilibrium found for {point_text(system)}: {reason} (relative residual "
            f"{rel:.2e} > {RESIDUAL_TOL:g}){hint}")


def solve_steady(system) -> tuple[np.ndarray, float, int]:
    """Steady sliding of a :class:`~stickslip.model.FrictionModel`.

    Returns
    -------
    q : ndarray (n,)
        Equilibrium coordinates (locked DOFs 0) [units of the dofs].
    relative_residual : float
        max|M q̈| / max(|K q|, |f0|, |Σ Gᵀ F|) on the free DOFs, by the simulator's right-hand side.
    iterations : int

    Raises
    ------
    EquilibriumError
        No solution to :data:`RESIDUAL_TOL`, or a contact that does not slide at the solution (speed
        0) or, for a 2-D contact, slides inside the low-speed band (the simulator's slip direction
        there is not v/|v|, so steady sliding is not an equilibrium of the simulated equations).
    """
    if _is_plates(system) and system.parameters["Omega"] == 0.0:
        raise EquilibriumError(_not_sliding_message(system, np.zeros(system.n)))
    free = np.flatnonzero(system.free).astype(np.int64)
    q, status, rel, iterations = steady.steady_sliding_point(system.data, free, MAX_ITER)
    if status == steady.NEWTON_NOT_SLIDING:
        raise EquilibriumError(_not_sliding_message(system, q))
    if not (np.all(np.isfinite(q)) and rel <= RESIDUAL_TOL):
        if np.all(np.isfinite(q)) and min(_speeds(system, q)) == 0.0:
            raise EquilibriumError(_not_sliding_message(system, q))
        raise EquilibriumError(_failure_message(system, q, status, rel))
    return q, float(rel), int(iterations)


def steady_sliding(system) -> np.ndarray:
    """Steady-sliding equilibrium q_e (n,) of any friction model (see :func:`solve_steady`)."""
    return solve_steady(system)[0]


def steady_residual(system, q: np.ndarray) -> float:
    """Relative force residual |M q̈| / max(|K q|, |f0|, |Σ Gᵀ F|) of steady sliding at q (q̇ = 0)."""
    n = system.n
    s = np.zeros(2 * n)
    s[:n] = q
    ds = np.zeros(2 * n)
    cst = np.zeros(CST * system.n_contacts)
    cst[0::CST] = MODE_SLIP_EXACT
    cst[3::CST] = np.inf
    rhs(s, cst, system.data, ds)
    free = np.flatnonzero(system.free)
    Q = (system.mass @ ds[n:])[free]
    Kq = (system.stiffness @ np.asarray(q, float))[free]
    f0 = system.force[free]
    num = float(np.max(np.abs(Q), initial=0.0))
    scale = max(float(np.max(np.abs(Kq), initial=0.0)), float(np.max(np.abs(f0), initial=0.0)),
                float(np.max(np.abs(Q + Kq - f0), initial=0.0)))
    if num == 0.0:
        return 0.0
    return num / scale if scale > 0.0 and np.isfinite(num) else math.inf


# --------------------------------------------------------------------------- the plates' API
def equilibrium_residual(system: System, q: np.ndarray) -> np.ndarray:
    """Force residual K q − Gᵀ F(v_r = Ω(Y, −X)) at rest (q̇ = 0) of the plates, shape (6,) [N or N m].

    This is −M q̈ of the slip equations at q̇ = 0, evaluated by the simulator's right-hand side, so
    its zero is exactly the steady sliding state the simulator sees. Locked DOFs give 0.
    """
    model = plates_model(system)
    s = np.zeros(12)
    s[:6] = q
    ds = np.zeros(12)
    cst = np.zeros(CST)
    cst[0] = MODE_SLIP_EXACT
    cst[3] = np.inf
    rhs(s, cst, model.data, ds)
    return np.where(system.minv > 0, -(model.mass @ ds[6:]), 0.0)


def solve_equilibrium(system: System) -> tuple[np.ndarray, float, int]:
    """Steady sliding (Eq. 14) of an assembled plates :class:`System`: :func:`solve_steady` on its model.

    Returns
    -------
    q : ndarray (6,)
        Equilibrium [m, m, m, m, rad, rad]; locked DOFs are 0.
    relative_residual : float
        max|K x − b| / max(|K x|, |b|), evaluated with the simulator's right-hand side.
    iterations : int

    Raises
    ------
    EquilibriumError
        See :func:`equilibrium`.
    """
    return solve_steady(plates_model(system))


def equilibrium(params: Parameters, model="full") -> np.ndarray:
    """Steady-sliding equilibrium q_e of the free DOFs (locked DOFs are 0), shape (6,).

    Solves K x = b(x) (paper Eq. 14, b from Appendix A.1) by damped Newton from x = 0 with the
    exact Jacobian (falling back to continuation in N from a fraction of the load when Newton
    from 0 stalls) and checks the residual with the simulator's kernel.

    Parameters
    ----------
    params : Parameters
    model : str, iterable of DOF names or Variant
        ``full`` (Model 1), ``x``, ``y``, ``rotation`` (Model 4), or the DOFs to free.

    Returns
    -------
    ndarray, shape (6,)
        [x1, y1, x2, y2, φ, ψ] at equilibrium [m, m, m, m, rad, rad].

    Raises
    ------
    EquilibriumError
        When Ω = 0 (v_r vanishes at rest, the friction direction is undefined: no steady
        sliding), or when Newton does not reach a relative residual of :data:`RESIDUAL_TOL`
        (e.g. at large N and small Ω, where the contact point is dragged to the centre of the
        lower plate and steady sliding ceases to exist), or when the sliding speed |Ω| R at
        equilibrium is inside the simulator's low-speed band (``model.system_model.DEFAULT_SLIP_BAND``).
    """
    if not isinstance(params, Parameters):
        raise TypeError(f"params must be a stickslip.Parameters, got {type(params).__name__}")
    q, _, _ = solve_equilibrium(assemble(params, model))
    return q


