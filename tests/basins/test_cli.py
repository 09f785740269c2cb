"""`stickslip basins`: files, JSON, the parameter study, the figure, and one-line errors for bad input."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from stickslip.basins import basin_stability, box, load_basins
from stickslip.cli import app
from stickslip.model.library import load_model

runner = CliRunner()
BELT_BOX = ["--model", "belt", "--box", "x=-2:2", "--box", "dx=-2:2"]


def run(*args):
    return runner.invoke(app, list(args))


def test_json_has_n_fractions_standard_errors_and_attractors(tmp_path):
    out = tmp_path / "b.nc"
    res = run("basins", *BELT_BOX, "--n", "120", "--executor", "serial", "--out", str(out), "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert s["n"] == 120 and set(s["fractions"]) == {"equilibrium", "periodic"}
    assert sum(s["fractions"].values()) == pytest.approx(1.0)
    for name, p in s["fractions"].items():
        assert s["standard_errors"][name] == pytest.approx(np.sqrt(p * (1 - p) / 120))
    cycle = next(a for a in s["attractors"] if a["name"] == "periodic")
    assert cycle["period"] == pytest.approx(6.3163, rel=1e-4) and cycle["frequency"] == pytest.approx(1 / cycle["period"])
    assert set(cycle["state"]) == {"x", "dx"} and cycle["amplitude"] > 0
    assert out.with_suffix(".png").stat().st_size > 0
    # the library gives the same study the same answer
    belt = load_model("belt")
    lib = basin_stability(belt, box(belt, {"x": (-2, 2), "dx": (-2, 2)}, n=120), executor="serial")
    assert np.array_equal(lib.labels(), np.array([load_basins(out)["attractor"].values[c]
                                                  for c in load_basins(out)["label"].values]))


def test_grid_and_flag_meanings(tmp_path):
    out = tmp_path / "g.nc"
    res = run("basins", *BELT_BOX, "--grid", "12,10", "--executor", "serial", "--out", str(out), "--no-progress")
    assert res.exit_code == 0, res.output
    ds = load_basins(out)
    assert ds.sizes["state"] == 120 and ds.attrs["sampler"] == "grid" and json.loads(ds.attrs["grid_counts"]) == [12, 10]
    assert ds["label"].attrs["flag_meanings"].split() == list(ds["attractor"].values)
    assert list(ds["label"].attrs["flag_values"]) == list(range(ds.sizes["attractor"]))
    assert ds["verdict"].attrs["flag_meanings"].split()[:2] == ["equilibrium", "periodic"]
    assert "basin stability of belt" in res.output


def test_ics_file_results_keep_the_row_order(tmp_path):
    path = tmp_path / "ics.csv"
    path.write_text("x,dx\n2,2\n0.1,0.1\n2,2\n")
    out = tmp_path / "i.nc"
    res = run("basins", "--model", "belt", "--ics", str(path), "--executor", "serial", "--out", str(out), "--json",
              "--no-plot")
    assert res.exit_code == 0, res.output
    ds = load_basins(out)
    names = [str(ds["attractor"].values[c]) for c in ds["label"].values]
    assert names == ["periodic", "equilibrium", "periodic"]
    assert np.array_equal(ds["initial_state"].values, [[2, 2], [0.1, 0.1], [2, 2]])


def test_parameter_study_gives_fractions_per_value_like_single_runs(tmp_path):
    out = tmp_path / "p.nc"
    res = run("basins", *BELT_BOX, "--n", "200", "--param", "contact.0.drive=1.3:1.7:3", "--executor", "serial",
              "--out", str(out), "--json")
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert s["param"] == "contact.0.drive" and s["values"] == pytest.approx([1.3, 1.5, 1.7])
    eq = s["fractions"]["equilibrium"]
    assert len(eq) == 3 and eq[0] < eq[1] < eq[2]  # faster belts: more steady sliding (bSTAB's v-study)
    single = run("basins", *BELT_BOX, "--n", "200", "--set", "contact.0.drive=1.5", "--executor", "serial",
                 "--out", str(tmp_path / "s.nc"), "--json", "--no-plot")
    assert json.loads(single.stdout.strip().splitlines()[-1])["fractions"]["equilibrium"] == eq[1]
    assert out.with_suffix(".png").stat().st_size > 0


@pytest.mark.parametrize("args, words", [
    (["--box", "z=0:1"], "unknown state 'z' of model 'belt'"),
    (["--box", "x=1:0"], "--box x=1:0: LO must be < HI"),
    (["--box", "x=0:1", "--n", "0"], "--n 0: give the number of random states"),
    (["--box", "x=0:1", "--n", "-2"], "--n -2"),
    (["--box", "x=0:1", "--grid", "1"], "give >= 2 points per axis"),
    (["--box", "x=0:1", "--grid", "a"], "--grid a: give points per axis"),
    (["--box", "x=0:1", "--grid", "5", "--n", "5"], "drop --n"),
    (["--box", "x"], "--box expects NAME=LO:HI"),
    (["--box", "x=0:1", "--param", "contact.0.drive=2:1:3"], "LO must be < HI"),
    (["--box", "x=0:1", "--param", "nope=1:2:3"], "--param nope: no key 'nope' under the model"),
    (["--box", "x=0:1", "--set", "nope=1"], "--set nope: no key 'nope' under the model"),
    (["--box", "x=0:1", "--model", "nomodel"], "unknown model 'nomodel'"),
    (["--box", "x=0:1", "--base", "far"], "--base far: choose one of equilibrium, zero"),
    (["--box", "x=0:1", "--t-end", "-1"], "t-end = -1.0 must be a finite number > 0"),
    (["--box", "x=0:1", "--t-end", "0.5"], "--t-end 0.5 is shorter than the characteristic period"),
    (["--box", "x=0:1", "--match-rtol", "2"], "match-rtol = 2.0 must be < 1"),
    (["--box", "x=0:1", "--workers", "100000"], "more than the"),
    (["--box", "x=0:1", "--executor", "threads"], "unknown executor 'threads'"),
    ([], "give at least one --box"),
])
def test_bad_input_is_one_line_exit_2(args, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv = ["basins", "--model", "belt", *args] if "--model" not in args else ["basins", *args]
    res = run(*argv, "--no-plot", "--no-progress")
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), res.output
    assert words in lines[0], lines[0]
    assert not list(tmp_path.glob("*.nc*"))  # refused before anything was computed or written


@pytest.mark.parametrize("text, words", [
    ("x\n1\n", "column(s) dx missing from the header"),
    ("x,dx,extra\n1,2,3\n", "column 'extra' is not a state"),
    ("x,dx\n1,2\n3,oops\n", "row 3, column dx: 'oops' is not a number"),
    ("x,dx\n1,2\n3\n", "row 3: 1 field(s)"),
])
def test_bad_csv_is_one_line_naming_row_or_column(text, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "ics.csv").write_text(text)
    res = run("basins", "--model", "belt", "--ics", "ics.csv", "--no-plot", "--no-progress")
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and words in lines[0], res.output
    res = run("basins", "--model", "belt", "--ics", "ics.csv", "--box", "x=0:1", "--no-plot")
    assert res.exit_code == 2 and "--ics gives every state" in res.output


def test_not_a_basins_file_is_refused_in_one_line(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "b.nc").write_text("not netcdf")
    res = run("basins", *BELT_BOX, "--n", "10", "--out", "b.nc", "--no-plot", "--no-progress")
    assert res.exit_code == 2 and "not a stickslip NetCDF file" in res.output and "--overwrite" in res.output
    assert (tmp_path / "b.nc").read_text() == "not netcdf"
