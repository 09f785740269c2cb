"""`stickslip orbit` and `stickslip lyapunov`: the files hold what the library computes with the
same options, the figures are drawn, --json parses, and bad input is one line with exit 2."""

import json

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from stickslip import Parameters
from stickslip.cli import app
from stickslip.orbits import lyapunov_spectrum, periodic_orbit
from stickslip.orbits.continuation import start_run
from stickslip.model.library import two_plates
from stickslip.sweep.spec import initial_condition

runner = CliRunner()

#: The default case (N = 50 N, Ω = 5 rad/s, Model 1): from --ic far a 10 s start run is on the
#: stick-slip orbit (T ≈ 0.37 s) closely enough for Newton (5 iterations, ~0.3 s).
SEARCH = 10.0

ORBIT_KEYS = {"out", "figure", "model", "period_s", "frequency_hz", "stick_phases", "stick_fraction", "contacts",
              "max_nontrivial_multiplier_abs", "trivial_multiplier_error", "stable", "verdict", "monodromy", "iterations",
              "residual", "wall_time_s", "compile_time_s"}
LYAPUNOV_KEYS = {"out", "figure", "model", "method", "t_transient_s", "t_average_s", "exponents", "largest",
                 "stick_phases", "wall_time_s", "compile_time_s", "seed", "t_frame_s"}


def _one_error_line(res, message):
    assert res.exit_code == 2, res.output
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and message in lines[0], res.output


@pytest.mark.parametrize("args, message", [
    (["--ic", "hot"], "unknown initial condition 'hot'; use 'zero', 'near', 'equilibrium', 'far'"),
    (["--search-time", "0"], "--search-time must be a finite number > 0"),
    (["--search-time", "nan"], "--search-time must be a finite number > 0"),
    (["--rtol", "-1e-10"], "rtol = -1e-10 must be a finite number > 0"),
    (["--tol", "inf"], "--tol must be a finite number > 0"),
    (["--slip-band", "0"], "slip_band = 0.0 must be a finite speed > 1e-13 m/s"),
    (["--monodromy", "exact"], "--monodromy exact: choose one of saltation, finite-difference"),
    (["--period-multiplicity", "0"], "--period-multiplicity must be >= 1"),
    (["--out", "o.txt"], "--out o.txt: give a path ending in .nc"),
    (["--model", "xyz"], "unknown model 'xyz'"),
    (["--set", "k_px"], "--set expects NAME=VALUE"),
    (["--N", "-5"], "N"),
])
def test_orbit_bad_input_is_one_line_and_exit_2(args, message, tmp_path):
    res = runner.invoke(app, ["orbit", *args] + ([] if "--out" in args else ["--out", str(tmp_path / "o.nc")]))
    _one_error_line(res, message)
    assert not (tmp_path / "o.nc").exists()


@pytest.mark.parametrize("args, message", [
    (["--ic", "hot"], "unknown initial condition 'hot'; use 'zero', 'near', 'equilibrium', 'far'"),
    (["--t-transient", "0"], "--t-transient must be a finite number > 0"),
    (["--t-average", "-10"], "--t-average must be a finite number > 0"),
    (["--t-average", "inf"], "--t-average must be a finite number > 0"),
    (["--rtol", "nan"], "rtol = nan must be a finite number > 0"),
    (["--slip-band", "-1"], "slip_band = -1.0 must be a finite speed > 1e-13 m/s"),
    (["--method", "qr"], "--method qr: choose one of variational, finite-difference"),
    (["--seed", "-1"], "--seed -1: give an integer >= 0"),
    (["--seed", "two"], "--seed"),
    (["--t-frame", "-1"], "--t-frame -1.0: give a finite time >= 0 [s]"),
    (["--t-frame", "nan"], "--t-frame nan: give a finite time >= 0 [s]"),
    (["--out", "l.csv"], "--out l.csv: give a path ending in .nc"),
    (["--model", "xyz"], "unknown model 'xyz'"),
    (["--config", "missing.toml"], "missing.toml"),
])
def test_lyapunov_bad_input_is_one_line_and_exit_2(args, message, tmp_path):
    res = runner.invoke(app, ["lyapunov", *args] + ([] if "--out" in args else ["--out", str(tmp_path / "l.nc")]))
    _one_error_line(res, message)
    assert not (tmp_path / "l.nc").exists()


