"""The stick step of ``aeom``, the paper's method of alternated equations of motion (Sect. 3).

The fixed-step loop, the slip steps and the samples are shared with ``naeom``
(:mod:`~stickslip.integrate.fixed_step`); what is specific to AEOM is the stick phase:

* stick: RK4 on the four "free" DOFs x1, y1, φ, ψ (Eq. 13), with x2, y2 taken from the
  trapezoidal rule of Eq. (12) and ẋ2, ẏ2 from the velocity constraint v_r = 0 (Eq. 11,
  first two lines), at every RK4 stage and at the step end;
* breakaway (Eq. 10) at a step end is located by bisection on re-taken stick steps.

The 4-DOF stick equations, Eq. (13), are Eq. (1) with F eliminated using the acceleration-level
constraint (Eq. 11, lines 3–4). That elimination is exactly the generic stick multiplier
(``physics.rhs`` with the contact in stick), so the stick accelerations of x1, y1, φ, ψ come from
the generic right-hand side on the stage state whose x2, y2, ẋ2, ẏ2 are the dependent values
above: no second copy of the model. What is specific to AEOM, and kept, is that x2, y2 are *not*
integrated by RK4 but by the trapezoidal rule (Eqs. 11–12), with its O(Δt²) error. The plates'
structure it needs is the plates' model's: q = [x1, y1, x2, y2, φ, ψ], the contact radius r and
the disc speed Ω from the kinematics data (``md.kin``, ``PlateKinematics``), which of x2, y2 are
free from the model data (``md.m``).

Model variants. The trick eliminates x2 (y2) through the x (y) component of
v_r = 0; a locked x2 or y2 (zero inverse mass) cannot absorb its component. Our choice:

* x2 and y2 free (Model 1): Eq. (12) as printed (the two trapezoidal relations are coupled
  through (Ω + ψ̇) and solved together);
* only x2 free (Model 2) or only y2 free (Model 3): the one trapezoidal relation of the free
  one, with the locked one at 0 (w = y2 − y1 = −y1, or u = −x1); the other component of
  v_r = 0 is carried by the constrained accelerations of the remaining DOFs;
* neither free (Model 4, and custom models without x2, y2): there is nothing to eliminate, the
  stick phase is RK4 on the constrained dynamics (rank-1 multiplier, rank-deficient G M⁻¹ Gᵀ).

Whenever a component of v_r = 0 is not enforced by construction (the last two cases), the
velocities are projected onto v_r = 0 in the M-metric after the step (``physics.project_velocities``,
the same drift removal as ``event``); no division by a zero mass happens anywhere, so no NaN.

"""

from __future__ import annotations

import math

import numpy as np

from ..model import csmath as csm
from ..model import physics as P
from ..model.bundle import offsets
from ..model.jit import kernel
from ..model.kinematics import model_sizes
from ..model.physics import general_rhs
from . import events as E
from . import rk4
from .step_physics import derivative_and_contact

__all__ = ["aeom_stick_branch", "aeom_stick_step", "dependent_states"]


# --------------------------------------------------------------------------- AEOM stick step
@kernel
def _trapezoid_base(y, md):
    """u = x2 − x1, w = y2 − y1 and their rates from v_r = 0 (Eq. 11) at the step start."""
    r = md.kin.r
    sphi = csm.sin(y[4])
    cphi = csm.cos(y[4])
    wt = md.kin.Omega + y[11]
    a0 = -r * y[10] * sphi + wt * (y[1] - y[3] + r * sphi)
    b0 = r * y[10] * cphi - wt * (y[0] - y[2] + r * cphi)
    return y[2] - y[0], y[3] - y[1], a0, b0


@kernel
def _free_lower_plate(md):
    """Whether x2 and y2 are free DOFs of the model (the variants lock them)."""
    o_free = offsets(model_sizes(md.kin, md.m)[0])[5]
    return md.m[o_free + 2] != 0.0, md.m[o_free + 3] != 0.0


@kernel
def dependent_states(s, tau, u0, w0, a0, b0, md):
    """Set x2, y2 by the trapezoidal rule (Eqs. 11–12) and ẋ2, ẏ2 from v_r = 0 (Eq. 11), in place.

    Parameters
    ----------
    s : ndarray (≥ 12,)
        State at t_{n−1} + τ whose x1, y1, φ, ψ and rates are given.
    tau : float
        Time since the step start t_{n−1} [s] (Δt of Eq. 12).
    u0, w0, a0, b0 : float
        (x2 − x1), (y2 − y1) [m] at t_{n−1} and their rates from Eq. (11) [m/s].
    md : ModelData
        The plates' model (r, Ω from ``md.kin``).

    Only free DOFs among x2, y2 are set (see the module docstring for the variants).
    """
    fx, fy = _free_lower_plate(md)
    if not (fx or fy):
        return
    r = md.kin.r
    sphi = csm.sin(s[4])
    cphi = csm.cos(s[4])
    dphi = s[10]
    wt = md.kin.Omega + s[11]
    half = 0.5 * tau
    # Λ and Π of Eq. (12): trapezoid with the t_n terms that do not involve x2, y2
    lam = u0 + half * (a0 + (-r * dphi * sphi + r * wt * sphi))
    pi = w0 + half * (b0 + (r * dphi * cphi - r * wt * cphi))
    if fx and fy:
        c = half * wt
        d = 1.0 + c * c
        u = (lam - c * pi) / d
        w = (c * lam + pi) / d
    elif fx:
        w = s[3] - s[1]  # y2 locked at 0
        u = lam - half * wt * w
    else:
        u = s[2] - s[0]  # x2 locked at 0
        w = pi + half * wt * u
    if fx:
        s[2] = s[0] + u
    if fy:
        s[3] = s[1] + w
    if fx:
        s[8] = s[6] - r * dphi * sphi + wt * (s[1] - s[3] + r * sphi)
    if fy:
        s[9] = s[7] + r * dphi * cphi - wt * (s[0] - s[2] + r * cphi)


