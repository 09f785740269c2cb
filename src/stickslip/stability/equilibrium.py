"""Steady-sliding equilibrium K x = b(x) (paper Eq. 14, Appendix A.1).

Solved by damped Newton from x = 0 with the exact Jacobian −K_L of the slip right-hand side
(complex-step differentiation, :mod:`stickslip.stability.linearize`) — with continuation in the
load N as a fallback near the fold where steady sliding ceases to exist — then checked with the
simulator's own kernel (:func:`equilibrium_residual`).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import StickSlipError
from ..model import kernels
from ..model.parameters import Parameters
from ..model.system import System, assemble
from . import linearize

__all__ = ["EquilibriumError", "equilibrium", "equilibrium_residual", "solve_equilibrium", "RESIDUAL_TOL",
           "steady_sliding", "steady_residual"]

#: Relative residual |K x − b| / max(|K x|, |b|) accepted as solved (Eq. 14). Newton reaches
#: ~1e-16 (round-off of the force balance); 1e-10 leaves room for ill-conditioned cases while
#: still pinning x far below any physical resolution.
RESIDUAL_TOL = 1e-10

#: Newton iterations allowed per solve. Converging cases take 3–8 from x = 0 (quadratic
#: convergence); 60 leaves room for the damped phase of strongly deflected cases.
MAX_ITER = 60


class EquilibriumError(StickSlipError, RuntimeError):
    """No steady-sliding equilibrium could be found."""


def equilibrium_residual(system: System, q: np.ndarray) -> np.ndarray:
    """Force residual K q − Gᵀ F(v_r = Ω(Y, −X)) at rest (q̇ = 0), shape (6,) [N or N m].

    This is −M q̈ of the slip equations at q̇ = 0, evaluated by the simulator's own kernel, so
    its zero is exactly the steady sliding state the simulator sees. Locked DOFs give 0.
    """
    s = np.zeros(12)
    s[:6] = q
    ds = np.zeros(12)
    Fx, Fy = kernels.contact_force(s, kernels.MODE_SLIP, 1.0, 0.0, system.minv, system.damp, system.stiff, system.p)
    kernels.dynamics(s, Fx, Fy, system.minv, system.damp, system.stiff, system.p, ds)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(system.minv > 0, -ds[6:] / np.where(system.minv > 0, system.minv, 1.0), 0.0)


def solve_equilibrium(system: System) -> tuple[np.ndarray, float, int]:
    """Newton solution of Eq. (14) for an assembled system.

    Returns
    -------
    q : ndarray (6,)
        Equilibrium [m, m, m, m, rad, rad]; locked DOFs are 0.
    relative_residual : float
        max|K x − b| / max(|K x|, |b|), evaluated with the simulator's kernel.
    iterations : int

    Raises
    ------
    EquilibriumError
        See :func:`equilibrium`.
    """
    P = system.params
    if P.Omega == 0.0:
        raise EquilibriumError(
            "no steady sliding at Omega = 0: the relative velocity vanishes at rest and the friction "
            "direction is undefined; choose Omega != 0"
        )
    free = system.variant.free_indices.astype(np.int64)
    q, status, rel, iterations = linearize.newton_equilibrium(free, system.damp, system.stiff, system.p, MAX_ITER)
    band = system.p[kernels.P_SLIP_BAND]
    speed = abs(P.Omega) * math.hypot(q[0] - q[2] + P.r * math.cos(q[4]), q[1] - q[3] + P.r * math.sin(q[4]))
    if rel <= RESIDUAL_TOL and speed <= band:
        raise EquilibriumError(
            f"sliding speed at equilibrium |Omega| R = {speed:.3g} m/s is inside the simulator's low-speed band "
            f"({band:g} m/s), where its slip direction is not v_r/|v_r| and steady sliding is not an equilibrium "
            "of the simulated equations; increase |Omega|"
        )
    # independent check with the simulator's kernel (not the differentiated copy)
    res = equilibrium_residual(system, q)[free]
    scale = max(float(np.max(np.abs(system.stiff[free] * q[free]))),
                float(np.max(np.abs(system.stiff[free] * q[free] - res))))
    kernel_rel = 0.0 if not np.any(res) else (float(np.max(np.abs(res))) / scale if scale > 0 else math.inf)
    if not np.all(np.isfinite(q)) or not (kernel_rel <= RESIDUAL_TOL):
        X = q[0] - q[2] + P.r * math.cos(q[4])
        Y = q[1] - q[3] + P.r * math.sin(q[4])
        reason = {
            linearize.NEWTON_MAX_ITER: f"Newton did not converge in {MAX_ITER} iterations",
            linearize.NEWTON_SINGULAR: "the Jacobian K_L became singular (is a free DOF without stiffness?)",
            linearize.NEWTON_NOT_FINITE: "the iteration produced non-finite values",
            linearize.NEWTON_NO_DESCENT: "Newton stalled (no step reduces the residual)",
        }.get(int(status), "the residual check failed")
        hint = ""
        if math.hypot(X, Y) < 0.5 * P.r:
            hint = (f"; the iterate has the contact point at R = {math.hypot(X, Y):.3g} m from the centre O2 "
                    f"(r = {P.r:g} m): the friction load mu N drags the contact point onto the centre of the "
                    "lower plate and steady sliding does not exist beyond that load (a fold of Eq. 14); "
                    "reduce N or mu")
        raise EquilibriumError(
            f"no steady-sliding equilibrium found for N = {P.N:g} N, Omega = {P.Omega:g} rad/s, model "
            f"{system.variant.name!r}: {reason} (relative residual {max(rel, kernel_rel):.2e} > {RESIDUAL_TOL:g})"
            f"{hint}"
        )
    return q, kernel_rel, int(iterations)


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
        equilibrium is inside the simulator's low-speed band (``kernels.DEFAULT_SLIP_BAND``).
    """
    if not isinstance(params, Parameters):
        raise TypeError(f"params must be a stickslip.Parameters, got {type(params).__name__}")
    q, _, _ = solve_equilibrium(assemble(params, model))
    return q


