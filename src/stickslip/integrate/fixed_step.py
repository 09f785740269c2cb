"""Fixed-step RK4 shared by the paper's two stick solvers, ``aeom`` and ``naeom`` (Sect. 3).

One compiled loop, :func:`integrate_fixed_step`, runs both methods on the generic physics; only
the stick step differs:

* slip (both): classic Runge–Kutta 4 (paper ref. [43]) on all twelve states with the slip force,
  Eq. (3); the slip → stick event (``events.EVENT_SLIP``) is monitored at every step end and
  located by **bisection on re-stepping** (the paper's choice): a step whose end shows the event
  is re-taken from its start with θ Δt, θ bisected until the bracket is shorter than
  ``events.EVENT_TIME_TOL``;
* stick: ``aeom`` — RK4 on x1, y1, φ, ψ with x2, y2 from the trapezoidal rule, Eqs. (11)–(13)
  (:func:`.method_aeom.aeom_stick_branch`); ``naeom`` — RK4 on all six DOF with the constant
  friction force solved per step so that v_r = 0 at its end
  (:func:`.method_naeom.naeom_stick_branch`). Each locates breakaway (Eq. 10) by bisection;
* after a transition the next step is the remainder up to the grid point t0 + k Δt, so the time
  grid is kept; uniform samples come from the cubic Hermite interpolant of each step.

The slip direction below the low-speed band is the quasi-static one, with the band widened to
what the step can resolve (:func:`step_band`). The physics is the generic one
(:mod:`stickslip.model.physics`, compiled for the plates' kinematics) on the plates' model data
``md``; the contact state ``cst`` (mode, slip direction) of the one contact is the loop's.
State layout: the plates' 2n states, then the work of friction and of damping [J].
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np

from ..errors import SimulationError
from ..model import physics as P
from ..model.bundle import CST, H_BAND, H_N, ModelData, offsets
from ..model.jit import inlined_kernel, kernel
from ..model.system_model import FrictionModel
from . import events as E
from . import rk4
from .bundles import Samples, on_stack, scratch, store_record
from .event_loop import N_EXTRA
from .fixed_samples import end_sample_only, write_initial_samples, write_samples
from .method_aeom import aeom_stick_branch, dependent_states
from .method_naeom import MAX_NEWTON, VR_TOL, ForceStep, naeom_stick_branch
from .runner import Chunk, Record, RunOutput, ToTheEnd, run_chunks, stats_dict, transition_room
from .status import MAX_STEPS as STATUS_MAX_STEPS
from .status import NOT_FINITE as STATUS_NOT_FINITE
from .status import SOLVE_FAILED as STATUS_SOLVE_FAILED
from .status import STEP_UNDERFLOW as STATUS_STEP_UNDERFLOW
from .status import SUCCESS as STATUS_OK
from .status import Status
from .step_physics import derivative_and_contact, derivative_under_force, stick_force
from .transitions import record_transition

__all__ = ["integrate_fixed_step", "fixed_loop", "run_fixed_step", "FixedStepper", "FixedStep", "StickArrays",
           "FixedControls",
           "FIXED_PROGRESS", "check_step", "step_band", "step_data", "STABILITY_LIMIT", "METHOD_AEOM", "METHOD_NAEOM"]

#: Stick solver codes of :func:`integrate_fixed_step`.
METHOD_AEOM = 0
METHOD_NAEOM = 1
METHOD_CODES = {"aeom": METHOD_AEOM, "naeom": METHOD_NAEOM}

#: Largest ω_max Δt accepted for fixed-step RK4, ω_max the highest natural angular frequency
#: √(k/m) of the free DOFs. Classic RK4 is stable for an undamped oscillator only while
#: ω Δt < 2√2 ≈ 2.83; 2.0 (Δt ≤ T_min/π) keeps a margin for the negative damping of the
#: falling friction law and the frictional coupling, and still admits the paper's largest step
#: Δt = 0.1 s for Table 1 (ω_max = 17.3 rad/s, ω_max Δt = 1.73).
STABILITY_LIMIT = 2.0

class FixedStep(NamedTuple):
    """The arrays of one RK4 step of a state of n entries.

    Attributes
    ----------
    y : ndarray (n,)
        The state at the step's start (advanced in place).
    K : ndarray (4, n)
        RK4 stages (:mod:`.rk4`); K[0] = f(y), carried from step to step.
    ynew, fnew : ndarray (n,)
        The state at the step's end and its derivative.
    ytmp : ndarray (n,)
        The state of the stage being evaluated.
    """

    y: np.ndarray
    K: np.ndarray
    ynew: np.ndarray
    fnew: np.ndarray
    ytmp: np.ndarray


class StickArrays(NamedTuple):
    """What the stick steps add to a :class:`FixedStep` (n states).

    Attributes
    ----------
    dense : ndarray (n, 3)
        The step's cubic Hermite interpolant (``events.hermite_coefficients``): samples inside the
        step, the first trials of breakaway's bisection.
    Kn : ndarray (4, n)
        Stages of NAEOM's constant-force steps.
    history : ndarray (7,)
        NAEOM's force history of the stick phase (:func:`.method_naeom.naeom_stick_branch`).
    """

    dense: np.ndarray
    Kn: np.ndarray
    history: np.ndarray


class FixedControls(NamedTuple):
    """What :func:`fixed_loop` is asked to do: the stick solver ``method`` (:data:`METHOD_AEOM` or
    :data:`METHOD_NAEOM`), the interval [``t0``, ``t_end``] [s], the step ``dt`` [s] and the cap on
    the steps ``max_steps``."""

    method: int
    t0: float
    t_end: float
    dt: float
    max_steps: int


#: The progress of :func:`fixed_loop`: its outcome (``status``), the time reached ``t`` [s], the
#: step just taken ``h`` [s], the next grid point ``k_grid`` (t0 + k Δt), the steps taken, the next
#: sample ``idx``, the transitions ``n_tr`` found (counted past the buffers' room), the ``mode``
#: (slip or stick) and the ``transition`` that ends the step just taken (0: none), whether a slip
#: step ended at a zero of the slip velocity (``crossed``), the reference direction (rx, ry) of
#: the slip → stick event (:func:`event_direction`), the slip velocity (vx, vy) [m/s] and the
#: friction force (Fx, Fy) [N] at the step's end.
FIXED_PROGRESS = np.dtype([("status", np.int64), ("t", np.float64), ("h", np.float64), ("k_grid", np.int64),
                           ("n_steps", np.int64), ("idx", np.int64), ("n_tr", np.int64), ("mode", np.int64),
                           ("transition", np.int64), ("crossed", np.bool_), ("rx", np.float64), ("ry", np.float64),
                           ("vx", np.float64), ("vy", np.float64), ("Fx", np.float64), ("Fy", np.float64)],
                          align=True)

#: Cap [m/s] of the step-adapted low-speed band (:func:`step_band`). A wider band would put the
#: quasi-static slip direction in place of v_r/|v_r| over a sizable part of the sliding range
#: (Ω r = 1 m/s in Sect. 4.2.1) and change the model rather than the numerics; measured at
#: Δt = 1e-4 s, a band of 1e-2 m/s still changes φ's amplitude by only 9e-5 relative.
MAX_STEP_BAND = 1e-2


# --------------------------------------------------------------------------- shared RK4 pieces
@kernel
def rk4_slip_step(y, K, h, cst, md, ynew, ytmp):
    """One classic RK4 step of length ``h`` [s] in slip (Eq. 1 with Eq. 3), K[0] = f(y) given.

    ``cst``: the contact state (mode slip, the stored slip direction). Writes ``ynew`` and the
    stages K[1:4] (:mod:`.rk4`); ``ytmp`` is a work array. Returns the rhs calls made (3).

    The three stages are one loop around one inlined copy of the generic right-hand side
    (``physics.rhs_body``): inlined, the stages skip a call that passes the arrays' descriptors;
    one copy instead of three keeps the compile time (model/jit.py).
    """
    for stage in range(3):
        rk4.stage_state(y, K, stage, h, ytmp)
        P.rhs_body(ytmp, cst, md, K[stage + 1])
    rk4.combine(y, h, K, ynew)
    return 3


@kernel
def slip_step_with_event(step, h, rx, ry, cst, md, F, N, v, stats):
    """A slip step with the slip → stick event located by bisection on re-stepping.

    The event function is the projection of v_r on the reference direction (rx, ry)
    (``events.EVENT_SLIP``; :func:`event_direction`). If it has turned ≤ 0 at the step end,
    θ ∈ (0, 1] is bisected, each trial re-taking the RK4 step with θ h from ``y``, until the
    bracket is shorter than ``events.EVENT_TIME_TOL``; the step is then the one that ends on the
    ≤ 0 side of the root.
    Plain halving from the whole step: unlike breakaway (``events.bisection_point``), the root
    on the step's interpolant is a poor guide here (measured off by 1e-4 to 0.2 of the step at
    Δt = 1e-3 s: near v_r = 0 the slip direction relaxes faster than the step resolves, and the
    re-taken RK4 steps of different lengths do not follow one smooth path).

    ``(rx, ry)``: unit reference direction, (0, 0) for none (right after breakaway, v_r = 0).
    Returns (h_taken, crossed, v1x, v1y, F1x, F1y): the step length actually taken [s], whether
    it ends at a zero of the slip velocity, and v_r [m/s] and the friction force [N] at the step
    end. ``step`` is a :class:`FixedStep` from ``step.y`` with K[0] = f(y); ``step.ynew``,
    ``step.fnew`` = f(ynew) hold the step end; ``F``, ``N``, ``v`` are work arrays. ``stats`` is
    updated (rhs calls at index 2, re-taken steps at 3).
    """
    y, K, ynew, fnew, ytmp = step.y, step.K, step.ynew, step.fnew, step.ytmp
    stats[2] += rk4_slip_step(y, K, h, cst, md, ynew, ytmp)
    F1x, F1y, v1x, v1y, _ = derivative_and_contact(ynew, cst, md, fnew, F, N, v)
    stats[2] += 1
    if rx == 0.0 and ry == 0.0:  # just after breakaway (v_r = 0) nothing to detect
        return h, False, v1x, v1y, F1x, F1y
    if v1x * rx + v1y * ry > 0.0:  # the slip event v_r·e0 (events.EVENT_SLIP) stays positive
        return h, False, v1x, v1y, F1x, F1y
    contact = np.int64(0)
    a, b, at, c = E.first_trial(-1.0, h)
    while c >= 0.0:
        stats[2] += rk4_slip_step(y, K, c * h, cst, md, ynew, ytmp)
        stats[3] += 1
        vx, vy = P.slip_velocity(ynew, contact, md)
        a, b, at, c = E.narrowed(a, b, c, vx * rx + vy * ry > 0.0, -1.0, h)
    if at != b:  # the last step re-taken ends before the root: re-take it to b
        stats[2] += rk4_slip_step(y, K, b * h, cst, md, ynew, ytmp)
        stats[3] += 1
    F1x, F1y, v1x, v1y, _ = derivative_and_contact(ynew, cst, md, fnew, F, N, v)
    stats[2] += 1
    return b * h, True, v1x, v1y, F1x, F1y


@kernel
def event_direction(vx, vy, rx, ry, band):
    """Reference direction of the slip → stick event for a step that starts with v_r = (vx, vy).

    Above the low-speed band ``band`` [m/s] it is v_r/|v_r| at the step start; inside the
    band it stays the direction v_r had when it entered (``(rx, ry)``, the last one returned),
    or v_r/|v_r| at the first step after breakaway ((rx, ry) = (0, 0)). Inside the band the
    slip direction is the quasi-static one, along which v_r changes: a v_r that enters it off
    that direction passes the origin at a distance below the band, turning by up to 180° over
    several short steps. The direction at the step start would see no step turn by 90° there
    (measured: stick entries up to 1.5e-4 s late at Δt = 1e-5 s); the direction at the band's
    entry sees the pass as one sign change, located by bisection, and the root counts as
    arrival (:func:`after_slip_root`). Returns (rx, ry); (0, 0) while v_r = 0.
    """
    speed = math.sqrt(vx * vx + vy * vy)
    if speed <= P.SPEED_FLOOR:
        return 0.0, 0.0
    if speed > band or (rx == 0.0 and ry == 0.0):
        return vx / speed, vy / speed
    return rx, ry


@kernel
def after_slip_root(ynew, cst, stick, md, F, N):
    """At a located zero of the projected slip velocity: arrival at v_r = 0, then
    ``contacts.try_stick`` (projection + Eq. 10 test).

    The root of v_r·e0 leaves the component of v_r across e0. A fixed step cannot resolve the
    direction of v_r below |v_r| ~ Δt μ N |G M⁻¹ Gᵀ| (~1e-3 m/s at Δt = 1e-4 s: the direction
    relaxes on the time scale |v_r| / (μ N |G M⁻¹ Gᵀ|)), and inside the low-speed band the slip
    direction is the quasi-static one, which misses the origin by O(band). So a root with
    |v_r| ≤ the low-speed band counts as arrival: the residual is removed by the M-metric
    projection (an impulsive friction force, booked as friction work) before ``try_stick``
    tests admissibility. A larger |v_r| is a mere turn of the slip direction.

    ``cst``: the contact state in slip (its slip direction), ``stick``: in stick. Returns True
    with ``ynew`` projected onto v_r = 0 when stick begins; else False, with ``cst``'s slip
    direction the one to continue with (the breakaway direction of an inadmissible stick
    force, or the current one after a turn).
    """
    contact = np.int64(0)
    vx, vy = P.slip_velocity(ynew, contact, md)
    if math.sqrt(vx * vx + vy * vy) <= max(E.STICK_SPEED_TOL, md.m[H_BAND]):
        P.project_velocities(ynew, stick, np.int64(-1), md)
    sticks, nex, ney = E.try_stick(ynew, stick, contact, md, E.STICK_SPEED_TOL, F, N)
    if not sticks and (nex != 0.0 or ney != 0.0):
        cst[1] = nex
        cst[2] = ney
    return sticks


@kernel
def next_step(t, t0, dt, k_grid, t_end):
    """Length of the next step: up to the grid point t0 + k Δt (or t_end), skipping grid points
    closer than ``events.EVENT_TIME_TOL`` (a transition that fell just before one).

    Returns (h, k_grid).
    """
    while True:
        t_next = min(t0 + k_grid * dt, t_end)
        h = t_next - t
        if h > E.EVENT_TIME_TOL or t_next >= t_end:
            return h, k_grid
        k_grid += 1


@inlined_kernel
def grid_step(progress, controls):
    """The next step's length (:func:`next_step`) into ``progress.h``; False where the run stops
    (the step cap, a step that is not positive)."""
    if progress.n_steps >= controls.max_steps:
        progress.status = STATUS_MAX_STEPS
        return False
    progress.n_steps += 1
    h, k_grid = next_step(progress.t, controls.t0, controls.dt, progress.k_grid, controls.t_end)
    progress.h = h
    progress.k_grid = k_grid
    if h <= 0.0:
        progress.status = STATUS_STEP_UNDERFLOW
        return False
    return True


@inlined_kernel
def take_fixed_step(progress, method, step, extra, cst, stick, md, scratch, stats):
    """One step in the current mode: a slip step with the slip → stick event, or the method's stick
    step with breakaway (each located by bisection on re-stepping; ``progress.h`` becomes the
    length taken). False where NAEOM's stick-force solve failed. Each step kernel is given the
    arrays it uses only: a kernel called at every step takes its arguments word by word."""
    progress.transition = 0
    progress.crossed = False
    if progress.mode == P.MODE_SLIP:
        rx, ry = event_direction(progress.vx, progress.vy, progress.rx, progress.ry, md.m[H_BAND])
        progress.rx = rx
        progress.ry = ry
        h, crossed, vx, vy, Fx, Fy = slip_step_with_event(step, progress.h, rx, ry, cst, md, scratch.F, scratch.N,
                                                          scratch.v, stats)
        progress.crossed = crossed
        progress.vx = vx
        progress.vy = vy
    elif method == METHOD_AEOM:
        h, transition, Fx, Fy = aeom_stick_branch(step, progress.h, stick, md, extra.dense, scratch, stats)
        progress.transition = transition
    else:
        forced = ForceStep(step.y, step.ynew, step.ytmp, extra.Kn, extra.history)
        h, transition, Fx, Fy, solved = naeom_stick_branch(forced, progress.t, progress.h, stick, md, extra.dense,
                                                           scratch, stats)
        if not solved:
            progress.status = STATUS_SOLVE_FAILED
            return False
        progress.transition = transition
    progress.h = h
    progress.Fx = Fx
    progress.Fy = Fy
    return True


@inlined_kernel
def step_samples(progress, method, step, dense, cst, md, samples, scratch, stats):
    """The samples of the step (the friction force at its end (Fx, Fy)), before a transition
    changes ``cst``: at its end alone where that is all (:func:`.fixed_samples.end_sample_only`),
    else from its cubic Hermite interpolant (for NAEOM in stick, under its constant force)."""
    mode = progress.mode
    Fx = progress.Fx
    Fy = progress.Fy
    idx, done = end_sample_only(progress.idx, progress.t, progress.h, step.ynew, mode, Fx, Fy, samples)
    if not done:
        fixed_force = np.bool_(False)  # not a literal: one compiled version of write_samples
        if mode == P.MODE_STICK and method == METHOD_NAEOM:
            # NAEOM's constant force: derivatives at both step ends under it, for the Hermite samples
            derivative_under_force(step.y, Fx, Fy, md, step.K[0])
            derivative_under_force(step.ynew, Fx, Fy, md, step.fnew)
            stats[2] += 2
            fixed_force = np.bool_(True)
        idx = write_samples(idx, progress.t, progress.h, step, dense, (Fx, Fy), mode, fixed_force, cst, md, samples,
                            scratch)
    progress.idx = idx


@inlined_kernel
def end_of_step(progress, step, history, cst, stick, md, scratch):
    """At the step's end: in slip, the slip direction there, and at a located zero of the slip
    velocity the stick test (:func:`after_slip_root`); after a breakaway, the direction slip
    departs in."""
    ynew = step.ynew
    if progress.mode == P.MODE_SLIP:
        ex, ey = P.slip_direction(ynew, cst, np.int64(0), md, progress.vx, progress.vy)
        cst[1] = ex
        cst[2] = ey
        if progress.crossed and after_slip_root(ynew, cst, stick, md, scratch.F, scratch.N):
            progress.transition = E.TRANSITION_TO_STICK
            history[0] = 0.0
    elif progress.transition == E.TRANSITION_TO_SLIP:
        Fx, Fy, _ = stick_force(ynew, stick, md, scratch.F, scratch.N)
        cst[1], cst[2] = E.breakaway_direction(Fx, Fy, np.int64(2))


@inlined_kernel
def advance(progress, step, stats):
    """Move to the step's end: the time, the state and its derivative (k1 of the next step; NAEOM in
    stick does not use it)."""
    progress.t += progress.h
    stats[0] += 1
    y = step.y
    ynew = step.ynew
    k1 = step.K[0]
    fnew = step.fnew
    for i in range(y.shape[0]):
        y[i] = ynew[i]
        k1[i] = fnew[i]


@inlined_kernel
def switch_mode(progress, step, cst, md, scratch, log, stats):
    """The step ended in a transition: the new mode, its record, the derivative in it."""
    transition = progress.transition
    mode = P.MODE_STICK if transition == E.TRANSITION_TO_STICK else P.MODE_SLIP
    progress.mode = mode
    cst[0] = mode
    stats[4 if transition == E.TRANSITION_TO_STICK else 5] += 1
    record_transition(log, progress.n_tr, progress.t, transition, np.int64(0), step.y)
    progress.n_tr += 1
    _, _, vx, vy, _ = derivative_and_contact(step.y, cst, md, step.K[0], scratch.F, scratch.N, scratch.v)  # projected
    progress.vx = vx
    progress.vy = vy
    stats[2] += 1


@inlined_kernel
def begin(progress, controls, step, cst, stick, md, samples, scratch, stats):
    """The mode the state starts in (AEOM in stick: x2, y2 from the trapezoidal rule), its
    derivative and slip velocity, the samples at or before the start."""
    y = step.y
    mode = E.initial_mode(y, cst, stick, md, scratch.F, scratch.N)
    if controls.method == METHOD_AEOM and mode == P.MODE_STICK:
        dependent_states(y, 0.0, y[2] - y[0], y[3] - y[1], 0.0, 0.0, md)
    _, _, vx, vy, _ = derivative_and_contact(y, cst, md, step.K[0], scratch.F, scratch.N, scratch.v)
    stats[2] += 1
    progress.idx = write_initial_samples(y, controls.t0, mode, cst, md, samples, scratch)
    progress.mode = mode
    progress.vx = vx
    progress.vy = vy
    progress.rx = 0.0  # no reference direction of the slip → stick event yet (event_direction)
    progress.ry = 0.0
    progress.t = controls.t0
    progress.k_grid = 1
    progress.status = STATUS_OK
    progress.n_steps = 0
    progress.n_tr = 0


@kernel
def fixed_loop(controls, md, start, step, extra, cst, stick, scratch, samples, log, stats):
    """The loop of :func:`integrate_fixed_step`: the model ``md`` (the plates) from ``step.y``
    (2n + 2 entries, advanced in place) over [t0, t_end] with the fixed step ``dt``.

    Parameters
    ----------
    controls : FixedControls
    md : ModelData
    start : ndarray (1,) of :data:`FIXED_PROGRESS`
        The loop's progress at its end.
    step : FixedStep
    extra : StickArrays
    cst, stick : ndarray (CST,)
        The contact's state in its current mode (mode, slip direction ex, ey, τ), and the same in
        stick (the stick multiplier, the projection, breakaway).
    scratch : :class:`~.bundles.Scratch`
    samples : :class:`~.bundles.Samples`
        Written as by the event loop (:mod:`.event_loop`).
    log : :class:`~.bundles.TransitionLog`
        The transitions, as far as it has room.
    stats : ndarray (8,) int64
        steps, 0 (no rejections), rhs calls (each RK4 stage counts one), re-taken (bisection)
        steps, slip → stick, stick → slip, NAEOM's total Newton iterations and most iterations
        of one solve.
    """
    progress = on_stack(start[0])
    begin(progress, controls, step, cst, stick, md, samples, scratch, stats)
    while progress.t < controls.t_end:
        if not grid_step(progress, controls):
            break
        if not take_fixed_step(progress, controls.method, step, extra, cst, stick, md, scratch, stats):
            break
        step_samples(progress, controls.method, step, extra.dense, cst, md, samples, scratch, stats)
        end_of_step(progress, step, extra.history, cst, stick, md, scratch)
        advance(progress, step, stats)
        if progress.transition != 0:
            switch_mode(progress, step, cst, md, scratch, log, stats)
        if not E.all_finite(step.y):
            progress.status = STATUS_NOT_FINITE
            break
    store_record(start, progress)


def integrate_fixed_step(method, y0, t0, t_end, dt, md, max_steps, samples, log):
    """Integrate the model ``md`` (the plates) from ``y0`` (2n + 2 entries) over [t0, t_end] with
    the fixed step ``dt`` [s]: allocates the work arrays and runs :func:`fixed_loop`.

    ``method`` is :data:`METHOD_AEOM` or :data:`METHOD_NAEOM` (the stick step). Samples go to the
    :class:`~.bundles.Samples` ``samples`` and transitions to the
    :class:`~.bundles.TransitionLog` ``log`` (contact 0), as by the event loop.

    Returns
    -------
    status : int
        A :mod:`.status` code.
    t : float
        Time reached [s].
    y : ndarray (2n + 2,)
        Final state.
    n_transitions : int
        Transitions found (in the buffers up to their room).
    stats : ndarray (8,) int64
        As :func:`fixed_loop`'s.
    """
    n = y0.shape[0]
    step = FixedStep(y0.copy(), np.empty((4, n)), np.empty(n), np.empty(n), np.empty(n))
    extra = StickArrays(np.empty((n, 3)), np.empty((4, n)), np.zeros(7))
    cst = np.empty(CST)
    stick = np.array([P.MODE_STICK, 0.0, 0.0, math.inf])
    stats = np.zeros(8, dtype=np.int64)
    start = np.zeros(1, dtype=FIXED_PROGRESS)
    fixed_loop(FixedControls(int(method), float(t0), float(t_end), float(dt), int(max_steps)), md, start, step, extra,
               cst, stick, scratch(n, 1), samples, log, stats)
    p = start[0]
    return int(p["status"]), float(p["t"]), step.y, int(p["n_tr"]), stats


# --------------------------------------------------------------------------- Python runners
def _diagonal(md: ModelData, block: int) -> np.ndarray:
    """Diagonal of the n × n block ``block`` of the model data (0: M⁻¹, 3: K; ``bundle.offsets``)."""
    n = int(md.m[H_N])
    o = offsets(n)[block]
    return md.m[o:o + n * n:n + 1].copy()


def check_step(method: str, model: FrictionModel, dt) -> float:
    """Validate the fixed step of ``method`` for the plates' ``model``; returns it [s].

    Raises
    ------
    SimulationError
        If ``dt`` is missing, or larger than ``STABILITY_LIMIT / ω_max`` with ω_max the highest
        natural angular frequency √(k/m) of the free DOFs (RK4 would be unstable or wrong).
    """

    if dt is None:
        raise SimulationError(
            f"method {method!r} is a fixed-step method: give the step dt in seconds, e.g. dt=1e-4 "
            "(the paper's converged step; CLI: --dt 1e-4)"
        )
    omega = np.sqrt(_diagonal(model.data, 3) * _diagonal(model.data, 0))
    omega_max = float(omega.max())
    if omega_max > 0.0 and dt * omega_max > STABILITY_LIMIT:
        raise SimulationError(
            f"dt = {dt:g} s is too large for fixed-step RK4 ({method}): the shortest natural period of "
            f"the free DOFs is {2 * math.pi / omega_max:.4g} s and the step must satisfy "
            f"ω_max·dt ≤ {STABILITY_LIMIT:g}, i.e. dt ≤ {STABILITY_LIMIT / omega_max:.4g} s; give a smaller dt"
        )
    return float(dt)


def step_band(model: FrictionModel, dt: float) -> float:
    """Low-speed band [m/s] the fixed step ``dt`` [s] needs: Δt μs N tr(G M⁻¹ Gᵀ).

    In slip the direction of v_r relaxes on the time scale |v_r| / (μ N λ), λ an eigenvalue of
    A = G M⁻¹ Gᵀ (``DEFAULT_SLIP_BAND``'s note in :mod:`stickslip.model.system_model`). An
    explicit step resolves it only when |v_r| ≳ Δt μ N λ; below that speed RK4 makes the
    direction chatter (measured at Δt = 1e-4 s with a band of 1e-4 m/s: stick entries late by up
    to 2.5e-4 s and a 1.2 % error of φ's amplitude). There the direction must sit on its slow
    manifold, which is what the low-speed band does, so the fixed-step methods use
    max(slip_band, this). λ is bounded by tr(A) taken at R = r (contact at its nominal radius;
    r from the plates' kinematics, the inverse masses from the model data). Table 1:
    3.4e-3 m/s at Δt = 1e-4 s. Capped at :data:`MAX_STEP_BAND`.
    """
    m = _diagonal(model.data, 0)
    r = model.data.kin.r
    trace = m[0] + m[1] + m[2] + m[3] + (m[4] + m[5]) * r * r
    contact = model.contacts[0]
    return float(min(dt * contact.friction.mu_s * contact.normal_force * trace, MAX_STEP_BAND))


def step_data(model: FrictionModel, dt: float) -> ModelData:
    """The model data of ``model`` with the low-speed band raised to :func:`step_band` where that
    is larger."""
    m = model.data.m.copy()
    m[H_BAND] = max(m[H_BAND], step_band(model, dt))
    return model.data._replace(m=m)


def warm_up(md: ModelData, ns: int, t0, dt, method) -> float:
    """Compile (or load from cache) :func:`integrate_fixed_step` on a one-step run of a state of
    ``ns`` entries; seconds spent, 0 if compiled already."""
    if fixed_loop.signatures:
        return 0.0
    start = time.perf_counter()
    samples = Samples(np.array([t0]), np.zeros((1, ns)), np.zeros(1, dtype=np.int8), np.zeros((1, 2)))
    integrate_fixed_step(method, np.zeros(ns), t0, t0 + dt, dt, md, 10, samples, transition_room(0.0, ns, 1))
    return time.perf_counter() - start


class FixedStepper:
    """A fixed-step method (``aeom`` or ``naeom``) of the plates' ``model`` from ``s0`` at ``t0``:
    one chunk to ``t_end`` (the stepper of :func:`.runner.run_chunks`; its loop keeps the time
    grid t0 + k Δt of the whole run, so it is not cut into chunks).

    Raises
    ------
    SimulationError
        If ``dt`` is missing or too large (:func:`check_step`).
    """

    def __init__(self, method: str, model: FrictionModel, s0: np.ndarray, t0: float, t_end: float, dt,
                 max_steps: int):
        self.dt = check_step(method, model, dt)
        self.code = METHOD_CODES[method]
        self.md = step_data(model, self.dt)
        self.ns = 2 * model.n + N_EXTRA
        self.prepare_s = warm_up(self.md, self.ns, t0, self.dt, self.code)
        self.y = np.zeros(self.ns)
        self.y[:2 * model.n] = s0
        self.t, self.t_end = float(t0), float(t_end)
        self.max_steps = int(max_steps)
        self.stats = np.zeros(6, dtype=np.int64)

    def advance(self, tau_stop: float, record: Record) -> Chunk:
        """The whole run (``tau_stop`` is not used), samples written into ``record``."""
        capacity = None
        while True:
            tr = transition_room(self.t_end - self.t, self.ns, capacity)
            samples, _ = record.loop_arrays()
            status, t_reached, _, n_tr, st = integrate_fixed_step(self.code, self.y, self.t, self.t_end, self.dt,
                                                                  self.md, self.max_steps, samples, tr)
            if n_tr <= tr.times.size:
                break
            capacity = n_tr  # again with room for every transition (same result)
        if status == STATUS_SOLVE_FAILED:
            raise SimulationError(
                f"naeom: the stick-force solve did not reach |v_r| ≤ {VR_TOL:g} m/s in {MAX_NEWTON} Newton "
                f"iterations at t = {t_reached:.6g} s (dt = {self.dt:g} s); give a smaller dt"
            )
        tau = t_reached - self.t
        self.t = t_reached
        self.stats += st[:6]
        kept = int(np.count_nonzero(record.sample_times <= t_reached))
        return Chunk(int(status), float(tau), kept, st[:6], -1, tuple(a[:n_tr] for a in tr))


def run_fixed_step(method: str, system: FrictionModel, s0: np.ndarray, t0: float, t_end: float,
                   sample_times: np.ndarray, *, dt: float | None, max_steps: int, **_) -> RunOutput:
    """Run ``method`` (``"aeom"`` or ``"naeom"``) on the plates' ``system`` for :func:`stickslip.simulate`.

    Raises
    ------
    SimulationError
        If ``dt`` is missing or too large (:func:`check_step`), or NAEOM's per-step stick-force
        solve does not converge (``method_naeom.MAX_NEWTON``).
    """
    stepper = FixedStepper(method, system, s0, t0, t_end, dt, max_steps)
    record = Record(system, sample_times)
    status, interrupted, _ = run_chunks(stepper, record, ToTheEnd())
    return RunOutput(Status(status), stepper.t, -1, record, stats_dict(stepper.stats, stepper.prepare_s), interrupted)
