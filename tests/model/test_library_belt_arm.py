"""The worked example of nonlinear kinematics (``stickslip.studies.models.belt_arm``, docs/models.md)
against its closed-form stick phases and a hand-written scipy solution of its slip phases.

An arm hinged at height H above a belt: its tip is at x = H tan θ, so v = (H / cos²θ) θ' − V and
J θ'' + c θ' + k θ = (H / cos²θ) F. In stick the tip moves with the belt, tan θ = tan θ_s + V t / H,
and the stick force F = (J θ'' + c θ' + k θ) cos²θ / H with θ' = (V / H) cos²θ,
θ'' = −2 (V / H)² cos³θ sin θ grows until it reaches μs N (breakaway). In slip (v < 0) the
friction force is +μk N.
"""

import inspect
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from stickslip import simulate
from stickslip.studies import models as studies

P = dict(J=1.0, c=0.02, k=1.0, H=1.0, V=0.1, N=1.0, mu_k=0.2, mu_s=0.3)  # belt_arm()'s defaults, written out
DOCS = Path(__file__).resolve().parents[2] / "docs" / "models.md"


def stick_force(theta):
    r = P["V"] / P["H"]
    cos, sin = math.cos(theta), math.sin(theta)
    acc = -2.0 * r * r * cos ** 3 * sin
    return (P["J"] * acc + P["c"] * r * cos * cos + P["k"] * theta) * cos * cos / P["H"]


def breakaway(theta_s):
    """(θ, time after entry) where the stick force reaches μs N, the stick phase in closed form
    (the force's main part k θ cos²θ / H rises up to θ ≈ 0.65, so the first crossing is below 0.6)."""
    theta_b = brentq(lambda th: stick_force(th) - P["mu_s"] * P["N"], theta_s, 0.6, xtol=1e-15, rtol=1e-15)
    return theta_b, P["H"] * (math.tan(theta_b) - math.tan(theta_s)) / P["V"]


def slip_until_stick(state):
    """Time and state at which slip from ``state`` (just after breakaway) sticks again (solve_ivp)."""
    def f(t, y):
        G = P["H"] / math.cos(y[0]) ** 2
        return [y[1], (-P["c"] * y[1] - P["k"] * y[0] + G * P["mu_k"] * P["N"]) / P["J"]]

    def arrive(t, y):
        return P["H"] * y[1] / math.cos(y[0]) ** 2 - P["V"]
    arrive.terminal, arrive.direction = True, 1.0
    sol = solve_ivp(f, (0.0, 50.0), state, method="DOP853", rtol=1e-12, atol=1e-14, events=arrive)
    return float(sol.t_events[0][0]), sol.y_events[0][0]


@pytest.fixture(scope="module")
def run():
    traj = simulate(studies.belt_arm(), 60.0, ic={"theta": 0.0, "dtheta": P["V"] / P["H"]}, rtol=1e-11, atol=1e-13,
                    sample_rate=50)
    assert traj.status == "success"
    return traj


def test_stick_phases_are_the_closed_form(run):
    tr = run.transitions
    assert tr.kind[0] == -1 and len(tr) >= 10  # starts stuck at θ = 0
    enter_t = np.concatenate([[0.0], tr.time[tr.kind == 1]])
    enter_theta = np.concatenate([[0.0], tr.state[tr.kind == 1, 0]])
    leave = tr.kind == -1
    for t_s, th_s, t_b, th_b in zip(enter_t, enter_theta, tr.time[leave], tr.state[leave, 0]):
        theta_b, duration = breakaway(th_s)
        assert th_b == pytest.approx(theta_b, abs=1e-10)
        assert t_b - t_s == pytest.approx(duration, rel=1e-9)
        inside = (run.t > t_s) & (run.t < t_b)
        theta = np.arctan(math.tan(th_s) + P["V"] * (run.t[inside] - t_s) / P["H"])
        np.testing.assert_allclose(run.states[inside, 0], theta, rtol=0, atol=1e-10)
        np.testing.assert_allclose(run.states[inside, 1], P["V"] / P["H"] * np.cos(theta) ** 2, rtol=0, atol=1e-10)


def test_slip_phases_match_solve_ivp(run):
    tr = run.transitions
    leave = np.flatnonzero(tr.kind == -1)
    leave = leave[leave + 1 < len(tr)]
    assert leave.size >= 4
    for i in leave:
        duration, state = slip_until_stick(tr.state[i])
        assert tr.kind[i + 1] == 1
        assert tr.time[i + 1] - tr.time[i] == pytest.approx(duration, abs=1e-8)
        np.testing.assert_allclose(tr.state[i + 1], state, rtol=0, atol=1e-9)


def test_docs_show_the_tested_code():
    """docs/models.md's worked example is this module's code, verbatim."""
    text = DOCS.read_text()
    blocks = "\n".join(re.findall(r"```python\n(.*?)```", text, flags=re.S))
    for obj in (studies.BeltArm, studies.belt_arm_frame, studies.belt_arm):
        assert inspect.getsource(obj) in blocks, obj.__name__
    assert "register_kinematics(BeltArm, belt_arm_frame, ndof=1, ncontacts=1, dim=1)" in blocks


#: A user's kinematics module: the worked example's frame under a class of its own.
VANISHING_MODULE = '''
from typing import NamedTuple
from stickslip.model.friction import FrictionLaw
from stickslip.model.kinematics import register_kinematics
from stickslip.model.system_model import Contact, FrictionModel
from stickslip.studies.models import belt_arm_frame

class VanishingArm(NamedTuple):
    H: float
    V: float

register_kinematics(VanishingArm, belt_arm_frame, ndof=1, ncontacts=1, dim=1)
MODEL = FrictionModel(name="arm", dofs=("theta",), mass=[[1.0]], damping=[[0.0]], stiffness=[[1.0]], force=[0.0],
                      contacts=(Contact(dim=1, friction=FrictionLaw("coulomb", 0.2, 0.1), normal_force=1.0),),
                      kinematics=VanishingArm(1.0, 0.1))
'''

RHS_OF = '''
import numpy as np
from stickslip.model.bundle import contact_state
from stickslip.model.physics import rhs
{setup}
ds = np.empty(2 * MODEL.n)
rhs(np.zeros(2 * MODEL.n), contact_state(MODEL.data.m), MODEL.data, ds)
print("ok")
'''


@pytest.mark.slow  # ~36 s: compiles a kinematics class in fresh processes
def test_kinematics_from_a_module_that_is_gone_do_not_break_other_models(tmp_path):
    """Two processes with a fresh kernel cache (~20 s of compiling)."""
    user = tmp_path / "user"
    user.mkdir()
    (user / "vanishing_arm.py").write_text(VANISHING_MODULE)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), PYTHONWARNINGS="ignore")
    first = subprocess.run([sys.executable, "-c", RHS_OF.format(setup="from vanishing_arm import MODEL")],
                           cwd=user, env=env, capture_output=True, text=True, timeout=600)
    assert first.returncode == 0, first.stderr[-2000:]
    # another process, where the user's module is not importable, runs a library model
    later = subprocess.run([sys.executable, "-c", RHS_OF.format(
        setup="from stickslip.model.library import load_model\nMODEL = load_model('belt')")],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert later.returncode == 0, later.stderr[-2000:]