# --------------------------------------------------------------------------- any friction model
#: Newton iterations of :func:`steady_sliding` per homotopy level.
STEADY_MAX_ITER = 50

#: Homotopy levels of the friction load tried when Newton from q = 0 at full load fails.
HOMOTOPY_LEVELS = (0.25, 0.5, 0.75, 0.9, 1.0)


def _sliding_state(system) -> np.ndarray:
    """Contact states for steady sliding: every contact slipping with the exact direction."""
    from ..model.bundle import CST, contact_state
    from ..model.physics import MODE_SLIP_EXACT

    cst = contact_state(system.data.m)
    cst[0::CST] = MODE_SLIP_EXACT
    return cst


def _newton_steady(system, md, q0: np.ndarray, free: np.ndarray, max_iter: int):
    """Damped Newton on the accelerations at rest; returns (q, |residual| relative, iterations)."""
    from ..model.derivatives import acceleration_jacobian

    n = system.n
    cst = _sliding_state(system)
    Jqq = np.empty((n, n))
    acc = np.empty(n)
    z = np.zeros(2 * n, dtype=complex)
    dz = np.zeros(2 * n, dtype=complex)
    q = q0.copy()
    M = system.mass[np.ix_(free, free)]
    K = system.stiffness[np.ix_(free, free)]
    f0 = system.force[free]

    def relative(a, qv):
        res = M @ a[free]
        scale = max(np.max(np.abs(K @ qv[free])), np.max(np.abs(f0)), np.max(np.abs(res + K @ qv[free] - f0)), 1e-300)
        return float(np.max(np.abs(res)) / scale)

    acceleration_jacobian(q, cst, md, Jqq, acc, z, dz)
    rel = relative(acc, q)
    for it in range(max_iter):
        if rel <= NEWTON_TARGET_GENERIC or not np.isfinite(rel):
            return q, rel, it
        try:
            step = np.linalg.solve(Jqq[np.ix_(free, free)], -acc[free])
        except np.linalg.LinAlgError:
            return q, rel, it
        lam = 1.0
        for _ in range(30):  # backtracking: accept the first step that reduces the residual
            trial = q.copy()
            trial[free] += lam * step
            acceleration_jacobian(trial, cst, md, Jqq, acc, z, dz)
            rel_trial = relative(acc, trial)
            if np.isfinite(rel_trial) and rel_trial < rel:
                q, rel = trial, rel_trial
                break
            lam *= 0.5
        else:
            return q, rel, it
    acceleration_jacobian(q, cst, md, Jqq, acc, z, dz)
    return q, relative(acc, q), max_iter


