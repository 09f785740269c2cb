"""`stickslip continue`: one-line errors for bad input (exit 2, nothing computed), a small branch
written to NetCDF and PNG that matches the library's result, and the two-mass belt a user
continued: a start on steady sliding, a collision of multipliers that is no Neimark–Sacker point."""

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from stickslip import Parameters
from stickslip.cli import app
from stickslip.model.library import two_plates
from stickslip.orbits.continuation import continue_orbit, load_branch, start_run

runner = CliRunner()

#: Slip band [m/s] of the successful run (see its docstring).
BAND = 1e-5


@pytest.mark.parametrize("args, message", [
    (["--param", "foo", "--from", "1", "--to", "2"], "--param foo: unknown parameter 'foo' of model 'two-plates'"),
    (["--param", "friction_law", "--from", "1", "--to", "2"], "is 'exponential', not a finite number"),
    (["--from", "3", "--to", "3"], "--from and --to are both 3"),
    (["--from", "nan", "--to", "3"], "--from must be a finite number"),
    (["--from", "3", "--to", "inf"], "--to must be a finite number"),
    (["--from", "3", "--to", "4", "--out", "b.txt"], "give a path ending in .nc"),
    (["--from", "3", "--to", "4", "--ic", "hot"], "unknown initial condition 'hot'; use 'zero', 'near', 'equilibrium', 'far'"),
    (["--from", "3", "--to", "4", "--max-points", "1"], "--max-points must be >= 2"),
    (["--from", "3", "--to", "4", "--step", "0"], "--step must be a finite number > 0"),
    (["--from", "3", "--to", "4", "--step", "0.5", "--max-step", "0.1"], "--step 0.5 is larger than --max-step 0.1"),
    (["--from", "3", "--to", "4", "--stop-on", "cusp"], "--stop-on cusp: choose from"),
    (["--from", "3", "--to", "4", "--set", "k_px"], "--set expects NAME=VALUE"),
    (["--from", "3", "--to", "4", "--set", "N=-5"], "N"),
    (["--from", "3", "--to", "4", "--model", "xyz"], "xyz"),
    (["--from", "3", "--to", "4", "--slip-band", "-1"], "slip_band = -1.0 must be a finite speed > 1e-13 m/s"),
    (["--from", "3", "--to", "4", "--rtol", "0"], "rtol = 0.0 must be a finite number > 0"),
])
def test_bad_input_is_one_line_and_exit_2(args, message, tmp_path):
    res = runner.invoke(app, ["continue", *args] + ([] if "--out" in args else ["--out", str(tmp_path / "b.nc")]))
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and message in lines[0], res.output
    assert not (tmp_path / "b.nc").exists()


def test_missing_range_is_a_usage_error():
    res = runner.invoke(app, ["continue", "--param", "Omega"])
    assert res.exit_code == 2 and "--from" in res.output


