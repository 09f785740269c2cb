"""The pseudo-arclength corrector: the shooting problem with the parameter as an unknown.

The orbit is the zero of the shooting map of :class:`.problem.ShootingProblem`, now with the
parameter λ (any numeric parameter of the model: the plates' ``N``, ``Omega``, ...; a model file's
``--set`` path such as ``contact.0.drive``) as an extra unknown. In
scaled unknowns v = (z, T/T_s, λ/λ_s) — z the unknown section states in units of σ — the
2 n_free equations are

    F(v) = (Φ(s(z), T; λ) − s(z))[free] / σ = 0,

closed by the pseudo-arclength condition τ_kᵀ (v − v_k) = h, τ_k the unit tangent at the last
point (the null vector of ∂F/∂v there) and h the step.

Each point with a Jacobian costs one finite-difference ∂F/∂v: the monodromy ∂Φ/∂s0 of the
shooting problem over every free state (the section coordinate's column is not part of ∂F/∂v but
completes the monodromy, whose eigenvalues are the Floquet multipliers), the exact T column and a
central difference in λ — 2 (2 n_free + 1) flow maps. The corrector is Newton's method started
with the Jacobian of the previous point and kept current by Broyden rank-one updates, one flow
map per iteration. :mod:`.branch` drives the steps; :mod:`.special_points` locates special points
with :func:`step_from`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import ContinuationError, OrbitError, SteadySlidingError
from ..integrate.result import find_impacts
from ..model.system_model import FrictionModel
from .layout import independent_states
from .models import parameter_value, with_parameter
from .problem import (DEFAULT_FD_STEP, DEFAULT_TOL, ShootingProblem, check_method, open_count, open_time,
                      sorted_eigenvalues, stick_count, stick_time)

__all__ = ["ContinuationError", "SteadySlidingError", "DEFAULT_TOL", "DEFAULT_FD_STEP", "MAX_CORRECTOR",
           "MIN_TANGENT_COS", "MAX_STEPS_PER_SECOND", "GRAZING_LANDING_RTOL", "monodromy_method"]

#: Corrector iterations before a step counts as failed (then halved). Broyden from the previous
#: point's Jacobian reduces the residual ~5× per iteration (measured on Model 1, N = 50 N: the
#: 0.997 multipliers make M − I nearly singular, so the FD Jacobian's noise limits the rate) and
#: converges in 4–6 iterations from a predictor error of ~5e-4 σ.
MAX_CORRECTOR = 8

#: Smallest cosine between consecutive tangents accepted: a larger turn means the step jumped
#: over a sharp feature (or onto another branch); the step is halved instead.
MIN_TANGENT_COS = 0.9

#: An impact landing slower than this fraction of the largest velocity scale σ is not resolved:
#: the multipliers of such a point are left unknown (NaN: no special point is classified on them,
#: and no stability is claimed). The impact's jump divides by the landing speed v_i, and its impact
#: map Π is differentiated by central differences whose velocity steps must stay below v_i / 2 (Π
#: has a kink where ġ⁻ reverses: no impulse), so their round-off, ~1e-16 |s| / v_i, enters divided
#: by v_i again: ~1e-16 (σ / v_i)² of the jump's large column, 1e-2 at 1e-7 σ. The flow direction
#: is mapped exactly regardless, so the trivial multiplier (the verdicts' error estimate) does not
#: show that error. Measured: the rigid slider towards its flight's vanishing has
#: {1, 0, 0, 0} to 1e-6 down to v_i = 3.7e-8 σ, and its monodromy equals forward differences of
#: plain runs to 1e-4 at 8.7e-8 σ; the belt with a stop, whose monodromy grows like 1/v_i, has
#: {1, 0} to 6e-5 at 2.4e-6 σ (tests/orbits/test_impact_grazing.py). Below, forward differences
#: cannot check it either: the distance to the grazing, ~v_i², is under the plain runs' resolution.
GRAZING_LANDING_RTOL = 1e-7

#: Steps of a flow map allowed per simulated second: a period of Model 1 takes ~1e3 steps at
#: rtol 1e-10; a stalled integration (approach to stick, docs/orbits.md) fails fast instead of
#: running 5e7 steps.
MAX_STEPS_PER_SECOND = 2e5


@dataclasses.dataclass(frozen=True, eq=False)
class Problem:
    """The shooting problem at the base parameters, with the parameter λ and the scales of T and λ."""

    shooting: ShootingProblem
    param: str
    T_scale: float  # [s]
    p_scale: float  # [unit of the parameter]
    monodromy: str = "finite-difference"  # how each point's ∂Φ/∂s0 is computed (:func:`monodromy_method`)

    @property
    def counter(self) -> dict:
        """``{"simulations": flow maps run}``."""
        return self.shooting.counter

    def system_at(self, lam: float) -> FrictionModel:
        """The model with the continuation parameter set to ``lam``."""
        return with_parameter(self.shooting.system, self.param, lam)

    def unpack(self, v: np.ndarray):
        """Scaled unknowns (n_unknown + 2,) → (state on the section, T [s], λ)."""
        return self.shooting.state(v[:-2]), float(v[-2] * self.T_scale), float(v[-1] * self.p_scale)

    def pack(self, s: np.ndarray, T: float, lam: float) -> np.ndarray:
        """Inverse of :meth:`unpack`."""
        return np.concatenate([self.shooting.unknowns(s), [T / self.T_scale, lam / self.p_scale]])


def numeric_parameter(system: FrictionModel, param: str) -> float:
    """The value of continuation parameter ``param`` of ``system``; ContinuationError if the model
    has no such parameter or it is not numeric."""
    try:
        return parameter_value(system, param)
    except OrbitError as exc:
        raise ContinuationError(f"cannot continue in {param!r}: {exc}") from None


def monodromy_method(system: FrictionModel, method: str = "auto") -> str:
    """How the points of a branch of ``system`` get ∂Φ/∂s0: ``saltation`` or ``finite-difference``;
    ``auto`` is ``saltation`` where the model has a rigid contact, else ``finite-difference``.

    Central differences of the flow map straddle every event whose instant moves with the
    perturbation, and near an impact that grazes (landing speed → 0) the flow map has a
    square-root singularity: differences of steps ``fd_step`` σ across it give multipliers of any
    size (|μ| up to 12 measured on the belt with a stop, where the cycle is stable with {1, 0}).
    The saltation matrices are exact there, as long as the impact lands at all.
    """
    if method == "auto":
        return "saltation" if system.rigid else "finite-difference"
    check_method(method, "monodromy method")
    return method


def problem_of(start, param: str, fd_step: float, param_scale: float | None,
               monodromy: str = "finite-difference") -> Problem:
    """The continuation problem of a start orbit (state, period, scale, system, section, options);
    ``monodromy``: ``saltation`` or ``finite-difference`` (:func:`monodromy_method`)."""
    lam0 = numeric_parameter(start.system, param)
    scale = abs(lam0) if param_scale is None else float(param_scale)
    if not (np.isfinite(scale) and scale > 0.0):
        scale = 1.0  # λ0 = 0: work in the parameter's own unit
    o = start.options
    shooting = ShootingProblem.build(start.system, sigma=start.scale, section=start.section, rtol=o["rtol"],
                                     constraint=independent_states(start.system, start.state)[1],
                                     atol=o["atol"], fd_step=fd_step, max_steps_per_second=MAX_STEPS_PER_SECOND)
    return Problem(shooting=shooting, param=param, T_scale=float(start.period), p_scale=scale, monodromy=monodromy)


def _residual(problem: Problem, v: np.ndarray):
    """F(v) (2 n_free,) in units of σ, the end state and the transitions of the run."""
    s, T, lam = problem.unpack(v)
    return problem.shooting.residual(s, T, problem.system_at(lam))


def _jacobian(problem: Problem, v: np.ndarray, end: np.ndarray):
    """Jacobian ∂F/∂v (2 n_free × 2 n_free + 1) and the monodromy matrix.

    The monodromy by ``problem.monodromy``: the variational equations with saltation matrices (one
    re-integration; central differences where it cannot follow the run's events) or central
    differences in every free state (2 (2 n_free) simulations); the T column is exact, f(Φ) from
    the vector field; the λ column a central difference (two simulations).

    Returns
    -------
    J : ndarray (2 n_free, 2 n_free + 1)
        In scaled units (rows / σ, columns × σ, T_s, λ_s).
    M : ndarray (2 n_free, 2 n_free)
        ∂Φ(s0, T)/∂s0 on the free states [state units].
    """
    s, T, lam = problem.unpack(v)
    system = problem.system_at(lam)
    sp = problem.shooting
    M = sp.monodromy_columns(s, T, problem.monodromy, system=system)
    J = np.empty((sp.free.size, sp.free.size + 1))
    J[:, :-1] = sp.jacobian(M[:, sp.unknown], end, system, problem.T_scale)
    dl = sp.fd_step * problem.p_scale
    ep = sp.flow(s, T, problem.system_at(lam + dl))[0][sp.free]
    em = sp.flow(s, T, problem.system_at(lam - dl))[0][sp.free]
    J[:, -1] = (ep - em) / (2.0 * dl) / sp.sigma * problem.p_scale
    return J, M


def _tangent(J: np.ndarray, previous: np.ndarray | None = None, direction: float = 1.0) -> np.ndarray:
    """Unit null vector of J (n × n + 1), oriented along ``previous`` (or with sign(τ_λ) = direction)."""
    t = np.linalg.svd(J)[2][-1]
    ref = float(t @ previous) if previous is not None else direction * t[-1]
    return -t if ref < 0.0 else t


def _correct(problem: Problem, v: np.ndarray, J: np.ndarray, row: np.ndarray, target: float, tol: float):
    """Newton–Broyden corrector on F(v) = 0, rowᵀ v = target.

    Starts from ``J`` (a Jacobian near ``v``) and keeps it current by Broyden's rank-one updates,
    so each iteration costs one simulation.

    Returns
    -------
    (v, R, end, transitions, iterations, J)
        At convergence; ``J`` the updated Jacobian.

    Raises
    ------
    OrbitError, SimulationError
        No convergence in :data:`MAX_CORRECTOR` iterations, growing residual, or a failed run.
    """
    R, end, tr = _residual(problem, v)
    J = J.copy()
    history = [float(np.max(np.abs(R)))]
    for it in range(MAX_CORRECTOR + 1):
        c = float(row @ v - target)
        if history[-1] <= tol and abs(c) <= tol:
            return v, R, end, tr, it, J
        if it == MAX_CORRECTOR:
            break
        A = np.vstack([J, row])
        dv = np.linalg.solve(A, -np.concatenate([R, [c]]))
        v_new = v + dv
        R_new, end, tr = _residual(problem, v_new)
        J += np.outer(R_new - R - J @ dv, dv) / float(dv @ dv)  # Broyden's good update
        v, R = v_new, R_new
        history.append(float(np.max(np.abs(R))))
        if it >= 1 and history[-1] > 0.5 * history[-2] and history[-1] > 10 * tol:
            break  # not contracting: give the step back
    raise OrbitError(f"corrector did not converge (residuals {', '.join(f'{r:.1e}' for r in history)})")


@dataclasses.dataclass(frozen=True, eq=False)
class Point:
    """One converged orbit of a branch (internal).

    ``stick_phases`` and ``stick_time`` [s] count the slip → stick transitions of its period and
    the time in stick; ``open_phases`` and ``open_time`` [s] the openings of unilateral contacts
    (flight phases) and the time with some contact open, None for a model without unilateral
    contacts; ``impact_speed`` the smallest landing speed −ġ⁻ of the rigid contacts' impacts
    over the period [m/s], None where it has none.
    """

    v: np.ndarray
    J: np.ndarray
    M: np.ndarray
    tangent: np.ndarray
    multipliers: np.ndarray
    stick_phases: int
    stick_time: float
    residual: float
    iterations: int
    open_phases: int | None = None
    open_time: float | None = None
    impact_speed: float | None = None

    @property
    def fresh(self) -> bool:
        """True if J is a Jacobian of this point's own (its monodromy M computed), not Broyden's update."""
        return bool(np.all(np.isfinite(self.M)))

    @property
    def has_multipliers(self) -> bool:
        """True if the point's multipliers are known: a fresh point whose impacts do not graze
        (:data:`GRAZING_LANDING_RTOL`)."""
        return bool(np.all(np.isfinite(self.multipliers)))


def phases(problem: Problem, v: np.ndarray, tr) -> dict:
    """The stick and flight phases of the period at ``v`` from its run's transitions ``tr``: the
    :class:`Point` fields ``stick_phases``, ``stick_time`` and, where the model has unilateral
    contacts, ``open_phases`` and ``open_time``, and where its period has impacts ``impact_speed``."""
    out = {"stick_phases": stick_count(tr), "stick_time": stick_time(tr)}
    if problem.shooting.system.unilateral:
        s, T, lam = problem.unpack(v)
        system = problem.system_at(lam)
        out.update(open_phases=open_count(tr), open_time=open_time(tr, T, system, s))
        landing = -find_impacts(system, tr).speed_before
        if landing.size:
            out["impact_speed"] = float(landing.min())
    return out


def _make_point(problem: Problem, v, R, end, tr, iterations, previous_tangent, direction) -> Point:
    """The point at ``v`` with its Jacobian, tangent and multipliers (NaN where an impact grazes,
    :func:`grazes`)."""
    J, M = _jacobian(problem, v, end)
    found = phases(problem, v, tr)
    multipliers = np.full(M.shape[0], np.nan + 0j) if grazes(problem, found.get("impact_speed")) \
        else sorted_eigenvalues(M)
    return Point(v=v, J=J, M=M, tangent=_tangent(J, previous_tangent, direction), multipliers=multipliers,
                 residual=float(np.max(np.abs(R))), iterations=iterations, **found)


def grazes(problem: Problem, impact_speed: float | None) -> bool:
    """Whether an orbit's slowest impact lands so slowly (``impact_speed`` [m/s], None: no impact)
    that its monodromy does not resolve the multipliers (:data:`GRAZING_LANDING_RTOL` of the
    largest velocity scale σ)."""
    if impact_speed is None:
        return False
    sp = problem.shooting
    velocities = sp.sigma[sp.free >= sp.system.n]
    return impact_speed < GRAZING_LANDING_RTOL * float(np.max(velocities))


def point_at(problem: Problem, v: np.ndarray, iterations: int, previous_tangent=None, direction: float = 1.0) -> Point:
    """The point at the converged ``v`` with a new Jacobian (one residual run + the differences)."""
    R, end, tr = _residual(problem, v)
    return _make_point(problem, v, R, end, tr, iterations, previous_tangent, direction)


def step_from(problem: Problem, point: Point, h: float, tol: float, with_jacobian: bool = True) -> Point:
    """The branch point at arclength ``h`` from ``point`` (predictor along its tangent + corrector)."""
    v_pred = point.v + h * point.tangent
    v, R, end, tr, it, J = _correct(problem, v_pred, point.J, point.tangent, float(point.tangent @ v_pred), tol)
    if not with_jacobian:  # Broyden-updated Jacobian: tangent, but no multipliers
        n = point.M.shape[0]
        return Point(v=v, J=J, M=np.full((n, n), np.nan), tangent=_tangent(J, point.tangent),
                      multipliers=np.full(n, np.nan + 0j), residual=float(np.max(np.abs(R))), iterations=it,
                      **phases(problem, v, tr))
    return _make_point(problem, v, R, end, tr, it, point.tangent, 1.0)


def correct_onto_bound(problem: Problem, last: Point, new: Point, edge: float, tol: float) -> Point:
    """The branch point at λ = ``edge`` (a bound the step ``last`` → ``new`` crossed)."""
    e = np.zeros_like(new.v)
    e[-1] = 1.0
    guess = last.v + (edge / problem.p_scale - last.v[-1]) / last.tangent[-1] * last.tangent \
        if abs(last.tangent[-1]) > 1e-12 else new.v
    v, R, end, tr, it, _ = _correct(problem, guess, last.J, e, edge / problem.p_scale, tol)
    return _make_point(problem, v, R, end, tr, it, last.tangent, 1.0)
