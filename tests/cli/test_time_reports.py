"""Every computing command reports its time the same way: under ``--json`` (one line on stdout,
nothing else) the wall time of its computation (``wall_time_s``) and the compiling apart
(``compile_time_s``), both in seconds, and in its table or last line the same two numbers
(``wall time 0.412 s (compiling 12.3 s apart)``)."""

import json
import math

import pytest
from typer.testing import CliRunner

from stickslip.cli import app

runner = CliRunner()

#: A quick call of each command that computes; outputs go to the test's folder.
COMMANDS = {
    "simulate": ["simulate", "--t-end", "0.5", "--sample-rate", "100", "--no-plot", "--out", "{tmp}/run.nc"],
    "stability": ["stability"],
    "stability-map": ["stability-map", "--N-points", "2", "--omega-points", "2", "--no-boundary", "--no-plot",
                      "--out", "{tmp}/map.nc"],
    "sweep": ["sweep", "--grid", "N=40,50", "--t-end", "0.5", "--executor", "serial", "--no-plot",
              "--out", "{tmp}/sweep.nc"],
    "bifurcation": ["bifurcation", "--range", "40,50", "--t-end", "0.5", "--executor", "serial", "--no-plot",
                    "--out", "{tmp}/bifurcation.nc"],
    "regions": ["regions", "--N", "50", "--omega", "5", "--t-end", "0.5", "--executor", "serial", "--no-plot",
                "--out", "{tmp}/regions.nc"],
    "basins": ["basins", "--model", "belt", "--box", "x=-1:1", "--grid", "2", "--t-end", "100", "--executor", "serial",
               "--no-plot", "--out", "{tmp}/basins.nc"],
}


def _invoke(name, tmp_path, *extra):
    args = [a.replace("{tmp}", str(tmp_path)) for a in COMMANDS[name]] + list(extra)
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    return res


@pytest.mark.parametrize("name", list(COMMANDS))
def test_json_is_one_line_with_the_wall_time_and_the_compiling_apart(name, tmp_path):
    [line] = _invoke(name, tmp_path, "--json").stdout.strip().splitlines()  # no progress bar before it
    summary = json.loads(line)
    for key in ("wall_time_s", "compile_time_s"):
        assert math.isfinite(summary[key]) and summary[key] >= 0.0, (key, summary[key])
    assert "total_s" not in summary


@pytest.mark.parametrize("name", list(COMMANDS))
def test_the_summary_says_the_wall_time(name, tmp_path):
    assert "wall time " in _invoke(name, tmp_path).stdout
