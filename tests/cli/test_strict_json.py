"""Every ``--json`` output is strict JSON: one encoder (``stickslip.cli._json``) writes undefined
values as null with a reason beside them, and refuses NaN and Infinity."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import stickslip.cli
from stickslip.cli import app
from stickslip.cli._json import strict_json

runner = CliRunner()


def strict_loads(text: str):
    """json.loads that refuses NaN, Infinity and -Infinity (what strict parsers do)."""
    def refuse(constant):
        raise ValueError(f"not JSON: {constant}")
    return json.loads(text, parse_constant=refuse)


def test_the_encoder_writes_null_with_a_reason_and_keeps_a_producers_reason():
    text = strict_json({"a": math.nan, "b": np.float64(-np.inf), "c": [1.0, math.nan], "d": {"e": math.inf},
                        "f": None, "f_reason": "told", "g": np.arange(2), "h": math.nan, "h_reason": "given"})
    assert strict_loads(text) == {
        "a": None, "a_reason": "not a number (undefined)", "b": None, "b_reason": "-infinite",
        "c": [1.0, None], "c_reason": "null entries: not a number (undefined)",
        "d": {"e": None, "e_reason": "infinite"}, "f": None, "f_reason": "told", "g": [0, 1],
        "h": None, "h_reason": "given"}


def test_no_command_writes_json_but_through_the_encoder():
    cli = Path(stickslip.cli.__file__).parent
    direct = [p.name for p in cli.glob("*.py") if p.name != "_json.py" and re.search(r"json\.dumps?\(", p.read_text())]
    assert direct == []


@pytest.fixture
def few_kept_states(monkeypatch):
    """A run keeps the states of its last 100 transitions only (10^5 in a real run)."""
    monkeypatch.setattr("stickslip.integrate.runner.KEEP_TRANSITION_STATES", 100)


ELASTIC = ["simulate", "--model", "impact-oscillator", "--set", "contact.0.normal.restitution=1", "--ic", "y=0.1",
           "--t-end", "200", "--sample-rate", "10", "--rtol", "1e-11", "--atol", "1e-13", "--json", "--no-plot"]


def test_max_impact_speed_is_the_closed_form_where_the_states_are_kept(tmp_path):
    """Dropped from rest at y0 = 0.1 with e = 1, every landing has the first one's speed
    ω √((y0 + d)² − d²) (docs/models/impact-oscillator.md)."""
    res = runner.invoke(app, [*ELASTIC, "--out", str(tmp_path / "a.nc")])
    assert res.exit_code == 0, res.output
    summary = strict_loads(res.stdout.strip().splitlines()[-1])
    assert summary["impacts"] == 300
    assert summary["max_impact_speed"] == pytest.approx(2 * math.pi * math.sqrt(0.2 ** 2 - 0.1 ** 2), rel=1e-8)


def test_max_impact_speed_of_impacts_whose_states_were_not_kept_is_still_the_closed_form(tmp_path, few_kept_states):
    """The run tallies its steady window's impacts as it goes, from every impact's state: the
    maximum stays exact where the transition log keeps only the last 100 states."""
    res = runner.invoke(app, [*ELASTIC, "--out", str(tmp_path / "a.nc")])
    assert res.exit_code == 0, res.output
    summary = strict_loads(res.stdout.strip().splitlines()[-1])
    assert summary["impacts"] == 300 and "max_impact_speed_reason" not in summary
    assert summary["max_impact_speed"] == pytest.approx(2 * math.pi * math.sqrt(0.2 ** 2 - 0.1 ** 2), rel=1e-8)
    run = stickslip.load_trajectory(tmp_path / "a.nc")
    assert np.isnan(run.transitions.state[:-100]).all()  # the states were dropped indeed
    # a window other than the run's own is taken from the kept states: unknown, with the reason
    other = run.steady_state(run.steady_from + 1.0)
    assert math.isnan(other.max_impact_speed) and "were not kept" in other.max_impact_speed_reason
