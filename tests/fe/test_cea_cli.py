"""``stickslip stability`` on finite-element model files: the band's JSON, the outputs, the refusals."""

import json

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.model.library import load_model
from stickslip.stability.band import band_stability

from .fe_models import pad_on_belt
from .refusals import refused


def run(*args):
    return CliRunner().invoke(app, ["stability", *args])


@pytest.fixture(scope="module")
def pad(tmp_path_factory):
    """A 10 × 4 pad on a belt (88 dofs, 11 contact nodes) in matrix files, past its flutter onset."""
    folder = tmp_path_factory.mktemp("pad")
    return pad_on_belt(10, 4, mu_k=0.5, delta_mu=0.0, preload=1e-5).write(folder / "pad", contacts="set")


def test_json_keeps_the_dense_form_and_lists_the_band(pad, tmp_path):
    out, vtk = tmp_path / "modes.nc", tmp_path / "modes.vtu"
    result = run("--model", str(pad), "--max-frequency", "4e5", "--json", "--out", str(out), "--vtk", str(vtk))
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output)
    library = band_stability(load_model(str(pad)), 4e5)
    assert summary["eigenvalues"] == [[v.real, v.imag] for v in library.eigenvalues]
    assert all(abs(im) <= 4e5 for _, im in summary["eigenvalues"]) and len(summary["eigenvalues"]) > 4
    assert summary["max_real_part"] == max(re for re, _ in summary["eigenvalues"])
    assert summary["stable"] is False and summary["method"] == "direct" and summary["dofs"] == 88
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        unstable = [j for j, v in enumerate(library.eigenvalues) if v.real > 0 and v.imag >= 0]
        assert list(ds["shape_mode"].values) == unstable
        np.testing.assert_array_equal(ds["shape_real"].values, library.mode_shapes[unstable].real)
    meshio = pytest.importorskip("meshio")
    mesh = meshio.read(vtk)
    assert len(mesh.point_data) == 2 * len(unstable)


def test_modal_method_table(pad):
    result = run("--model", str(pad), "--max-frequency", "4e5", "--method", "modal")
    assert result.exit_code == 0, result.output
    assert "modal CEA" in result.output and "max real part in the band" in result.output
    summary = json.loads(run("--model", str(pad), "--max-frequency", "4e5", "--method", "modal", "--json").output)
    alone = json.loads(run("--model", str(pad), "--max-frequency", "4e5", "--method", "modal", "--json",
                           "--no-residual-vectors").output)
    assert summary["modal"]["residual_vectors"] > 0 and alone["modal"]["residual_vectors"] == 0
    # both refined on the full model
    np.testing.assert_allclose(summary["eigenvalues"], alone["eigenvalues"], rtol=1e-9)
    last, last_alone = summary["modal"]["convergence"][-1], alone["modal"]["convergence"][-1]
    assert last["modes_only_error"] == pytest.approx(last_alone["max_relative_error"], rel=1e-9)


def test_refusals(pad, tmp_path):
    refused(run("--model", str(pad)), "give --max-frequency")
    refused(run("--model", str(pad), "--max-frequency", "10"), "no eigenvalue with frequency below 10 rad/s")
    refused(run("--model", str(pad), "--max-frequency", "-1"), "--max-frequency -1 must be")
    refused(run("--model", str(pad), "--max-frequency", "4e5", "--method", "qz"), "--method qz: choose one of")
    refused(run("--model", str(pad), "--max-frequency", "4e5", "--cutoff", "1e6"), "give --method modal")
    refused(run("--model", str(pad), "--max-frequency", "4e5", "--no-residual-vectors"), "belongs to --method modal")
    out = tmp_path / "exists.nc"
    out.write_text("mine")
    refused(run("--model", str(pad), "--max-frequency", "4e5", "--out", str(out)), "--overwrite")
    assert out.read_text() == "mine"
    refused(run("--model", "belt", "--max-frequency", "3", "--vtk", str(tmp_path / "b.vtu")), "no node coordinates")


def test_small_library_model_unchanged_without_band_options():
    result = run("--model", "hoffmann", "--json")
    assert result.exit_code == 0
    assert "method" not in json.loads(result.output)
