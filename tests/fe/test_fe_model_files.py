"""Model files of finite-element size (docs/models.md, "Finite-element models"): matrix files,
dofs by count, sparse tables, Rayleigh damping, contact sets, nodes; the same model as written
out inline; every --set path; a large pad kept sparse."""

import copy

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp
import tomli_w

from stickslip.errors import ModelFileError
from stickslip.model.library import system_from_description, describe_system
from stickslip.model.model_file import load_model_file, model_from_spec

from .fe_models import bar_chain, pad_on_belt


def same_model(a, b):
    """The same M, C, K, f0, contacts (rows, drives, laws, gaps) and compiled data, bit for bit."""
    for key in ("mass", "damping", "stiffness"):
        x, y = getattr(a, key), getattr(b, key)
        x, y = (x.toarray() if sp.issparse(x) else x), (y.toarray() if sp.issparse(y) else y)
        assert np.array_equal(x, y), key
    assert np.array_equal(a.force, b.force) and a.dofs == b.dofs and a.n_contacts == b.n_contacts
    fa, fb = a.sparse_form(), b.sparse_form()
    for key in ("tangent", "gap_gradient", "normal_gradient"):
        assert abs(getattr(fa, key) - getattr(fb, key)).max() == 0.0 if getattr(fa, key).nnz else True, key
    for key in ("drive", "gap", "normal_force", "contact_stiffness", "contact_damping", "unilateral", "normal_law"):
        assert np.array_equal(getattr(fa, key), getattr(fb, key)), key
    assert [law.to_dict() for law in fa.friction] == [law.to_dict() for law in fb.friction]
    if a.dense:
        assert a.data.m.tobytes() == b.data.m.tobytes()


@pytest.mark.parametrize("matrix_format", ["mtx", "npz", "mat"])
@pytest.mark.parametrize("contacts", ["set", "set-inline", "tables"])
def test_a_model_with_matrix_files_is_the_model_written_inline(tmp_path, matrix_format, contacts):
    fe = pad_on_belt(3, 2, alpha=3.0)
    inline = model_from_spec(fe.inline_spec())
    files = load_model_file(fe.write(tmp_path, matrix_format=matrix_format, contacts=contacts))
    assert files.n == 16 and files.dense and files.n_contacts == 4
    same_model(files, inline)


def test_an_explicit_damping_file_and_a_sparse_force(tmp_path):
    fe = bar_chain(5, damping=0.3)
    fe.force = {1: 0.25, 4: -0.5}
    files = load_model_file(fe.write(tmp_path, contacts="tables"))
    same_model(files, model_from_spec(fe.inline_spec()))
    assert files.force.tolist() == [0.0, 0.25, 0.0, 0.0, -0.5]
    assert files.replace(**{"force.u4": 1.0}).force[4] == 1.0


def test_rayleigh_damping_follows_its_coefficients_and_the_matrices(tmp_path):
    fe = pad_on_belt(3, 2, rayleigh=(0.5, 2e-6))
    model = load_model_file(fe.write(tmp_path))
    M, K = fe.mass.toarray(), fe.stiffness.toarray()
    assert np.array_equal(model.damping, 0.5 * M + 2e-6 * K)
    changed = model.replace(**{"damping.rayleigh.1": 1e-5, "stiffness.scale": 2.0})
    assert np.allclose(changed.damping, 0.5 * M + 1e-5 * 2.0 * K, rtol=1e-15, atol=0)
    assert np.array_equal(changed.stiffness, 2.0 * K)


def test_every_number_of_a_contact_set_is_a_parameter(tmp_path):
    fe = pad_on_belt(3, 2)
    model = load_model_file(fe.write(tmp_path))
    paths = set(model.parameters)
    for path in ("contact_set.pad.friction.mu_k", "contact_set.pad.friction.law", "contact_set.pad.normal.stiffness",
                 "contact_set.pad.normal.damping", "contact_set.pad.drive", "mass.scale", "stiffness.scale",
                 "damping.rayleigh.0", "damping.rayleigh.1", "contact_set.pad.nodes.1.gap", "slip_band"):
        assert path in paths, path
    changed = model.replace(**{"contact_set.pad.friction.mu_k": 0.45, "contact_set.pad.nodes.2.gap": -3e-6,
                               "contact_set.pad.drive": 0.8})
    form = changed.sparse_form()
    assert all(law.mu_k == 0.45 for law in form.friction)
    assert form.gap.tolist() == [-1e-6, -3e-6, -1e-6, -1e-6]
    assert np.all(form.drive == 0.8)
    assert changed.contact_names == ("pad_1", "pad_2", "pad_3", "pad_4")