def test_continue_writes_the_library_branch_and_a_figure(tmp_path):
    """Model 4, N = 50 N, Ω from 3 towards 3.3 rad/s, 4 orbits: the file holds what
    `continue_orbit` computes from the same start run (same code path, identical numbers).

    Slip band 1e-5 m/s: with the default 1e-3 one Newton flow of the start orbit's shooting takes
    27 s here (an integrator stall, reported; 2 s in all with 1e-5)."""
    out = tmp_path / "branch.nc"
    res = runner.invoke(app, ["continue", "--param", "Omega", "--from", "3", "--to", "3.3", "--N", "50",
                              "--model", "rotation", "--search-time", "30", "--max-points", "4", "--out", str(out),
                              "--slip-band", str(BAND), "--json"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout.strip().splitlines()[-1])
    assert summary["points"] == 4 and summary["from"] == 3.0 and summary["param"] == "Omega"
    assert summary["compile_time_s"] >= 0.0 and summary["wall_time_s"] > 0.0
    assert out.with_suffix(".png").stat().st_size > 10_000  # a drawn figure, not an empty canvas
    ds = load_branch(out)
    assert ds.attrs["model"] == "rotation" and ds.attrs["param_N"] == 50.0
    values = ds["value"].values
    assert values[0] == 3.0 and np.all(np.diff(values) > 0) and values[-1] <= 3.3

    rotation = two_plates(Parameters(N=50.0, Omega=3.0), "rotation")
    b = continue_orbit(rotation, "Omega", start=start_run(rotation, "far", t_end=30.0, slip_band=BAND), max_points=4,
                       bounds=(3.0, 3.3), slip_band=BAND)
    assert ds.attrs["options"] and '"slip_band": 1e-05' in ds.attrs["options"]
    assert np.array_equal(b.values, values)
    assert np.array_equal(b.periods, ds["period"].values)
    assert np.array_equal(b.stable.astype(np.int8), ds["stable"].values)


_ARGS = ["continue", "--param", "Omega", "--from", "3", "--to", "3.3", "--N", "50", "--model", "rotation",
         "--search-time", "30", "--max-points", "4", "--slip-band", str(BAND), "--no-plot", "--json"]


class _Interrupt(Exception):
    """Raised by the progress callback: the run stops as if killed after a journaled orbit."""


def test_same_command_resumes_and_other_settings_are_refused(tmp_path):
    """An interrupted run (3 orbits journaled by the library with the command's settings) is
    resumed by the command: one note line, then the branch of an uninterrupted run; the same
    command again reads the finished file; another --max-points with the same --out exits 2."""
    out = tmp_path / "branch.nc"
    rotation = two_plates(Parameters(N=50.0, Omega=3.0), "rotation")
    opts = dict(max_points=4, bounds=(3.0, 3.3), slip_band=BAND)

    def stop_after_two(i, *_):
        if i == 2:
            raise _Interrupt

    with pytest.raises(_Interrupt):
        continue_orbit(rotation, "Omega", start=start_run(rotation, "far", t_end=30.0, slip_band=BAND),
                       out=out, callback=stop_after_two, **opts)
    assert not out.exists()
    res = runner.invoke(app, _ARGS + ["--out", str(out)])
    assert res.exit_code == 0, res.output
    assert res.stderr.strip() == "resuming from 3 points"
    summary = json.loads(res.stdout.strip().splitlines()[-1])
    assert summary["points"] == 4 and summary["points_resumed"] == 3
    b = continue_orbit(rotation, "Omega", start=start_run(rotation, "far", t_end=30.0, slip_band=BAND), **opts)
    ds = load_branch(out)
    assert np.array_equal(b.values, ds["value"].values) and np.array_equal(b.periods, ds["period"].values)
    assert np.array_equal(b.states, ds["state_on_section"].values)
    assert np.array_equal(b.amplitude, ds["amplitude"].values)

    again = runner.invoke(app, _ARGS + ["--out", str(out)])
    assert again.exit_code == 0 and again.stderr.strip() == "resuming from 4 points", again.output
    assert json.loads(again.stdout.strip().splitlines()[-1])["points_resumed"] == 4

    other = runner.invoke(app, [a if a != "4" else "5" for a in _ARGS] + ["--out", str(out)])
    assert other.exit_code == 2, other.output
    lines = [ln for ln in other.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and "choose another output (--out) or delete" in lines[0]
    assert load_branch(out)["value"].size == 4  # the finished file is left as it was


def test_continue_a_model_file_over_a_set_path(tmp_path):
    """`stickslip continue --model belt --param contact.0.drive`: the branch file holds the library's
    branch over the same path (the same start run and options)."""
    from stickslip.model.library import load_model

    out = tmp_path / "belt.nc"
    res = runner.invoke(app, ["continue", "--model", "belt", "--param", "contact.0.drive", "--from", "1.5", "--to",
                              "1.6", "--ic", "x=0,dx=1.5", "--max-points", "6", "--step", "0.02", "--max-step", "0.05",
                              "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.output)
    assert s["param"] == "contact.0.drive" and s["from"] == 1.5
    belt = load_model("belt")
    run = start_run(belt, {"x": 0.0, "dx": 1.5}, t_end=60.0)
    ref = continue_orbit(belt, "contact.0.drive", start=run, step=0.02, max_step=0.05, max_points=6,
                         bounds=(1.5, 1.6))
    ds = load_branch(out)
    assert ds.attrs["model"] == "belt" and list(ds["state"].values) == ["x", "dx"]
    assert np.array_equal(ds["value"].values, ref.values) and np.array_equal(ds["period"].values, ref.periods)
    assert (tmp_path / "belt.png").stat().st_size > 0
    bad = runner.invoke(app, ["continue", "--model", "belt", "--param", "Omega", "--from", "1", "--to", "2",
                              "--out", str(tmp_path / "b.nc")])
    assert bad.exit_code == 2 and "unknown parameter 'Omega' of model 'belt'" in bad.output


#: The two-mass belt model file a user continued in its first drive (tests/orbits/two_mass_belt.toml).
TWO_MASS = str(Path(__file__).parents[1] / "orbits" / "two_mass_belt.toml")
_TWO_MASS_ARGS = ["continue", "--model", TWO_MASS, "--param", "contact.0.drive", "--from", "0.2", "--to", "1.2",
                  "--ic", "zero", "--max-points", "30", "--no-plot"]


def test_start_on_steady_sliding_is_one_error_line_and_nothing_is_written(tmp_path):
    """The user's first command: the 60 s start run from rest shoots onto steady sliding. It is
    said so in one line naming what to change (exit 2), not continued as a branch with a fold."""
    out = tmp_path / "b.nc"
    res = runner.invoke(app, _TWO_MASS_ARGS + ["--out", str(out)])
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: converged to steady sliding at contact.0.drive=0.2:")
    assert "--ic x1=" in lines[0] and "--search-time" in lines[0] and "fold" not in lines[0]
    assert not out.exists() and not Path(str(out) + ".journal").exists()


def test_collision_of_multipliers_is_no_neimark_sacker_and_special_points_carry_their_multipliers(tmp_path):
    """The user's second command (--search-time 30): no Neimark–Sacker point at 0.5557 (a complex pair
    meets the real axis outside the unit circle there, tests/orbits/test_special_points.py), the period
    doubling between 0.5858 and 0.5958; the JSON and the file carry the multipliers on either side."""
    out = tmp_path / "b.nc"
    res = runner.invoke(app, _TWO_MASS_ARGS + ["--search-time", "30", "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    kinds = [q["kind"] for q in s["special"]]
    assert "neimark-sacker" not in kinds and kinds[0] == "period-doubling"
    pd = s["special"][0]
    assert 0.5858 < pd["value"] < 0.5958
    before = np.array([complex(*z) for z in pd["multipliers_before"]])
    after = np.array([complex(*z) for z in pd["multipliers_after"]])
    assert np.sum(np.abs(before.imag) > 0) == 2 and np.all(np.abs(before[np.abs(before.imag) > 0]) > 1.0)
    assert np.sum(after.real < -1.0) == 1 and np.sum((after.real > -1.0) & (after.real < -0.9)) == 1
    ds = load_branch(out)
    assert list(ds["special_kind"].values) == kinds
    for side, mult in (("before", before), ("after", after)):
        stored = ds[f"special_multiplier_{side}_real"].values[0] + 1j * ds[f"special_multiplier_{side}_imag"].values[0]
        assert np.array_equal(stored, mult)
    table = runner.invoke(app, _TWO_MASS_ARGS + ["--search-time", "30", "--out", str(out), "--no-progress"])
    assert table.exit_code == 0 and "multipliers" in table.stdout and "neimark-sacker" not in table.stdout


def test_continuation_that_converges_onto_steady_sliding_writes_its_orbits_and_exits_1(tmp_path, monkeypatch):
    """Every new point taken for steady sliding (the test made so): the branch ends after its start
    orbit, the file holds that orbit, the JSON summary is printed and one error line says where it
    converged (exit 1, a run that stopped early)."""
    from stickslip.orbits import special_points

    monkeypatch.setattr(special_points, "is_orbit", lambda *a: False)
    out = tmp_path / "b.nc"
    res = runner.invoke(app, _TWO_MASS_ARGS + ["--search-time", "30", "--out", str(out), "--json"])
    assert res.exit_code == 1, res.output
    s = json.loads(res.stdout.strip().splitlines()[-1])
    assert s["points"] == 1 and s["special"] == [] and s["stop_reason"].startswith("steady sliding at contact.0.drive")
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: the continuation converged to steady sliding at")
    assert load_branch(out)["value"].size == 1
