"""Model-file validation: every bad file stops with one ModelFileError line naming the key and the fix."""

import copy
import math
import unicodedata

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.errors import StickSlipError
from stickslip.model.friction import FrictionLaw
from stickslip.model.library import load_model
from stickslip.model.model_file import (CONTACT_KEYS, TOP_KEYS, ModelFileError, load_model_file, model_from_spec)
from stickslip.model.system_model import Contact, FrictionModel, ModelError

#: Words of the fix that every message gives.
FIX_WORDS = ("give", "choose", "add", "must", "fix", "valid keys", "e.g.", "needs", "use")

#: Valid specs to corrupt: the library's model files and a 2-D contact on three dofs.
PLANAR = {
    "name": "planar", "dofs": ["x", "y", "phi"],
    "mass": [[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 0.5]],
    "damping": [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.01]],
    "stiffness": [[10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 3.0]],
    "force": [0.0, 0.0, 0.0], "slip_band": 1e-4,
    "contact": [{"name": "pad", "tangent": [[1.0, 0.0, 0.0], [0.0, 1.0, 0.2]], "drive": [1.0, 0.0],
                 "normal_force": 5.0, "normal_gradient": [0.0, 0.0, 0.0], "normal_rate_gradient": [0.0, 0.0, 0.0],
                 "friction": {"law": "exponential", "mu_k": 0.3, "delta_mu": 0.2, "alpha": 4.0, "mu_v": 0.01}}],
}
BASES = [dict(load_model(name).spec) for name in ("belt", "hoffmann", "popp-stelter")] + [PLANAR]


def write(tmp_path, spec, name="model.toml"):
    path = tmp_path / name
    path.write_text(tomli_w.dumps(spec))
    return path


def refused(path, *keys, any_of=()):
    """The ModelFileError of loading ``path``: one line, naming ``keys`` (and one of ``any_of``) and a fix."""
    with pytest.raises(ModelFileError) as info:
        load_model_file(path)
    message = str(info.value)
    assert "\n" not in message
    for key in keys:
        assert key in message, (key, message)
    assert not any_of or any(key in message for key in any_of), (any_of, message)
    assert any(word in message for word in FIX_WORDS), message
    return message


def leaves(node, path=()):
    """Paths of every number in a spec (list indices as ints)."""
    if isinstance(node, bool):
        return []
    if isinstance(node, (int, float)):
        return [path]
    if isinstance(node, list):
        return [p for i, item in enumerate(node) for p in leaves(item, path + (i,))]
    if isinstance(node, dict):
        return [p for key, item in node.items() for p in leaves(item, path + (key,))]
    return []


def tables(spec):
    """Every table of a spec with the path prefix its errors name."""
    out = [(spec, "")]
    for c, contact in enumerate(spec["contact"]):
        out += [(contact, f"contact.{c}"), (contact["friction"], f"contact.{c}.friction")]
    return out


def set_at(spec, path, value):
    node = spec
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value


def last_key(path):
    return next(p for p in reversed(path) if isinstance(p, str))


# --------------------------------------------------------------------------- one case each
def test_library_files_load(tmp_path):
    for spec in BASES:
        model = load_model_file(write(tmp_path, spec))
        assert model.n == len(spec["dofs"]) and model.n_contacts == len(spec["contact"])


@pytest.mark.parametrize("key, value, named", [
    ("mass", [[1.0, 0.0]], "mass"),                              # one row short
    ("stiffness", [[1.0, 0.0], [0.0]], "stiffness"),              # ragged
    ("damping", 0.1, "damping"),                                  # not a matrix
    ("force", [0.0, 0.0, 0.0], "force"),                          # three entries for two dofs
])
def test_wrong_shapes(tmp_path, key, value, named):
    spec = copy.deepcopy(BASES[1])
    spec[key] = value
    refused(write(tmp_path, spec), named)


@pytest.mark.parametrize("key, value", [
    ("tangent", [[1.0, 0.0, 0.0]]), ("tangent", [[1.0, 0.0]] * 3), ("drive", [1.0, 2.0]),
    ("normal_gradient", [1.0]),
])
def test_wrong_contact_shapes(tmp_path, key, value):
    spec = copy.deepcopy(BASES[2])  # popp-stelter: two dofs, pressed contacts
    spec["contact"][0][key] = value
    refused(write(tmp_path, spec), f"contact.0.{key}")