def test_library_error_is_one_line(tmp_path):
    """A start run too short for two section crossings: the library's OrbitError, as one line."""
    res = runner.invoke(app, ["orbit", "--search-time", "0.05", "--out", str(tmp_path / "o.nc")])
    _one_error_line(res, "the guess run crosses section phi_max 0 times")
    assert not (tmp_path / "o.nc").exists()


def test_orbit_writes_the_library_orbit_and_a_figure(tmp_path):
    out = tmp_path / "orbit.nc"
    res = runner.invoke(app, ["orbit", "--N", "50", "--omega", "5", "--search-time", str(SEARCH), "--out", str(out),
                              "--json"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout.strip().splitlines()[-1])
    assert set(summary) == ORBIT_KEYS
    assert out.with_suffix(".png").stat().st_size > 10_000  # a drawn figure, not an empty canvas

    p = Parameters(N=50.0, Omega=5.0)
    orbit = periodic_orbit(p, start_run(p, "far", t_end=SEARCH), monodromy="saltation")
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["period"] == orbit.period
        assert ds.attrs["iterations"] == orbit.iterations and ds.attrs["model"] == "full"
        assert np.array_equal(ds["state_on_section"].values, orbit.state)
        assert np.array_equal(ds["multiplier_abs"].values, np.abs(orbit.multipliers))
    assert summary["period_s"] == orbit.period and summary["frequency_hz"] == orbit.frequency
    assert summary["stable"] == orbit.stable and summary["stick_phases"] == orbit.stick_phases
    assert summary["max_nontrivial_multiplier_abs"] == np.abs(orbit.nontrivial_multipliers).max()
    assert 0.0 < summary["stick_fraction"] < 1.0 and summary["monodromy"] == "saltation"


def test_orbit_human_summary(tmp_path):
    res = runner.invoke(app, ["orbit", "--search-time", str(SEARCH), "--monodromy", "finite-difference",
                              "--no-plot", "--out", str(tmp_path / "o.nc")])
    assert res.exit_code == 0, res.output
    assert "period" in res.output and "finite-difference" in res.output and "stable" in res.output
    assert (tmp_path / "o.nc").exists() and not (tmp_path / "o.png").exists()


@pytest.mark.parametrize("method", ["variational", "finite-difference"])
def test_lyapunov_writes_the_library_spectrum_and_a_figure(method, tmp_path):
    out = tmp_path / "lyapunov.nc"
    cfg = tmp_path / "p.toml"
    cfg.write_text("[parameters]\nN = 50\n")
    res = runner.invoke(app, ["lyapunov", "--config", str(cfg), "--omega", "5", "--t-transient", "5",
                              "--t-average", "10", "--method", method, "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.stdout.strip().splitlines()[-1])
    assert set(summary) == LYAPUNOV_KEYS and summary["method"] == method
    assert out.with_suffix(".png").stat().st_size > 10_000

    p = Parameters(N=50.0, Omega=5.0)
    state, pert = initial_condition("far", two_plates(p, "full"))
    S = lyapunov_spectrum(p, state, t_transient=5.0, t_average=10.0, perturbation=pert, method=method)
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert np.array_equal(ds["exponent"].values, S.exponents)
        assert np.array_equal(ds["estimate"].values, S.estimate)
    assert summary["exponents"] == sorted(S.exponents.tolist(), reverse=True)
    assert summary["largest"] == S.exponents.max()


def test_lyapunov_human_summary(tmp_path):
    res = runner.invoke(app, ["lyapunov", "--ic", "near", "--t-transient", "2", "--t-average", "3", "--no-plot",
                              "--out", str(tmp_path / "l.nc")])
    assert res.exit_code == 0, res.output
    assert "λ [1/s]" in res.output and "wall time" in res.output
    assert (tmp_path / "l.nc").exists() and not (tmp_path / "l.png").exists()


def test_orbit_and_lyapunov_of_a_model_file(tmp_path):
    """--model on a library model file, --ic by state name, --section on a named dof: the files hold
    what the library computes; the figures are drawn for a model without φ."""
    out = tmp_path / "belt.nc"
    res = runner.invoke(app, ["orbit", "--model", "belt", "--ic", "x=0,dx=1.5", "--search-time", "60",
                              "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    s = json.loads(res.output)
    ref = periodic_orbit("belt", {"x": 0.0, "dx": 1.5}, search_time=60.0)
    assert s["model"] == "belt" and s["period_s"] == pytest.approx(ref.period, rel=1e-12)
    assert s["stick_phases"] == 1 and s["max_nontrivial_multiplier_abs"] < 1e-8
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert list(ds["state"].values) == ["x", "dx"] and ds.attrs["model"] == "belt"
    assert (tmp_path / "belt.png").stat().st_size > 0
    ps = tmp_path / "ps.nc"
    res = runner.invoke(app, ["orbit", "--model", "popp-stelter", "--ic", "x1=0.5,x2=-0.5", "--search-time", "200",
                              "--section", "x2_max", "--out", str(ps), "--json", "--no-plot"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.output)["stick_phases"] == 2
    ly = tmp_path / "ly.nc"
    res = runner.invoke(app, ["lyapunov", "--model", "belt", "--ic", "x=0,dx=1.5", "--t-transient", "20",
                              "--t-average", "60", "--out", str(ly), "--json"])
    assert res.exit_code == 0, res.output
    ex = json.loads(res.output)["exponents"]
    ref = lyapunov_spectrum("belt", {"x": 0.0, "dx": 1.5}, t_transient=20.0, t_average=60.0)
    assert np.allclose(ex, ref.exponents, rtol=1e-12)
    res = runner.invoke(app, ["lyapunov", "--model", "belt", "--ic", "x=0,dx=1.5", "--t-transient", "20",
                              "--t-average", "60", "--seed", "7", "--t-frame", "0", "--out", str(ly), "--overwrite",
                              "--json", "--no-plot"])
    assert res.exit_code == 0, res.output
    summary = json.loads(res.output)
    assert summary["seed"] == 7 and summary["t_frame_s"] == 0.0
    ref = lyapunov_spectrum("belt", {"x": 0.0, "dx": 1.5}, t_transient=20.0, t_average=60.0, seed=7, t_frame=0.0)
    assert np.allclose(summary["exponents"], sorted(ref.exponents, reverse=True), rtol=1e-12)
    assert not np.allclose(summary["exponents"], ex, rtol=1e-12)  # another frame, another finite-time estimate


@pytest.mark.parametrize("cmd, args, message", [
    ("orbit", ["--model", "belt", "--ic", "far"], "unknown initial condition 'far'; use 'zero', 'near', 'equilibrium', a path"),
    ("orbit", ["--model", "belt", "--N", "40"], "--N is a parameter of the two plates"),
    ("orbit", ["--model", "belt", "--section", "phi_max", "--ic", "zero"], "unknown section 'phi_max'"),
    ("orbit", ["--model", "belt", "--section", "x=high"], "--section x=high"),
    ("lyapunov", ["--model", "belt", "--set", "contact.0.drive=fast"], "contact.0.drive"),
])
def test_model_file_bad_input_is_one_line_and_exit_2(tmp_path, cmd, args, message):
    res = runner.invoke(app, [cmd, *args, "--out", str(tmp_path / "o.nc"), "--search-time", "1"]
                        if cmd == "orbit" else [cmd, *args, "--out", str(tmp_path / "o.nc")])
    _one_error_line(res, message)


def test_orbit_that_converges_onto_steady_sliding_is_refused_in_one_line(tmp_path):
    """The two-mass belt from rest: shooting from the 59.9 s start run's crossings converges onto
    steady sliding (tests/orbits/test_special_points.py shows independently that a run from such a
    state barely moves); it is refused as such, exit 2, nothing written."""
    from pathlib import Path

    model = Path(__file__).parents[1] / "orbits" / "two_mass_belt.toml"
    out = tmp_path / "o.nc"
    res = runner.invoke(app, ["orbit", "--model", str(model), "--ic", "zero", "--search-time", "59.9",
                              "--period-multiplicity", "2", "--no-plot", "--json", "--out", str(out)])
    assert res.exit_code == 2, res.output
    assert res.stdout == "" and len(res.stderr.strip().splitlines()) == 1
    assert "converged onto steady sliding" in res.stderr and "--search-time" in res.stderr
    assert not out.exists()


def test_a_negative_return_time_suggests_another_section():
    from stickslip.errors import OrbitError
    from stickslip.model.library import load_model
    from stickslip.orbits.section import flow

    with pytest.raises(OrbitError, match=r"T = -0\.836 s is not positive.*--section on the command line"):
        flow(load_model("impact-oscillator"), np.zeros(4), -0.836, rtol=1e-10, atol=1e-13)
