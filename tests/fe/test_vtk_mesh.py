"""Mode shapes on the mesh: a model file's elements (``nodes = { file, elements }``) carried into
the VTK cells, read back with meshio and compared with the nodes' displacements computed here from
the CSVs alone; element types of 2-D and 3-D meshes; the refusals of a bad elements file."""

import csv
import dataclasses
import math

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import LineCollection
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.errors import ModelError, ModelFileError
from stickslip.model.library import load_model
from stickslip.model.model_file import model_from_spec
from stickslip.model.sparse_form import NodeMap
from stickslip.plot.fe import cell_edges, plot_mode_shape
from stickslip.stability.band import band_stability

from .brake_models import pad_on_belt_2d, pad_on_surface_3d
from .fe_models import pad_on_belt

meshio = pytest.importorskip("meshio")


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def pad(tmp_path_factory):
    """A 10 × 4 pad on a belt with its elements (88 dofs), past its flutter onset."""
    folder = tmp_path_factory.mktemp("pad")
    return pad_on_belt(10, 4, mu_k=0.5, delta_mu=0.0, preload=1e-5).write(folder / "pad", elements=True)


def test_vtu_cells_and_shapes_from_the_model_files(pad, tmp_path):
    vtu = tmp_path / "modes.vtu"
    result = CliRunner().invoke(app, ["stability", "--model", str(pad), "--max-frequency", "4e5", "--vtk", str(vtu),
                                      "--all-shapes"])
    assert result.exit_code == 0, result.output
    band = band_stability(load_model(str(pad)), 4e5)
    mesh = meshio.read(vtu)
    # the points and cells are the CSVs' nodes and elements (node ids turned into point indices)
    nodes = _rows(pad.parent / "nodes.csv")
    point = {int(row["node"]): k for k, row in enumerate(nodes)}
    np.testing.assert_array_equal(mesh.points, [[float(row[c]) for c in "xyz"] for row in nodes])
    elements = _rows(pad.parent / "elements.csv")
    assert [block.type for block in mesh.cells] == ["quad"]
    np.testing.assert_array_equal(mesh.cells[0].data, [[point[int(row[f"n{k}"])] for k in range(1, 5)]
                                                       for row in elements])
    # each mode's fields: the shape's value on each node's dof_x and dof_y, 0 on the clamped nodes
    index = {name: i for i, name in enumerate(band.dofs)}
    modes = [j for j, lam in enumerate(band.eigenvalues) if lam.imag >= 0.0]
    assert 2 * len(modes) == len(mesh.point_data) > 4
    for j in modes:
        expected = np.zeros((len(nodes), 3), complex)
        for k, row in enumerate(nodes):
            for axis, column in enumerate(("dof_x", "dof_y")):
                if row[column]:
                    expected[k, axis] = band.mode_shapes[j, index[row[column]]]
        name = f"mode{j}_{band.eigenvalues[j].imag / (2 * math.pi):.6g}Hz"
        np.testing.assert_array_equal(mesh.point_data[f"{name}_real"], expected.real)
        np.testing.assert_array_equal(mesh.point_data[f"{name}_imag"], expected.imag)


def _split(kind, cells):
    """Quads into two triangles each, hexahedra into six tetrahedra each (about the 0–6 diagonal)."""
    if kind == "triangle":
        return np.vstack([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])
    tets = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]
    return np.vstack([cells[:, t] for t in tets])


@pytest.mark.parametrize("make, kinds", [(lambda: pad_on_belt_2d(4, 2, mu=0.3), ("quad", "triangle")),
                                         (lambda: pad_on_surface_3d((2, 1, 1), mu=0.3), ("hexahedron", "tetra"))])
def test_element_types_round_trip(make, kinds, tmp_path):
    form = make()
    result = band_stability(form, 5e6)
    (kind, cells), = form.nodes.cells
    assert kind == kinds[0]
    for blocks in ([(kind, cells)], [(kinds[1], _split(kinds[1], cells))],
                   [(kind, cells[:1]), (kinds[1], _split(kinds[1], cells[1:]))]):
        nodes = dataclasses.replace(form.nodes, cells=tuple(blocks))
        path = tmp_path / f"{len(blocks)}-{blocks[-1][0]}.vtu"
        dataclasses.replace(result, form=dataclasses.replace(form, nodes=nodes)).write_vtk(path, "all")
        mesh = meshio.read(path)
        assert [(b.type, b.data.tolist()) for b in mesh.cells] == [(k, c.tolist()) for k, c in blocks]
        assert len(mesh.point_data) == 2 * int(np.sum(result.eigenvalues.imag >= 0))