#: Relative residual at which the generic Newton stops (a few ulps above round-off).
NEWTON_TARGET_GENERIC = 1e-14


def steady_residual(system, q: np.ndarray) -> float:
    """Relative force residual |M q̈| / max(|K q|, |f0|, |Σ Gᵀ F|) of steady sliding at q (q̇ = 0)."""
    free = np.flatnonzero(system.free)
    _, rel, _ = _newton_steady(system, system.data, np.asarray(q, dtype=float), free, 0)
    return rel


def steady_sliding(system) -> np.ndarray:
    """Steady-sliding equilibrium q_e (n,) of any friction model: q̇ = 0 and
    f0 − K q + Σ_c G_cᵀ F_c(q, q̇ = 0) = 0 with every contact slipping.

    Damped Newton from q = 0 with the exact Jacobian of the simulator's right-hand side (complex
    step, :mod:`stickslip.model.derivatives`); when that fails, a homotopy in the normal forces
    (friction load 25 %, 50 %, ... 100 %) from the unloaded equilibrium.

    Raises
    ------
    EquilibriumError
        No solution to :data:`RESIDUAL_TOL`, or a slip velocity at equilibrium that is zero (no
        sliding: the friction direction is undefined) or inside the low-speed band of a 2-D
        contact (the simulator's slip direction there is not v/|v|, so steady sliding is not an
        equilibrium of the simulated equations).
    """
    from ..model.bundle import C_N0, ModelData, contact_offsets
    from ..model.physics import slip_velocity

    free = np.flatnonzero(system.free)
    md = system.data
    q, rel, _ = _newton_steady(system, md, np.zeros(system.n), free, STEADY_MAX_ITER)
    if not rel <= RESIDUAL_TOL:
        q = np.zeros(system.n)
        for level in HOMOTOPY_LEVELS:
            m = md.m.copy()
            for c in range(system.n_contacts):
                o = contact_offsets.py_func(system.n, c)[0]
                m[o + C_N0] *= level
            q, rel, _ = _newton_steady(system, ModelData(m, md.kin), q, free, STEADY_MAX_ITER)
            if not rel <= RESIDUAL_TOL:
                break
    if not (np.all(np.isfinite(q)) and rel <= RESIDUAL_TOL):
        raise EquilibriumError(
            f"no steady-sliding equilibrium found for model {system.name!r}: Newton reached a relative "
            f"residual of {rel:.2e} > {RESIDUAL_TOL:g} (steady sliding may not exist at these parameters: "
            "e.g. a friction load that drags the contact into a fold)")
    s = np.zeros(2 * system.n)
    s[:system.n] = q
    for c, contact in enumerate(system.contacts):
        v = np.array(slip_velocity(s, c, md))
        speed = float(np.hypot(*v))
        if speed == 0.0:
            raise EquilibriumError(f"no steady sliding: contact {c} does not slide at rest (its drive is 0); "
                                   "give the contact a non-zero drive")
        if contact.dim == 2 and speed <= system.slip_band:
            raise EquilibriumError(
                f"sliding speed at equilibrium {speed:.3g} m/s of contact {c} is inside the simulator's low-speed "
                f"band ({system.slip_band:g} m/s), where its slip direction is not v/|v| and steady sliding is not an "
                "equilibrium of the simulated equations; increase the drive")
    return q