def test_a_pressed_set_takes_its_normal_force_per_node_or_for_the_set(tmp_path):
    fe = pad_on_belt(3, 2, normal_force=2.5)
    model = load_model_file(fe.write(tmp_path, contacts="set-inline"))
    assert [c.normal_force for c in model.contacts] == [2.5] * 4 and not model.unilateral
    spec = copy.deepcopy(model.spec)
    del spec["contact_set"]["pad"]["normal_force"]
    for k, node in enumerate(spec["contact_set"]["pad"]["nodes"].values()):
        node["normal_force"] = 1.0 + k
    per_node = model_from_spec(spec)
    assert [c.normal_force for c in per_node.contacts] == [1.0, 2.0, 3.0, 4.0]
    assert per_node.replace(**{"contact_set.pad.nodes.4.normal_force": 9.0}).contacts[3].normal_force == 9.0


def test_a_result_rebuilds_its_model_from_the_frozen_spec(tmp_path, monkeypatch):
    folder = tmp_path / "model"
    model = load_model_file(pad_on_belt(3, 2).write(folder))
    (folder / "contact_nodes.csv").unlink()  # the spec holds the set's nodes itself
    monkeypatch.chdir(tmp_path)
    rebuilt = system_from_description(describe_system(model))
    same_model(rebuilt, model)
    assert rebuilt.spec["mass"]["file"] == str(folder / "M.mtx") and len(rebuilt.spec["mass"]["sha256"]) == 64
    scipy.io.mmwrite(str(folder / "M.mtx"), (pad_on_belt(3, 2).mass * 2.0).tocoo())
    with pytest.raises(ModelFileError, match="not the file the model was made with"):
        system_from_description(describe_system(model))


def test_nodes_map_each_dof_to_its_node(tmp_path):
    fe = pad_on_belt(3, 2, length=0.3, height=0.2)
    model = load_model_file(fe.write(tmp_path))
    nodes = model.sparse_form().nodes
    assert len(nodes.ids) == 4 * 3 and np.array_equal(nodes.node, np.arange(16) // 2)
    assert np.array_equal(nodes.component, np.arange(16) % 2)
    assert np.allclose(nodes.coordinates[nodes.node[11]], [0.1, 0.1, 0.0])  # u11: the y of node (1, 1), index 5
    shape = np.zeros(16)
    shape[11] = 1.0
    assert np.array_equal(nodes.displacement(shape)[5], [0.0, 1.0, 0.0])


def test_a_large_pad_stays_sparse_from_its_files(tmp_path):
    fe = pad_on_belt(60, 12)
    model = load_model_file(fe.write(tmp_path, matrix_format="npz"))
    assert model.n == 1464 and not model.dense and model.n_contacts == 61
    assert isinstance(model.mass, sp.csr_matrix) and model.mass.nnz == fe.mass.nnz
    assert all(sp.issparse(c.tangent) and c.tangent.nnz == 1 for c in model.contacts)
    form = model.sparse_form()
    assert abs(form.stiffness - fe.stiffness).max() == 0.0
    assert np.array_equal(form.tangent.indices, fe.tangent_dof)
    assert np.array_equal(form.gap_gradient.indices, fe.normal_dof)
    assert model.replace(**{"contact_set.pad.friction.mu_k": 0.2}).mass is model.mass  # not read or copied again


def test_sparse_tables_name_dofs(tmp_path):
    spec = {"name": "t", "dofs": {"count": 3, "prefix": "q"}, "mass": [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]],
            "stiffness": [[2.0, -1, 0], [-1, 2.0, -1], [0, -1, 1.0]], "force": {"q2": 0.5},
            "contact": [{"tangent": [{"q0": 1.0, "q2": -0.5}], "drive": 0.3, "gap": -0.01,
                         "gap_gradient": {"q1": -1.0}, "normal": {"stiffness": 100.0},
                         "friction": {"law": "coulomb", "mu_k": 0.2, "delta_mu": 0.0}}]}
    model = model_from_spec(spec)
    assert model.dofs == ("q0", "q1", "q2") and np.array_equal(model.damping, np.zeros((3, 3)))
    assert model.contacts[0].tangent.tolist() == [[1.0, 0.0, -0.5]]
    assert model.contacts[0].gap_gradient.tolist() == [0.0, -1.0, 0.0]
    assert model.replace(**{"contact.0.tangent.0.q2": 0.25}).contacts[0].tangent[0, 2] == 0.25
    assert model.replace(**{"contact.0.gap_gradient.q1": -2.0}).contacts[0].gap_gradient[1] == -2.0


