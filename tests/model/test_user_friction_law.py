"""A friction law of the user's own (a compiled function of |v|), on the belt: its stick phases in
closed form, its slip phases against scipy's solve_ivp with the law written out here in numpy, its
Jacobian against central differences, and the refusals of a law that cannot be used."""


import numpy as np
import pytest
from scipy.integrate import solve_ivp

from stickslip import simulate
from stickslip.model.friction import FrictionLaw, FrictionLawError
from stickslip.model.library.laws import Stribeck
from stickslip.model.model_file import ModelFileError, model_from_spec
from stickslip.model.system_model import Contact, FrictionModel

P = dict(m=1.0, c=0.1, k=1.0, V=0.3, N=1.0)
LAW = dict(mu_c=0.5, mu_s=1.0, v_s=0.5, mu_v=0.05)


def mu(speed):
    """The Stribeck curve, written independently of the package."""
    return LAW["mu_c"] + (LAW["mu_s"] - LAW["mu_c"]) * np.exp(-(speed / LAW["v_s"]) ** 2) + LAW["mu_v"] * speed


def stribeck_belt() -> FrictionModel:
    law = FrictionLaw.from_user(Stribeck(**LAW))
    return FrictionModel(name="stribeck-belt", dofs=("x",), mass=[[P["m"]]], damping=[[P["c"]]],
                         stiffness=[[P["k"]]], force=[0.0],
                         contacts=(Contact(dim=1, friction=law, normal_force=P["N"], tangent=[[1.0]], drive=[P["V"]]),))


@pytest.fixture(scope="module")
def run():
    return simulate(stribeck_belt(), 60.0, ic={"x": 2.0, "dx": 2.0}, rtol=1e-11, atol=1e-13, sample_rate=20)


def test_the_law_object():
    law = FrictionLaw.from_user(Stribeck(**LAW))
    assert law.mu_s == LAW["mu_s"]  # μ(0) by default
    speeds = np.array([0.0, 0.1, 0.5, 2.0])
    np.testing.assert_allclose(law.coefficient(speeds), mu(speeds), rtol=1e-15)
    assert FrictionLaw.from_user(Stribeck(**LAW), mu_s=1.2).mu_s == 1.2
    assert law.to_dict()["law"] == "user" and law.to_dict()["v_s"] == LAW["v_s"]


def test_stick_phases_are_the_closed_form(run):
    """In stick x' = V and the contact breaks away where k x + c V reaches μs N."""
    assert run.status == "success"
    tr = run.transitions
    enter = np.flatnonzero(tr.kind == 1)
    enter = enter[enter + 1 < len(tr)]
    assert enter.size >= 4
    x_break = (LAW["mu_s"] * P["N"] - P["c"] * P["V"]) / P["k"]
    np.testing.assert_allclose(tr.state[enter + 1, 0], x_break, rtol=1e-10)
    np.testing.assert_allclose(tr.time[enter + 1] - tr.time[enter], (x_break - tr.state[enter, 0]) / P["V"], rtol=1e-9)


def test_slip_phases_match_solve_ivp(run):
    """From each breakaway, m x'' = −c x' − k x + μ(|x' − V|) N sign(V − x') until x' = V again."""
    tr = run.transitions
    leave = np.flatnonzero(tr.kind == -1)
    leave = leave[leave + 1 < len(tr)]
    assert leave.size >= 3

    def rhs(t, y):
        rel = y[1] - P["V"]
        return [y[1], (-P["c"] * y[1] - P["k"] * y[0] - np.sign(rel) * mu(abs(rel)) * P["N"]) / P["m"]]

    def sticks(t, y):
        return y[1] - P["V"] if t > 1e-9 else -1.0
    sticks.terminal, sticks.direction = True, 1.0

    for i in leave:
        # start just after breakaway: the mass falls behind the belt (x' < V) at once
        y0 = tr.state[i, :2]
        sol = solve_ivp(rhs, (0.0, 50.0), y0, events=sticks, rtol=1e-12, atol=1e-14, method="DOP853")
        assert sol.status == 1
        assert tr.kind[i + 1] == 1
        assert tr.time[i + 1] - tr.time[i] == pytest.approx(sol.t_events[0][0], rel=1e-8)
        assert tr.state[i + 1, 0] == pytest.approx(sol.y_events[0][0][0], rel=1e-8)


@pytest.mark.slow  # the complex-step kernels of a new law class: ~30 s of compilation
def test_jacobian_equals_central_differences():
    """The complex step runs through the user's law: slip (where μ'(|v|) enters) and stick."""
    from test_jacobians import assert_jacobians_agree

    from stickslip.model.physics import MODE_SLIP, MODE_STICK

    model = stribeck_belt()
    assert_jacobians_agree(model, [MODE_SLIP])
    assert_jacobians_agree(model, [MODE_STICK])


def test_a_law_that_cannot_be_used_is_refused():
    class Unregistered(tuple):
        _fields = ()
    with pytest.raises(FrictionLawError, match="not registered"):
        FrictionLaw.from_user(Unregistered())
    with pytest.raises(FrictionLawError, match="from_user"):
        FrictionLaw("user", mu_k=0.5)
    with pytest.raises(FrictionLawError, match="mu_s = -1"):
        FrictionLaw.from_user(Stribeck(**LAW), mu_s=-1.0)
    with pytest.raises(FrictionLawError, match="mu_s = nan"):
        FrictionLaw.from_user(Stribeck(**LAW), mu_s=float("nan"))
    with pytest.raises(FrictionLawError, match=r"mu\(0\) cannot be evaluated"):
        FrictionLaw.from_user(Stribeck(**{**LAW, "v_s": 0.0}))
    spec = {"name": "b", "dofs": ["x"], "mass": [[1.0]], "damping": [[0.1]], "stiffness": [[1.0]],
            "contact": [{"tangent": [[1.0]], "drive": [1.5], "normal_force": 1.0,
                         "friction": {"law": "user", "mu_k": 0.5, "delta_mu": 0.5}}]}
    with pytest.raises((ModelFileError, FrictionLawError), match="cannot be stated in a file"):
        model_from_spec(spec)


def test_contacts_share_one_user_law():
    a = FrictionLaw.from_user(Stribeck(**LAW))
    b = FrictionLaw.from_user(Stribeck(**{**LAW, "v_s": 0.2}))
    model = FrictionModel(name="two", dofs=("x", "y"), mass=np.eye(2), damping=0.1 * np.eye(2),
                          stiffness=np.eye(2), force=[0.0, 0.0],
                          contacts=(Contact(dim=1, friction=a, normal_force=1.0, tangent=[[1.0, 0.0]], drive=[1.0]),
                                    Contact(dim=1, friction=b, normal_force=1.0, tangent=[[0.0, 1.0]], drive=[1.0])))
    with pytest.raises(Exception, match="share one instance"):
        model.data


def test_docs_show_the_tested_code():
    """docs/models.md shows the library's Stribeck law and the belt tested here."""
    import inspect
    import re
    from pathlib import Path

    from stickslip.model.library import laws

    text = (Path(__file__).resolve().parents[2] / "docs" / "models.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    source = inspect.getsource(laws)
    law_block = next(b for b in blocks if "def stribeck" in b)
    for line in law_block.strip().splitlines():
        assert line.strip() in source, line
    belt_block = next(b for b in blocks if 'name="stribeck-belt"' in b)
    namespace = {"FrictionModel": FrictionModel, "Contact": Contact}
    exec(belt_block, namespace)
    assert namespace["law"] == stribeck_belt().contacts[0].friction
    assert namespace["belt"].contacts[0].drive[0] == P["V"]
