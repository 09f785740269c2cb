"""Named parameters and expressions in model files: the numbers they give, ``replace``/``--set`` by
name, results that rebuild the same model, and one-line refusals naming the key."""

import copy
import json

import numpy as np
import pytest
import tomli_w
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.model.library import describe_system, load_model, system_from_description
from stickslip.model.model_file import ModelFileError, model_from_spec
from stickslip.model.system_model import ModelError
from stickslip.stability.maps import stability_map

#: Two masses on one belt (the library's popp-stelter structure) with named parameters.
PARAMETRIC = {
    "name": "two-mass", "dofs": ["x1", "x2"],
    "parameters": {"V": 0.3, "k1": 1.0, "k2": 2.0, "kc": 1.0, "m": 1.5},
    "mass": [["m", 0.0], [0.0, "m / 2"]],
    "damping": [[0.05, 0.0], [0.0, 0.05]],
    "stiffness": [["k1 + kc", "-kc"], ["-kc", "k2 + kc"]],
    "contact": [{"tangent": [[1.0, 0.0]], "drive": ["V"], "normal_force": 1.0,
                 "friction": {"law": "exponential", "mu_k": 0.5, "delta_mu": 0.5, "alpha": 2.0}},
                {"tangent": [[0.0, 1.0]], "drive": ["V"], "normal_force": "2 * sqrt(kc)",
                 "friction": {"law": "exponential", "mu_k": 0.5, "delta_mu": 0.5, "alpha": "exp(0) + 1"}}],
}


def numeric(V=0.3, k1=1.0, k2=2.0, kc=1.0, m=1.5):
    """The same model with every number written out (the arithmetic done here, in the test)."""
    spec = copy.deepcopy(PARAMETRIC)
    del spec["parameters"]
    spec["mass"] = [[m, 0.0], [0.0, m / 2]]
    spec["stiffness"] = [[k1 + kc, -kc], [-kc, k2 + kc]]
    for contact in spec["contact"]:
        contact["drive"] = [V]
    spec["contact"][1]["normal_force"] = 2.0 * kc ** 0.5
    spec["contact"][1]["friction"]["alpha"] = 2.0
    return model_from_spec(spec, name="two-mass")


