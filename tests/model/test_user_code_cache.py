"""Cached kernels of a model whose frame (or friction law) is the user's own code follow that code:
numba keys a cached kernel by the kernel's file and signature only, and with ``inline=True`` the
package's kernels inline the user's frame, so an edited frame used to load the kernel compiled
with the old one. (A frame compiled apart: ``test_frame_pointers.py``.)"""

import importlib
import json
import os
import subprocess
import sys
from typing import NamedTuple

import numpy as np
import pytest
from numba import typeof

from stickslip.model import physics
from stickslip.model.kernel_cache import patch_tag

MODULE = """
from typing import NamedTuple
from stickslip.model import csmath as csm
from stickslip.model.bundle import C_N0, contact_offsets
from stickslip.model.kinematics import register_kinematics

FACTOR = {factor}


class ArmKin(NamedTuple):
    H: float
    V: float


def arm_frame(kin, s, c, m, G, w):
    cos = csm.cos(s[0])
    G[0, 0] = kin.H / (cos * cos)
    G[1, 0] = 0.0
    w[0] = kin.V
    w[1] = 0.0
    return FACTOR * m[contact_offsets(1, c)[0] + C_N0] + csm.zero(s[0])


register_kinematics(ArmKin, arm_frame, ndof=1, ncontacts=1, dim=1, inline={inline})
"""


def _index_key(kin):
    cache = physics.rhs._cache
    return cache._index_key((typeof(kin),), physics.rhs.targetctx.codegen())


def _code_part(kin):
    """The key's parts beside the signature (a reloaded module's class is another type object here;
    across processes it is the same class by its import path)."""
    return _index_key(kin)[1:]


def test_the_index_key_follows_the_users_module(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    path = tmp_path / "user_arm_kinematics.py"
    path.write_text(MODULE.format(factor=1.0, inline=True))
    module = importlib.import_module("user_arm_kinematics")
    first = _code_part(module.ArmKin(1.0, 0.1))
    assert _code_part(module.ArmKin(2.0, 0.3)) == first  # numbers are data: the same kernels
    path.write_text(MODULE.format(factor=2.0, inline=True))
    module = importlib.reload(module)  # registers the edited frame for the new class
    assert _code_part(module.ArmKin(1.0, 0.1)) != first
    path.write_text(MODULE.format(factor=1.0, inline=True))
    module = importlib.reload(module)
    assert _code_part(module.ArmKin(1.0, 0.1)) == first  # back to the first code: its kernels again


def test_a_signature_without_user_code_keeps_numbas_key():
    class Plain(NamedTuple):  # no frame registered: the package's kernels keep their cache
        a: float

    key = _index_key(Plain(1.0))  # (signature, machine, code hashes): numba's own, and the patches' tag
    assert len(key) == 4 and key[3] == patch_tag()


@pytest.mark.slow
def test_an_edited_frame_recompiles_its_kernels_and_gives_the_new_result(tmp_path):
    """Three processes on one cache: the frame as written, edited (the normal force doubled), and
    the edited one again. Against numba's compile events and the results."""
    (tmp_path / "user_arm_kinematics.py").write_text(MODULE.format(factor=1.0, inline=True))
    code = ("import json, sys\n"
            f"sys.path.insert(0, {str(tmp_path)!r})\n"
            "from numba.core import event\n"
            "seen = []\n"
            "class L(event.Listener):\n"
            "    def on_start(self, ev): seen.append(1)\n"
            "    def on_end(self, ev): pass\n"
            "event.register('numba:compile', L())\n"
            "import stickslip\n"
            "from stickslip.model.friction import FrictionLaw\n"
            "from stickslip.model.system_model import Contact, FrictionModel\n"
            "import user_arm_kinematics as u\n"
            "m = FrictionModel(name='arm', dofs=('theta',), mass=[[1.0]], damping=[[0.02]], stiffness=[[1.0]],\n"
            "                  force=[0.0], contacts=(Contact(dim=1, friction=FrictionLaw('coulomb', 0.2, 0.1),\n"
            "                  normal_force=1.0),), kinematics=u.ArmKin(1.0, 0.1))\n"
            "t = stickslip.simulate(m, 30.0, ic={'theta': 0.0, 'dtheta': 0.1})\n"
            "print(json.dumps({'end': t.final_state.tolist(), 'compiles': len(seen)}))\n")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))

    def run():
        res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=900)
        assert res.returncode == 0, res.stderr
        return json.loads(res.stdout.strip().splitlines()[-1])

    first = run()
    (tmp_path / "user_arm_kinematics.py").write_text(MODULE.format(factor=2.0, inline=True))
    edited = run()
    again = run()
    assert first["compiles"] > 0 and edited["compiles"] > 0 and again["compiles"] == 0
    assert not np.allclose(first["end"], edited["end"])  # twice the normal force: another motion
    assert again["end"] == edited["end"]