def test_nodes_without_elements_are_vertices(tmp_path):
    form = pad_on_belt_2d(4, 2, mu=0.3)
    result = band_stability(dataclasses.replace(form, nodes=dataclasses.replace(form.nodes, cells=())), 5e6)
    result.write_vtk(tmp_path / "points.vtu", "all")
    mesh = meshio.read(tmp_path / "points.vtu")
    assert [b.type for b in mesh.cells] == ["vertex"] and len(mesh.cells[0].data) == len(form.nodes.ids)


def test_edges_and_the_mesh_in_the_mode_shape_figure():
    assert cell_edges([("quad", np.array([[0, 1, 4, 3], [1, 2, 5, 4]]))]).tolist() == [
        [0, 1], [0, 3], [1, 2], [1, 4], [2, 5], [3, 4], [4, 5]]
    assert len(cell_edges([("hexahedron", np.arange(8)[None])])) == 12
    assert len(cell_edges([("tetra", np.arange(4)[None]), ("triangle", np.array([[0, 1, 2]]))])) == 6
    form = pad_on_belt_2d(4, 2, mu=0.3)
    fig = plot_mode_shape(band_stability(form, 5e6))
    meshes = [c for c in fig.axes[0].collections if isinstance(c, LineCollection)]
    assert [len(c.get_segments()) for c in meshes] == [4 * 3 + 5 * 2] * 2  # undeformed and displaced
    plt.close(fig)


def _write(folder, pad_file, text):
    (folder / "bad.csv").write_text(text)
    spec = pad_file.read_text().replace('elements = "elements.csv"', 'elements = "bad.csv"')
    (folder / "bad.toml").write_text(spec)
    return folder / "bad.toml"


@pytest.mark.parametrize("text, words", [
    ("type,n1,n2,n3,n4\nbrick,1,2,13,12\n", ["line 2: type 'brick' is not an element type", "hexahedron"]),
    ("type,n1,n2,n3,n4\nquad,1,2,13\n", ["line 2: a quad element has 4 nodes", "n1 … n4"]),
    ("type,n1,n2,n3,n4\ntriangle,1,2,13,12\n", ["a triangle element has 3 nodes"]),
    ("type,n1,n2,n3,n4\nquad,1,2,13,999\n", ["node 999 is not in the nodes file"]),
    ("kind,n1\nquad,1\n", ["needs a header line with the columns type, n1"]),
])
def test_bad_elements_refused_in_one_line(pad, text, words):
    path = _write(pad.parent, pad, text)
    with pytest.raises(ModelFileError) as info:
        load_model(str(path))
    message = str(info.value)
    assert "\n" not in message and "bad.csv" in message
    for word in words:
        assert word in message, (word, message)


def test_the_spec_records_the_elements_file(pad, tmp_path):
    model = load_model(str(pad))
    table = model.spec["nodes"]
    assert table["elements"]["file"] == str(pad.parent / "elements.csv") and len(table["elements"]["sha256"]) == 64
    cells = model.sparse_form().nodes.cells
    assert cells[0][1].shape == (40, 4)
    rebuilt = model_from_spec(model.spec, base=tmp_path)  # a result's spec: absolute paths, checked digests
    np.testing.assert_array_equal(rebuilt.sparse_form().nodes.cells[0][1], cells[0][1])
    changed = dict(model.spec, nodes=dict(table, elements=dict(table["elements"], sha256="0" * 64)))
    with pytest.raises(ModelFileError, match="nodes.elements: elements.csv is not the file the model was made with"):
        model_from_spec(changed)


def test_node_map_refuses_bad_cells():
    base = {"ids": [1, 2, 3], "coordinates": np.zeros((3, 3)), "node": [0], "component": [0]}
    with pytest.raises(ModelError, match="quad elements have 4 nodes each"):
        NodeMap(**base, cells=[("quad", [[0, 1, 2]])])
    with pytest.raises(ModelError, match=r"node index must lie in \[0, 3\)"):
        NodeMap(**base, cells=[("triangle", [[0, 1, 3]])])
    with pytest.raises(ModelError, match="element type 'hex' is not one of"):
        NodeMap(**base, cells=[("hex", [[0, 1, 2]])])