@pytest.mark.parametrize("mass", [[[1.0, 0.0], [0.0, -1.0]], [[1.0, 2.0], [2.0, 1.0]], [[1.0, 0.5], [0.0, 1.0]],
                                  [[0.0, 0.0], [0.0, 1.0]]])
def test_mass_not_symmetric_positive_definite(tmp_path, mass):
    spec = copy.deepcopy(BASES[1])
    spec["mass"] = mass
    refused(write(tmp_path, spec), "mass")


@pytest.mark.parametrize("law", ["stribeck", "Coulomb", ""])
def test_unknown_law(tmp_path, law):
    spec = copy.deepcopy(BASES[0])
    spec["contact"][0]["friction"]["law"] = law
    message = refused(write(tmp_path, spec), "contact.0.friction.law", "coulomb", "exponential")
    assert "unknown" in message


@pytest.mark.parametrize("normal_force", [0.0, -1.0, -1e-300])
def test_normal_force_must_be_positive(tmp_path, normal_force):
    spec = copy.deepcopy(BASES[2])
    spec["contact"][1]["normal_force"] = normal_force
    refused(write(tmp_path, spec), "contact.1.normal_force", "> 0")


@pytest.mark.parametrize("where, key", [(None, k) for k in ("dofs", "mass", "stiffness", "contact")]
                         + [(("contact", 0), k) for k in ("tangent", "normal_force", "friction")]
                         + [(("contact", 0, "friction"), k) for k in ("mu_k", "delta_mu", "alpha")])
def test_missing_key(tmp_path, where, key):
    spec = copy.deepcopy(BASES[0])
    node = spec if where is None else spec[where[0]][where[1]] if len(where) == 2 else spec["contact"][0]["friction"]
    del node[key]
    message = refused(write(tmp_path, spec), key)
    assert "missing" in message


def test_damping_left_out_is_zero():
    spec = copy.deepcopy(BASES[1])
    del spec["damping"]
    model = model_from_spec(spec)
    assert np.array_equal(model.damping, np.zeros((model.n, model.n)))


@pytest.mark.parametrize("value", ["one", "1.0 +", True, [1.0], {"a": 1.0}, math.nan, math.inf])
def test_non_number(tmp_path, value):
    """Strings are expressions of [parameters]: one that is not valid is refused like a non-number."""
    spec = copy.deepcopy(BASES[0])
    spec["stiffness"][0][0] = value
    refused(write(tmp_path, spec), "stiffness[0][0]")


@pytest.mark.parametrize("where", ["top", "contact", "friction"])
def test_unknown_key(tmp_path, where):
    spec = copy.deepcopy(BASES[0])
    node = {"top": spec, "contact": spec["contact"][0], "friction": spec["contact"][0]["friction"]}[where]
    node["stifness"] = 1.0
    message = refused(write(tmp_path, spec), "stifness")
    assert "unknown" in message and "valid keys" in message


def test_file_errors_name_the_file(tmp_path):
    missing = tmp_path / "nope.toml"
    message = refused(missing, "nope.toml", "does not exist")
    bad = tmp_path / "bad.toml"
    bad.write_text("dofs = [\"x\"\nmass = 1")
    message = refused(bad, "bad.toml", "not valid TOML")
    assert message.startswith(str(bad))


def test_set_paths_are_checked():
    model = load_model("popp-stelter")
    for path, value, named in [("mass.9.0", 1.0, "mass.9.0"), ("bogus", 1.0, "bogus"), ("mass", 1.0, "mass"),
                               ("contact.0.friction.law", "stribeck", "law"), ("mass.0.0", "abc", "mass[0][0]"),
                               ("contact.1.normal_force", 0.0, "normal_force"), ("mass.x1.x1", -2.0, "mass")]:
        with pytest.raises(ModelError) as info:
            model.replace(**{path: value})
        assert "\n" not in str(info.value) and named in str(info.value)


# --------------------------------------------------------------------------- properties
def cannot_be_an_expression(text):
    """Whether ``text`` has no number, ``pi`` or name a valid expression needs (these files have no
    [parameters]): no digit and no letter after Unicode normalisation, which Python applies to names."""
    text = unicodedata.normalize("NFKC", text)
    return not any(ch.isdigit() or ch.isalpha() or ch == "_" for ch in text)


