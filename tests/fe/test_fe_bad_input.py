"""Bad input of finite-element model files on the command line, the cases the other files leave out:
a dof name in a sparse contact table that the model lacks, and a dense path asked of a model too large
for memory (`stability --method dense`, `reduce`), each one line naming the setting that fits, exit 2."""

import pytest
import tomli_w
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.model.model_file import load_model_file

from .fe_models import pad_on_belt
from .refusals import refused


@pytest.fixture
def tables(tmp_path):
    """A 3 × 2 pad (16 dofs) whose contacts are ``[[contact]]`` tables with sparse rows by dof name."""
    path = pad_on_belt(3, 2).write(tmp_path / "pad", contacts="tables")
    return tmp_path, dict(load_model_file(path).spec)


@pytest.mark.parametrize("entry, value, words", [
    ("tangent", [{"u99": 1.0}], ("contact", "u99", "not a dof")),
    ("gap_gradient", {"v1": 1.0}, ("contact", "v1", "not a dof")),
])
def test_a_sparse_row_naming_a_dof_the_model_lacks(tables, entry, value, words):
    folder, spec = tables
    contacts = [dict(table) for table in spec["contact"]]
    contacts[1][entry] = value
    path = folder / "bad.toml"
    path.write_text(tomli_w.dumps({**spec, "contact": contacts}))
    refused(CliRunner().invoke(app, ["simulate", "--model", str(path), "--t-end", "1", "--no-plot"]), *words)
    refused(CliRunner().invoke(app, ["stability", "--model", str(path), "--max-frequency", "1e5"]), *words)


@pytest.fixture
def pad(tmp_path):
    """A 10 × 4 pad on a belt (88 dofs, 11 contact nodes) in matrix files."""
    return pad_on_belt(10, 4, mu_k=0.3, delta_mu=0.0, preload=1e-5).write(tmp_path / "pad", matrix_format="npz")


def test_dense_eigenvalues_of_a_model_too_large_for_memory(pad, monkeypatch):
    import stickslip.memory as memory

    # 88 dofs: the dense eigenvalues take 32 (2·88)² bytes = 0.99 MB; 0.2 MB holds 39 dofs
    monkeypatch.setattr(memory, "available_memory", lambda: 2e5)
    refused(CliRunner().invoke(app, ["stability", "--model", str(pad), "--max-frequency", "2e5", "--method", "dense"]),
            "88 DOFs", "--method direct", "fits up to 39 DOFs")


def test_a_matrix_file_too_large_for_memory_says_how_to_fit(pad, monkeypatch):
    import stickslip.memory as memory

    monkeypatch.setattr(memory, "available_memory", lambda: 1e4)
    result = CliRunner().invoke(app, ["stability", "--model", str(pad), "--max-frequency", "2e5"])
    refused(result, "reading mass from M.npz", "free memory")
    assert "(.npz)" not in result.output  # the file is an .npz already


def test_a_reduction_basis_too_large_for_memory(pad, monkeypatch, tmp_path):
    import stickslip.memory as memory

    # the basis: 24 bytes × 88 dofs × (22 kept + 10 modes) = 68 kB; reading the matrices takes 34 kB
    monkeypatch.setattr(memory, "available_memory", lambda: 5e4)
    refused(CliRunner().invoke(app, ["reduce", "--model", str(pad), "--modes", "10", "--out",
                                     str(tmp_path / "red.toml")]), "reduction basis", "88 DOFs", "keep fewer")
