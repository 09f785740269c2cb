"""A cold start's steady-sliding kernels in two processes (:mod:`stickslip.integrate.compile_ahead`).

A module of its own, imported when a steady state is first solved: the integrators import the
steady-state solver, so the solver's modules cannot import the integrators' package as they load.
"""

from __future__ import annotations

from ..integrate.compile_ahead import Split, compile_apart
from ..model.kinematics import sizes_at_run_time

__all__ = ["STEADY", "compile_steady"]

#: For kinematics whose sizes are run-time data (model files; fixed sizes are compile-time constants
#: in these signatures): the complex-step stick solve (the deepest level of the chain under the
#: Newton) in the helper; the friction coefficient, the frame's central-difference bias (complex)
#: and the Newton's linear solve here; :func:`~stickslip.stability.steady.steady_sliding_point`
#: then loads both.
STEADY = Split(
    helper=("stickslip.model.forces.solve_stick_rows",),
    own=("stickslip.model.model_data.kinetic_coefficient", "stickslip.model.frames._frame_bias_central",
         "stickslip.stability.steady._solve_inplace"),
    caller="stickslip.stability.steady.steady_sliding_point",
    signatures={
        "stickslip.model.forces.solve_stick_rows": "z M i i B v i Z z z z Z",
        "stickslip.model.model_data.kinetic_coefficient": "M i i c",
        "stickslip.model.frames._frame_bias_central": "z i M Z z z",
        "stickslip.stability.steady._solve_inplace": "m v",
    },
    applies=lambda md: sizes_at_run_time(md.kin))


def compile_steady(md) -> bool:
    """:func:`~stickslip.integrate.compile_ahead.compile_apart` of :data:`STEADY` for the model data ``md``."""
    return compile_apart(md, STEADY, f"{__name__}:STEADY")
