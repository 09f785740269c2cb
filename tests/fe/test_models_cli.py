"""``stickslip models FILE`` on finite-element model files: counts with a short head and tail instead
of every name, runs of alike contacts on one line, per-node parameters as one row; ``--json``
complete and strict."""

import json
import types

from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.cli.models import contact_lines, parameter_rows
from stickslip.model.friction import FrictionLaw
from stickslip.model.library import load_model

from .fe_models import pad_on_belt


def run(*args):
    return CliRunner().invoke(app, ["models", *args])


def test_a_large_model_is_shown_by_counts(tmp_path):
    path = pad_on_belt(40, 6).write(tmp_path / "pad")  # 492 dofs, 41 contact nodes
    result = run(str(path))
    assert result.exit_code == 0, result.output
    text = " ".join(result.output.split())  # rich wraps long lines
    assert "dofs: 492 (u0, u1, u2, u3, u4, …, u489, u490, u491); states: 984" in text
    assert "free DOFs: all; observed: u0" in text
    assert "contacts 0–40 (pad_1 … pad_41): 1-D slip, law coulomb, mu_k 0.3, delta_mu 0.1" in text
    assert "contact_set.pad.nodes.*.gap (41 paths)" in text and "-1e-06" in text
    assert "u250" not in text and "pad_20" not in text
    assert len(result.output.splitlines()) < 40


def _not_json(constant):
    raise AssertionError(f"{constant} is not strict JSON")


def test_json_stays_complete(tmp_path):
    path = pad_on_belt(40, 6).write(tmp_path / "pad")
    result = run(str(path), "--json")
    assert result.exit_code == 0, result.output
    d = json.loads(result.output, parse_constant=_not_json)
    model = load_model(str(path))
    assert d["dofs"] == list(model.dofs) and d["states"] == list(model.state_names)
    assert d["counts"] == {"dofs": 492, "states": 984, "contacts": 41, "parameters": len(model.parameters)}
    assert len(d["contacts"]) == 41 and d["parameters"] == dict(model.parameters)
    assert "contact_set.pad.nodes.41.gap" in d["parameters"]
    assert d["natural_frequencies_hz"] is None  # every one needs the dense M⁻¹K
    assert len(result.output) < 100 * 492  # of the order of its names, nothing quadratic


def test_runs_of_contacts_and_groups_of_parameters():
    coulomb, other = FrictionLaw("coulomb", mu_k=0.3, delta_mu=0.0), FrictionLaw("coulomb", mu_k=0.5, delta_mu=0.0)
    contacts = [types.SimpleNamespace(dim=1, friction=law, frictionless=False) for law in [coulomb] * 3 + [other] + [coulomb] * 2]
    system = types.SimpleNamespace(contacts=contacts, contact_names=tuple(f"c{k}" for k in range(6)))
    assert contact_lines(system) == ["contacts 0–2 (c0 … c2): 1-D slip, law coulomb, mu_k 0.3, delta_mu 0",
                                     "contact 3 (c3): 1-D slip, law coulomb, mu_k 0.5, delta_mu 0",
                                     "contacts 4–5 (c4 … c5): 1-D slip, law coulomb, mu_k 0.3, delta_mu 0"]
    parameters = {"k1": 2.0, **{f"force.u{k}": float(k) for k in range(10)}, "k2": 3.0,
                  **{f"law.{k}": "coulomb" if k % 2 else "exponential" for k in range(9)}}
    assert parameter_rows(parameters) == [("k1", "2"), ("k2", "3"), ("force.u* (10 paths)", "0 … 9"),
                                          ("law.* (9 paths)", "coulomb, exponential")]