#: Values that are not a finite number (those a TOML file can hold); strings that could be an
#: expression are left out.
NOT_A_NUMBER = st.one_of(st.text(max_size=5).filter(cannot_be_an_expression), st.booleans(),
                         st.lists(st.floats(allow_nan=False), max_size=2),
                         st.dictionaries(st.text("abc", min_size=1, max_size=3), st.integers(-5, 5), max_size=2),
                         st.sampled_from([math.nan, math.inf, -math.inf]))

SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


@SETTINGS
@given(base=st.sampled_from(BASES), data=st.data(), value=NOT_A_NUMBER)
def test_any_number_replaced_by_a_non_number_is_refused(tmp_path, base, data, value):
    spec = copy.deepcopy(base)
    path = data.draw(st.sampled_from(leaves(spec)))
    set_at(spec, path, value)
    refused(write(tmp_path, spec), last_key(path))


@SETTINGS
@given(base=st.sampled_from(BASES), data=st.data(), value=st.floats(max_value=-1e-300, allow_nan=False))
def test_any_negative_friction_coefficient_or_normal_force_is_refused(tmp_path, base, data, value):
    spec = copy.deepcopy(base)
    c = data.draw(st.integers(0, len(spec["contact"]) - 1))
    key = data.draw(st.sampled_from(["normal_force", "mu_k", "delta_mu", "alpha", "mu_v"]))
    node = spec["contact"][c] if key == "normal_force" else spec["contact"][c]["friction"]
    node[key] = value
    refused(write(tmp_path, spec), key)


