"""The classic Runge–Kutta 4 pieces shared by the fixed-step methods (paper ref. [43]).

The slip step (``fixed_step.rk4_slip_step``), AEOM's stick step (``method_aeom.aeom_stick_step``)
and NAEOM's constant-force step (``method_naeom.rk4_force_step``) each loop over the three
stages after k1 with one right-hand side in the loop body (one inlined copy, ``model/jit.py``):

    for stage in range(3):
        c, k_in, k_out = stage_arrays(stage, h, k1, k2, k3, k4)
        stage_state(y, k_in, c, ytmp)             # ytmp = y + c k_in
        <k_out = f(ytmp)>
    combine(y, h, k1, k2, k3, k4, ynew)            # ynew = y + h/6 (k1 + 2 k2 + 2 k3 + k4)
"""

from __future__ import annotations

from ..model.jit import inlined_kernel

__all__ = ["stage_arrays", "stage_state", "combine"]


@inlined_kernel
def stage_arrays(stage, h, k1, k2, k3, k4):
    """(c, k_in, k_out) of RK4 stage ``stage`` = 0, 1, 2 (the 2nd to 4th evaluation): the stage
    state is y + c k_in [c in s] and its derivative goes to k_out."""
    if stage == 0:
        return 0.5 * h, k1, k2
    if stage == 1:
        return 0.5 * h, k2, k3
    return h, k3, k4


@inlined_kernel
def stage_state(y, k_in, c, ytmp):
    """ytmp = y + c k_in."""
    for i in range(y.shape[0]):
        ytmp[i] = y[i] + c * k_in[i]


@inlined_kernel
def combine(y, h, k1, k2, k3, k4, ynew):
    """The RK4 update ynew = y + h/6 (k1 + 2 k2 + 2 k3 + k4)."""
    sixth = h / 6.0
    for i in range(y.shape[0]):
        ynew[i] = y[i] + sixth * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
