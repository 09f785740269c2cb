"""Reduction: Craig–Bampton and modal truncation with the contact DOFs kept, the model file it writes,
the error report against the full model, and ``stickslip reduce``."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.model.library import load_model
from stickslip.reduction import ReductionError, boundary_dofs, reduce_model, reduction_report, write_model_file
from stickslip.stability.band import band_stability

from .brake_models import pad_on_strip_2d
from .fe_models import pad_on_belt


@pytest.fixture(scope="module")
def strip():
    return pad_on_strip_2d(strip=(60, 4), pad=(20, 4), mu=0.6, beta=2e-7)


OMEGA = 2 * np.pi * 30e3


@pytest.mark.parametrize("method", ["craig-bampton", "modal"])
def test_converges_to_the_full_eigenvalues(strip, method):
    errors = [reduction_report(strip, reduce_model(strip, method=method, modes=m).form, OMEGA).max_error
              for m in (10, 40, 80)]
    assert errors[2] < errors[1] < errors[0]
    assert errors[2] < (2e-3 if method == "craig-bampton" else 1e-5)


def test_kept_dofs_and_contacts_on_them(strip):
    reduced = reduce_model(strip, modes=20)
    b = boundary_dofs(strip)
    form = reduced.form
    assert form.dofs[:b.size] == tuple(strip.dofs[j] for j in b) and form.n == b.size + 20
    # the contact rows are the full model's rows on the kept DOFs, zero on the modal coordinates
    np.testing.assert_array_equal(form.tangent[:, :b.size].toarray(), strip.tangent[:, b].toarray())
    assert form.tangent[:, b.size:].nnz == 0 and form.gap_gradient[:, b.size:].nnz == 0
    # static condensation: the reduced model's steady state equals the full one on the kept DOFs
    full, red = band_stability(strip, OMEGA), band_stability(form, OMEGA * 1.2)
    np.testing.assert_allclose(red.equilibrium[:b.size], full.equilibrium[b], rtol=1e-9,
                               atol=1e-9 * np.max(np.abs(full.equilibrium)))


def test_model_file_reads_back(strip, tmp_path):
    reduced = reduce_model(strip, method="modal", modes=40)
    written = write_model_file(reduced.form, tmp_path / "red.toml")
    assert {p.name for p in written} == {"red.toml", "red_M.npz", "red_K.npz", "red_C.npz", "red_nodes.csv"}
    model = load_model(str(tmp_path / "red.toml"))
    assert model.dofs == reduced.form.dofs and model.n_contacts == strip.nc
    a, b = band_stability(model, OMEGA), band_stability(reduced.form, OMEGA)
    np.testing.assert_array_equal(a.eigenvalues, b.eigenvalues)
    from stickslip.errors import OutputError

    with pytest.raises(OutputError):
        write_model_file(reduced.form, tmp_path / "red.toml")


def test_refusals(strip):
    with pytest.raises(ReductionError, match="choose one of craig-bampton, modal"):
        reduce_model(strip, method="guyan", modes=3)
    with pytest.raises(ReductionError, match="give the modes to keep"):
        reduce_model(strip)


def test_cli(tmp_path):
    pad = pad_on_belt(10, 4, mu_k=0.5, delta_mu=0.0, preload=1e-5).write(tmp_path / "pad", contacts="set")
    out = tmp_path / "red.toml"
    args = ["reduce", "--model", str(pad), "--modes", "30", "--method", "modal", "--out", str(out), "--json"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output)
    assert summary["reduced_dofs"] == summary["kept_dofs"] + 30 and summary["check"]["max_relative_error"] < 1e-3
    again = CliRunner().invoke(app, args)
    assert again.exit_code == 2 and "--overwrite" in again.output and len(again.output.strip().splitlines()) == 1
    stable = CliRunner().invoke(app, ["stability", "--model", str(out), "--max-frequency", "2e5", "--json"])
    assert stable.exit_code == 0, stable.output
    missing = CliRunner().invoke(app, ["reduce", "--model", str(pad), "--out", str(tmp_path / "x.toml")])
    assert missing.exit_code == 2 and "give the modes to keep" in missing.output


def test_the_same_reduction_every_run(strip):
    """ARPACK starts from a fixed vector: two reductions of one model are the same bit for bit
    (its own start is random, and the modes' last digits would differ from run to run)."""
    first, second = (reduce_model(strip, method="craig-bampton", modes=6).form for _ in range(2))
    for a, b in zip((first.mass, first.stiffness), (second.mass, second.stiffness)):
        assert (abs(a - b)).max() == 0.0
