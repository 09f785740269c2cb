"""A contact frame compiled apart (``register_kinematics(..., inline=False)``, the default for
classes defined outside the package): the kernels call it through its address, are shared by
every such class and do not compile again when the frame is edited.

Against the same frame compiled into the kernels (the worked example's ``BeltArm``, a class of
the package): the same runs bit for bit; steady sliding against its closed-form eigenvalues; a
closed-form bias through its address against the complex-step bias; a stability map over a
kinematics field against the stability of each point; a model sent to another process; and the
edit, against numba's compile events.
"""

import dataclasses
import inspect
import json
import os
import pickle
import subprocess
import sys
import textwrap
from typing import NamedTuple

import numpy as np
import pytest
from numba import njit

import stickslip
from stickslip.model import csmath as csm
from stickslip.model.bundle import C_N0, contact_offsets
from stickslip.model.frame_pointers import is_pointer_class
from stickslip.model.kinematics import register_kinematics
from stickslip.studies import models as studies
from test_user_code_cache import MODULE

IC = {"theta": 0.0, "dtheta": 0.1}


class ApartArm(NamedTuple):
    H: float
    V: float


class BiasedArm(NamedTuple):
    H: float
    V: float


class WrongBiasArm(NamedTuple):
    H: float
    V: float


arm_frame = njit(studies.belt_arm_frame)  # called from the bias functions below


@njit
def arm_bias(kin, s, c, m, G, w, h):
    """The belt arm's frame and its velocity bias h = d/dt(H / cos²θ) θ̇ = 2 H sin θ / cos³θ θ̇²."""
    normal = arm_frame(kin, s, c, m, G, w)
    cos = csm.cos(s[0])
    h[0] = 2.0 * kin.H * csm.sin(s[0]) / (cos * cos * cos) * s[1] * s[1]
    h[1] = 0.0 * s[1]
    return normal


def wrong_bias(kin, s, c, m, G, w, h):
    normal = arm_bias(kin, s, c, m, G, w, h)
    h[0] = 3.0 * h[0]
    return normal


register_kinematics(ApartArm, studies.belt_arm_frame, ndof=1, ncontacts=1, dim=1)
register_kinematics(BiasedArm, studies.belt_arm_frame, ndof=1, ncontacts=1, dim=1, frame_bias=arm_bias)
register_kinematics(WrongBiasArm, studies.belt_arm_frame, ndof=1, ncontacts=1, dim=1, frame_bias=wrong_bias)


def arm(cls, **changes):
    """The worked example's belt arm (``studies.belt_arm``) with its kinematics data of class ``cls``."""
    base = studies.belt_arm(**changes)
    return dataclasses.replace(base, kinematics=cls(*base.kinematics), builder=lambda p: arm(cls, **p))


def test_the_package_inlines_its_own_frames_and_compiles_a_users_apart():
    assert type(studies.belt_arm().data.kin) is studies.BeltArm
    kin = arm(ApartArm).data.kin
    assert type(kin).__name__ == "FramePointersPressed_n1_c1_dim1" and kin.values == (1.0, 0.1)
    assert kin.frame != 0 and kin.frame_complex != 0 and kin.bias == 0 and kin.gap == 0


def test_a_frame_compiled_apart_runs_bit_for_bit_like_the_inlined_one():
    inlined = stickslip.simulate(studies.belt_arm(), 60.0, ic=IC)
    apart = stickslip.simulate(arm(ApartArm), 60.0, ic=IC)
    assert inlined.stats.slip_to_stick > 2  # stick-slip: the stick multipliers and their events
    np.testing.assert_array_equal(apart.states, inlined.states)
    np.testing.assert_array_equal(apart.transitions.time, inlined.transitions.time)
    np.testing.assert_array_equal(apart.friction, inlined.friction)


class TypedArm(NamedTuple):
    H: float
    V: float


def test_a_frame_without_a_source_file_is_compiled_uncached_and_runs_alike():
    """A frame typed in an interactive session has no file for numba's cache to key it by: it is
    compiled in each process instead, and runs as the same frame from a module does."""
    namespace = {"csm": csm, "C_N0": C_N0, "contact_offsets": contact_offsets}
    exec(compile(inspect.getsource(studies.belt_arm_frame), "<stdin>", "exec"), namespace)  # noqa: S102
    register_kinematics(TypedArm, namespace["belt_arm_frame"], ndof=1, ncontacts=1, dim=1)
    typed = stickslip.simulate(arm(TypedArm), 60.0, ic=IC)
    from_module = stickslip.simulate(arm(ApartArm), 60.0, ic=IC)
    np.testing.assert_array_equal(typed.states, from_module.states)


def test_steady_sliding_of_a_frame_compiled_apart_has_the_closed_form_eigenvalues():
    """The complex-step Jacobian goes through the frame's complex version. In steady slip the tip's
    friction force is μk N, so k θe = μk N H / cos²θe and J δθ'' + c δθ' + (k − 2 μk N H tan θe / cos²θe) δθ = 0."""
    J, c, k, H, N, mu_k = 1.0, 0.02, 1.0, 1.0, 1.0, 0.2
    result = stickslip.stability(arm(ApartArm, V=0.3))
    theta = result.equilibrium[0]
    assert k * theta == pytest.approx(mu_k * N * H / np.cos(theta) ** 2, rel=1e-12)
    stiffness = k - 2.0 * mu_k * N * H * np.tan(theta) / np.cos(theta) ** 2
    expected = np.roots([J, c, stiffness])
    np.testing.assert_allclose(np.sort_complex(result.eigenvalues), np.sort_complex(expected), rtol=1e-10)


