"""The Dormand–Prince 5(4) pair with its 4th-order dense output, shared by the compiled integrators.

Dormand & Prince (1980), dense output after Shampine (1986): the coefficients of scipy's RK45.
The integrators (:mod:`.event_loop` on the 2n (+2) states, :mod:`stickslip.orbits.variational`
on the 12 + 144 variational states) own their right-hand sides, error norms and events; this
module owns the tableau and what is computed from it, as scalar constants so that the compiled
stage sums are fully unrolled (A_ij: stage i from stage j; B: 5th-order weights; E: error
weights, 5th minus 4th order; P_jc: dense output, stage j, power θ^(c+1)).

Stage derivatives are the rows ``Kst[0:7]`` of a (7, n) array; stage 7 is f at the 5th-order
solution (first-same-as-last). :class:`Step` bundles the arrays of one step.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..model.jit import kernel, standalone

A21 = 1 / 5
A31, A32 = 3 / 40, 9 / 40
A41, A42, A43 = 44 / 45, -56 / 15, 32 / 9
A51, A52, A53, A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
A61, A62, A63, A64, A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
B1, B3, B4, B5, B6 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
E1, E3, E4, E5, E6, E7 = -71 / 57600, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40
P10, P11, P12, P13 = 1.0, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432
P31, P32, P33 = 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799
P41, P42, P43 = -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072
P51, P52, P53 = 127303824393 / 49829197408, -318862633887 / 49829197408, 701980252875 / 199316789632
P61, P62, P63 = -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844
P71, P72, P73 = 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423

#: Number of stage derivatives (rows of ``Kst``).
N_STAGES = 7

SAFETY = 0.9        # standard step-size safety factor
MIN_FACTOR = 0.2    # largest step reduction after a rejection
MAX_FACTOR = 5.0    # largest step growth after an acceptance


class Step(NamedTuple):
    """The arrays of one Dormand–Prince step of a state of n entries.

    Attributes
    ----------
    y : ndarray (n,)
        The state at the step's start (advanced in place when a step is accepted).
    k1 : ndarray (n,)
        Its derivative f(y).
    stages : ndarray (7, n)
        The stage derivatives (:func:`stage_state`); row 6 is f at the step's end.
    ynew : ndarray (n,)
        The 5th-order state at the step's end.
    ytmp : ndarray (n,)
        The state of the stage being evaluated.
    dense : ndarray (n, 4)
        The dense-output coefficients (:func:`dense_coefficients`), formed only when needed.
    """

    y: np.ndarray
    k1: np.ndarray
    stages: np.ndarray
    ynew: np.ndarray
    ytmp: np.ndarray
    dense: np.ndarray


def new_step(y: np.ndarray) -> Step:
    """A :class:`Step` from the state ``y`` (its own array: advanced in place)."""
    n = y.shape[0]
    return Step(y, np.empty(n), np.empty((N_STAGES, n)), np.empty(n), np.empty(n), np.empty((n, 4)))


@kernel
def stage_state(y, Kst, h, stage, out):
    """``out`` = y + h Σ_j a_{stage, j} k_j: the state at which stage ``stage`` (1–5) is evaluated;
    ``stage`` = 6 gives the 5th-order solution y + h Σ_j b_j k_j."""
    n = y.shape[0]
    if stage == 1:
        for i in range(n):
            out[i] = y[i] + h * A21 * Kst[0, i]
    elif stage == 2:
        for i in range(n):
            out[i] = y[i] + h * (A31 * Kst[0, i] + A32 * Kst[1, i])
    elif stage == 3:
        for i in range(n):
            out[i] = y[i] + h * (A41 * Kst[0, i] + A42 * Kst[1, i] + A43 * Kst[2, i])
    elif stage == 4:
        for i in range(n):
            out[i] = y[i] + h * (A51 * Kst[0, i] + A52 * Kst[1, i] + A53 * Kst[2, i] + A54 * Kst[3, i])
    elif stage == 5:
        for i in range(n):
            out[i] = y[i] + h * (A61 * Kst[0, i] + A62 * Kst[1, i] + A63 * Kst[2, i] + A64 * Kst[3, i]
                                 + A65 * Kst[4, i])
    else:
        for i in range(n):
            out[i] = y[i] + h * (B1 * Kst[0, i] + B3 * Kst[2, i] + B4 * Kst[3, i] + B5 * Kst[4, i]
                                 + B6 * Kst[5, i])


@kernel
def local_error(Kst, h, i):
    """Embedded error estimate (5th minus 4th order) of component ``i`` over a step of length h."""
    return h * (E1 * Kst[0, i] + E3 * Kst[2, i] + E4 * Kst[3, i] + E5 * Kst[4, i] + E6 * Kst[5, i]
                + E7 * Kst[6, i])


@standalone
@kernel
def dense_coefficients(Kst, Q):
    """Q (n, 4) = Kᵀ P, the interpolant y(θ) = y0 + h Q [θ, θ², θ³, θ⁴]ᵀ (``events.dense_state``)."""
    for i in range(Q.shape[0]):
        k1 = Kst[0, i]
        k3 = Kst[2, i]
        k4 = Kst[3, i]
        k5 = Kst[4, i]
        k6 = Kst[5, i]
        k7 = Kst[6, i]
        Q[i, 0] = P10 * k1
        Q[i, 1] = P11 * k1 + P31 * k3 + P41 * k4 + P51 * k5 + P61 * k6 + P71 * k7
        Q[i, 2] = P12 * k1 + P32 * k3 + P42 * k4 + P52 * k5 + P62 * k6 + P72 * k7
        Q[i, 3] = P13 * k1 + P33 * k3 + P43 * k4 + P53 * k5 + P63 * k6 + P73 * k7