@kernel
def aeom_stick_step(y, K, h, stick, md, ynew, ytmp):
    """One AEOM stick step of length ``h`` [s]: RK4 on x1, y1, φ, ψ (Eq. 13), x2, y2 by Eq. (12).

    ``K`` (4, n): the RK4 stages with K[0] = f(y) in stick (:mod:`.rk4`); ``stick`` the contact
    state in stick. At every stage the dependent x2, y2, ẋ2, ẏ2 are recomputed with
    :func:`dependent_states` for the stage time, then the stick accelerations are evaluated
    (``physics.general_rhs`` in stick ≡ Eq. 13). The RK4 update of the dependent entries is
    discarded and replaced by Eq. (12) at the step end. Returns the rhs calls made (3).

    The stages call ``physics.general_rhs``, the right-hand side's path for stick, which
    ``physics.rhs_body`` calls after its fast path (every contact sliding) declines: inlining
    ``rhs_body`` here, as the slip step does, would add its cold compile for nothing, and calling
    ``physics.rhs`` would add a call per stage.
    """
    u0, w0, a0, b0 = _trapezoid_base(y, md)
    for stage in range(3):
        rk4.stage_state(y, K, stage, h, ytmp)
        dependent_states(ytmp, rk4.stage_time(stage, h), u0, w0, a0, b0, md)
        general_rhs(ytmp, stick, md, K[stage + 1])
    rk4.combine(y, h, K, ynew)
    dependent_states(ynew, h, u0, w0, a0, b0, md)
    fx, fy = _free_lower_plate(md)
    if not (fx and fy):
        P.project_velocities(ynew, stick, np.int64(-1), md)  # the component(s) of v_r = 0 not built in
    return 3


@kernel
def aeom_stick_branch(step, h, stick, md, dense, scratch, stats):
    """An AEOM stick step of length ``h`` [s] with breakaway located by bisection on re-stepping.

    If the stick force at the step end violates Eq. (10), θ ∈ (0, 1] is bisected, each trial
    re-taking the stick step with θ h from ``step.y``, until the bracket is shorter than
    ``events.EVENT_TIME_TOL``; the step then ends on the slip side of the root.

    ``step``: a :class:`~.fixed_step.FixedStep` whose stages K have K[0] = f(y) in stick. Returns
    (h_taken, transition, Fx, Fy): the step length taken [s], 0 or ``events.TRANSITION_TO_SLIP``
    and the stick force at the step end [N]. ``step.ynew`` and ``step.fnew`` = f(ynew) (stick)
    hold the step end; ``stats`` counts rhs calls (index 2) and re-taken steps (index 3);
    ``dense`` (n, 3) and ``scratch`` (:class:`~.bundles.Scratch`) are work arrays.
    """
    y, K, ynew, fnew, ytmp = step.y, step.K, step.ynew, step.fnew, step.ytmp
    F, N, v = scratch.F, scratch.N, scratch.v
    calls = aeom_stick_step(y, K, h, stick, md, ynew, ytmp)
    Fx, Fy, _, _, normal = derivative_and_contact(ynew, stick, md, fnew, F, N, v)
    stats[2] += calls + 1
    limit = P.static_limit(md.m, model_sizes(md.kin, md.m)[0], np.int64(0), normal)
    if limit - math.sqrt(Fx * Fx + Fy * Fy) > 0.0:  # Eq. (10) holds: still stuck
        return h, 0, Fx, Fy
    estimate = E.interpolated_crossing(E.EVENT_STICK, y, K[0], ynew, fnew, h, stick, md, dense, scratch)
    a, b, at, c = E.first_trial(estimate, h)
    while c >= 0.0:
        stats[2] += aeom_stick_step(y, K, c * h, stick, md, ynew, ytmp)
        stats[3] += 1
        a, b, at, c = E.narrowed(a, b, c, E.stick_margin(ynew, stick, md, F, N) > 0.0, estimate, h)
    if at != b:  # the last step re-taken ends before the root: re-take it to b
        stats[2] += aeom_stick_step(y, K, b * h, stick, md, ynew, ytmp)
        stats[3] += 1
    Fx, Fy, _, _, _ = derivative_and_contact(ynew, stick, md, fnew, F, N, v)
    stats[2] += 1
    return b * h, E.TRANSITION_TO_SLIP, Fx, Fy