def write(tmp_path, spec, name="model.toml"):
    path = tmp_path / name
    path.write_text(tomli_w.dumps(spec))
    return path


def refused(path, *words):
    with pytest.raises(ModelFileError) as info:
        load_model_file(path)
    message = str(info.value)
    assert "\n" not in message, message
    for word in words:
        assert word in message, (word, message)
    return message


def fe_spec(tmp_path, **changes):
    fe = pad_on_belt(3, 2)
    path = fe.write(tmp_path / "base", contacts="set-inline")
    spec = {**load_model_file(path).spec}
    spec.update(changes)
    return spec


@pytest.mark.parametrize("change, words", [
    ({"mass": "missing.mtx"}, ("mass", "missing.mtx", "does not exist")),
    ({"dofs": {"count": 15, "prefix": "u"}}, ("mass", "16×16", "must be 15×15")),
    ({"dofs": {"count": 0}}, ("dofs.count",)),
    ({"dofs": {"counts": 3}}, ("dofs as a table",)),
    ({"mass": {"file": "M.mtx", "scal": 2.0}}, ("mass", "unknown key", "scal")),
    ({"damping": {"rayleigh": [1.0]}}, ("damping.rayleigh", "[alpha, beta]")),
    ({"force": {"u99": 1.0}}, ("force.u99", "not a dof")),
    ({"nodes": "nope.csv"}, ("nodes file", "does not exist")),
])
def test_bad_fe_entries_are_refused_in_one_line(tmp_path, change, words):
    spec = fe_spec(tmp_path, **change)
    if isinstance(change.get("mass"), dict):
        spec["mass"] = {**change["mass"], "file": str(tmp_path / "base" / "M.mtx")}
    refused(write(tmp_path, spec), *words)


def test_bad_matrix_files_are_refused_in_one_line(tmp_path):
    spec = fe_spec(tmp_path)
    M = pad_on_belt(3, 2).mass
    bad = {
        "rect.mtx": lambda p: scipy.io.mmwrite(str(p), sp.random(16, 15, density=0.2, random_state=0)),
        "nan.mtx": lambda p: scipy.io.mmwrite(str(p), sp.csr_matrix(np.diag([np.nan] + [1.0] * 15))),
        "text.mtx": lambda p: p.write_text("not a matrix\n"),
        "broken.npz": lambda p: p.write_bytes(b"PK\x03\x04 not a zip"),
        "skew.mtx": lambda p: scipy.io.mmwrite(str(p), (M + sp.csr_matrix(([1e-3], ([0], [1])), shape=(16, 16)))
                                               .tocoo()),
        "indefinite.mtx": lambda p: scipy.io.mmwrite(str(p), (M - 1e-3 * sp.identity(16)).tocoo()),
    }
    words = {"rect.mtx": ("16×15", "must be 16×16"), "nan.mtx": ("non-finite",), "text.mtx": ("Abaqus",),
             "broken.npz": ("cannot be read",), "skew.mtx": ("symmetric",), "indefinite.mtx": ("positive definite",)}
    for name, make in bad.items():
        make(tmp_path / name)
        refused(write(tmp_path, {**spec, "mass": name}), name if name not in ("skew.mtx", "indefinite.mtx") else "mass",
                *words[name])


def test_a_matrix_file_that_is_a_folder_pipe_or_device_is_refused(tmp_path):
    import os
    spec = fe_spec(tmp_path)
    (tmp_path / "folder.mtx").mkdir()
    os.mkfifo(tmp_path / "pipe.mtx")
    (tmp_path / "zero.mtx").symlink_to("/dev/zero")
    for name in ("folder.mtx", "pipe.mtx", "zero.mtx"):
        refused(write(tmp_path, {**spec, "mass": name}), name, "not a regular file")


