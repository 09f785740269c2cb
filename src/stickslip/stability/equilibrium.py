"""Steady-sliding equilibrium of any friction model (for the plates: paper Eq. 14, Appendix A.1).

q̇ = 0 and f0 − K q + Σ_c G_cᵀ F_c(q, 0) = 0 with every contact slipping, solved by damped Newton
from q = 0 with the exact Jacobian of the simulator's own right-hand side (complex step), with a
continuation in the normal load as a fallback near the fold where steady sliding ceases to exist
(:mod:`stickslip.stability.steady`, compiled).

A model with rigid contacts: each closed rigid contact holds its gap at 0, W_R q = −g0, and its
normal force is the multiplier of the simulator's right-hand side. The equilibrium is then solved
on that constraint, q = q_p + Z r (q_p the least-norm point on it, Z an orthonormal basis of
null(W_R) on the free DOFs), for Zᵀ q̈(q, 0) = 0 (:func:`_solve_rigid`); W_R q̈ = 0 holds already.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import EquilibriumError, StickSlipError
from ..model.compile_ahead import compile_apart
from ..model.bundle import CST
from ..model.library import resolve_model
from ..model.parameters import Parameters
from ..model.physics import MODE_OPEN, MODE_SLIP_EXACT, gap, normal_force_of, rhs, rigid_pivot, slip_velocity
from ..model.system_model import FrictionModel
from . import steady

__all__ = ["EquilibriumError", "equilibrium", "equilibrium_residual", "RESIDUAL_TOL", "steady_sliding",
           "steady_residual", "solve_steady", "solve_steady_modes",
           "point_text", "sliding_speeds", "model_of", "rigid_constraint"]

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


def point_text(system) -> str:
    """The point in words for messages (:meth:`~stickslip.model.FrictionModel.point_text`)."""
    return system.point_text()


def sliding_speeds(system, q: np.ndarray) -> list[float]:
    """Sliding speed of each contact at (q, q̇ = 0) [m/s]."""
    s = np.zeros(2 * system.n)
    s[:system.n] = q
    return [float(np.hypot(*slip_velocity(s, c, system.data))) for c in range(system.n_contacts)]


def _not_sliding_message(system, q: np.ndarray) -> str:
    for c, (speed, contact) in enumerate(zip(sliding_speeds(system, q), system.contacts)):
        if speed == 0.0:
            return (f"no steady sliding at {system.point_text()}: contact {c} does not slide at rest (its drive is "
                    "0: the slip velocity vanishes and the friction direction is undefined); give the contact a "
                    "non-zero drive")
        if contact.dim == 2 and speed <= system.slip_band:
            return (f"the sliding speed of contact {c} at equilibrium, {speed:.3g} m/s, is inside the simulator's "
                    f"low-speed band ({system.slip_band:g} m/s), where its slip direction is not v/|v| and steady "
                    "sliding is not an equilibrium of the simulated equations; increase the drive")
    return "steady sliding is not an equilibrium of the simulated equations"


def _failure_message(system, q: np.ndarray, status: int, rel: float) -> str:
    reason = _REASONS.get(int(status), "the residual check failed")
    hint = system.steady_hint(system, q) if system.steady_hint is not None else (
        "steady sliding may not exist at these parameters (e.g. a friction load that drags the contact into a fold)")
    hint = f"; {hint}" if hint else ""
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
    return solve_steady_modes(system)[:3]


def solve_steady_modes(system) -> tuple[np.ndarray, float, int, tuple[int, ...]]:
    """:func:`solve_steady`, with the unilateral contacts that steady sliding leaves open.

    Every unilateral contact is first held closed. Where that leaves some of them not pressed
    (λ ≤ 0; a rigid one at rest at λ = 0 counts as closed), they are opened and the equilibrium
    solved again with them carrying no force, until the set is consistent: each open contact's gap
    is positive at the equilibrium (it contributes nothing there, nor to the linearisation) and
    each closed one is pressed, and some contact with friction stays closed (slides: with all of them
    open there is no sliding). The refusal where no such set exists is that of the closed solve (the
    contact is not pressed at all, or the friction jams it).

    Returns
    -------
    q, relative_residual, iterations
        As :func:`solve_steady`.
    open_contacts : tuple of int
        The contacts open at the equilibrium, ascending (empty where all are closed).
    """
    try:
        q, rel, iterations = _solve_rigid(system) if system.rigid else _solve_closed(system)
    except EquilibriumError as exc:
        if not system.unilateral:
            raise
        return _solve_open(system, None, exc)
    if _open_contact(system, q) is None:
        return q, rel, iterations, ()
    return _solve_open(system, q, None)


def _solve_open(system, q_closed, failure) -> tuple[np.ndarray, float, int, tuple[int, ...]]:
    """The active set of :func:`solve_steady_modes` from the closed solve's ``q_closed`` (None where
    it failed, with ``failure``): open the contacts it leaves unpressed, solve, and move contacts
    between the sets until each open one has a positive gap and each closed one is pressed."""
    unilateral = {c for c, contact in enumerate(system.contacts) if contact.unilateral}
    opened = set(unilateral) if q_closed is None else set(_unpressed(system, q_closed, ()))
    iterations = 0
    for _ in range(len(unilateral) + 1):
        try:
            q, rel, it = _solve_with_open(system, tuple(sorted(opened)))
        except EquilibriumError:
            break
        iterations += it
        s = np.zeros(2 * system.n)
        s[:system.n] = q
        closing = {c for c in opened if not gap(s, c, system.data)[0] > 0.0}
        opening = set(_unpressed(system, q, opened))
        if not closing and not opening and rigid_pivot(s, _sliding_modes(system, opened), system.data) > 0.0:
            if not any(c not in opened and not contact.frictionless for c, contact in enumerate(system.contacts)):
                break  # every contact with friction open: a free equilibrium, no sliding
            return q, rel, iterations, tuple(sorted(opened))
        if opened == (opened - closing) | opening:
            break
        opened = (opened - closing) | opening
    if failure is not None:
        raise failure
    _check_closed(system, q_closed)
    raise EquilibriumError(f"no steady sliding at {system.point_text()}: no set of open contacts is consistent")


def _unpressed(system, q: np.ndarray, opened) -> list[int]:
    """The unilateral contacts closed in the steady state ``q`` (those not in ``opened``) that
    nothing presses: a compliant one with g ≥ 0 or λ ≤ 0, a rigid one with λ < 0."""
    s = np.zeros(2 * system.n)
    s[:system.n] = q
    cst = _sliding_modes(system, opened)
    out = []
    for c, contact in enumerate(system.contacts):
        if contact.unilateral and c not in opened:
            g = gap(s, c, system.data)[0]
            lam = normal_force_of(s, cst, c, system.data)
            if not (lam >= 0.0 if contact.normal.law == "rigid" else (g < 0.0 and lam > 0.0)):
                out.append(c)
    return out


def _solve_with_open(system, opened: tuple[int, ...]) -> tuple[np.ndarray, float, int]:
    """Steady sliding with the contacts ``opened`` open (no force) and the others closed: scipy's
    hybrid Powell method on Zᵀ q̈(q_p + Z r, 0) = 0, (q_p, Z) the closed rigid contacts' constraint
    (:func:`rigid_constraint`; q_p = 0 and Z the free DOFs where none is closed)."""
    n = system.n
    cst = _sliding_modes(system, opened)
    speeds = sliding_speeds(system, np.zeros(n))
    if any(speeds[c] == 0.0 for c in range(system.n_contacts) if c not in opened):
        raise EquilibriumError(_not_sliding_message(system, np.zeros(n)))
    q, nfev, _ = _root_on_constraint(system, cst, *rigid_constraint(system, exclude=opened))
    rel = steady_residual(system, q, cst)
    if not (np.all(np.isfinite(q)) and rel <= RESIDUAL_TOL):
        raise EquilibriumError(f"no steady sliding with contacts {list(opened)} open (relative residual {rel:.2e})")
    return q, float(rel), nfev


def rigid_constraint(system, exclude=()) -> tuple[np.ndarray, np.ndarray]:
    """(q_p, Z): the least-norm point q_p (n,) of W_R q = −g0 and an orthonormal basis Z (n, k − m)
    of null(W_R) on the free DOFs (zero rows on locked ones), W_R (m, n) the rigid contacts' gap
    gradients, g0 their gaps; the contacts in ``exclude`` (open ones) left out (q_p = 0 and Z the
    free DOFs' columns of the identity where no rigid contact is left)."""
    from scipy.linalg import null_space  # imported on use: scipy takes ~0.3 s of every command's start

    rows = [(np.asarray(c.gap_gradient, float).reshape(-1), c.gap) for i, c in enumerate(system.contacts)
            if c.unilateral and c.normal.law == "rigid" and i not in exclude]
    free = np.flatnonzero(system.free)
    if not rows:
        return np.zeros(system.n), np.eye(system.n)[:, free]
    W = np.array([w for w, _ in rows])
    g0 = np.array([g for _, g in rows])
    q_p = np.zeros(system.n)
    q_p[free] = -np.linalg.pinv(W[:, free]) @ g0
    Z = np.zeros((system.n, free.size - np.linalg.matrix_rank(W[:, free])))
    Z[free] = null_space(W[:, free])
    return q_p, Z


def _root_on_constraint(system, cst: np.ndarray, q_p: np.ndarray, Z: np.ndarray) -> tuple[np.ndarray, int, str]:
    """(q, evaluations, the root finder's message): scipy's hybrid Powell method on
    Zᵀ q̈(q_p + Z r, 0) = 0 from r = 0 in the contact modes ``cst`` (q_p where Z has no column:
    the closed contacts fix every free dof)."""
    from scipy.optimize import root  # imported on use, as in rigid_constraint

    n = system.n
    if not Z.shape[1]:
        return q_p, 0, "the constraint fixes every free dof"

    def acceleration(r):
        s = np.zeros(2 * n)
        s[:n] = q_p + Z @ r
        ds = np.zeros(2 * n)
        rhs(s, cst, system.data, ds)
        return Z.T @ ds[n:]
    sol = root(acceleration, np.zeros(Z.shape[1]), method="hybr", options={"xtol": 1e-14})
    return q_p + Z @ sol.x, int(sol.nfev), sol.message


def _solve_rigid(system) -> tuple[np.ndarray, float, int]:
    """:func:`solve_steady` with every contact sliding and the rigid ones closed (module docstring):
    scipy's hybrid Powell method on Zᵀ q̈(q_p + Z r, 0) = 0 from r = 0, the rigid normal forces
    the right-hand side's multipliers."""
    if min(sliding_speeds(system, np.zeros(system.n))) == 0.0:
        raise EquilibriumError(_not_sliding_message(system, np.zeros(system.n)))
    q_p, Z = rigid_constraint(system)
    n = system.n
    cst = _sliding_modes(system)
    q, nfev, message = _root_on_constraint(system, cst, q_p, Z)
    for at in (q, q_p):  # where the solve ended, else (a state not finite) on the constraint at r = 0
        s = np.zeros(2 * n)
        s[:n] = at
        pivot = rigid_pivot(s, cst, system.data)
        if np.isfinite(pivot):
            break
    if pivot <= 0.0:
        raise EquilibriumError(f"no steady sliding at {system.point_text()}: the Painlevé paradox — while a rigid "
                               "contact slides, the normal force that keeps it closed has no consistent value, or two "
                               f"(the relative pivot of its normal-force equation is {pivot:.3g} ≤ 0: friction turns "
                               "the normal acceleration against the normal force); lower the friction coefficient")
    rel = steady_residual(system, q)
    if not (np.all(np.isfinite(q)) and rel <= RESIDUAL_TOL):
        raise EquilibriumError(f"no steady-sliding equilibrium found for {point_text(system)}: no position with the "
                               f"rigid contacts closed balances the forces (relative residual {rel:.2e} > "
                               f"{RESIDUAL_TOL:g} where the root finder stopped: {message.rstrip('.')}); steady "
                               "sliding may not exist at these parameters (is there a free direction along the contact "
                               "without stiffness against the friction?)")
    return q, float(rel), nfev


def _solve_closed(system) -> tuple[np.ndarray, float, int]:
    """:func:`solve_steady` with every unilateral contact held closed, whatever its normal force."""
    if min(sliding_speeds(system, np.zeros(system.n))) == 0.0:  # a contact at rest does not slide (e.g. Ω = 0)
        raise EquilibriumError(_not_sliding_message(system, np.zeros(system.n)))
    free = np.flatnonzero(system.free).astype(np.int64)
    compile_apart(system.data, steady.STEADY, f"{steady.__name__}:STEADY")
    q, status, rel, iterations = steady.steady_sliding_point(system.data, free, MAX_ITER)
    if status == steady.NEWTON_NOT_SLIDING:
        raise EquilibriumError(_not_sliding_message(system, q))
    if not (np.all(np.isfinite(q)) and rel <= RESIDUAL_TOL):
        if np.all(np.isfinite(q)) and min(sliding_speeds(system, q)) == 0.0:
            raise EquilibriumError(_not_sliding_message(system, q))
        raise EquilibriumError(_failure_message(system, q, status, rel))
    return q, float(rel), int(iterations)


def _open_contact(system, q: np.ndarray):
    """(c, g, λ) of the first unilateral contact that is not closed (g < 0, λ > 0; a rigid one:
    λ > 0, its gap held at 0) at the steady state ``q`` solved with it closed, or None."""
    s = np.zeros(2 * system.n)
    s[:system.n] = q
    cst = _sliding_modes(system)
    for c, contact in enumerate(system.contacts):
        if contact.unilateral:
            g = gap(s, c, system.data)[0]
            lam = normal_force_of(s, cst, c, system.data)
            closed = lam > 0.0 if contact.normal.law == "rigid" else (g < 0.0 and lam > 0.0)
            if not closed:
                return c, g, lam
    return None


def _closed_without_friction(system) -> bool:
    """Whether the model's steady state with every friction coefficient 0 has its unilateral
    contacts closed (False where that model cannot be built or solved: a user law, say)."""
    zero = {f"contact.{c}.friction.{key}": 0.0 for c in range(system.n_contacts) for key in ("mu_k", "delta_mu")}
    try:
        smooth = system.replace(**zero)
        return _open_contact(smooth, (_solve_rigid if smooth.rigid else _solve_closed)(smooth)[0]) is None
    except (StickSlipError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return False


def _check_closed(system, q: np.ndarray) -> None:
    """Steady sliding needs every unilateral contact closed (g < 0, λ > 0) at the equilibrium found
    with them closed; otherwise it does not exist. The refusal says why: the contact is not pressed
    at all, or it is pressed without friction and the friction pulls it open (sprag: a friction
    coefficient past the model's threshold)."""
    found = _open_contact(system, q)
    if found is None:
        return
    c, g, lam = found
    head = (f"no steady sliding at {system.point_text()}: contact {c} ({system.contact_names[c]}) would be open "
            f"(gap {g:.6g}, normal force {lam:.6g} with it closed)")
    if _closed_without_friction(system):
        raise EquilibriumError(f"{head}, though it is pressed without friction: the friction jams it (sprag: the "
                               "friction coefficient is past the model's threshold); lower it or simulate the motion")
    raise EquilibriumError(f"{head}, so nothing presses it onto its surface; press it (a force towards the contact, a "
                           "negative gap) or simulate the free motion")


def _sliding_modes(system, opened=()) -> np.ndarray:
    """Contact states with every contact slipping (exact direction), as steady sliding has them,
    but those in ``opened``, open."""
    cst = np.zeros(CST * system.n_contacts)
    cst[0::CST] = MODE_SLIP_EXACT
    cst[3::CST] = np.inf
    for c in opened:
        cst[CST * c] = MODE_OPEN
    return cst


def steady_sliding(system) -> np.ndarray:
    """Steady-sliding equilibrium q_e (n,) of any friction model (see :func:`solve_steady`)."""
    return solve_steady(system)[0]


def equilibrium_residual(system, q: np.ndarray, cst: np.ndarray | None = None) -> np.ndarray:
    """Force residual −M q̈ of the slip equations at (q, q̇ = 0), shape (n,) [N or N m per dof].

    Evaluated by the simulator's right-hand side, so its zero is exactly the steady sliding state
    the simulator sees (for the plates: K q − Gᵀ F(v_r = Ω(Y, −X)), paper Eq. 14). Locked DOFs give 0.
    ``cst``: the contacts' modes (default every contact sliding).
    """
    n = system.n
    s = np.zeros(2 * n)
    s[:n] = q
    ds = np.zeros(2 * n)
    rhs(s, _sliding_modes(system) if cst is None else cst, system.data, ds)
    return np.where(system.free, -(system.mass @ ds[n:]), 0.0)


def steady_residual(system, q: np.ndarray, cst: np.ndarray | None = None) -> float:
    """Relative force residual |M q̈| / max(|K q|, |f0|, |Σ Gᵀ F|) of steady sliding at q (q̇ = 0)
    (``cst``: the contacts' modes, default every contact sliding)."""
    free = np.flatnonzero(system.free)
    Q = -equilibrium_residual(system, q, cst)[free]
    Kq = (system.stiffness @ np.asarray(q, float))[free]
    f0 = system.force[free]
    num = float(np.max(np.abs(Q), initial=0.0))
    scale = max(float(np.max(np.abs(Kq), initial=0.0)), float(np.max(np.abs(f0), initial=0.0)),
                float(np.max(np.abs(Q + Kq - f0), initial=0.0)))
    if num == 0.0:
        return 0.0
    return num / scale if scale > 0.0 and np.isfinite(num) else math.inf


def equilibrium(model=None) -> np.ndarray:
    """Steady-sliding equilibrium q_e (n,) of a model, locked DOFs 0 [units of the dofs].

    Solves the force balance at rest (for the plates K x = b(x), paper Eq. 14, b from Appendix
    A.1) by damped Newton from x = 0 with the exact Jacobian (falling back to continuation in the
    load from a fraction of it when Newton from 0 stalls) and checks the residual with the
    simulator's kernel (:func:`solve_steady`).

    Parameters
    ----------
    model : FrictionModel, Parameters or str, optional
        The model, as :func:`stickslip.simulate` takes it (default the plates with Table 1; the
        plates in a variant: ``two_plates(params, "rotation")``).

    Raises
    ------
    EquilibriumError
        When a contact does not slide at rest (the plates at Ω = 0: v_r vanishes, the friction
        direction is undefined), when Newton does not reach a relative residual of
        :data:`RESIDUAL_TOL` (e.g. the plates at large N and small Ω, where the contact point is
        dragged to the centre of the lower plate and steady sliding ceases to exist), or when the
        sliding speed at equilibrium is inside the simulator's low-speed band.
    """
    return steady_sliding(model_of(model))


def model_of(model) -> FrictionModel:
    """The model that ``model`` names (as :func:`stickslip.simulate` takes it).

    Raises
    ------
    TypeError
        For ``model`` that is not a model, the plates' Parameters, a library name or a model file.
    """
    if model is not None and not isinstance(model, (Parameters, FrictionModel, str, Path)):
        raise TypeError(f"model must be a FrictionModel, the plates' Parameters or a model's name, got "
                        f"{type(model).__name__}")
    return resolve_model(model)
