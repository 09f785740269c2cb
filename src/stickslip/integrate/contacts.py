"""Transition logic of the contacts, shared by the integrators: events, stick entry, active set.

Event functions are evaluated on a state vector; roots are located on any "dense output" of the
form ``y(θ) = y0 + h Σ_j Q[:, j] θ^(j+1)``, θ ∈ [0, 1] (every Runge–Kutta interpolant used here).

* slip → stick of contact c: ``EVENT_SLIP`` is the projection of v_c on its direction at the
  start of the step. A sign change means the slip velocity passed (near) zero; at the located
  root, if |v_c| is below the arrival speed and the stick force is admissible (|F_c| ≤ μs N_c,
  paper Eq. 10) the contact sticks; if not, v_c is set to zero and slip departs as at breakaway.
* stick → slip of contact c: ``EVENT_STICK`` = μs N_c − |F_c|; its root is breakaway. Slip
  starts with v_c = 0 in the direction e = −F_c/|F_c|, so F is continuous.
* several contacts: the multipliers of all sticking contacts are solved together; after any
  transition the sticking set is re-checked and a contact whose force exceeds its limit is
  released (:func:`release_most_overloaded`), the active-set view of Pfeiffer and Glocker.
* a prescribed normal force that reaches zero ends the run at that instant (``EVENT_NORMAL``:
  contact lost).
* a unilateral contact opens where its indicator φ = min(−g, λ/k) falls through zero and closes
  where −φ does (``EVENT_GAP``, :mod:`stickslip.model.normal`); an open contact carries no force;
  it closes sliding, or sticking if it arrives with v_c = 0 and the stick force is admissible.
* a rigid contact opens where its normal force (a multiplier) falls through zero and closes where
  its gap does, with an impact (:func:`land`, :mod:`stickslip.model.impact`): it bounces off, or
  stays closed (sliding or sticking), or, where its bounces would accumulate within ZENO_TIME,
  closes at once (a Zeno sequence's limit).
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import overload

from ..analysis.modes import MODE_WORD_BITS
from ..model import physics as P
from ..model.bundle import C_NORMAL_C, C_NORMAL_K, CST, contact_offsets
from ..model.jit import KERNEL_OPTIONS, api_kernel, inlined_kernel, kernel, standalone
from ..model.kinematics import model_sizes, rigid_kernel
from ..model.impact import IMPACT_INCONSISTENT, impact, remove_gap_rate, restitution_of
from ..model.normal import gap_and_rate, gap_with_rate, is_open, is_rigid, starts_open

__all__ = ["EVENT_SLIP", "EVENT_STICK", "EVENT_NORMAL", "EVENT_GAP", "TRANSITION_TO_STICK", "TRANSITION_TO_SLIP",
           "TRANSITION_OPEN", "TRANSITION_CLOSE", "TRANSITION_IMPACT", "TRANSITION_KINDS",
           "LAND_OPEN", "LAND_CLOSED", "LAND_ZENO", "LAND_INCONSISTENT", "ZENO_TIME", "land", "EVENT_TIME_TOL", "close_contact",
           "ARRIVAL_TIME_TOL", "STICK_SPEED_TOL", "event_value", "first_crossing", "refined_crossing", "dense_state",
           "try_stick", "release_most_overloaded", "initial_modes", "arrival_speed", "breakaway_direction",
           "time_to_zero_of", "slip_event_possible", "hermite_dip", "gap_dip", "probed_crossing", "contact_lost",
           "mode_flags", "store_mode", "leaves_state", "open_pulled_off"]

EVENT_SLIP = 0    # slip → stick candidate: v_c · e0
EVENT_STICK = 1   # stick → slip: μs N_c − |F_c|
EVENT_NORMAL = 2  # contact lost: N_c
EVENT_GAP = 3     # a unilateral contact opens or closes: its indicator

TRANSITION_TO_STICK = 1
TRANSITION_TO_SLIP = -1
TRANSITION_OPEN = 2
TRANSITION_CLOSE = 3
TRANSITION_IMPACT = 4

#: Names of the transition kinds, as results write them.
TRANSITION_KINDS = {TRANSITION_TO_STICK: "stick", TRANSITION_TO_SLIP: "slip", TRANSITION_OPEN: "open",
                    TRANSITION_CLOSE: "close", TRANSITION_IMPACT: "impact"}

#: What follows the impact of a rigid contact (:func:`land`): it bounces off, stays closed, closes
#: at the accumulation point of its bounces, or has no consistent impulse.
LAND_OPEN, LAND_CLOSED, LAND_ZENO, LAND_INCONSISTENT = 0, 1, 2, 3

#: [s] A rigid contact whose bounces would all end within this time (their geometric series,
#: 2 ġ⁺ / (|g̈| (1 − e)) under the normal acceleration of its flight) closes at the impact
#: instead: the instant it comes to rest is then off by less than this.
ZENO_TIME = 1e-9

#: Time resolution [s] to which transition instants are located on the dense output.
EVENT_TIME_TOL = 1e-12

#: Extrapolated time [s] to v_c = 0 below which slip counts as arrived; homing steps shorter than
#: this are dominated by the direction singularity of v/|v| at zero and get rejected.
ARRIVAL_TIME_TOL = 1e-10

#: |v_c| [m/s] at or below which slip is close enough to v_c = 0 to finish the approach. When v
#: heads for zero (within 60° of head-on) the last steps are homed onto it until the
#: extrapolated time left is below ARRIVAL_TIME_TOL; when it spirals in (anisotropic
#: G M⁻¹ Gᵀ: the stiff direction dynamics turn v faster than it shrinks, and explicit steps at
#: their stability limit can hover, seen at |v_r| ~ 2e-8 m/s for the plates at N = 80 N,
#: Ω = 1 rad/s) the residual ≤ 1e-6 m/s is removed by the projection at once: an impulse of at
#: most 1e-6 m/s × mass and an instant error of ≤ 1e-6 / |dv/dt| (~1e-7 s).
STICK_SPEED_TOL = 1e-6

#: Cap on the Illinois iterations refining one root (each at least halves the bracket every
#: few steps; ~40 are needed from a step of 0.1 s down to EVENT_TIME_TOL).
MAX_REFINEMENTS = 200

#: Sub-intervals of a step on which the event function is sampled for a sign change.
EVENT_CHECKS = 4

#: Passes of one settling of the sticking set, at least (each pass releases one contact, so nc
#: passes always suffice: a model of more contacts takes nc).
MAX_SETTLE = 64


@standalone
@kernel
def dense_state(y0, Q, h, theta, out):
    """Evaluate ``out = y0 + h Σ_j Q[:, j] θ^(j+1)`` (Horner)."""
    n, m = Q.shape
    if m == 4:  # Dormand–Prince dense output: unrolled (the samples' inner loop)
        for i in range(n):
            out[i] = y0[i] + h * theta * (Q[i, 0] + theta * (Q[i, 1] + theta * (Q[i, 2] + theta * Q[i, 3])))
        return
    for i in range(n):
        acc = Q[i, m - 1]
        for j in range(m - 2, -1, -1):
            acc = Q[i, j] + theta * acc
        out[i] = y0[i] + h * theta * acc


@kernel
def all_finite(y):
    """Whether every entry of ``y`` is finite (one branch on Σ y_i·0, NaN exactly when some y_i is not)."""
    acc = 0.0
    for i in range(y.shape[0]):
        acc += y[i] * 0.0
    return acc == 0.0


@kernel
def mode_flags(cst, nc):
    """Bit c set when contact c sticks, bit nc + c when it is open (the sample's mode; 1 = stick
    for a one-contact model)."""
    flags = 0
    for c in range(nc):
        mode = np.int64(cst[CST * c])
        if mode == P.MODE_STICK:
            flags |= 1 << c
        elif mode == P.MODE_OPEN:
            flags |= 1 << (nc + c)
    return flags


def store_mode(out_mode, idx, cst, nc):  # pragma: no cover - resolved by numba (overload below)
    """Write sample ``idx``'s mode flags (:func:`mode_flags`) into ``out_mode``: one integer per
    sample (k,), or for a model of more flags words of MODE_WORD_BITS (k, words)
    (:func:`stickslip.analysis.modes.mode_shape`)."""
    raise NotImplementedError("store_mode is called from compiled code only")


@overload(store_mode, jit_options=KERNEL_OPTIONS, inline="always")
def _store_mode(out_mode, idx, cst, nc):
    if out_mode.ndim == 1:
        def one(out_mode, idx, cst, nc):
            out_mode[idx] = mode_flags(cst, nc)
        return one

    def words(out_mode, idx, cst, nc):
        for w in range(out_mode.shape[1]):
            out_mode[idx, w] = 0
        for c in range(nc):
            mode = np.int64(cst[CST * c])
            bit = c if mode == P.MODE_STICK else nc + c if mode == P.MODE_OPEN else -1
            if bit >= 0:
                out_mode[idx, bit // MODE_WORD_BITS] |= np.int64(1) << np.int64(bit % MODE_WORD_BITS)
    return words


@inlined_kernel
def event_value(kind, c, y, e0x, e0y, cst, md, F, N):
    """Event function of ``kind`` for contact ``c`` at state ``y`` (module docstring).

    ``F`` (2 nc,), ``N`` (nc,) are work arrays.
    """
    if kind == EVENT_SLIP:
        vx, vy = P.slip_velocity(y, c, md)
        return vx * e0x + vy * e0y
    if kind == EVENT_NORMAL:
        return P.normal_force(y, c, md)
    if kind == EVENT_GAP:
        return P.indicator(y, cst, c, md)
    return P.stick_margin(y, cst, c, md)


@kernel
def regula_falsi_point(a, ga, b, gb):
    """Secant point of the bracket [a, b] with values ga, gb of opposite sides, kept strictly inside."""
    c = b - gb * (b - a) / (gb - ga)
    if not (a < c < b):
        c = 0.5 * (a + b)
    return c


@kernel
def illinois_update(a, ga, b, gb, c, gc, before, side):
    """One Illinois regula-falsi update: c (value gc) replaces a if ``before`` (c lies before the
    root), else b; when the same end moves twice the other end's value is halved.

    ``side`` is the end moved last (+1 a, −1 b, 0 none). Returns (a, ga, b, gb, side).
    """
    if before:
        if side == 1:
            gb *= 0.5
        return c, gc, b, gb, 1
    if side == -1:
        ga *= 0.5
    return a, ga, c, gc, -1


@inlined_kernel
def first_crossing(kind, c, y0, Q, h, e0x, e0y, cst, md, scratch):
    """First θ ∈ (0, 1] where the event function of contact ``c`` turns ≤ 0 on the dense output
    (``y0``, ``Q``) of a step of length ``h``, located to EVENT_TIME_TOL; −1.0 if no sign change is
    seen at the EVENT_CHECKS sample points. ``(e0x, e0y)``: the slip event's direction;
    ``scratch``: a :class:`~.bundles.Scratch`.

    The function is positive at θ = 0 by construction, so its value there is computed only when
    the crossing lies in the first sub-interval (it is the bracket's left end). Refinement:
    Illinois regula falsi.
    """
    return probed_crossing(-1.0, kind, c, y0, Q, h, e0x, e0y, cst, md, scratch)


@standalone
@kernel
def probed_crossing(probe, kind, c, y0, Q, h, e0x, e0y, cst, md, scratch):
    """:func:`first_crossing` with one more sample point at θ = ``probe`` ∈ (0, 1) (−1.0: none),
    where a dip of the event function between the regular sample points is expected."""
    work = scratch.state
    F = scratch.F
    N = scratch.N
    a = 0.0
    ga = -1.0  # not yet computed (the function is > 0 at θ = 0)
    b = -1.0
    gb = 0.0
    j = 1
    while j <= EVENT_CHECKS:
        theta = j / EVENT_CHECKS
        if a < probe < theta:  # the probe lies before the next regular point: sample it first
            theta = probe
        else:
            j += 1
        dense_state(y0, Q, h, theta, work)
        g = event_value(kind, c, work, e0x, e0y, cst, md, F, N)
        if g <= 0.0:
            b = theta
            gb = g
            break
        a = theta
        ga = g
    if b < 0.0:
        return -1.0
    if ga < 0.0:
        ga = event_value(kind, c, y0, e0x, e0y, cst, md, F, N)
    return refined_crossing(kind, c, y0, Q, h, (a, ga, b, gb), e0x, e0y, cst, md, scratch)


@inlined_kernel
def refined_crossing(kind, c, y0, Q, h, bracket, e0x, e0y, cst, md, scratch):
    """The root of the event function of ``kind`` for contact ``c`` in the ``bracket`` (a, ga, b, gb):
    θ ∈ (a, b] of the dense output (``y0``, ``Q``) of a step of length ``h``, with values ga > 0 and
    gb ≤ 0 at its ends, located to EVENT_TIME_TOL by Illinois regula falsi: the end b of the last
    bracket."""
    a, ga, b, gb = bracket
    work = scratch.state
    F = scratch.F
    N = scratch.N
    tol = EVENT_TIME_TOL / h if h > 0.0 else 0.0
    side = np.int64(0)  # not a literal: one compiled version of illinois_update
    for _ in range(MAX_REFINEMENTS):
        if gb == 0.0 or (b - a) <= tol:
            break
        cc = regula_falsi_point(a, ga, b, gb)
        dense_state(y0, Q, h, cc, work)
        gc = event_value(kind, c, work, e0x, e0y, cst, md, F, N)
        a, ga, b, gb, side = illinois_update(a, ga, b, gb, cc, gc, gc > 0.0, side)
    return b


@kernel
def time_to_zero_of(vx, vy, ax, ay):
    """Time [s] to the closest approach of v = (vx, vy) to zero under constant dv/dt = (ax, ay).

    −(v·v)/(v·a); +inf unless v heads for zero within 60° of head-on (a turning slip direction
    is not an approach). Used to home the last step of an approach onto v = 0 and to scale the
    steps of the approach.
    """
    va = vx * ax + vy * ay
    if va >= -0.5 * math.sqrt((vx * vx + vy * vy) * (ax * ax + ay * ay)):  # cos 60° = 0.5
        return math.inf
    return -(vx * vx + vy * vy) / va


@kernel
def hermite_dip(g0, dg0, g1, dg1):
    """θ ∈ (0, 1) where the cubic Hermite interpolant of a function over a step (values ``g0, g1``
    > 0 at its ends, derivatives ``dg0, dg1`` with respect to θ ∈ [0, 1]) has its lowest interior
    minimum, if that comes at or below half the smaller end value (a dip that may reach zero inside
    the step, to be checked on the step's dense output there); −1.0 otherwise.

    The cubic is a θ³ + b θ² + dg0 θ + g0 with a = 2 (g0 − g1) + dg0 + dg1, b = 3 (g1 − g0) − 2 dg0
    − dg1; its one local minimum is the root of 3a θ² + 2b θ + dg0 where the second derivative is
    2 √(b² − 3a dg0) > 0: θ = (√(b² − 3a dg0) − b) / (3a), or −dg0 / (b + √(b² − 3a dg0)) where
    b > 0 (the same root without cancellation, and right for a parabola, a = 0).
    """
    # the cubic minus the chord is θ (1 − θ) ((dg0 − Δ)(1 − θ) − (dg1 − Δ) θ), Δ = g1 − g0: at
    # most a quarter of the larger |dg − Δ| below the chord, so no dip is possible unless that
    # reaches from the smaller end value down to half of it
    delta = g1 - g0
    if max(abs(dg0 - delta), abs(dg1 - delta)) < 2.0 * min(g0, g1):
        return -1.0
    a = 2.0 * (g0 - g1) + dg0 + dg1
    b = 3.0 * (g1 - g0) - 2.0 * dg0 - dg1
    disc = b * b - 3.0 * a * dg0
    if disc <= 0.0:
        return -1.0
    r = math.sqrt(disc)
    if b > 0.0:
        th = -dg0 / (b + r)
    elif a != 0.0:
        th = (r - b) / (3.0 * a)
    else:
        return -1.0
    if not (0.0 < th < 1.0) or ((a * th + b) * th + dg0) * th + g0 > 0.5 * min(g0, g1):
        return -1.0
    return th


@inlined_kernel
def gap_dip(y0, dy0, y1, dy1, h, cst, c, md):
    """θ where unilateral contact ``c`` may open or close *inside* a step from ``y0`` to ``y1`` of
    length ``h`` [s] although its indicator is positive at both ends (a flight, or a touch, shorter
    than the step); −1.0 where it cannot (:func:`hermite_dip` on the step's cubic Hermite
    interpolants, ``dy0``, ``dy1`` the state derivatives at the ends).

    A closed contact opens where −g or λ̃/k = −g − (c/k) ġ reaches 0; an open one can close only
    where g reaches 0.
    """
    m = md.m
    n = model_sizes(md.kin, m)[0]
    g0, r0 = gap_and_rate(y0, md, n, c)
    g1, r1 = gap_and_rate(y1, md, n, c)
    if is_open(cst, c):
        return hermite_dip(g0, h * r0, g1, h * r1)
    if is_rigid(md, n, c):  # closed: g ≡ 0; it opens only where its multiplier λ falls through 0
        return -1.0
    dip = hermite_dip(-g0, -h * r0, -g1, -h * r1)
    o = contact_offsets(n, c)[0]
    ratio = m[o + C_NORMAL_C] / m[o + C_NORMAL_K]
    if dip > 0.0 or ratio == 0.0:
        return dip
    a0 = gap_with_rate(y0, dy0, md, n, c)[1]  # W·q̈ (of a nonlinear gap, g̈ less its q̇ᵀ ∂W/∂q q̇)
    a1 = gap_with_rate(y1, dy1, md, n, c)[1]
    return hermite_dip(-g0 - ratio * r0, -h * (r0 + ratio * a0), -g1 - ratio * r1, -h * (r1 + ratio * a1))


@kernel
def slip_event_possible(g0, dg0, g1, dg1):
    """Whether the slip event g = v·e0 may reach zero inside a step (cheap pre-check).

    ``g0, g1`` are its values at the ends of the step and ``dg0, dg1`` its derivatives with
    respect to θ ∈ [0, 1] (h × dv/dt · e0). The cubic Hermite interpolant of these four numbers
    is checked at θ = 1/4, 1/2, 3/4 and at the end; a possible crossing is any value at or below
    half the smaller end value (so a dip that the cubic only approximates still gets the full
    check on the step's dense output). A monotone approach (g falls from g0 to g1 > 0) needs none.
    """
    if g1 <= 0.0:
        return True
    floor = 0.5 * min(g0, g1)
    for j in range(1, 4):
        th = 0.25 * j
        th2 = th * th
        th3 = th2 * th
        h00 = 2.0 * th3 - 3.0 * th2 + 1.0
        h10 = th3 - 2.0 * th2 + th
        h01 = -2.0 * th3 + 3.0 * th2
        h11 = th3 - th2
        if h00 * g0 + h10 * dg0 + h01 * g1 + h11 * dg1 <= floor:
            return True
    return False


@kernel
def breakaway_direction(Fx, Fy, dim):
    """Slip direction at breakaway e = −F/|F| (for a 1-D contact ±1 in the first entry)."""
    if dim == 1:
        return (-1.0 if Fx > 0.0 else 1.0), 0.0
    norm = math.sqrt(Fx * Fx + Fy * Fy)
    if norm == 0.0:
        return 1.0, 0.0
    return -Fx / norm, -Fy / norm


@kernel
def arrival_speed(y, n, rtol, atol):
    """|v| [m/s] at or below which slip has arrived at v = 0 for an integration at (rtol, atol).

    The larger of STICK_SPEED_TOL and ten times the velocity resolution of the error control,
    atol + rtol max|q̇_i|: below that, v is integration noise, its direction wanders and no step
    can home further (seen at rtol 1e-8 with |q̇| ~ 3.5 rad/s: |v_r| hovered at 2e-8).
    """
    qd = 0.0
    for i in range(n, 2 * n):
        qd = max(qd, abs(y[i]))
    return max(STICK_SPEED_TOL, 10.0 * (atol + rtol * qd))


@standalone
@kernel
def try_stick(y, cst, c, md, speed_tol, F, N):
    """At a zero of contact ``c``'s slip velocity: project and test stick admissibility (Eq. 10).

    If |v_c| > ``speed_tol`` [m/s] nothing happens and ``(False, 0, 0)`` is returned. Otherwise
    ``y`` is projected onto v = 0 for the sticking contacts and c (the residual ≤ speed_tol
    removed by an impulsive friction force, booked as friction work) and either ``(True, 0, 0)``
    (stick of c is admissible) or ``(False, ex, ey)``: the breakaway direction of the inadmissible
    stick force, along which slip departs again (a velocity reversal through zero).
    """
    vx, vy = P.slip_velocity(y, c, md)
    if math.sqrt(vx * vx + vy * vy) > speed_tol:
        return False, 0.0, 0.0
    P.project_velocities(y, cst, c, md)
    P.stick_forces(y, cst, c, md, F, N)
    n = model_sizes(md.kin, md.m)[0]
    Fx = F[2 * c]
    Fy = F[2 * c + 1]
    if math.sqrt(Fx * Fx + Fy * Fy) <= P.static_limit(md.m, n, c, N[c]):
        return True, 0.0, 0.0
    ex, ey = breakaway_direction(Fx, Fy, P.contact_dim(md.kin, md.m, n, c))
    return False, ex, ey


@kernel
def release_most_overloaded(y, cst, md, F, N):
    """If some sticking contact's joint stick force exceeds μs N, release the most overloaded one
    (quasi-static slip along its breakaway direction) and return its index; else −1."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    if P.stick_forces(y, cst, np.int64(-1), md, F, N) == 0:
        return -1
    worst = -1
    worst_ratio = 1.0
    for c in range(nc):
        if np.int64(cst[CST * c]) != P.MODE_STICK:
            continue
        limit = P.static_limit(m, n, c, N[c])
        Fx = F[2 * c]
        Fy = F[2 * c + 1]
        mag = math.sqrt(Fx * Fx + Fy * Fy)
        ratio = mag / limit if limit > 0.0 else math.inf
        if ratio > worst_ratio:
            worst = c
            worst_ratio = ratio
    if worst >= 0:
        ex, ey = breakaway_direction(F[2 * worst], F[2 * worst + 1], P.contact_dim(md.kin, m, n, worst))
        cst[CST * worst] = P.MODE_SLIP_QUASI_STATIC
        cst[CST * worst + 1] = ex
        cst[CST * worst + 2] = ey
        cst[CST * worst + 3] = math.inf
    return worst


@kernel
def leaves_state(y, cst, c, md):
    """Whether unilateral contact ``c`` leaves its state of ``cst`` at ``y``: its indicator is ≤ 0
    (:func:`stickslip.model.physics.indicator`), except that a closed rigid contact leaves only
    where its normal force turns negative, λ < 0 (the free motion would lift it: its gap
    acceleration turns positive). A rigid contact at rest at zero force, λ = 0, stays closed: a
    state, not an opening followed by a landing at zero speed, again and again."""
    phi = P.indicator(y, cst, c, md)
    if phi < 0.0:
        return True
    return phi == 0.0 and (is_open(cst, c) or not P.rigid(c, md))


@kernel
def contact_lost(y, md):
    """Index of the first contact with a prescribed load whose normal force is ≤ 0 at ``y``, or −1."""
    nc = model_sizes(md.kin, md.m)[1]
    for c in range(nc):
        if not P.unilateral(c, md) and P.normal_force(y, c, md) <= 0.0:
            return c
    return -1


@kernel
def close_contact(y, cst, c, md, rtol, atol, F, N):
    """Unilateral contact ``c`` closes at ``y``: it sticks if it arrives with v_c = 0 (to the
    arrival speed) under a normal force and the stick force is admissible; else it slides (the
    exact direction v/|v|; from v = 0 the breakaway direction, or the stored one when no normal
    force holds it yet, c = 0). Returns whether it sticks; ``y`` may be projected."""
    n = model_sizes(md.kin, md.m)[0]
    cst[CST * c] = P.MODE_SLIP_EXACT
    cst[CST * c + 3] = math.inf
    vx, vy = P.slip_velocity(y, c, md)
    speed = math.sqrt(vx * vx + vy * vy)
    if speed > arrival_speed(y, n, rtol, atol):
        cst[CST * c + 1] = vx / speed
        cst[CST * c + 2] = vy / speed
        return False
    cst[CST * c] = P.MODE_SLIP_QUASI_STATIC  # from v = 0: the direction the forces give
    if P.normal_force_of(y, cst, c, md) > 0.0:
        stick, ex, ey = try_stick(y, cst, c, md, arrival_speed(y, n, rtol, atol), F, N)
        if stick:
            cst[CST * c] = P.MODE_STICK
            return True
        if ex != 0.0 or ey != 0.0:
            cst[CST * c + 1] = ex
            cst[CST * c + 2] = ey
    return False


@standalone
@api_kernel
def initial_modes(y, cst, md, rtol, atol, F, N):
    """Modes a state starts in: each contact sticks if its v = 0 (to STICK_SPEED_TOL) and the joint
    stick force is admissible; the others slip (the exact direction when sliding, the
    quasi-static one from v = 0). Fills ``cst``; ``y`` may be projected."""
    nc = model_sizes(md.kin, md.m)[1]
    for c in range(nc):
        cst[CST * c] = P.MODE_SLIP
        cst[CST * c + 1] = 1.0
        cst[CST * c + 2] = 0.0
        cst[CST * c + 3] = math.inf
    for c in range(nc):  # a unilateral contact that is not closed at the start is open
        if starts_open(y, cst, c, md):
            cst[CST * c] = P.MODE_OPEN
    for c in range(nc):
        if np.int64(cst[CST * c]) == P.MODE_OPEN:
            continue
        stick, ex, ey = try_stick(y, cst, c, md, STICK_SPEED_TOL, F, N)
        if stick:
            cst[CST * c] = P.MODE_STICK
        elif ex != 0.0 or ey != 0.0:
            cst[CST * c + 1] = ex
            cst[CST * c + 2] = ey
    for _ in range(max(MAX_SETTLE, nc)):
        if release_most_overloaded(y, cst, md, F, N) < 0:
            break
    open_pulled_off(y, cst, md)
    for c in range(nc):
        if np.int64(cst[CST * c]) == P.MODE_STICK or np.int64(cst[CST * c]) == P.MODE_OPEN:
            continue
        vx, vy = P.slip_velocity(y, c, md)
        speed = math.sqrt(vx * vx + vy * vy)
        if speed > STICK_SPEED_TOL:
            # a run that starts sliding is not departing from v = 0: watch it for stick at once
            cst[CST * c] = P.MODE_SLIP_EXACT
            cst[CST * c + 1] = vx / speed
            cst[CST * c + 2] = vy / speed
        else:
            cst[CST * c] = P.MODE_SLIP_QUASI_STATIC
            if speed > P.SPEED_FLOOR:
                cst[CST * c + 1] = vx / speed
                cst[CST * c + 2] = vy / speed


@rigid_kernel(lambda y, cst, md: None)
def open_pulled_off(y, cst, md):  # pragma: no cover - compiled only
    """Open each closed rigid contact that the forces at ``y`` pull off (λ < 0), where the closed
    rigid contacts' normal forces are consistent at all (else it stays closed and the run reports
    that, Painlevé); at λ = 0 it rests on the contact. (Compiled only for kinematics that may have
    rigid contacts: the starting modes of the others compile none of it.)"""
    n, nc, _ = model_sizes(md.kin, md.m)
    for c in range(nc):
        if is_rigid(md, n, c) and not is_open(cst, c) and leaves_state(y, cst, c, md) \
                and P.rigid_pivot(y, cst, md) > 0.0:
            cst[CST * c] = P.MODE_OPEN


@rigid_kernel(lambda y, cst, c, md, rtol, atol, F, N, work: (LAND_INCONSISTENT, False, 0.0, 0.0, 0.0, math.inf),
              inline="always")
def land(y, cst, c, md, rtol, atol, F, N, work):  # pragma: no cover - compiled only
    """:func:`rigid_landing` for kinematics that may have rigid contacts (a constant for the others,
    whose kernels then compile none of it)."""
    return rigid_landing(y, cst, c, md, rtol, atol, F, N, work)


@standalone
@kernel
def rigid_landing(y, cst, c, md, rtol, atol, F, N, work):
    """Rigid contact ``c`` closes at ``y`` (its gap through 0): the impact, then what follows.

    Returns (phase, sticks, impulse, before, after, flight): ``phase`` one of ``LAND_*``; ``sticks``
    whether it closed sticking; the normal impulse [N s]; ġ⁻ and ġ⁺ [m/s]; for ``LAND_OPEN`` the
    flight time [s] that the normal acceleration at the take-off predicts (∞ if it does not pull
    the contact back). ``y`` and ``cst`` are updated. A contact that stays closed but whose
    normal force comes out < 0 (the motion leaves it with ġ = 0) is left open; at λ = 0 it rests on
    it. A standalone kernel (the one compiled copy that its callers call: the impacts' code is not
    optimised again in the event loop), compiled only for kinematics that may have rigid contacts.
    """
    n = model_sizes(md.kin, md.m)[0]
    e = restitution_of(c, md)
    outcome, impulse, before, after = impact(y, cst, c, md, e)
    if outcome == IMPACT_INCONSISTENT:
        return LAND_INCONSISTENT, False, impulse, before, after, math.inf
    phase = LAND_CLOSED
    if after > 0.0:
        cst[CST * c] = P.MODE_OPEN
        P.rhs(y, cst, md, work)
        acc = gap_with_rate(y, work, md, n, c)[1]  # g̈ = W q̈ in flight
        flight = 2.0 * after / -acc if acc < 0.0 else math.inf
        if not (e < 1.0 and flight <= ZENO_TIME * (1.0 - e)):
            return LAND_OPEN, False, impulse, before, after, flight
        remove_gap_rate(y, c, md)  # the bounces' limit: at rest on the contact
        phase = LAND_ZENO
    cst[CST * c] = P.MODE_SLIP
    sticks = close_contact(y, cst, c, md, rtol, atol, F, N)
    if leaves_state(y, cst, c, md):
        cst[CST * c] = P.MODE_OPEN
        cst[CST * c + 3] = math.inf
        return LAND_OPEN, False, impulse, before, after, math.inf
    return phase, sticks, impulse, before, after, math.inf