def same_numbers(a, b):
    """Bit for bit: the matrices, the contacts and the compiled model's data array."""
    for key in ("mass", "damping", "stiffness", "force"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key
    for ca, cb in zip(a.contacts, b.contacts, strict=True):
        assert np.array_equal(ca.tangent, cb.tangent) and np.array_equal(ca.drive, cb.drive)
        assert ca.normal_force == cb.normal_force and ca.friction == cb.friction
    assert a.slip_band == b.slip_band
    assert a.data.m.tobytes() == b.data.m.tobytes()


def test_expressions_give_the_numbers_written_out():
    same_numbers(model_from_spec(PARAMETRIC), numeric())


def test_a_named_parameter_moves_every_number_that_uses_it():
    model = model_from_spec(PARAMETRIC)
    moved = model.replace(V=0.7)
    same_numbers(moved, numeric(V=0.7))
    # the same as setting both drives of the numeric model
    same_numbers(moved, numeric().replace(**{"contact.0.drive": 0.7, "contact.1.drive": 0.7}))
    same_numbers(model.replace(kc=2.25, m=3.0), numeric(kc=2.25, m=3.0))
    same_numbers(model.replace(**{"parameters.k1": 4.0}), numeric(k1=4.0))  # the alias by table
    assert moved.parameters["V"] == 0.7 and model.parameters["V"] == 0.3   # the first model is unchanged


def test_parameters_list_the_named_ones_first_and_expressions_as_written():
    params = model_from_spec(PARAMETRIC).parameters
    assert list(params)[:5] == ["V", "k1", "k2", "kc", "m"]
    assert params["stiffness.0.0"] == "k1 + kc" and params["contact.1.drive.0"] == "V"
    assert params["damping.0.0"] == 0.05 and params["contact.0.friction.law"] == "exponential"


def test_a_path_into_an_expression_is_refused_in_one_line():
    model = model_from_spec(PARAMETRIC)
    for path in ("contact.0.drive", "contact.0.drive.0", "stiffness.x1.x2"):
        with pytest.raises(ModelFileError) as info:
            model.replace(**{path: 0.5})
        message = str(info.value)
        assert "\n" not in message and "is the expression" in message and "set the parameters it uses" in message
    assert "(V)" in str(pytest.raises(ModelFileError, model.replace, **{"contact.0.drive": 0.5}).value)
    # a number entry may be set, and given an expression
    same_numbers(model.replace(**{"damping.0.0": 0.1}).replace(**{"damping.0.0": "V / 3"}),
                 model.replace(**{"damping.0.0": 0.3 / 3}))


def test_replace_leaves_the_spec_of_the_model_and_the_callers_dict_alone():
    spec = copy.deepcopy(PARAMETRIC)
    model = model_from_spec(spec)
    before = copy.deepcopy(model.spec)
    moved = model.replace(V=0.5, **{"damping.1.1": 0.2, "contact.1.friction.law": "coulomb"})
    assert model.spec == before and spec == PARAMETRIC
    assert moved.spec["parameters"]["V"] == 0.5 and moved.spec["damping"][1][1] == 0.2
    assert moved.spec["contact"][1]["friction"]["law"] == "coulomb" and moved.contacts[1].friction.law == "coulomb"
    assert moved.spec["contact"][0] is model.spec["contact"][0]  # what did not change is shared, not copied


@pytest.mark.parametrize("changes", [{}, {"V": 0.55}, {"kc": 0.5, "contact.0.friction.mu_k": 0.25}])
def test_a_result_rebuilds_the_same_model(changes):
    """describe_system → JSON (as result files store it) → system_from_description."""
    model = model_from_spec(PARAMETRIC, source="file:two-mass.toml", name="two-mass").replace(**changes)
    text = json.dumps(describe_system(model))
    again = system_from_description(json.loads(text))
    same_numbers(again, model)
    assert again.parameters == model.parameters and again.spec == model.spec and again.name == model.name
    same_numbers(again.replace(V=0.9), model.replace(V=0.9))


def expression_error(spec):
    with pytest.raises(ModelFileError) as info:
        model_from_spec(spec)
    message = str(info.value)
    assert "\n" not in message, message
    return message


def test_a_bad_expression_names_the_key_and_the_grammar():
    spec = copy.deepcopy(PARAMETRIC)
    spec["contact"][0]["drive"] = ["V*"]
    assert expression_error(spec).startswith(
        'contact.0.drive[0] = "V*" is not a valid expression: syntax error')
    assert expression_error(spec).endswith(
        "; use + - * / ** ( ) sqrt exp sin cos pi and the names in [parameters]: V, k1, k2, kc, m")
    spec["contact"][0]["drive"] = ["W"]
    assert "unknown name 'W'" in expression_error(spec)
    spec = copy.deepcopy(PARAMETRIC)
    del spec["parameters"]
    spec["mass"][0][0] = "m"
    assert "names in [parameters]: (none: add a [parameters] table" in expression_error(spec)


@pytest.mark.parametrize("edit, words", [
    (lambda s: s["parameters"].update(V=float("inf")), "parameters.V = inf is not finite"),
    (lambda s: s["parameters"].update(V=float("nan")), "parameters.V = nan is not finite"),
    (lambda s: s["parameters"].update(V="2 * k1"), 'parameters.V = "2 * k1" is not a number'),
    (lambda s: s["parameters"].update(V=True), "parameters.V = True is not a number"),
    (lambda s: s["parameters"].update(V=[1.0]), "parameters.V = [1.0] is not a number"),
    (lambda s: s.update(parameters=[1.0]), "parameters = [1.0] must be a table"),
    (lambda s: s["parameters"].update(pi=1.0), "'pi' is reserved"),
    (lambda s: s["parameters"].update(sqrt=1.0), "'sqrt' is reserved"),
    (lambda s: s["parameters"].update(mass=1.0), "'mass' is reserved"),
    (lambda s: s["parameters"].update(ic=1.0), "'ic' is reserved"),
    (lambda s: s["parameters"].update(perturb_x1=1.0), "'perturb_x1' is reserved"),
    (lambda s: s["parameters"].update({"lambda": 1.0}), "'lambda' is reserved"),
    (lambda s: s["parameters"].update({"a b": 1.0}),
     "'a b' is not a valid name; give a name of ASCII letters, digits and _"),
    (lambda s: s["parameters"].update({"k.1": 1.0}), "'k.1' is not a valid name"),
    (lambda s: s["parameters"].update({"1k": 1.0}), "not starting with a digit"),
    (lambda s: s["contact"][0].update(drive=["1 / (V - 0.3)"]),
     'contact.0.drive[0] = "1 / (V - 0.3)" cannot be evaluated with V = 0.3: it divides by zero'),
    (lambda s: s["contact"][0].update(drive=["sqrt(-V)"]), "outside its domain"),
    (lambda s: s["contact"][0].update(drive=["exp(1e4 * V)"]), "overflows"),
    (lambda s: s["contact"][0].update(drive=["V\n+ 1"]), "contact.0.drive[0] contains the control character U+000A"),
    (lambda s: s.update(mass=[["-m", 0.0], [0.0, "m"]]), "mass is not positive definite"),
])
def test_bad_parameters_are_refused_in_one_line(edit, words):
    spec = copy.deepcopy(PARAMETRIC)
    edit(spec)
    message = expression_error(spec) if "positive definite" not in words else str(
        pytest.raises(ModelError, model_from_spec, spec).value)
    assert words in message, message


def test_normal_force_from_an_expression_must_be_positive():
    with pytest.raises(ModelFileError, match=r"contact.1.normal_force = 0 must be > 0"):
        model_from_spec(PARAMETRIC).replace(kc=0.0)


@pytest.mark.parametrize("changes, words", [
    ({"V": "fast"}, 'parameter V = "fast" is not a number'),
    ({"V": float("inf")}, "parameters.V = inf is not finite"),
    ({"W": 1.0}, "no key 'W' under the model and no parameter of that name; named parameters: V, k1, k2, kc, m; "
                 "keys there: name, dofs"),
    ({"kc": 0.0}, "contact.1.normal_force = 0 must be > 0"),
    ({"m": 1e-320}, "mass is singular or not positive definite to working precision"),
])
def test_replace_refuses_bad_values_in_one_line(changes, words):
    with pytest.raises(ModelError) as info:
        model_from_spec(PARAMETRIC).replace(**changes)
    assert "\n" not in str(info.value) and words in str(info.value), str(info.value)


def test_a_file_without_parameters_says_how_to_name_one():
    with pytest.raises(ModelFileError, match=r"named parameters: none \(name one in a \[parameters\] table\)"):
        load_model("belt").replace(V=0.3)


# --------------------------------------------------------------------------- the command line
runner = CliRunner()


def steady_sliding(V=0.3, k1=1.0, k2=2.0, kc=1.0):
    """Equilibrium of steady sliding of the two masses, K q = μ(V) [N0, N1] (both slip at −V)."""
    mu = 0.5 + 0.5 * np.exp(-2.0 * V)
    K = np.array([[k1 + kc, -kc], [-kc, k2 + kc]])
    return np.linalg.solve(K, mu * np.array([1.0, 2.0 * np.sqrt(kc)]))


def equilibrium(*args):
    res = runner.invoke(app, ["stability", *args, "--json"])
    assert res.exit_code == 0, res.output
    found = json.loads(res.stdout.strip().splitlines()[-1])["equilibrium"]
    return np.array([found["x1"], found["x2"]])


def test_set_a_named_parameter_from_the_command_line(tmp_path):
    path = tmp_path / "two-mass.toml"
    path.write_text(tomli_w.dumps(PARAMETRIC))
    res = runner.invoke(app, ["models", str(path), "--json"])
    assert res.exit_code == 0, res.output
    described = json.loads(res.stdout)
    assert list(described["parameters"])[:2] == ["V", "k1"] and described["parameters"]["stiffness.0.0"] == "k1 + kc"
    assert equilibrium("--model", str(path), "--set", "V=0.7") == pytest.approx(steady_sliding(V=0.7), rel=1e-12)
    config = tmp_path / "config.toml"
    config.write_text("[parameters]\nV = 0.9\nkc = 2.0\n")
    assert equilibrium("--model", str(path), "--config", str(config)) == pytest.approx(
        steady_sliding(V=0.9, kc=2.0), rel=1e-12)
    res = runner.invoke(app, ["stability", "--model", str(path), "--set", "contact.0.drive=0.7"])
    assert res.exit_code == 2 and len(res.output.strip().splitlines()) == 1, res.output
    assert 'is the expression "V" of [parameters]' in res.output


def test_stability_map_over_a_named_parameter_finds_the_closed_form_boundary():
    """Equal masses, dampings c and normal forces: the linearised damping is (c − e^{−2V}) I for
    every kc (μ' = −Δμ α e^{−αV}), so steady sliding turns stable at V = ln(1/c)/2 for any kc."""
    spec = copy.deepcopy(PARAMETRIC)
    spec["mass"] = [[1.0, 0.0], [0.0, 1.0]]
    spec["contact"][1]["normal_force"] = 1.0
    spec["contact"][1]["friction"]["alpha"] = 2.0
    smap = stability_map(model_from_spec(spec), np.linspace(0.5, 2.0, 4), np.linspace(0.5, 3.0, 11), axes=("kc", "V"))
    assert smap.boundary[0][:, 0] == pytest.approx(np.full(4, np.log(1.0 / 0.05) / 2.0), rel=1e-9)
