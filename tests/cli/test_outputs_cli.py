"""No command replaces a file without --overwrite (refused in one line, before anything is
computed), resumable commands resume into their own output, and option conflicts, ranges
and suggestions of the commands other than simulate."""

import pytest
from typer.testing import CliRunner

from stickslip.cli import app

runner = CliRunner()

#: Commands that write OUT.nc and OUT.png, with options that make them quick.
WRITERS = {
    "stability-map": ["stability-map", "--N-points", "3", "--omega-points", "3", "--no-boundary"],
    "orbit": ["orbit", "--search-time", "2"],
    "lyapunov": ["lyapunov", "--t-transient", "1", "--t-average", "1"],
}


def lines_of(res) -> list:
    return [ln for ln in res.output.splitlines() if ln.strip()]


def refused(res, *words) -> str:
    assert res.exit_code == 2, res.output
    lines = lines_of(res)
    assert len(lines) == 1 and lines[0].startswith("error:"), res.output
    for w in words:
        assert w in lines[0], lines[0]
    return lines[0]


@pytest.mark.parametrize("command", list(WRITERS))
@pytest.mark.parametrize("existing", ["r.nc", "r.png"])
def test_an_existing_output_is_refused(command, existing, tmp_path):
    (tmp_path / existing).write_text("the user's file")
    res = runner.invoke(app, [*WRITERS[command], "--out", str(tmp_path / "r.nc")])
    refused(res, f"{tmp_path / existing} exists", "--overwrite")
    assert (tmp_path / existing).read_text() == "the user's file"
    assert sorted(p.name for p in tmp_path.iterdir()) == [existing]


def test_overwrite_replaces_an_existing_stability_map(tmp_path):
    (tmp_path / "r.nc").write_text("old")
    (tmp_path / "r.png").write_text("old")
    res = runner.invoke(app, [*WRITERS["stability-map"], "--out", str(tmp_path / "r.nc"), "--overwrite", "--json"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "r.nc").stat().st_size > 1000 and (tmp_path / "r.png").stat().st_size > 10_000


@pytest.mark.parametrize("args", [
    ["sweep", "--grid", "N=30,50", "--grid", "Omega=0.5"],
    ["bifurcation", "--range", "30,50"],
    ["regions", "--N", "50", "--omega", "8.5,12"],
    ["continue", "--from", "5", "--to", "6"],
])
def test_a_fresh_resumable_run_does_not_replace_a_figure_that_is_not_its_own(args, tmp_path):
    (tmp_path / "r.png").write_text("the user's figure")
    res = runner.invoke(app, [*args, "--out", str(tmp_path / "r.nc"), "--no-progress"])
    refused(res, f"{tmp_path / 'r.png'} exists", "--overwrite")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.png"]


@pytest.mark.parametrize("args", [["study", "timestep", "--t-end", "1"], ["reproduce", "--only", "fig3"]])
def test_an_output_folder_with_files_is_refused(args, tmp_path):
    (tmp_path / "report.md").write_text("the user's notes")
    res = runner.invoke(app, [*args, "--out", str(tmp_path)])
    refused(res, f"--out {tmp_path} is not empty", "--overwrite")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.md"]


# ----------------------------------------------------------------------------- options
@pytest.mark.parametrize("args, words", [
    (["bifurcation", "--range", "1:2"], "e.g. --range 10:130:13 or --range 30,50,70"),
    (["bifurcation", "--range", "1:x:3"], "e.g. --range 10:130:13"),
    (["regions", "--omega", "1:2"], "e.g. --omega 10:130:13"),
    (["sweep", "--grid", "N=1:2"], "e.g. --grid N=10:130:13"),
    (["stability-map", "--omega-min", "-1", "--omega-max", "1"], "straddle 0"),
    (["stability-map", "--omega-min", "-1", "--omega-max", "0"], "straddle 0"),
    (["stability-map", "--N-min", "0"], "--N-min 0: normal loads must be > 0"),
    (["stability-map", "--N-min", "nan"], "--N-min must be a finite number"),
    (["stability-map", "--family", "N=1,2"], "N is an axis of the map"),
    (["stability-map", "--family", "delta_mu"], "--family"),
    (["stability-map", "--N-points", "1000000000", "--omega-points", "1000000000"],
     "--N-points 1000000000 needs ≈ 64 GB"),
    (["stability", "--omega", "5", "--set", "Omega=3"], "--set Omega=3 and --omega 5 both set Omega"),
    (["stability", "--omega", "-2.1199605744342958e+229"], "not finite"),  # found by the property tests
    (["orbit", "--N", "50", "--set", "N=30"], "--set N=30 and --N 50 both set N"),
    (["orbit", "--search-time", "1e12"], "the start run (--search-time) of 1e+12 s"),
    (["continue", "--from", "5", "--to", "6", "--omega", "3"], "--param Omega and --omega 3 both set Omega"),
    (["continue", "--param", "N", "--from", "5", "--to", "6", "--set", "N=3"], "--param N and --set N=3 both set N"),
    (["sweep", "--grid", "N=30,50", "--set", "N=3"], "--grid N and --set N=3 both set N"),
    (["bifurcation", "--param", "Omega", "--set", "Omega=3"], "--param Omega and --set Omega=3 both set Omega"),
    (["regions", "--set", "Omega=3"], "--omega and --set Omega=3 both set Omega"),
    (["sweep", "--grid", "N=30", "--t-end", "1e12"], "lower the sample rate to at most"),
    (["sweep", "--grid", "N=1:2:1000000000000"], "give a count of at most"),
    (["sweep", "--grid", "N=1:2:1000000", "--grid", "Omega=1:2:1000000"], "a sweep of 1e+12 points"),
    (["bifurcation", "--range", "30,50", "--peaks", "1000000000000"], "keep at most"),
    (["orbit", "--tol", "1e300"], "--tol 1e+300: a relative tolerance must be < 1"),
    (["continue", "--from", "5", "--to", "6", "--tol", "2"], "--tol 2: a relative tolerance must be < 1"),
    (["study", "timestep", "--t-end", "0"], "t_end - t0 = 0.0 must be a finite number > 0"),
])
def test_refused_options_say_why_in_one_line(args, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    quiet = {"stability": [], "study": [], "stability-map": ["--no-plot"], "orbit": ["--no-plot"]}.get(args[0],
                                                                                 ["--no-plot", "--no-progress"])
    refused(runner.invoke(app, [*args, *quiet]), words)
    assert not list(tmp_path.iterdir())
