"""The work arrays' size codes are literals when a kernel is typed, on every numba the project allows."""

import numba
import numpy as np
import pytest
from numba.core import types

from stickslip.model import stack
from stickslip.model.kinematics import ConstantKinematics, LargeConstantKinematics


#: The heap class's empty arrays: its values float64 (W and G M⁻¹ two-dimensional), its patterns int64 (the
#: factor's runs (k, 3)).
_FLOATS = {"factor_values", "factor_diagonal", "row_values", "normal_q", "normal_v", "gap_values", "damping_values",
           "stiffness_values", "mass_values"}
_EMPTY = {"delassus": np.zeros((0, 0)), "inverse_mass_rows": np.zeros((0, 0)), "factor_segments": np.zeros((0, 3), np.int64)}
HEAP = LargeConstantKinematics(70, 20, *[_EMPTY[f] if f in _EMPTY else np.zeros(0, float if f in _FLOATS else np.int64)
                                         for f in LargeConstantKinematics._fields[2:]])


@pytest.mark.parametrize("kin", [ConstantKinematics(), HEAP], ids=["stack", "heap"])
def test_work_matrix_is_typed_only_with_literal_size_codes(kin):
    """numba 0.57 types an intrinsic with plain integers first and keeps the first typing that
    succeeds (its ``intrinsic`` ignores ``prefer_literal``): the typing must refuse plain integers,
    for the stack and the heap flavour alike (the heap flavour's lowering failed on 0.57, every
    large model's run with it)."""
    kin_type, like = numba.typeof(kin), types.float64[:]
    with pytest.raises(AttributeError, match="literal_value"):
        stack.work_matrix._defn(None, kin_type, types.intp, types.intp, like)
    signature, _ = stack.work_matrix._defn(None, kin_type, types.IntegerLiteral(stack.TWO),
                                           types.IntegerLiteral(stack.DOFS), like)
    assert signature.return_type == types.Array(types.float64, 2, "C")
