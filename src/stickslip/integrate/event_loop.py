"""The ``event`` integrator: adaptive Dormand–Prince 5(4) with exact stick and located transitions.

One compiled loop for any friction-contact model (no Python per step):

* each contact slips or sticks on its own; the multipliers of all sticking contacts are solved
  together (:mod:`stickslip.model.physics`), and q̇ is re-projected onto their constraints after
  each step to remove drift;
* error control on the free DOFs with ``rtol``/``atol`` (RMS norm, as scipy's RK45);
* transitions located on the 4th-order dense output to ``contacts.EVENT_TIME_TOL``: a step whose
  dense output shows a slip velocity through zero is re-taken to end at the root, so no stage
  ever straddles the non-smooth point; a breakaway, and the opening or closing of a unilateral
  contact, cut the step at their root (the flow is smooth up to it);
* uniform samples written from the dense output.

Time inside the loop is *local*: the caller passes ``t_base`` and the loop integrates
τ = t − t_base from 0, so that step sizes and event tolerances are resolved against τ, not
against an absolute time whose unit in the last place grows with the run (at t ~ 4e4 s it
exceeds the event tolerance). The runner calls the loop in chunks
(:class:`stickslip.integrate.runner.EventStepper`), rebasing each; a chunk ends at the first
accepted step past ``tau_stop`` that is not in the middle of an approach, or before it at such a
step where its transition log has room for less than two transitions per contact more (a model of
many contacts, hundreds of transitions a period), so the steps taken are the same as in one long
call and a chunk is run again only where one step outgrew that room.

The loop (:func:`event_loop`) is a sequence of named steps, each inlined into it at its one call
site, over bundled state: the step's arrays (:class:`~.dormand_prince.Step`), what is kept of
each slipping contact (:class:`~.slip_watch.SlipWatch`), the samples, the transitions and the
work arrays (:mod:`.bundles`), the chunk's request (:class:`Controls`) and its progress (a
:data:`PROGRESS` record on the loop's stack):

* :func:`take_step`: a step of the size proposed, under the error control;
* :func:`lost_contact`: a prescribed normal force through zero inside it (the run ends there);
* :func:`.slip_roots`: departures that overshoot the low-speed band, slip → stick roots;
  :func:`retake`: the step re-taken shorter for either;
* :func:`.gap_crossing`: a unilateral contact that opens or closes inside the step;
  :func:`breakaway_root`: the first breakaway inside it; :func:`cut_at_gap`,
  :func:`cut_at_breakaway`: the step cut at the earlier root, the transition applied there;
* otherwise :func:`accept_step`: the whole step, its samples, the state advanced;
  :func:`.arrivals`: the slipping contacts' band departures, homing onto v = 0 and stick entry,
  and the derivative again where a mode changed;
* :func:`next_step_size`: the next step's size, and whether the chunk ends.

State layout: the 2n physical states, then the accumulated work of friction and of damping [J],
integrated with the same steps as quadratures.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..model import physics as P
from ..model.bundle import offsets
from ..model.jit import formula, inlined_kernel, kernel, standalone
from ..model.kinematics import model_sizes
from ..model.normal import is_unilateral
from . import contacts as E
from . import dormand_prince as DP
from .bundles import on_stack, scratch, store_record
from .slip_watch import MAX_RETAKES, arrivals, slip_roots, slip_watch
from .status import CHUNK_END, CONTACT_LOST, INCONSISTENT, MAX_STEPS, NOT_FINITE, STEP_UNDERFLOW, SUCCESS
from .transitions import break_away, breakaway_search, crossing_in_step, gap_crossing, jammed_contact, switch_gap

__all__ = ["integrate_event", "event_loop", "loop_arrays", "fresh_progress", "Controls", "controls", "PROGRESS",
           "N_EXTRA"]

N_EXTRA = 2  # work of friction, work of damping

#: The progress of a chunk of the loop: its outcome (``status``: :mod:`.status`; ``lost``: the
#: contact lost or inconsistent, −1), the local time reached ``tau`` [s], the step size ``h`` [s]
#: (to continue with), the next sample ``idx`` and the transitions ``n_tr`` found so far (counted
#: past the buffers' room), and what the loop carries from step to step: the steps taken, the
#: re-takes of the current step, the step imposed on the next one (``h_override``, −1: none),
#: the error controller's step before a homing episode (``h_free``, −1: none), the growth factor
#: of the step just taken, whether the last step was rejected, whether the slip cache holds the
#: values at the step's start (``slips_ready``).
PROGRESS = np.dtype([("status", np.int64), ("lost", np.int64), ("tau", np.float64), ("h", np.float64),
                     ("idx", np.int64), ("n_tr", np.int64), ("n_steps", np.int64), ("retakes", np.int64),
                     ("h_override", np.float64), ("h_free", np.float64), ("factor", np.float64),
                     ("rejected", np.bool_), ("slips_ready", np.bool_)], align=True)


@formula
def fresh_progress(start, h, idx, n_tr):
    """``start[0]`` (a :data:`PROGRESS` record) as a chunk of the loop starts it: every field zero
    (false) but ``lost`` (−1: none), the step size ``h`` [s], the next sample ``idx`` and the
    transitions ``n_tr`` found before. Python (:func:`loop_arrays`) and compiled callers (a basin
    batch's loop call) share it."""
    p = start[0]
    p["status"] = 0
    p["lost"] = -1
    p["tau"] = 0.0
    p["h"] = h
    p["idx"] = idx
    p["n_tr"] = n_tr
    p["n_steps"] = 0
    p["retakes"] = 0
    p["h_override"] = 0.0
    p["h_free"] = 0.0
    p["factor"] = 0.0
    p["rejected"] = False
    p["slips_ready"] = False


#: What :func:`take_step` found: the step is taken, or rejected (try again with ``progress.h``),
#: or the run stops (``progress.status``).
TAKEN, RETRY, STOP = 0, 1, 2


class Controls(NamedTuple):
    """What a chunk of the loop is asked to do.

    Attributes
    ----------
    t_base : float
        Absolute time [s] of the chunk's local time 0 (the samples' and transitions' times are
        absolute).
    tau_stop : float
        Local time [s] after which the chunk ends at the first accepted step outside an approach.
    tau_end : float
        Local time [s] of the run's end.
    rtol, atol : float
        Local error tolerances.
    h_max : float
        Largest step [s].
    max_steps : int
        Steps (accepted and rejected) the chunk may take.
    """

    t_base: float
    tau_stop: float
    tau_end: float
    rtol: float
    atol: float
    h_max: float
    max_steps: int


def controls(t_base, tau_stop, tau_end, rtol, atol, h_max, max_steps) -> Controls:
    """:class:`Controls` of the types the loop is compiled for."""
    return Controls(float(t_base), float(tau_stop), float(tau_end), float(rtol), float(atol), float(h_max),
                    int(max_steps))


# ----------------------------------------------------------------------------- the step
@standalone
@kernel
def dp_step(y, k1, h, cst, md, Kst, ynew, ytmp):
    """One Dormand–Prince step from y with k1 = f(y); fills the stages Kst[0:7] and ynew.

    The five inner stages are one loop around one inlined right-hand side.
    """
    for i in range(y.shape[0]):
        Kst[0, i] = k1[i]
    for stage in range(1, 6):
        DP.stage_state(y, Kst, h, stage, ytmp)
        P.rhs_body(ytmp, cst, md, Kst[stage])
    DP.stage_state(y, Kst, h, np.int64(6), ynew)  # not a literal: one compiled version
    P.rhs(ynew, cst, md, Kst[6])


@kernel
def error_norm(y, ynew, Kst, h, md, rtol, atol):
    """RMS of the embedded error estimate over the free DOFs' positions and velocities."""
    m = md.m
    n = model_sizes(md.kin, m)[0]
    o_free = offsets(n)[5]
    total = 0.0
    count = 0
    for d in range(n):
        if m[o_free + d] == 0.0:
            continue
        for i in (d, d + n):
            scale = atol + rtol * max(abs(y[i]), abs(ynew[i]))
            total += (DP.local_error(Kst, h, i) / scale) ** 2
            count += 1
    if count == 0:
        return 0.0
    return math.sqrt(total / count)


@inlined_kernel
def take_step(progress, controls, step, cst, md, stats):
    """A Dormand–Prince step of the size proposed (``progress.h``, bounded by ``h_max`` and the
    run's end) and its error control: :data:`TAKEN` (``progress.factor`` the growth it allows;
    none right after a rejection, Hairer's DOPRI5 rule), :data:`RETRY` (rejected: ``progress.h``
    shrunk; a rejected re-take keeps homing, the root found before still lies ahead) or
    :data:`STOP` (the step cap, a step below the round-off of τ, a state that is not finite)."""
    if progress.n_steps >= controls.max_steps:
        progress.status = MAX_STEPS
        return STOP
    progress.n_steps += 1
    h = min(progress.h, controls.h_max, controls.tau_end - progress.tau)
    progress.h = h
    if h <= 1e-14 * max(1.0, abs(progress.tau)):  # below round-off of τ: no progress possible
        progress.status = STEP_UNDERFLOW
        return STOP
    dp_step(step.y, step.k1, h, cst, md, step.stages, step.ynew, step.ytmp)
    stats[2] += 6
    err = error_norm(step.y, step.ynew, step.stages, h, md, controls.rtol, controls.atol)
    if not math.isfinite(err):
        if h < 1e-10:
            progress.status = NOT_FINITE
            return STOP
        progress.h = h * DP.MIN_FACTOR
        stats[1] += 1
        return RETRY
    if err > 1.0:
        progress.h = h * max(DP.MIN_FACTOR, DP.SAFETY * err ** -0.2)
        stats[1] += 1
        progress.rejected = True
        return RETRY
    factor = DP.MAX_FACTOR if err == 0.0 else min(DP.MAX_FACTOR, DP.SAFETY * err ** -0.2)
    if progress.rejected:
        factor = min(factor, 1.0)
        progress.rejected = False
    progress.factor = factor
    return TAKEN


@inlined_kernel
def retake(progress, shrink, theta_slip, stats):
    """Whether the step is re-taken shorter: by ``shrink`` (a departure that overshoots the
    low-speed band), or to end at ``theta_slip`` (a slip velocity passes zero inside it; the error
    controller's step is kept in ``progress.h_free``, to resume from after the event)."""
    if shrink > 0.0:
        progress.h *= shrink
    elif theta_slip > 0.0 and (1.0 - theta_slip) * progress.h > E.EVENT_TIME_TOL and progress.retakes < MAX_RETAKES:
        if progress.retakes == 0 and progress.h_override < 0.0 and progress.h_free < 0.0:
            progress.h_free = progress.h
        progress.h *= theta_slip
    else:
        return False
    progress.retakes += 1
    stats[3] += 1
    return True


@kernel
def homing_left(homing):
    """Whether any contact is in the middle of homing in on v = 0 (a loop: ``homing.sum()`` would
    compile numpy's reduction with its axis checks)."""
    for c in range(homing.shape[0]):
        if homing[c] != 0:
            return True
    return False


@inlined_kernel
def next_step_size(progress, controls, homing, log_full):
    """The next step's size: the one imposed (homing, a bounce's flight), else the error
    controller's. Returns whether the chunk ends here, outside an approach: past ``tau_stop``,
    or before it where the transition log is nearly full (``log_full``: the chunk ends where a
    run of many contacts would outgrow it, instead of being run again with room for all)."""
    if progress.h_override > 0.0:
        progress.h = progress.h_override
        progress.h_override = -1.0
        return False
    progress.h *= progress.factor
    return ((controls.tau_stop <= progress.tau or log_full) and progress.tau < controls.tau_end
            and progress.h_free < 0.0 and not homing_left(homing))


# ----------------------------------------------------------------------------- samples
@inlined_kernel
def store_sample(idx, y, cst, md, scratch, samples):
    """Write sample ``idx``: the state, the mode flags (bit c: contact c sticks) and each contact's
    friction force at ``y``."""
    nc = model_sizes(md.kin, md.m)[1]
    F = scratch.F
    P.contact_forces(y, cst, md, F, scratch.N, scratch.v)
    states = samples.states
    for i in range(states.shape[1]):
        states[idx, i] = y[i]
    E.store_mode(samples.modes, idx, cst, nc)
    forces = samples.forces
    for i in range(2 * nc):
        forces[idx, i] = F[i]


@standalone
@kernel
def write_samples(idx, tau_to, tau_step, h, t_base, y0, Q, cst, md, samples, scratch):
    """Write the samples from index ``idx`` up to local time ``tau_to`` from the dense output
    (``y0``, ``Q``) of the step of length ``h`` that starts at local time ``tau_step`` (sample
    times are absolute; ``t_base`` is the local origin). Returns the next index."""
    times = samples.times
    n_samples = times.shape[0]
    while idx < n_samples and times[idx] - t_base <= tau_to:
        theta = (times[idx] - t_base - tau_step) / h if h > 0.0 else 0.0
        E.dense_state(y0, Q, h, theta, scratch.state)
        store_sample(idx, scratch.state, cst, md, scratch, samples)
        idx += 1
    return idx


@inlined_kernel
def first_samples(idx, t_base, y, cst, md, samples, scratch):
    """Write the samples at or before the chunk's start (local time 0) at ``y``; returns the next index."""
    times = samples.times
    while idx < times.shape[0] and times[idx] - t_base <= 0.0:
        store_sample(idx, y, cst, md, scratch, samples)
        idx += 1
    return idx


# ----------------------------------------------------------------------------- events inside the step
@inlined_kernel
def lost_contact(progress, t_base, step, cst, md, samples, scratch, stats):
    """A prescribed normal force through zero inside the step: the run ends at the first root
    (the step cut there, ``progress.status`` CONTACT_LOST). Returns (whether it ends, whether the
    step's dense-output coefficients are formed)."""
    n, nc, _ = model_sizes(md.kin, md.m)
    h = progress.h
    theta_lost = -1.0
    lost = np.int64(-1)
    q_ready = False
    for c in range(nc):
        if not is_unilateral(md, n, c) and P.normal_force(step.ynew, c, md) <= 0.0:
            th = crossing_in_step(E.EVENT_NORMAL, c, step, q_ready, h, cst, md, scratch)
            q_ready = True
            if theta_lost < 0.0 or th < theta_lost:
                theta_lost = th
                lost = c
    if theta_lost > 0.0:
        idx, tau = cut_step(theta_lost, progress.idx, progress.tau, h, t_base, step, cst, md, samples, scratch)
        progress.idx = idx
        progress.tau = tau
        stats[0] += 1
        progress.status = CONTACT_LOST
        progress.lost = lost
        return True, q_ready
    return False, q_ready


@inlined_kernel
def breakaway_root(any_stick, step, q_ready, h, cst, md, scratch):
    """(θ, contact, q_ready): the first breakaway of a sticking contact inside the step (θ = −1.0,
    contact −1: none; :func:`.breakaway_search`)."""
    if not any_stick:
        return -1.0, np.int64(-1), q_ready
    if not q_ready:
        DP.dense_coefficients(step.stages, step.dense)
    theta_b, c_b = breakaway_search(step, h, cst, md, scratch)
    return theta_b, c_b, True


@standalone
@kernel
def cut_step(theta, idx, tau, h, t_base, step, cst, md, samples, scratch):
    """End the step of length ``h`` from local time ``tau`` at θ ∈ (0, 1] (an event's root): write
    the samples up to there and move ``step.y`` (the step's start) onto it. Returns (idx, local
    time of the cut)."""
    tau_cut = tau + theta * h
    idx = write_samples(idx, tau_cut, tau, h, t_base, step.y, step.dense, cst, md, samples, scratch)
    y = step.y
    work = scratch.state
    E.dense_state(y, step.dense, h, theta, work)
    for i in range(y.shape[0]):
        y[i] = work[i]
    return idx, tau_cut


@inlined_kernel
def cut_at_gap(progress, theta, c, controls, step, cst, md, samples, scratch, log, stats):
    """Unilateral contact ``c`` opens or closes at θ inside the step: the step is cut there and
    the contact switched (:func:`.switch_gap`); a bounce bounds the next step by half its flight.
    Returns whether the run goes on (False: ``progress.status`` says why)."""
    idx, tau = cut_step(theta, progress.idx, progress.tau, progress.h, controls.t_base, step, cst, md, samples,
                        scratch)
    progress.idx = idx
    progress.tau = tau
    n_tr, status, flight = switch_gap(step.y, cst, c, md, controls.rtol, controls.atol, scratch,
                                      controls.t_base + tau, log, progress.n_tr, stats)
    progress.n_tr = n_tr
    if status != SUCCESS:
        stats[0] += 1
        progress.status = status
        progress.lost = c
        return False
    if flight < math.inf:  # a bounce: the next step ends inside its flight
        progress.h_override = 0.5 * flight
    return True


@inlined_kernel
def cut_at_breakaway(progress, theta, c, controls, step, cst, md, samples, scratch, log, stats):
    """Sticking contact ``c`` breaks away at θ inside the step: the flow is smooth up to it, so the
    step is cut there and the breakaway applied (:func:`.break_away`)."""
    idx, tau = cut_step(theta, progress.idx, progress.tau, progress.h, controls.t_base, step, cst, md, samples,
                        scratch)
    progress.idx = idx
    progress.tau = tau
    progress.n_tr = break_away(step.y, cst, c, md, scratch, controls.t_base + tau, log, progress.n_tr, stats)


@inlined_kernel
def new_piece(progress, step, cst, md, stats):
    """After a cut: a new smooth piece starts at the root (its derivative in the new modes)."""
    stats[0] += 1
    P.rhs(step.y, cst, md, step.k1)
    stats[2] += 1
    progress.slips_ready = False
    progress.retakes = 0


# ----------------------------------------------------------------------------- the whole step
@inlined_kernel
def accept_step(progress, t_base, step, slips, cst, md, samples, scratch, q_ready, stats):
    """Accept the whole step: write its samples, advance the state and its derivative to the
    step's end, and keep the slip velocities there as those at the next step's start."""
    h = progress.h
    tau = progress.tau
    times = samples.times
    if progress.idx < times.shape[0] and times[progress.idx] - t_base <= tau + h:
        if not q_ready:
            DP.dense_coefficients(step.stages, step.dense)
        progress.idx = write_samples(progress.idx, tau + h, tau, h, t_base, step.y, step.dense, cst, md, samples,
                                     scratch)
    progress.tau = tau + h
    y = step.y
    ynew = step.ynew
    k1 = step.k1
    stages = step.stages
    for i in range(y.shape[0]):
        y[i] = ynew[i]
        k1[i] = stages[6, i]
    stats[0] += 1
    start = slips.start
    end = slips.end
    for i in range(start.shape[0]):
        start[i] = end[i]
    progress.slips_ready = True


# ----------------------------------------------------------------------------- the loop
@standalone
@kernel
def event_loop(controls, md, cst, start, step, slips, scratch, samples, log, stats, start_modes):
    """The loop of :func:`integrate_event` (module docstring), free of reference counting.

    Parameters
    ----------
    controls : Controls
    md : ModelData
    cst : ndarray (CST nc,)
        The contacts' integration state, updated in place (pass the one of the previous chunk).
    start : ndarray (1,) of :data:`PROGRESS`
        ``h`` (the first step size), ``idx`` (the first sample) and ``n_tr`` (the transitions
        before) at the start; the chunk's progress at the end.
    step : :class:`~.dormand_prince.Step`
        ``step.y`` (2n + 2,) is advanced in place from local time 0.
    slips : :class:`~.slip_watch.SlipWatch`
    scratch : :class:`~.bundles.Scratch`
    samples : :class:`~.bundles.Samples`
        Written from ``idx`` at their absolute times.
    log : :class:`~.bundles.TransitionLog`
        Transitions from ``n_tr`` on, as far as it has room.
    stats : ndarray (6,) int64
        Receives accepted steps, rejected steps, rhs calls, step re-takes at slip → stick roots,
        slip → stick and stick → slip transitions.
    start_modes : bool
        Set ``cst`` first to the modes that ``step.y`` starts in
        (:func:`~stickslip.integrate.contacts.initial_modes`, which may project it): the first
        call of a run, made with ``tau_end = 0``, does only that (one compiled module instead of
        two, on a cold start).
    """
    progress = on_stack(start[0])
    progress.status = SUCCESS
    progress.lost = -1
    progress.tau = 0.0
    if start_modes:
        E.initial_modes(step.y, cst, md, controls.rtol, controls.atol, scratch.F, scratch.N)
    P.rhs(step.y, cst, md, step.k1)
    stats[2] += 1
    progress.idx = first_samples(progress.idx, controls.t_base, step.y, cst, md, samples, scratch)
    progress.lost = jammed_contact(step.y, cst, md)
    if progress.lost >= 0:
        progress.status = INCONSISTENT
        store_record(start, progress)
        return
    progress.h = min(progress.h, controls.h_max)
    room_kept = 2 * model_sizes(md.kin, md.m)[1] + 2  # more than one step records (a release of every contact)
    progress.n_steps = 0
    progress.retakes = 0
    progress.h_override = -1.0
    progress.h_free = -1.0
    progress.rejected = False
    progress.slips_ready = False
    while progress.tau < controls.tau_end:
        taken = take_step(progress, controls, step, cst, md, stats)
        if taken == STOP:
            break
        if taken == RETRY:
            continue
        ended, q_ready = lost_contact(progress, controls.t_base, step, cst, md, samples, scratch, stats)
        if ended:
            break
        shrink, theta_slip, any_stick, q_ready = slip_roots(progress, step, slips, cst, md, scratch, q_ready)
        if retake(progress, shrink, theta_slip, stats):
            continue
        theta_g, c_g, q_ready = gap_crossing(step, q_ready, progress.h, cst, md, scratch)
        theta_b, c_b, q_ready = breakaway_root(any_stick, step, q_ready, progress.h, cst, md, scratch)
        cut = theta_g > 0.0 and (theta_b < 0.0 or theta_g <= theta_b)
        if cut:
            if not cut_at_gap(progress, theta_g, c_g, controls, step, cst, md, samples, scratch, log, stats):
                break
        elif theta_b > 0.0:
            cut = True
            cut_at_breakaway(progress, theta_b, c_b, controls, step, cst, md, samples, scratch, log, stats)
        else:
            accept_step(progress, controls.t_base, step, slips, cst, md, samples, scratch, q_ready, stats)
            arrivals(progress, controls, step, slips, cst, md, scratch, log, theta_slip, any_stick, stats)
        if cut:
            new_piece(progress, step, cst, md, stats)
        if not E.all_finite(step.y):
            progress.status = NOT_FINITE
            break
        progress.lost = jammed_contact(step.y, cst, md)
        if progress.lost >= 0:
            progress.status = INCONSISTENT
            break
        if next_step_size(progress, controls, slips.homing, progress.n_tr + room_kept > log.times.shape[0]):
            progress.status = CHUNK_END
            break
    store_record(start, progress)


def loop_arrays(y0: np.ndarray, nc: int, h_init: float = 0.0, idx0: int = 0, n_tr0: int = 0):
    """The arrays :func:`event_loop` works on for a state ``y0`` (copied) and ``nc`` contacts:
    (start, step, slips, scratch, stats)."""
    start = np.zeros(1, dtype=PROGRESS)
    fresh_progress(start, h_init, idx0, n_tr0)
    ns = y0.shape[0]
    return start, DP.new_step(y0.copy()), slip_watch(nc), scratch(ns, nc), np.zeros(6, dtype=np.int64)


def integrate_event(md, cst, y0, controls, h_init, samples, idx0, log, n_tr0=0, start_modes=False):
    """Integrate from ``y0`` at local time 0 (absolute ``controls.t_base``) towards
    ``controls.tau_end``: allocates the work arrays and runs :func:`event_loop` (see there for the
    arguments).

    Plain Python: a compiled wrapper would link the whole loop, physics included, into a module of
    its own and have LLVM optimise and emit all of it a second time on a cold start; a call from
    Python costs microseconds per chunk.

    Returns
    -------
    status : int
        :mod:`stickslip.integrate.status` code; CHUNK_END when stopped at ``tau_stop``.
    tau : float
        Local time reached [s].
    y : ndarray (2n + 2,)
        The state there.
    h : float
        Step size to continue with [s].
    idx : int
        Next sample index.
    n_tr : int
        Transitions found so far (counted past the buffers' room).
    stats : ndarray (6,) int64
        As :func:`event_loop`'s.
    lost : int
        Contact whose normal force reached 0 (status CONTACT_LOST) or without a consistent normal
        force (INCONSISTENT), else −1.
    """
    nc = samples.forces.shape[1] // 2
    start, step, slips, work, stats = loop_arrays(y0, nc, float(h_init), int(idx0), int(n_tr0))
    event_loop(controls, md, cst, start, step, slips, work, samples, log, stats, bool(start_modes))
    p = start[0]
    return (int(p["status"]), float(p["tau"]), step.y, float(p["h"]), int(p["idx"]), int(p["n_tr"]), stats,
            int(p["lost"]))