def test_bad_contact_sets_are_refused_in_one_line(tmp_path):
    spec = fe_spec(tmp_path)
    pad = spec["contact_set"]["pad"]
    nodes = pad["nodes"]
    cases = [
        ({**pad, "nodes": {**nodes, "1": {**nodes["1"], "tangent": "x9"}}},
         ("contact_set.pad.nodes.1.tangent", "not a dof")),
        ({**pad, "nodes": {**nodes, "1": {**nodes["1"], "normal": "u99"}}}, ("nodes.1.normal", "not a dof")),
        ({k: v for k, v in pad.items() if k != "friction"}, ("contact_set.pad.friction is missing",)),
        ({k: v for k, v in pad.items() if k != "normal"}, ("nodes.1.normal is a unilateral contact's",)),
        ({**{k: v for k, v in pad.items() if k not in ("normal", "gap")},
          "nodes": {key: {"tangent": row["tangent"]} for key, row in nodes.items()}}, ("normal_force is missing",)),
        ({**pad, "nodes": {**nodes, "1": {**nodes["1"], "colour": 1}}}, ("unknown key", "colour")),
        ({**pad, "normal_sign": 2}, ("normal_sign",)),
        ({**pad, "normal": {"law": "compliant"}}, ("contact_set.pad.normal.stiffness is missing",)),
    ]
    for table, words in cases:
        refused(write(tmp_path, {**spec, "contact_set": {"pad": table}}), *words)
    (tmp_path / "nodes.csv").write_text("node,tangent,normal,gap\n1,u0,u1,0.0\n1,u2,u3,0.0\n")
    refused(write(tmp_path, {**spec, "contact_set": {"pad": {**pad, "nodes": "nodes.csv"}}}), "listed twice")
    (tmp_path / "nodes.csv").write_text("node,tangent,normal,gap\n1,u0,u1,zero\n")
    refused(write(tmp_path, {**spec, "contact_set": {"pad": {**pad, "nodes": "nodes.csv"}}}), "not a number")
    (tmp_path / "nodes.csv").write_text("nod,tangent\n1,u0\n")
    refused(write(tmp_path, {**spec, "contact_set": {"pad": {**pad, "nodes": "nodes.csv"}}}), "header", "node")


def test_the_docs_example_reads(tmp_path):
    """docs/models.md's pad.toml, beside the files the generator writes for the same pad."""
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "models.md").read_text()
    block = re.search(r"```toml\n# pad\.toml\n(.*?)```", text, re.DOTALL).group(1)
    fe = pad_on_belt(10, 4)
    fe.write(tmp_path, matrix_format="npz")  # K.npz, M.npz, nodes.csv, contact_nodes.csv
    scipy.io.mmwrite(str(tmp_path / "M.mtx"), fe.mass.tocoo(), precision=17)
    (tmp_path / "pad.toml").write_text(block)
    model = load_model_file(tmp_path / "pad.toml")
    assert model.n == 88 and model.n_contacts == 11 and not model.dense and model.force[3] == -0.5
    assert abs(model.damping - 1e-6 * fe.stiffness).max() == 0.0 and abs(model.mass - fe.mass).max() == 0.0
    assert model.nodes is not None and model.contact_names[0] == "pad_1"
    assert model.replace(**{"contact_set.pad.friction.mu_k": 0.2}).contacts[5].friction.mu_k == 0.2


def test_simulate_runs_the_same_on_matrix_files_and_inline(tmp_path):
    """The pad read from its matrix files and its contact set runs, step for step, as the same pad
    written out inline (16 dofs, four compliant contacts pressed into the belt)."""
    from stickslip import simulate

    fe = pad_on_belt(3, 2, E=1e6, rho=1000.0, contact_stiffness=1e4, preload=1e-4, rayleigh=(0.0, 1e-4))
    files = load_model_file(fe.write(tmp_path, matrix_format="npz"))
    inline = model_from_spec(fe.inline_spec())
    a, b = simulate(files, 0.05), simulate(inline, 0.05)
    assert a.status == "success" and a.stats.steps > 10
    for key in ("t", "states", "friction", "mode"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key
