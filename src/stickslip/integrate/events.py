"""Transitions of the paper's fixed-step methods (AEOM, NAEOM): what they add to the generic
transition logic of :mod:`.contacts`.

The event functions, the Illinois root refinement on a dense output, the stick test and the
breakaway direction are those of the generic event integrator (:mod:`.contacts`, on the generic
physics). This module holds what the fixed-step methods add: the step's cubic Hermite
interpolant (a dense output ``y(θ) = y0 + h Σ_j Q[:, j] θ^(j+1)`` with three columns), the root of
an event on it, the trial points of bisection on re-stepping and the mode a run starts in. The
models have one contact (the plates), contact 0.

* slip → stick: ``EVENT_SLIP`` is the projection of v_r on a reference direction (its direction at
  the start of the step). A sign change means the 2-D velocity passed (near) zero; at the located
  root, if |v_r| is below :data:`STICK_SPEED_TOL` and the stick force is admissible
  (|F| ≤ μs N, Eq. 10), stick begins; if it is not admissible, v_r is set to zero and slip departs
  as at breakaway.
* stick → slip: ``EVENT_STICK`` = μs N − |F_stick|; its root is breakaway (Eq. 10). Slip starts
  with v_r = 0 in the direction e = −F_stick/|F_stick|, so F is continuous.
"""

from __future__ import annotations

import math

import numpy as np

from ..model import physics as P
from ..model.jit import kernel
# the event codes, tolerances and transition steps are those of the generic event integrator
from .contacts import (EVENT_SLIP, EVENT_STICK, EVENT_TIME_TOL, STICK_SPEED_TOL, TRANSITION_TO_SLIP,  # noqa: F401
                       TRANSITION_TO_STICK, all_finite, breakaway_direction, dense_state, event_value, first_crossing,
                       try_stick)

#: First half-width, as a fraction of the step, of the bracket that bisection on re-stepping
#: (the fixed-step methods) tries around the root of the event on the step's cubic Hermite
#: interpolant (:func:`bisection_point`), widened ×10 while the root lies outside. AEOM's
#: breakaway roots on the interpolant were measured within 1e-8 of the re-stepped ones at
#: Δt = 1e-4 s and within 1e-6 at Δt = 1e-3 s (Sect. 4.2.1 case); the width affects only the
#: number of trials, never the root.
ROOT_BRACKET = 1e-7


@kernel
def hermite_coefficients(y0, f0, y1, f1, h, Q):
    """Cubic Hermite interpolant of a step as ``y(θ) = y0 + h Σ_j Q[:, j] θ^(j+1)`` (3 columns).

    Matches y and dy/dt = f at both ends (θ = 0, 1); 3rd order in h, the form used by
    ``contacts.dense_state``.
    """
    for i in range(y0.shape[0]):
        d = (y1[i] - y0[i]) / h
        Q[i, 0] = f0[i]
        Q[i, 1] = 3.0 * d - 2.0 * f0[i] - f1[i]
        Q[i, 2] = f0[i] + f1[i] - 2.0 * d


@kernel
def interpolated_crossing(kind, y0, f0, y1, f1, h, stick, md, Q, scratch):
    """Root θ ∈ (0, 1] of the event ``kind`` (reference direction none: the stick event) on the
    cubic Hermite interpolant of a step from (y0, f0 = dy/dt) to (y1, f1) of length ``h`` [s]
    (``contacts.first_crossing``); −1.0 if the interpolant shows none. ``Q`` (n, 3) and
    ``scratch`` (:class:`~.bundles.Scratch`) are work arrays.

    The estimate that bisection on re-stepping starts from (:func:`bisection_point`).
    """
    hermite_coefficients(y0, f0, y1, f1, h, Q)
    return first_crossing(kind, np.int64(0), y0, Q, h, 0.0, 0.0, stick, md, scratch)


@kernel
def stick_margin(y, stick, md, F, N):
    """The stick → slip event μs N − |F_stick| at ``y`` [N] (``stick``: the contact state in stick)."""
    return event_value(EVENT_STICK, np.int64(0), y, 0.0, 0.0, stick, md, F, N)


@kernel
def bisection_point(a, b, estimate, h):
    """Next θ to re-take a step of length ``h`` [s] to, in bisection on re-stepping for the root
    bracketed by [a, b]; −1.0 once the bracket is shorter than :data:`EVENT_TIME_TOL`.

    ``estimate`` is the root on the step's interpolant (:func:`interpolated_crossing`; ≤ 0 for
    none). The trials first search outwards from it, at estimate ± w for w = ROOT_BRACKET,
    10 ROOT_BRACKET, … (each that lies inside (a, b), nearest first); once none does, [a, b] is
    halved. Every trial narrows the bracket, so a poor estimate costs a few trials and never
    the result. With a good one the halving starts from a bracket of ~1e-7 of the step instead
    of the whole step (AEOM at Δt = 1e-3 s: ~12 re-steps per breakaway instead of 31).

    Every trial lies strictly inside (a, b), so the search ends: ~40 halvings take a bracket
    from Δt = 0.1 s to the tolerance, and a bracket that no longer halves in floating point (or
    a step length that is not a finite number) ends it as well.
    """
    mid = 0.5 * (a + b)
    if not ((b - a) * h > EVENT_TIME_TOL and a < mid < b and h < math.inf):
        return -1.0
    if estimate > 0.0:
        w = ROOT_BRACKET
        while w < 0.5:
            if a < estimate - w < b:
                return estimate - w
            if a < estimate + w < b:
                return estimate + w
            w *= 10.0
    return mid


@kernel
def first_trial(estimate, h):
    """Start of the search for a root inside a step of length ``h`` [s] that ends past it: the
    bracket [a, b] = [0, 1] (fractions of the step), where the step's end state stands (θ = 1),
    and the first θ to re-take the step to (:func:`bisection_point`). Returns (a, b, at, θ)."""
    return 0.0, 1.0, 1.0, bisection_point(0.0, 1.0, estimate, h)


@kernel
def narrowed(a, b, theta, before_root, estimate, h):
    """The bracket after the step was re-taken to ``theta``: [θ, b] when that step still ends
    before the root (``before_root``), else [a, θ]. Returns (a, b, at, next θ) with ``at`` = θ,
    where the end state now stands, and the next trial from :func:`bisection_point` (−1.0 once
    the bracket is short enough: the caller then re-takes the step to b unless ``at`` is b)."""
    if before_root:
        a = theta
    else:
        b = theta
    return a, b, theta, bisection_point(a, b, estimate, h)


@kernel
def initial_mode(y, cst, stick, md, F, N):
    """The mode a state starts in, written to ``cst`` (mode, ex, ey, τ): stick if v_r = 0 (to
    STICK_SPEED_TOL; ``y`` is then projected onto v_r = 0) and stick is admissible (Eq. 10), else
    slip along v_r/|v_r|, or from v_r = 0 along the breakaway direction of the inadmissible stick
    force. Returns the mode."""
    contact = np.int64(0)
    sticks, ex, ey = try_stick(y, stick, contact, md, STICK_SPEED_TOL, F, N)
    mode = P.MODE_STICK
    if not sticks:
        mode = P.MODE_SLIP
        vx, vy = P.slip_velocity(y, contact, md)
        speed = math.sqrt(vx * vx + vy * vy)
        if speed > P.SPEED_FLOOR:
            ex = vx / speed
            ey = vy / speed
    cst[0] = mode
    cst[1] = ex
    cst[2] = ey
    cst[3] = math.inf
    return mode
