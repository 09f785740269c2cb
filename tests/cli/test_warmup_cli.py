"""``stickslip warmup``: the kernels each command needs, compiled ahead and then found in the cache."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from stickslip.cli import app

runner = CliRunner()


def test_stages_of_one_model_as_json():
    result = runner.invoke(app, ["warmup", "--model", "belt", "--model", "x", "--methods", "event,aeom", "--json"])
    assert result.exit_code == 0, result.output
    report = json.loads(result.stdout)
    stages = ["simulate (event)", "stability", "orbits (variational equations)"]
    assert [row["stage"] for row in report if row["model"] == "belt"] == stages  # the fixed-step methods: plates only
    assert [row["stage"] for row in report if row["model"] == "x"] == stages[:1] + ["simulate (aeom)"] + stages[1:]
    assert all(row["outcome"] == "ready" and row["seconds"] >= 0.0 for row in report)


def test_a_model_whose_contact_opens():
    result = runner.invoke(app, ["warmup", "--model", "hoffmann", "--json"])
    assert result.exit_code == 0, result.output
    assert [row["outcome"] for row in json.loads(result.stdout)] == ["ready"] * 3


OPEN_AT_REST = Path(__file__).parents[1] / "contacts" / "open_at_rest.toml"


def test_a_stage_that_fails_is_reported_and_the_others_run():
    # a contact open at rest: steady sliding has an open contact, which the stability stage
    # reports as its outcome; simulate and the flow map still compile
    result = runner.invoke(app, ["warmup", "--model", str(OPEN_AT_REST), "--json"])
    assert result.exit_code == 0, result.output
    outcome = {row["stage"]: row["outcome"] for row in json.loads(result.stdout)}
    assert outcome["simulate (event)"] == outcome["orbits (variational equations)"] == "ready"
    assert outcome["stability"].startswith("ran into: ") and "open" in outcome["stability"]


@pytest.mark.parametrize("methods", ["rk45", "", "event,,bogus"])
def test_unknown_method_is_one_line(methods):
    result = runner.invoke(app, ["warmup", "--methods", methods])
    assert result.exit_code == 2 and result.output.count("\n") == 1 and "event, aeom, naeom" in result.output


@pytest.mark.slow
def test_a_later_process_compiles_nothing(tmp_path):
    """Against numba's own compile events, in a fresh cache: after warmup, a new process running
    simulate, stability and a flow map of the same model loads every kernel from the cache."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    subprocess.run([sys.executable, "-c", "from stickslip.cli import app; app()", "warmup", "--model", "belt"],
                   env=env, check=True, capture_output=True, timeout=600)
    code = ("from numba.core import event\n"
            "import stickslip\n"
            "seen = []\n"
            "class L(event.Listener):\n"
            "    def on_start(self, ev): seen.append(ev)\n"
            "    def on_end(self, ev): pass\n"
            "event.register('numba:compile', L())\n"
            "m = stickslip.load_model('belt')\n"
            "t = stickslip.simulate(m, 5.0)\n"
            "stickslip.stability(m)\n"
            "stickslip.flow_jacobian(m, t.final_state, 0.5)\n"
            "print(len(seen))\n")
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "0"