@SETTINGS
@given(base=st.sampled_from(BASES), data=st.data(),
       key=st.text("abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=12))
def test_any_unknown_key_is_refused(tmp_path, base, data, key):
    spec = copy.deepcopy(base)
    node, _ = data.draw(st.sampled_from(tables(spec)))
    if key in node or key in TOP_KEYS + CONTACT_KEYS + ("law", "mu_k", "delta_mu", "alpha", "mu_v"):
        return
    node[key] = 1.0
    refused(write(tmp_path, spec), key, "unknown")


@SETTINGS
@given(base=st.sampled_from(BASES), data=st.data())
def test_any_matrix_with_a_wrong_shape_is_refused(tmp_path, base, data):
    spec = copy.deepcopy(base)
    choices = [(spec, k) for k in ("mass", "damping", "stiffness")] + [(c, "tangent") for c in spec["contact"]]
    node, key = data.draw(st.sampled_from(choices))
    matrix = node[key]
    row = data.draw(st.integers(0, len(matrix) - 1))
    if data.draw(st.booleans()):
        matrix[row] = matrix[row] + [0.0]   # one number too many in a row
    elif len(matrix[row]) > 1:
        matrix[row] = matrix[row][:-1]      # one too few
    else:
        matrix.append(list(matrix[row]))    # an extra row of a 1×1 matrix
    # a tangent with one more row is a 2-D contact whose drive now has one entry too few
    refused(write(tmp_path, spec), any_of=(key, "drive") if key == "tangent" else (key,))


@SETTINGS
@given(n=st.integers(1, 4), data=st.data())
def test_any_mass_that_is_not_positive_definite_is_refused(tmp_path, n, data):
    """Symmetric M = Q diag(λ) Qᵀ with at least one eigenvalue ≤ 0."""
    lam = np.array(data.draw(st.lists(st.floats(0.1, 10.0), min_size=n, max_size=n)))
    lam[data.draw(st.integers(0, n - 1))] = data.draw(st.floats(-10.0, 0.0))
    q, _ = np.linalg.qr(np.array(data.draw(st.lists(st.floats(-1, 1), min_size=n * n, max_size=n * n))).reshape(n, n)
                        + 3.0 * np.eye(n))
    mass = q @ np.diag(lam) @ q.T
    mass = 0.5 * (mass + mass.T)
    spec = {"dofs": [f"q{i}" for i in range(n)], "mass": mass.tolist(), "damping": np.zeros((n, n)).tolist(),
            "stiffness": np.eye(n).tolist(),
            "contact": [{"tangent": [[1.0] + [0.0] * (n - 1)], "drive": [1.0], "normal_force": 1.0,
                         "friction": {"law": "coulomb", "mu_k": 0.2, "delta_mu": 0.1}}]}
    if np.linalg.eigvalsh(mass).min() > 0.0:  # round-off of a zero eigenvalue: not a counterexample
        return
    refused(write(tmp_path, spec), "mass", "positive definite")


# --------------------------------------------------------------------------- found by the property tests
def test_integer_too_large_for_a_float_is_refused(tmp_path):
    spec = copy.deepcopy(BASES[0])
    spec["stiffness"][0][0] = 10 ** 400
    refused(write(tmp_path, spec), "stiffness")


@pytest.mark.parametrize("law", [["coulomb"], {"name": "coulomb"}])
def test_law_that_is_not_a_name_is_refused(tmp_path, law):
    spec = copy.deepcopy(BASES[0])
    spec["contact"][0]["friction"]["law"] = law
    refused(write(tmp_path, spec), "law")


def test_errors_are_stickslip_errors():
    """What the CLI turns into one line and exit code 2."""
    assert issubclass(ModelFileError, StickSlipError) and issubclass(ModelFileError, ValueError)
    with pytest.raises(StickSlipError):
        model_from_spec({"dofs": ["x"]})


# --------------------------------------------------------------------------- input defects
def test_replace_on_a_model_without_parameters_says_how_to_give_it_some():

    model = FrictionModel(name="hand", dofs=("x",), mass=[[1.0]], damping=[[0.1]], stiffness=[[1.0]], force=[0.0],
                          contacts=(Contact(dim=1, friction=FrictionLaw("coulomb", 0.3, 0.1), normal_force=1.0,
                                            tangent=[[1.0]], drive=[0.5]),))
    with pytest.raises(ModelError) as info:
        model.replace(**{"contact.0.drive": 0.3})
    message = str(info.value)
    assert "valid names" not in message and "no named parameters" in message
    assert "builder=" in message and "parameters=" in message and "model file" in message


@pytest.mark.parametrize("dofs, words", [
    (["x", "dx"], "dofs x and dx both have the state name dx"),
    (["x=1"], "dofs[0] = 'x=1' is not a valid name"), (["a,b"], "is not a valid name"), (["x y"], "not a valid name"),
    (["x.y"], "not a valid name"), (["x\t"], "not a valid name"), (["1x"], "not starting with a digit"),
    (["φ"], "ASCII letters, digits and _"), (["x", "x-1"], "dofs[1] = 'x-1'"),
])
def test_dof_names_that_collide_or_cannot_be_reached_are_refused(tmp_path, dofs, words):
    spec = copy.deepcopy(BASES[0]) if len(dofs) == 1 else copy.deepcopy(BASES[1])
    spec["dofs"] = dofs
    spec.pop("units", None)
    spec.pop("observe", None)
    message = refused(write(tmp_path, spec), "dof")
    assert words in message and ("ASCII letters, digits and _" in message or "state name" in message), message


def test_python_models_refuse_colliding_state_names():

    base = load_model("popp-stelter")
    with pytest.raises(ModelError, match="dofs x and dx both have the state name dx"):
        FrictionModel(name="m", dofs=("x", "dx"), mass=base.mass, damping=base.damping, stiffness=base.stiffness,
                      force=base.force, contacts=base.contacts)


@pytest.mark.parametrize("path, value", [("mass.0.0", 1e-320), ("mass.1.1", 5e-324), ("mass.0.0", 1e-14)])
def test_mass_singular_to_working_precision_is_refused_in_one_line(path, value):
    with pytest.raises(ModelError) as info:
        load_model("popp-stelter").replace(**{path: value})
    message = str(info.value)
    assert "\n" not in message and "singular or not positive definite to working precision" in message


def test_tiny_mass_of_a_file_is_refused_and_a_well_conditioned_one_is_not(tmp_path):
    spec = copy.deepcopy(BASES[0])
    spec["mass"] = [[5e-324]]
    refused(write(tmp_path, spec), "mass", "working precision")
    spec = copy.deepcopy(BASES[1])
    spec["mass"] = [[1.0, 0.0], [0.0, 1e-12]]    # condition number 1e12: below the limit
    assert load_model_file(write(tmp_path, spec)).mass[1, 1] == 1e-12
    spec["mass"] = [[1.0, 0.0], [0.0, 1e-14]]    # 1e14: above it
    refused(write(tmp_path, spec), "mass", "working precision")


def test_set_a_subnormal_mass_on_the_command_line_is_one_line():
    res = CliRunner().invoke(app, ["stability", "--model", "popp-stelter", "--set", "mass.0.0=1e-320"])
    assert res.exit_code == 2 and "Traceback" not in res.output, res.output
    assert len(res.output.strip().splitlines()) == 1 and "working precision" in res.output


def nested(depth, leaf=1.0):
    value = leaf
    for _ in range(depth):
        value = [value]
    return value


def test_deeply_nested_value_is_one_line(tmp_path):
    path = tmp_path / "deep.toml"
    path.write_text("mass = " + "[" * 1000 + "1.0" + "]" * 1000 + "\n")  # TOML's reader recurses per level
    message = refused(path, "deep.toml", "nested too deeply")
    assert len(message) < 300
    for depth in (300, 1000, 3000):
        spec = copy.deepcopy(BASES[0])
        spec["mass"] = nested(depth)
        with pytest.raises(ModelFileError) as info:
            model_from_spec(spec)
        assert len(str(info.value)) < 300 and "mass[0][0]" in str(info.value)


@pytest.mark.parametrize("where, text", [
    ("name", "\x1b[31mred"), ("description", "one\ntwo"), ("description", "tab\there"),
    ("description", "right-to-left \u202e override"), ("contact.0.name", "\x1b[2J"), ("units", None),
])
def test_control_characters_in_names_and_descriptions_are_refused(tmp_path, where, text):
    spec = copy.deepcopy(BASES[0])
    if where == "contact.0.name":
        spec["contact"][0]["name"] = text
    elif where == "units":
        spec["dofs"] = ["x\x1b"]
        spec.pop("units", None)
        spec.pop("observe", None)
        where = "dofs[0]"
    else:
        spec[where] = text
    message = refused(write(tmp_path, spec), where)
    assert "\x1b" not in message and "\t" not in message and "\u202e" not in message


def test_python_models_refuse_control_characters():

    base = load_model("belt")
    for changes in ({"name": "a\x1bb"}, {"description": "x\r\ny"},
                    {"contacts": (Contact(dim=1, friction=base.contacts[0].friction, normal_force=1.0,
                                          tangent=[[1.0]], drive=[1.0], name="c\n"),)}):
        fields = dict(name="m", dofs=("x",), mass=base.mass, damping=base.damping, stiffness=base.stiffness,
                      force=base.force, contacts=base.contacts) | changes
        with pytest.raises(ModelError, match="control character"):
            FrictionModel(**fields)


def test_the_cli_prints_no_escape_sequence_from_a_model_file(tmp_path):
    spec = copy.deepcopy(BASES[0])
    spec["description"] = "\x1b[31mred\x1b[0m"
    res = CliRunner().invoke(app, ["models", str(write(tmp_path, spec))])
    assert res.exit_code == 2 and "\x1b" not in res.output and len(res.output.strip().splitlines()) == 1


def test_units_name_dofs_and_parameters_and_refuse_anything_else():
    spec = copy.deepcopy(BASES[0])  # the belt
    spec["parameters"] = {"V": 1.0}
    spec["contact"][0]["drive"] = ["V"]
    spec["units"] = {"x": "m", "V": "m/s"}
    assert model_from_spec(spec).units == {"x": "m", "V": "m/s"}
    spec["units"]["v"] = "m/s"
    with pytest.raises(ModelFileError, match="units: 'v' is neither a dof nor a named parameter"):
        model_from_spec(spec)


@pytest.mark.parametrize("normal, words", [
    ({"law": "rigid", "damping": 0.0}, ("contact.0.normal", "rigid contact has no stiffness or damping")),
    ({"law": "rigid", "stiffness": 10.0, "restitution": 0.5}, ("rigid contact has no stiffness or damping",)),
    ({}, ("contact.0.normal.stiffness is missing",)),
    ({"law": "compliant", "damping": 0.1}, ("contact.0.normal.stiffness is missing",)),
    ({"stiffness": 40.0, "restitution": 0.0}, ("restitution is a rigid contact's",)),
])
def test_a_normal_table_states_its_own_laws_numbers(tmp_path, normal, words):
    """docs/contacts.md: a rigid contact's table refuses stiffness and damping (given at all, not only
    nonzero), a compliant one's needs its stiffness and refuses a restitution."""
    spec = copy.deepcopy(dict(load_model("impact-oscillator").spec))
    spec["contact"][0]["normal"] = normal
    refused(write(tmp_path, spec), *words)