def test_a_closed_form_bias_is_called_through_its_address():
    """The closed-form bias and the complex step of the frame are both exact to round-off; a wrong
    bias (three times h) changes the stick forces, so the closed form is the one called."""
    plain = stickslip.simulate(arm(ApartArm), 60.0, ic=IC)
    biased = stickslip.simulate(arm(BiasedArm), 60.0, ic=IC)
    wrong = stickslip.simulate(arm(WrongBiasArm), 60.0, ic=IC)
    assert arm(BiasedArm).data.kin.bias != 0
    np.testing.assert_allclose(biased.states, plain.states, rtol=0, atol=1e-9)
    assert np.abs(wrong.states - plain.states).max() > 1e-4


def test_a_stability_map_over_a_kinematics_field_matches_each_points_stability():
    """The map varies the frame's data (the belt speed V, a field of the kinematics tuple) inside
    one compiled call; each point's own stability analysis builds its model anew."""
    V = np.array([0.2, 0.4])
    k = np.array([0.5, 1.5])
    smap = stickslip.stability_map(arm(ApartArm), V, k, axes=("V", "k"), boundary=False)
    for i, v in enumerate(V):
        for j, kk in enumerate(k):
            expected = stickslip.stability(arm(ApartArm, V=v, k=kk)).eigenvalues.real.max()
            assert smap.max_real_part[0, i, j] == pytest.approx(expected, rel=1e-9, abs=1e-12)


#: The user's kinematics module of ``test_user_code_cache`` (its frame's normal force scaled by
#: FACTOR), its frame compiled apart, with a model.
USER_MODULE = MODULE.format(factor="{factor}", inline=False) + textwrap.dedent('''
    from stickslip.model import Contact, FrictionLaw, FrictionModel
    MODEL = FrictionModel(name="arm", dofs=("theta",), mass=[[1.0]], damping=[[0.02]], stiffness=[[1.0]],
                          force=[0.0], contacts=(Contact(dim=1, friction=FrictionLaw("coulomb", 0.2, 0.1),
                                                         normal_force=1.0),), kinematics=ArmKin(1.0, 0.1))
''')

RUN = textwrap.dedent('''
    import json, pickle, sys
    from numba.core import event
    compiled, depth = [], [0]
    class Listener(event.Listener):  # the outermost compilations (not what they compile inside)
        def on_start(self, ev):
            if depth[0] == 0:
                compiled.append(ev.data["dispatcher"].py_func.__qualname__)
            depth[0] += 1
        def on_end(self, ev):
            depth[0] -= 1
    event.register("numba:compile", Listener())
    import stickslip, user_arm
    if len(sys.argv) > 1:  # the model data pickled by another process
        with open(sys.argv[1], "rb") as f:
            data = pickle.load(f)
        from stickslip.model.physics import rhs
        from stickslip.model.bundle import contact_state
        import numpy as np
        out = np.empty(2)
        rhs(np.array([0.3, -0.2]), contact_state(data.m), data, out)
        print(json.dumps({"rhs": out.tolist()}))
    else:
        end = stickslip.simulate(user_arm.MODEL, 30.0, ic=[0.0, 0.1]).final_state.tolist()
        print(json.dumps({"end": end, "compiled": sorted(set(compiled))}))
''')


def _run(folder, *args):
    res = subprocess.run([sys.executable, "-c", RUN, *map(str, args)], cwd=folder, capture_output=True, text=True,
                         env=dict(os.environ, PYTHONPATH=os.pathsep.join([str(folder), *sys.path])), timeout=900)
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_an_edited_frame_compiles_alone_and_gives_the_new_motion(tmp_path):
    """Three processes on one kernel cache: the frame as written, edited (its normal force ×1.5), and
    the edited one again. After the edit only the frame compiles (a float and a complex version),
    and the run follows the new frame; the third run compiles nothing."""
    module = tmp_path / "user_arm.py"
    module.write_text(USER_MODULE.format(factor=1.0))
    first = _run(tmp_path)
    module.write_text(USER_MODULE.format(factor=1.5))
    edited = _run(tmp_path)
    again = _run(tmp_path)
    assert edited["compiled"] == ["arm_frame"]
    assert again["compiled"] == []
    assert not np.allclose(first["end"], edited["end"])
    assert again["end"] == edited["end"]


def test_the_model_data_of_a_frame_compiled_apart_crosses_to_another_process(tmp_path):
    """Addresses belong to one process: the data pickles as the user's kinematics object and is
    rebuilt with the other process's addresses (its right-hand side then equals this one's)."""
    (tmp_path / "user_arm.py").write_text(USER_MODULE.format(factor=1.0))
    sys.path.insert(0, str(tmp_path))
    try:
        import user_arm
        from stickslip.model.bundle import contact_state
        from stickslip.model.physics import rhs

        data = user_arm.MODEL.data
        assert is_pointer_class(type(data.kin))
        copy = pickle.loads(pickle.dumps(data))
        assert copy.kin == data.kin  # in this process: the same addresses
        (tmp_path / "data.pkl").write_bytes(pickle.dumps(data))
        here = np.empty(2)
        rhs(np.array([0.3, -0.2]), contact_state(data.m), data, here)
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("user_arm", None)
    there = _run(tmp_path, tmp_path / "data.pkl")["rhs"]
    assert there == here.tolist()
