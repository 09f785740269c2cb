"""``stickslip stability`` and ``stickslip stability-map`` on models other than the plates."""

import json
import math

import numpy as np
import xarray as xr
from typer.testing import CliRunner

from stickslip.cli import app

runner = CliRunner()

# written by hand as in docs/models.md: Hoffmann's minimal flutter model with damping
HOFFMANN = """
name = "my-hoffmann"
dofs = ["x", "y"]
mass = [[1.0, 0.0], [0.0, 1.0]]
damping = [[0.1, 0.0], [0.0, 0.1]]
stiffness = [[2.0, 1.0], [1.0, 2.0]]

[[contact]]
tangent = [[1.0, 0.0]]
drive = [1.0]
normal_force = 1.0
normal_gradient = [0.0, 1.0]
[contact.friction]
law = "coulomb"
mu_k = 0.5
delta_mu = 0.0
"""


def test_stability_json_of_a_hand_written_model_file(tmp_path):
    path = tmp_path / "hoffmann.toml"
    path.write_text(HOFFMANN)
    result = runner.invoke(app, ["stability", "--model", str(path), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert set(data) >= {"equilibrium", "eigenvalues", "max_real_part", "stable"}
    # K(μ) q = (μ N0, 0) with K(μ) = [[2, 1 − μ], [1, 2]], μ = 0.5
    q = np.linalg.solve([[2.0, 0.5], [1.0, 2.0]], [0.5, 0.0])
    assert set(data["equilibrium"]) == {"x", "y"}
    assert math.isclose(data["equilibrium"]["x"], q[0], abs_tol=1e-14)
    A = np.zeros((4, 4))
    A[:2, 2:] = np.eye(2)
    A[2:, :2] = -np.array([[2.0, 0.5], [1.0, 2.0]])
    A[2:, 2:] = -0.1 * np.eye(2)
    ref = np.sort_complex(np.linalg.eigvals(A))
    got = np.sort_complex(np.array([complex(re, im) for re, im in data["eigenvalues"]]))
    np.testing.assert_allclose(got, ref, atol=1e-12)
    assert data["stable"] is True
    table = runner.invoke(app, ["stability", "--model", str(path), "--set", "contact.0.friction.mu_k=1.5"])
    assert table.exit_code == 0 and "unstable" in table.stdout and "my-hoffmann" in table.stdout


def test_stability_of_a_library_model_with_set():
    result = runner.invoke(app, ["stability", "--model", "belt", "--set", "contact.0.drive=0.8", "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["stable"] is False  # below V_c = 1.15 (docs/stability.md)
    result = runner.invoke(app, ["stability", "--model", "belt", "--N", "50"])
    assert result.exit_code == 2 and "--N is a parameter of the two plates" in result.output


def test_stability_map_over_model_paths(tmp_path):
    out = tmp_path / "belt.nc"
    result = runner.invoke(app, ["stability-map", "--model", "belt", "--axis", "contact.0.normal_force=0.5:2:4",
                                 "--axis", "contact.0.drive=0.2:3:8", "--family", "contact.0.friction.alpha=1.5,2",
                                 "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["axes"] == ["contact.0.normal_force", "contact.0.drive"] and len(data["members"]) == 2
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds["max_real_part"].dims == ("family", "contact.0.normal_force", "contact.0.drive")
        # the boundary along the drive is V_c = ln(α Δμ N / 2ξ)/α (Δμ = 0.5, 2ξ = 0.1)
        for f, alpha in enumerate((1.5, 2.0)):
            for a, n in enumerate(ds["contact.0.normal_force"].values):
                expected = math.log(alpha * 0.5 * n / 0.1) / alpha
                assert abs(float(ds["boundary"][f, a, 0]) - expected) < 1e-9
    assert out.with_suffix(".png").exists()


def test_stability_map_errors(tmp_path):
    out = str(tmp_path / "m.nc")
    result = runner.invoke(app, ["stability-map", "--model", "belt", "--out", out])
    assert result.exit_code == 2 and "give its two axes" in result.output
    result = runner.invoke(app, ["stability-map", "--model", "belt", "--axis", "contact.0.drive=0.2:3:8", "--out", out])
    assert result.exit_code == 2 and "exactly twice" in result.output
    result = runner.invoke(app, ["stability-map", "--model", "belt", "--axis", "contact.0.drive=0.2:3:8",
                                 "--axis", "contact.0.nonsense=1:2:3", "--out", out])
    assert result.exit_code == 2 and "nonsense" in result.output and "Traceback" not in result.output
