"""Bad input of finite-element models on the command line: one line, exit 2, never a traceback
(matrix files, dof names, the model file and --config as folders, pipes or /dev/zero, sizes)."""

import os

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp
import tomli_w
from typer.testing import CliRunner

from stickslip.cli import app

from .fe_models import pad_on_belt
from .refusals import refused


def run(*args):
    return CliRunner().invoke(app, ["simulate", "--t-end", "1", "--no-plot", *args])


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    pad_on_belt(3, 2).write(tmp_path / "pad", contacts="set-inline")
    return tmp_path


def model_file(folder, **changes):
    from stickslip.model.model_file import load_model_file

    spec = dict(load_model_file(folder / "pad" / "model.toml").spec)
    spec.update(changes)
    path = folder / "bad.toml"
    path.write_text(tomli_w.dumps(spec))
    return str(path)


def test_matrix_files_that_cannot_be_the_model_are_refused(folder):
    n = 16
    M = pad_on_belt(3, 2).mass
    scipy.io.mmwrite(str(folder / "rect.mtx"), sp.random(n, n - 1, density=0.3, random_state=1))
    scipy.io.mmwrite(str(folder / "nan.mtx"), sp.csr_matrix(np.diag([np.inf] + [1.0] * (n - 1))))
    scipy.io.mmwrite(str(folder / "indefinite.mtx"), (M - 1e-3 * sp.identity(n)).tocoo())
    (folder / "unreadable.mtx").write_text("1 2\n")
    os.chmod(folder / "unreadable.mtx", 0)
    cases = [("missing.mtx", ("mass", "missing.mtx", "does not exist")),
             ("rect.mtx", ("16×15", "16×16")),
             ("nan.mtx", ("non-finite",)),
             ("indefinite.mtx", ("mass", "not positive definite")),
             ("unreadable.mtx" if os.geteuid() != 0 else "missing.mtx", ("mass",))]
    for name, words in cases:
        refused(run("--model", model_file(folder, mass=name)), *words)


def test_dof_names_that_do_not_exist_or_repeat_are_refused(folder):
    refused(run("--model", model_file(folder, force={"u16": 1.0})), "force.u16", "not a dof")
    spec_dofs = [f"u{i}" for i in range(15)] + ["u3"]
    refused(run("--model", model_file(folder, dofs=spec_dofs)), "u3", "given twice")


def test_a_model_a_folder_a_pipe_or_a_device_is_not_a_regular_file(folder):
    (folder / "dir.toml").mkdir()
    os.mkfifo(folder / "pipe.toml")
    (folder / "zero.toml").symlink_to("/dev/zero")
    for name in ("dir.toml", "pipe.toml", "zero.toml"):
        refused(run("--model", name), name, "not a regular file")
        refused(run("--config", name), "--config", name, "not a regular file")


def test_a_model_file_or_config_past_its_size_limit_is_refused(folder):
    with open(folder / "huge.toml", "wb") as fh:  # a sparse file: its size without writing it
        fh.truncate(65 * 2**20)
    refused(run("--model", "huge.toml"), "huge.toml", "larger than")
    refused(run("--config", "huge.toml"), "--config", "larger than")


def test_a_model_too_large_for_memory_is_refused_by_simulate(folder, monkeypatch):
    import stickslip.memory as memory

    pad_on_belt(10, 4).write(folder / "big", matrix_format="npz")
    monkeypatch.setattr(memory, "available_memory", lambda: 2e5)
    refused(run("--model", str(folder / "big" / "model.toml")), "88 dofs", "dofs fit", "stickslip reduce")
