"""`stickslip sweep`, `bifurcation`, `regions`: files, data against direct simulations, resuming,
and one-line errors for bad input."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

import stickslip
from stickslip import Parameters
from stickslip.analysis import classify
from stickslip.attractors import attractor
from stickslip.cli import app
from stickslip.sweep import load_region_map, load_sweep
from stickslip.sweep.bistability import classify_regions
from stickslip.model.library import two_plates
from stickslip.sweep.spec import initial_condition

runner = CliRunner()

#: A tiny grid: 6 s runs at Ω = 0.5 rad/s (stick-slip from rest within the first second).
T_END, T_FROM = 6.0, 3.0
#: Options of every sweep point (the library defaults the CLI passes on).
SIM = dict(rtol=1e-8, atol=1e-10, sample_rate=200.0, steady_from=T_FROM, max_steps=5_000_000)


def run(*args):
    res = runner.invoke(app, list(args))
    return res


def summary(res) -> dict:
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout.strip().splitlines()[-1])


def direct(params, model="full", ic="zero"):
    """The sweep point recomputed by `stickslip.simulate` + `classify` and `attractor` (what the
    sweep must store)."""
    ic_arg, pert = initial_condition(ic, two_plates(params, model))
    traj = stickslip.simulate(two_plates(params, model), T_END, ic=ic_arg, perturbation=pert, **SIM)
    return attractor(traj), classify(traj, T_FROM)


def assert_point_matches(point, verdict, c):
    """Stored reductions of one grid point equal the direct run's: same code, same options, so
    identical floating-point results (no tolerance)."""
    assert point["attractor"].item() == verdict.code
    assert point["stick_fraction"].item() == c.stick_fraction
    assert point["amplitude"].item() == c.amplitude
    # the column's definition: 1/period when periodic, else the mean rate of the peaks
    expected = c.frequency_hz if c.outcome == "periodic" else c.peak_rate_hz
    assert np.array_equal(point["frequency"].item(), expected, equal_nan=True)
    peaks = point["peaks"].values
    last = c.peaks.value[-peaks.size:]
    assert last.size > 0 and np.array_equal(peaks[: last.size], last)
    assert np.all(np.isnan(peaks[last.size:]))


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "s.nc"
    args = ("sweep", "--grid", "N=30,50", "--grid", "Omega=0.5", "--t-end", str(T_END), "--executor", "serial",
            "--plot", "stick_fraction", "--out", str(out), "--json")
    return out, args, summary(run(*args))


def test_sweep_writes_netcdf_and_png_with_the_direct_runs_data(swept):
    out, _, s = swept
    assert s["points_computed"] == 2 and s["shape"] == {"N": 2, "Omega": 1}
    assert out.with_suffix(".png").stat().st_size > 10_000  # a drawn figure, not an empty canvas
    ds = load_sweep(out)
    assert ds.attrs["complete"] == 1 and ds.attrs["t_end"] == T_END and ds.attrs["t_from"] == T_FROM
    verdict, c = direct(Parameters(N=50.0, Omega=0.5))
    assert c.stick_fraction > 0  # the point is a stick-slip oscillation, not a trivial rest
    assert_point_matches(ds.sel(N=50.0, Omega=0.5), verdict, c)


def test_resuming_a_finished_sweep_recomputes_nothing(swept):
    out, args, _ = swept
    before = load_sweep(out)
    again = summary(run(*args))
    assert again["points_computed"] == 0 and again["points_resumed"] == 2
    after = load_sweep(out)
    assert after["peaks"].equals(before["peaks"]) and after["wall_time"].equals(before["wall_time"])


def test_another_grid_on_the_same_output_is_refused_then_overwritten(swept, tmp_path):
    out, args, _ = swept
    copy = tmp_path / "s.nc"
    copy.write_bytes(out.read_bytes())
    base = ["sweep", "--grid", "N=30", "--t-end", str(T_END), "--executor", "serial", "--no-plot", "--out", str(copy)]
    res = run(*base)
    assert res.exit_code == 2 and "--overwrite" in res.output
    s = summary(run(*base, "--overwrite", "--json"))
    assert s["points_computed"] == 1 and s["shape"] == {"N": 1}


def test_bifurcation_uses_the_paper_base_values_and_agrees_with_sweep(swept, tmp_path):
    out = tmp_path / "b.nc"
    s = summary(run("bifurcation", "--param", "N", "--range", "30,50", "--t-end", str(T_END),
                    "--executor", "serial", "--out", str(out), "--json"))
    assert s["points_computed"] == 2
    assert out.with_suffix(".png").stat().st_size > 10_000
    ds = load_sweep(out)
    assert ds.attrs["param_Omega"] == 0.5  # Figs. 12(a), 13, 14: Ω = 0.5 rad/s unless swept
    sw = load_sweep(swept[0]).sel(Omega=0.5)
    for name in ("attractor", "peaks", "frequency", "stick_fraction"):
        assert ds[name].equals(sw[name].drop_vars("Omega")), name


def test_bifurcation_over_omega_and_models(tmp_path):
    out = tmp_path / "w.nc"
    s = summary(run("bifurcation", "--param", "Omega", "--range", "0.5:1:2", "--model", "full,rotation",
                    "--t-end", str(T_END), "--executor", "serial", "--out", str(out), "--json", "--no-progress"))
    assert s["shape"] == {"model": 2, "Omega": 2}
    ds = load_sweep(out)
    assert ds.attrs["param_N"] == 50.0  # Fig. 12(b): N = 50 N
    verdict, c = direct(Parameters(N=50.0, Omega=1.0), model="rotation")
    assert_point_matches(ds.sel(model="rotation", Omega=1.0), verdict, c)


def test_regions_of_known_cases_and_direct_run(tmp_path):
    # Sect. 4.2.2, N = 50 N: coexistence (II) at Ω = 8.5 rad/s, equilibrium only (III) at 12 rad/s;
    # 60 s runs settle both (the library test uses the same case)
    out = tmp_path / "r.nc"
    s = summary(run("regions", "--N", "50", "--omega", "8.5,12", "--t-end", "60", "--t-from", "30", "--executor", "serial",
                    "--out", str(out), "--json"))
    assert s["regions"] == {"II: coexistence": 1, "III: equilibrium only": 1}
    assert s["stick_slip_omega_max"] == {"full": [8.5]}
    assert out.with_suffix(".png").stat().st_size > 10_000
    rm = load_region_map(out)
    ds = rm.dataset
    assert rm.region[0, 0].tolist() == [2, 3]
    outcome = ds["attractor"].transpose("model", "N", "Omega", "ic").values
    sf = ds["stick_fraction"].transpose("model", "N", "Omega", "ic").values
    assert np.array_equal(classify_regions(outcome, sf), rm.region)
    assert (ds.attrs["t_end"], ds.attrs["t_from"]) == (60.0, 30.0) and list(ds["ic"].values) == ["far", "near"]


@pytest.mark.parametrize("args, words", [
    (["sweep"], "at least one --grid"),
    (["sweep", "--grid", "N"], "NAME=VALUES"),
    (["sweep", "--grid", "N=10:130"], "start:stop:count"),
    (["sweep", "--grid", "N=10:130:1"], "count must be >= 2"),
    (["sweep", "--grid", "N=10:10:3"], "start equals stop"),
    (["sweep", "--grid", "N=10:x:3"], "must be numbers"),
    (["sweep", "--grid", "N=inf:30:3"], "finite"),
    (["sweep", "--grid", "N=30,nan"], "finite"),
    (["sweep", "--grid", "N=a,b"], "numbers separated by commas"),
    (["sweep", "--grid", "N=30", "--grid", "N=50"], "given twice"),
    (["sweep", "--grid", "N=30,30"], "repeats"),
    (["sweep", "--grid", "N=-5,30"], "N"),
    (["sweep", "--grid", "bogus=1,2"], "cannot sweep"),
    (["sweep", "--grid", "model=full,z"], "unknown model"),
    (["sweep", "--grid", "N=30", "--ic", "sideways"], "unknown"),
    (["sweep", "--grid", "N=30", "--set", "bogus=1"], "unknown parameter"),
    (["sweep", "--grid", "N=30", "--set", "alpha=nan"], "not finite"),
    (["sweep", "--grid", "N=30", "--out", "x.txt"], ".nc"),
    (["sweep", "--grid", "N=30", "--executor", "threads"], "unknown executor"),
    (["sweep", "--grid", "N=30", "--executor", "serial", "--scheduler", "tcp://h:8786"], "--executor dask"),
    (["sweep", "--grid", "N=30", "--workers", "0"], "workers must be >= 1, got 0"),
    (["sweep", "--grid", "N=30", "--t-end", "-1"], "--t-end"),
    (["sweep", "--grid", "N=30", "--t-end", "10", "--t-from", "20"], "t_from"),
    (["sweep", "--grid", "N=30", "--t-from", "nan"], "t_from = nan s must lie in [0, t_end = 200.0 s)"),
    (["sweep", "--grid", "N=30", "--settle", "--cap", "100"], "cap = 100.0 s must be a finite number ≥ t_end = 200.0 s"),
    (["sweep", "--grid", "N=30", "--cap", "300"], "--cap is the longest run when settling; give --settle"),
    (["sweep", "--grid", "N=30", "--plot", "colour"], "--plot"),
    (["sweep", "--grid", "N=30", "--config", "missing.toml"], "does not exist"),
    (["bifurcation", "--param", "N", "--N", "30"], "--param N and --N 30 both set N"),
    (["bifurcation", "--param", "model"], "numeric"),
    (["bifurcation", "--param", "bogus", "--range", "1,2"], "cannot sweep"),
    (["bifurcation", "--range", "1:2"], "start:stop:count"),
    (["bifurcation", "--peaks", "0"], "--peaks"),
    (["regions", "--omega", "5:1:0"], "count must be >= 2"),
    (["regions", "--model", "full,z"], "unknown model"),
    (["regions", "--N", "30,inf"], "finite"),
])
def test_bad_input_gives_one_line_error(args, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    res = run(*args, "--no-plot", "--no-progress")
    assert res.exit_code == 2, res.output
    lines = res.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), res.output
    assert words in lines[0], lines[0]
    assert not list(tmp_path.glob("*.nc*"))  # refused before anything was computed or written


@pytest.mark.parametrize("command", ["sweep", "bifurcation", "regions"])
def test_unknown_option_is_refused(command):
    res = run(command, "--bogus", "1")
    assert res.exit_code == 2 and "No such option" in res.output


def test_bifurcation_takes_omega_from_a_config_file(tmp_path):
    cfg = tmp_path / "p.toml"
    cfg.write_text("[parameters]\nOmega = 1.0\nalpha = 4\n")
    out = tmp_path / "c.nc"
    summary(run("bifurcation", "--range", "30,50", "--config", str(cfg), "--t-end", str(T_END), "--executor", "serial",
                "--no-plot", "--no-progress", "--out", str(out), "--json"))
    ds = load_sweep(out)
    # the file's Ω wins over the paper's 0.5 rad/s; N is swept, the rest comes from the file
    assert (ds.attrs["param_Omega"], ds.attrs["param_alpha"]) == (1.0, 4.0)
    assert not out.with_suffix(".png").exists()


@pytest.mark.parametrize("var", ["attractor", "frequency", "intensity_r_phi"])
def test_sweep_figures_of_other_reductions(swept, tmp_path, var):
    from stickslip.plot.sweep import save_sweep_figure

    path = save_sweep_figure(load_sweep(swept[0]), tmp_path / f"{var}.png", var=var)
    assert path.stat().st_size > 10_000  # a drawn figure, not an empty canvas
    with pytest.raises(ValueError, match="choose one of"):
        save_sweep_figure(load_sweep(swept[0]), tmp_path / "x.png", var="peaks")


def test_regions_window_defaults_to_the_last_100_s_or_half(tmp_path):
    out = tmp_path / "w.nc"
    summary(run("regions", "--N", "50", "--omega", "12", "--t-end", "20", "--executor", "serial", "--no-plot",
                "--no-progress", "--out", str(out), "--json"))
    assert load_sweep(out).attrs["t_from"] == 10.0  # half of a run shorter than 200 s
