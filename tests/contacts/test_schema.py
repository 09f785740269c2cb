"""The model-file schema of unilateral contacts: keys, --set paths, one-line refusals, files."""

from __future__ import annotations

import copy

import numpy as np
import pytest

import stickslip
from stickslip.errors import ModelError, ModelFileError
from stickslip.model import model_from_spec

SPEC = {
    "name": "slider", "dofs": ["x", "y"],
    "mass": [[1.0, 0.0], [0.0, 1.0]], "damping": [[0.1, 0.0], [0.0, 0.1]],
    "stiffness": [[1.0, 0.0], [0.0, 1.0]], "force": [0.0, 0.5],
    "contact": [{"tangent": [[1.0, 0.0]], "drive": [1.0], "gap": 0.0, "gap_gradient": [0.0, -1.0],
                 "normal": {"law": "compliant", "stiffness": 40.0, "damping": 0.5},
                 "friction": {"law": "coulomb", "mu_k": 0.6, "delta_mu": 0.0}}],
}


def spec_with(**contact):
    spec = copy.deepcopy(SPEC)
    spec["contact"][0].update(contact)
    for key, value in list(spec["contact"][0].items()):
        if value is None:
            del spec["contact"][0][key]
    return spec


def test_the_schema_builds_the_contact_it_states():
    model = model_from_spec(SPEC)
    (contact,) = model.contacts
    assert model.unilateral and contact.unilateral
    assert contact.normal.law == "compliant" and contact.normal.stiffness == 40.0 and contact.normal.damping == 0.5
    assert contact.gap == 0.0 and np.array_equal(contact.gap_gradient, [0.0, -1.0])


@pytest.mark.parametrize("path, value, check", [
    ("contact.0.gap", -0.1, lambda m: m.contacts[0].gap == -0.1),
    ("contact.0.gap_gradient.y", -2.0, lambda m: m.contacts[0].gap_gradient[1] == -2.0),
    ("contact.0.normal.stiffness", 80.0, lambda m: m.contacts[0].normal.stiffness == 80.0),
    ("contact.0.normal.damping", 0.0, lambda m: m.contacts[0].normal.damping == 0.0),
    ("contact.0.normal.law", "compliant", lambda m: m.contacts[0].normal.law == "compliant"),
])
def test_every_new_path_is_reached_by_set(path, value, check):
    assert check(model_from_spec(SPEC).replace(**{path: value}))


@pytest.mark.parametrize("contact, message", [
    ({"normal_force": 1.0}, "normal_force (a prescribed load) and gap (a unilateral contact) both given"),
    ({"gap": None, "gap_gradient": None, "normal": None},
     "contact.0.normal_force is missing; give normal_force = N0 > 0 [N] for a contact that is always pressed, or "
     "gap_gradient with a [contact.normal] table"),
    ({"normal": None}, "contact.0.normal is missing for a unilateral contact"),
    ({"gap_gradient": None}, "contact.0.gap_gradient is missing for a unilateral contact"),
    ({"normal": {"law": "compliant", "stiffness": -1.0}}, "stiffness = -1 must be a finite contact stiffness > 0"),
    ({"normal": {"law": "compliant", "stiffness": 1.0, "damping": -0.1}}, "damping = -0.1 must be finite and >= 0"),
    ({"normal": {"law": "rigid", "stiffness": 10.0}}, "a rigid contact has no stiffness or damping"),
    ({"normal": {"law": "rigid", "restitution": -0.5}}, "restitution = -0.5 must lie in [0, 1]"),
    ({"normal": {"law": "soft", "stiffness": 1.0}}, "law = 'soft' is not a normal law; choose compliant or rigid"),
    ({"normal": {"law": "compliant", "stiffness": 1.0, "spring": 2.0}}, "contact.0.normal: unknown key(s) spring"),
    ({"gap_gradient": [1.0, 0.0, 0.0]}, "contact.0.gap_gradient must be a list of 2 number(s)"),
    ({"gap_gradient": [0.0, 0.0]}, "gap_gradient is zero on every free dof"),
    ({"gap": "nan"}, "contact.0.gap"),
])
def test_a_contact_with_a_wrong_normal_part_is_refused_in_one_line(contact, message):
    with pytest.raises((ModelFileError, ModelError)) as info:
        model_from_spec(spec_with(**contact))
    text = str(info.value)
    assert message in text and "\n" not in text


def test_a_model_file_run_writes_open_state_gap_and_normal_force(tmp_path):
    model = model_from_spec(SPEC)
    traj = stickslip.simulate(model, 30.0, ic={"y": -0.3})
    assert traj.open.any() and (~traj.open).any()
    path = traj.to_netcdf(tmp_path / "run.nc")
    back = stickslip.load_trajectory(path)
    assert np.array_equal(back.mode, traj.mode) and back.system.unilateral
    ds = traj.to_xarray()
    assert {"open", "gap", "normal_force"} <= set(ds.data_vars)
    assert ds["gap"].attrs["units"] == "m" and ds["normal_force"].attrs["units"] == "N"
    assert np.array_equal(ds["open"].values[:, 0].astype(bool), traj.open[:, 0])
    assert ds.attrs["steady_open_fraction"] == pytest.approx(traj.steady.open_fraction)
    assert ds["transition_kind"].attrs["flag_meanings"] == "stick_to_slip slip_to_stick open close"


def test_pressed_models_keep_their_results_unchanged():
    """A model whose contacts are all pressed has no open flags, keys or variables."""
    traj = stickslip.simulate("belt", 10.0)
    assert not traj.system.unilateral and not traj.open.any()
    assert "open_fraction" not in traj.steady.to_dict()
    assert "open" not in traj.to_xarray().data_vars

