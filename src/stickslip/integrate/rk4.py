"""The classic Runge–Kutta 4 pieces shared by the fixed-step methods (paper ref. [43]).

The slip step (``fixed_step.rk4_slip_step``), AEOM's stick step (``method_aeom.aeom_stick_step``)
and NAEOM's constant-force step (``method_naeom.rk4_force_step``) each loop over the three
stages after k1 with one right-hand side in the loop body (one inlined copy, ``model/jit.py``),
on a stage matrix K (4, n) whose row 0 is k1 = f(y):

    for stage in range(3):
        stage_state(y, K, stage, h, ytmp)         # ytmp = y + c K[stage], c = stage_time(stage, h)
        <K[stage + 1] = f(ytmp)>
    combine(y, h, K, ynew)                        # ynew = y + h/6 (k1 + 2 k2 + 2 k3 + k4)

The derivative goes to a row of K, not to one of four arrays picked by the stage: numba's inlining
of the generic right-hand side into the stage loop mis-resolves an array chosen by a branch (the
work rates at 2n, 2n + 1 of the derivative went unwritten), while a row of one matrix is one
well-defined value.
"""

from __future__ import annotations

from ..model.jit import inlined_kernel

__all__ = ["stage_time", "stage_state", "combine"]


@inlined_kernel
def stage_time(stage, h):
    """Time [s] after the step start of the state of RK4 stage ``stage`` = 0, 1, 2 (the 2nd to 4th
    evaluation): h/2, h/2, h."""
    return h if stage == 2 else 0.5 * h


@inlined_kernel
def stage_state(y, K, stage, h, ytmp):
    """ytmp = y + c K[stage], the state of RK4 stage ``stage`` (c = :func:`stage_time`)."""
    c = stage_time(stage, h)
    for i in range(y.shape[0]):
        ytmp[i] = y[i] + c * K[stage, i]


@inlined_kernel
def combine(y, h, K, ynew):
    """The RK4 update ynew = y + h/6 (k1 + 2 k2 + 2 k3 + k4) with k_j = K[j − 1]."""
    sixth = h / 6.0
    for i in range(y.shape[0]):
        ynew[i] = y[i] + sixth * (K[0, i] + 2.0 * K[1, i] + 2.0 * K[2, i] + K[3, i])
