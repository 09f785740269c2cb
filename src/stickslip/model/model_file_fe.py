"""Model files of finite-element size: dofs by count, matrices in files, sparse tables, Rayleigh
damping, contact sets and mesh nodes (docs/models.md, "Finite-element models").

What :mod:`stickslip.model.model_file` takes from here:

* :func:`dof_names` — ``dofs = ["x", "y"]``, ``{ count = N, prefix = "u" }`` (``u0 … u{N-1}``) or
  ``{ from = "stiffness", prefix = "n" }`` (named after a matrix file's node and component labels:
  ``n12_1``);
* :class:`FileMatrices` — the matrix files of ``mass``, ``stiffness``, ``damping`` (a path relative to
  the model file, or a table ``{ file, matrix, format, symmetric, scale, sha256 }``), read once per
  model file, checked square of the model's size, labelled ones aligned by label; ``scale`` is a
  parameter (``--set mass.scale=1.1``), ``sha256`` (written into results) checks that a file has not
  changed;
* sparse tables ``{ dof = value }`` for any vector and for each row of a contact's ``tangent``;
* :class:`ContactSet` — ``[contact_set.NAME]``: many alike contacts from a CSV (or a table) of
  contact nodes, sharing their laws;
* :func:`read_nodes` — ``nodes = "nodes.csv"``: the mesh's coordinates and each dof's node
  (:class:`~stickslip.model.sparse_form.NodeMap`); ``nodes = { file = "nodes.csv", elements =
  "elements.csv" }`` adds the elements (type and node ids), so that mode shapes are drawn on the
  mesh.

A model file is read once: files and CSVs are read into the checked template, and the frozen spec
(``model.spec``, written into results) holds each file as an absolute path with its SHA-256 and each
contact set's nodes as a table, so that a result rebuilds its model without the CSVs and refuses
a matrix file that has changed since.
"""

from __future__ import annotations

import csv
import dataclasses
import io
from pathlib import Path
from typing import Mapping

import numpy as np
# scipy.sparse is imported in the functions that use it: a dense model (the two plates, most model
# files) never needs it, and its import costs every command's start-up time.

from ..errors import ModelError, ModelFileError
from ..inputs import read_regular_file, regular_file_size
from ..memory import check_memory, format_bytes
from .fe_files import MatrixData, file_digest, read_matrix, split_reference
from .sparse_form import CELL_NODES, COMPONENTS, NodeMap
from .system_model import check_name, check_text

__all__ = ["dof_names", "FileMatrices", "ContactSet", "read_nodes", "read_elements", "ELEMENT_COLUMNS",
           "is_file_reference", "Triplets", "FILE_KEYS",
           "SET_KEYS", "MAX_TABLE_BYTES", "MAX_DOF_COUNT", "dof_index", "set_nodes", "contact_set", "file_table"]

#: Keys of a matrix file's table.
FILE_KEYS = ("file", "matrix", "format", "symmetric", "scale", "sha256")
#: Keys of a ``[contact_set.NAME]`` table.
SET_KEYS = ("nodes", "drive", "gap", "normal_force", "normal_sign", "normal", "friction")
#: Columns of a contact set's nodes (``node`` and ``tangent`` required).
SET_COLUMNS = ("node", "name", "tangent", "tangent2", "normal", "gap", "drive", "drive2", "normal_force")
#: Columns of a ``nodes`` CSV (``node``, ``x``, ``y`` required).
NODE_COLUMNS = ("node", "x", "y", "z") + tuple(f"dof_{c}" for c in COMPONENTS)
#: Columns of an ``elements`` CSV: ``type`` and the element's node ids ``n1`` … (VTK's order; as many
#: as its type has, the rest empty); ``element``, the element's id, is optional.
ELEMENT_COLUMNS = ("element", "type") + tuple(f"n{k}" for k in range(1, max(CELL_NODES.values()) + 1))
#: Largest CSV of nodes or contact nodes read [bytes].
MAX_TABLE_BYTES = 2**30
#: Python objects per byte of a CSV while parsed (strings and lists of the rows).
_CSV_COPIES = 12
#: Most dofs ``{ count = N }`` may name (the names alone take about 60 bytes each).
MAX_DOF_COUNT = 10**8


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def is_file_reference(value) -> bool:
    """Whether a matrix entry names a file (a path, or a table with ``file``)."""
    return isinstance(value, str) or (isinstance(value, Mapping) and "file" in value)


# ----------------------------------------------------------------------------- dofs
def dof_names(value, labels=None) -> tuple[str, ...]:
    """The dof names of ``dofs``: a list, ``{ count, prefix }``, or ``{ from, prefix }`` with the
    (node, component) ``labels`` of that matrix (read by the caller)."""
    if isinstance(value, list):
        if not value or not all(isinstance(d, str) and d for d in value):
            raise ModelFileError(f"dofs must be a non-empty list of names, e.g. dofs = [\"x\", \"y\"], got "
                                 f"{_short(value)}")
        if len(set(value)) != len(value):
            seen: set = set()
            twice = next(d for d in value if d in seen or seen.add(d))
            raise ModelFileError(f"dofs: {twice!r} is given twice; give each dof its own name")
        return tuple(value)
    if not isinstance(value, Mapping):
        raise ModelFileError(f"dofs must be a list of names or a table {{ count = N, prefix = \"u\" }}, got "
                             f"{_short(value)}")
    unknown = sorted(set(value) - {"count", "prefix", "from"})
    if unknown or ("count" in value) == ("from" in value):
        raise ModelFileError("dofs as a table takes count (and prefix), or from (and prefix): e.g. dofs = { count = "
                             "40902, prefix = \"u\" } or dofs = { from = \"stiffness\" }")
    default = "u" if "count" in value else "n"
    prefix = value.get("prefix", default)
    if not isinstance(prefix, str):
        raise ModelFileError(f"dofs.prefix = {_short(prefix)} must be a string, e.g. prefix = \"u\"")
    check_name(prefix + "0", "dofs.prefix + 0")
    if "from" in value:
        return tuple(f"{prefix}{node}_{component}" for node, component in labels)
    count = value["count"]
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_DOF_COUNT:
        raise ModelFileError(f"dofs.count = {_short(count)} must be a whole number from 1 to {MAX_DOF_COUNT:.0e}")
    return tuple(f"{prefix}{i}" for i in range(count))


def labels_source(value) -> str | None:
    """The matrix key that ``dofs = { from = KEY }`` names, None for other dofs."""
    if isinstance(value, Mapping) and "from" in value:
        key = value["from"]
        if key not in ("mass", "stiffness", "damping"):
            raise ModelFileError(f"dofs.from = {_short(key)} must name a matrix file: \"stiffness\" or \"mass\"")
        return key
    return None


# ----------------------------------------------------------------------------- matrix files
def file_table(value, key: str, base: Path | None) -> dict:
    """A matrix file reference as its canonical table: the absolute path, the optional keys as given,
    and ``scale`` (default 1)."""
    if isinstance(value, str):
        path, name = split_reference(value)
        table = {"file": path} if name is None else {"file": path, "matrix": name}
    else:
        unknown = sorted(set(value) - set(FILE_KEYS))
        if unknown:
            raise ModelFileError(f"{key}: unknown key(s) {', '.join(unknown)} of a matrix file; valid keys are "
                                 f"{', '.join(FILE_KEYS)}")
        table = dict(value)
    for name in ("file", "matrix", "format", "sha256"):
        if name in table and not isinstance(table[name], str):
            raise ModelFileError(f"{key}.{name} = {_short(table[name])} must be a string")
    if "symmetric" in table and not isinstance(table["symmetric"], bool):
        raise ModelFileError(f"{key}.symmetric = {_short(table['symmetric'])} must be true or false")
    path = Path(table["file"]).expanduser()
    if not path.is_absolute():
        path = (base or Path.cwd()) / path
    table["file"] = str(path.absolute())
    table.setdefault("scale", 1.0)
    return table


def load_file(table: Mapping, key: str) -> MatrixData:
    """Read the matrix file of a canonical table; refuse one whose SHA-256 differs from the table's."""
    where = key
    data = read_matrix(Path(table["file"]), where, table.get("matrix"), table.get("format"),
                       table.get("symmetric", True))
    expected = table.get("sha256")
    if expected is not None and expected.lower() != data.sha256:
        raise ModelFileError(f"{key}: {Path(table['file']).name} is not the file the model was made with (its SHA-256 "
                             f"is {data.sha256[:12]}…, the model's {expected[:12]}…); give that file, or remove "
                             f"{key}.sha256 to take this one")
    return data


@dataclasses.dataclass
class FileMatrices:
    """The matrix files of a model file, read once: key → CSR (n, n), aligned to the dofs."""

    matrices: dict = dataclasses.field(default_factory=dict)
    tables: dict = dataclasses.field(default_factory=dict)
    labels: tuple | None = None

    @classmethod
    def read(cls, spec: Mapping, base: Path | None) -> "FileMatrices":
        out = cls()
        source = labels_source(spec.get("dofs"))
        keys = [k for k in ("mass", "stiffness", "damping") if k in spec and is_file_reference(spec[k])]
        if source is not None and source not in keys:
            raise ModelFileError(f"dofs.from = \"{source}\" names no matrix file; give {source} as a file with node "
                                 "labels (Abaqus, DMIG), or dofs = { count = N }")
        read = {}
        for key in sorted(keys, key=lambda k: k != source):  # the labels' source first
            out.tables[key] = file_table(spec[key], key, base)
            read[key] = load_file(out.tables[key], key)
            out.tables[key]["sha256"] = read[key].sha256
        if source is not None:
            if read[source].labels is None:
                raise ModelFileError(f"dofs.from = \"{source}\": {Path(out.tables[source]['file']).name} numbers its "
                                     "rows without node labels; give dofs = { count = N } (its size) instead")
            out.labels = read[source].labels
        for key, data in read.items():
            out.matrices[key] = out._aligned(key, data)
        return out

    def _aligned(self, key: str, data: MatrixData) -> sp.csr_matrix:
        """The matrix in the order of the dofs: by labels where the dofs come from labels."""
        import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

        if self.labels is None or data.labels is None or data.labels == self.labels:
            return data.matrix
        index = {label: k for k, label in enumerate(self.labels)}
        missing = [label for label in data.labels if label not in index]
        if missing:
            raise ModelFileError(f"{key}: {Path(self.tables[key]['file']).name} has node {missing[0][0]} component "
                                 f"{missing[0][1]}, which the dofs (from {next(iter(self.tables))}) do not; give "
                                 "matrices of the same nodes")
        rows = np.array([index[label] for label in data.labels])
        coo = data.matrix.tocoo()
        n = len(self.labels)
        return sp.csr_matrix((coo.data, (rows[coo.row], rows[coo.col])), shape=(n, n))

    def check_sizes(self, n: int) -> None:
        """Each matrix square, one row and column per dof."""
        for key, matrix in self.matrices.items():
            if matrix.shape != (n, n):
                name = Path(self.tables[key]["file"]).name
                raise ModelFileError(f"{key}: {name} holds a {matrix.shape[0]}×{matrix.shape[1]} matrix; {key} must "
                                     f"be {n}×{n}, one row and column per dof (dofs has {n})")


# ----------------------------------------------------------------------------- sparse tables
class Triplets:
    """A sparse container that slots fill by (row, column); :meth:`matrix` gives its CSR (rows, n)."""

    def __init__(self, rows: int, n: int) -> None:
        self.shape = (rows, n)
        self.entries: dict = {}

    def __setitem__(self, index, value) -> None:
        self.entries[index] = value

    def matrix(self) -> sp.csr_matrix:
        import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

        if not self.entries:
            return sp.csr_matrix(self.shape)
        (i, j), values = zip(*self.entries.keys()), list(self.entries.values())
        return sp.csr_matrix((values, (i, j)), shape=self.shape)


def dof_index(names: Mapping[str, int], dof, where: str) -> int:
    """The index of a dof named in a sparse table or a CSV."""
    index = names.get(dof) if isinstance(dof, str) else None
    if index is None:
        raise ModelFileError(f"{where}: {_short(dof)} is not a dof of the model; give one of the names in dofs "
                             f"(e.g. {next(iter(names))})")
    return index


# ----------------------------------------------------------------------------- CSV tables
def read_csv(path: Path, what: str, required: tuple, known: tuple) -> tuple[list[dict], str]:
    """The rows of a CSV with a header line (bounded; columns checked) and the file's SHA-256."""
    size = regular_file_size(path, what, ModelFileError)
    check_memory(_CSV_COPIES * size, f"reading {what} {path.name} ({format_bytes(size)})", "free memory")
    data = read_regular_file(path, MAX_TABLE_BYTES, what, ModelFileError)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise ModelFileError(f"{what} {path.name} is not UTF-8 text; save it as a CSV file") from None
    rows = list(csv.DictReader(io.StringIO(text)))
    columns = [c.strip() for c in (rows[0].keys() if rows else [])]
    missing = [c for c in required if c not in columns]
    unknown = [c for c in columns if c not in known]
    if not rows or missing or unknown:
        raise ModelFileError(f"{what} {path.name} needs a header line with the columns {', '.join(required)} "
                             "(optional: "
                             f"{', '.join(c for c in known if c not in required)}) and one row per entry"
                             + (f"; unknown column {unknown[0]!r}" if unknown else "")
                             + (f"; missing {', '.join(missing)}" if missing and rows else ""))
    return [{k.strip(): (v or "").strip() for k, v in row.items() if k is not None} for row in rows], file_digest(data)


def _csv_number(text: str, where: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ModelFileError(f"{where} = {_short(text)} is not a number; give a finite number") from None
    if not np.isfinite(value):
        raise ModelFileError(f"{where} = {text} must be finite")
    return value


def read_nodes(table, base: Path | None, names: Mapping[str, int], labels) -> tuple[NodeMap, dict]:
    """``nodes = "nodes.csv"`` or ``{ file = "nodes.csv", elements = "elements.csv" }``: its
    :class:`NodeMap` and the canonical table of the files (absolute paths and SHA-256)."""
    elements = table.get("elements") if isinstance(table, Mapping) else None
    ref = file_table({k: v for k, v in table.items() if k != "elements"} if isinstance(table, Mapping) else table,
                     "nodes", base)
    unknown = sorted(set(ref) - {"file", "sha256", "scale"})
    if unknown:
        raise ModelFileError(f"nodes: unknown key(s) {', '.join(unknown)}; give nodes = \"nodes.csv\" or nodes = "
                             "{ file = \"nodes.csv\", elements = \"elements.csv\" }")
    ref.pop("scale", None)
    path = Path(ref["file"])
    rows, digest = read_csv(path, "nodes file", ("node", "x", "y"), NODE_COLUMNS)
    _same_file(ref, digest, "nodes", path)
    ids = [int(_csv_number(r["node"], f"nodes: {path.name} node")) for r in rows]
    xyz = [[_csv_number(r.get(c) or "0", f"nodes: {path.name} node {i} {c}") for c in "xyz"] for i, r in zip(ids, rows)]
    n = len(names)
    node, component = np.full(n, -1), np.full(n, -1)
    position = {node_id: k for k, node_id in enumerate(ids)}
    for k, row in enumerate(rows):
        for c, comp in enumerate(COMPONENTS):
            dof = row.get(f"dof_{comp}")
            if dof:
                i = dof_index(names, dof, f"nodes: {path.name} node {ids[k]} dof_{comp}")
                node[i], component[i] = k, c
    if labels is not None and (node < 0).all():  # dofs named after node labels: their nodes are known
        for i, (node_id, comp) in enumerate(labels):
            if node_id in position and 1 <= comp <= len(COMPONENTS):
                node[i], component[i] = position[node_id], comp - 1
    cells = ()
    if elements is not None:
        cells, ref["elements"] = read_elements(elements, base, position)
    try:
        return NodeMap(ids=ids, coordinates=xyz, node=node, component=component, cells=cells), ref
    except ModelError as exc:
        raise ModelFileError(f"{path.name}: {exc}") from None


def _same_file(ref: dict, digest: str, key: str, path: Path) -> None:
    """Refuse a file whose SHA-256 differs from the one its table records; record it otherwise."""
    if ref.get("sha256", digest).lower() != digest:
        raise ModelFileError(f"{key}: {path.name} is not the file the model was made with (its SHA-256 differs); give "
                             f"that file, or remove {key}.sha256")
    ref["sha256"] = digest


def read_elements(value, base: Path | None, position: Mapping[int, int]) -> tuple[tuple, dict]:
    """``nodes.elements = "elements.csv"``: the elements as :attr:`NodeMap.cells` blocks (node ids
    turned into indices of the nodes file, one block per type in the order of first appearance)
    and the file's canonical table."""
    ref = file_table(value, "nodes.elements", base)
    ref.pop("scale", None)
    unknown = sorted(set(ref) - {"file", "sha256"})
    if unknown:
        raise ModelFileError(f"nodes.elements: unknown key(s) {', '.join(unknown)}; give elements = \"elements.csv\"")
    path = Path(ref["file"])
    rows, digest = read_csv(path, "elements file", ("type", "n1"), ELEMENT_COLUMNS)
    _same_file(ref, digest, "nodes.elements", path)
    blocks: dict = {}
    for k, row in enumerate(rows, start=2):  # line numbers of the file (its header is line 1)
        kind = row["type"].lower()
        if kind not in CELL_NODES:
            raise ModelFileError(f"nodes.elements: {path.name} line {k}: type {row['type']!r} is not an element type; "
                                 f"give one of {', '.join(CELL_NODES)}")
        count = CELL_NODES[kind]
        given = [row.get(f"n{j}", "") for j in range(1, len(ELEMENT_COLUMNS) - 1)]
        if any(not text for text in given[:count]) or any(text for text in given[count:]):
            raise ModelFileError(f"nodes.elements: {path.name} line {k}: a {kind} element has {count} nodes: give "
                                 f"n1 … n{count} and leave the other columns empty")
        indices = []
        for text in given[:count]:
            node_id = int(_csv_number(text, f"nodes.elements: {path.name} line {k} node"))
            if node_id not in position:
                raise ModelFileError(f"nodes.elements: {path.name} line {k}: node {node_id} is not in the nodes file; "
                                     "give the ids of the nodes file's nodes")
            indices.append(position[node_id])
        blocks.setdefault(kind, []).append(indices)
    return tuple((kind, np.array(block, dtype=np.int64)) for kind, block in blocks.items()), ref


# ----------------------------------------------------------------------------- contact sets
@dataclasses.dataclass(frozen=True, eq=False)
class ContactSet:
    """A ``[contact_set.NAME]`` checked: its nodes' structure (fixed) and which numbers are per node.

    ``tangent`` (count,) of CSR (dim, n) rows and ``gap_gradient`` (count,) of CSR (1, n) (None for a
    pressed set) are built once; the numbers (drive, gap, normal force, the laws) are slots of the
    template under ``contact_set.NAME.…`` and ``contact_set.NAME.nodes.NODE.…``.
    """

    name: str
    nodes: tuple[str, ...]
    contact_names: tuple[str, ...]
    dim: int
    unilateral: bool
    tangent: tuple
    gap_gradient: tuple | None
    per_node: frozenset

    def container(self, what: str) -> str:
        return f"set.{self.name}.{what}"


def set_nodes(table: Mapping, where: str, base: Path | None) -> dict:
    """A set's nodes as the frozen spec keeps them: node → {column: value} (from a CSV or a table)."""
    nodes = table.get("nodes")
    if isinstance(nodes, str) or (isinstance(nodes, Mapping) and "file" in nodes):
        ref = file_table(nodes, f"{where}.nodes", base)
        rows, _ = read_csv(Path(ref["file"]), f"{where}.nodes: contact nodes file", ("node", "tangent"), SET_COLUMNS)
        out = {}
        for row in rows:
            key = row.pop("node")
            if key in out:
                raise ModelFileError(f"{where}.nodes: node {key} is listed twice; give each contact node once")
            out[key] = {k: (v if k in ("name", "tangent", "tangent2", "normal") else
                            _csv_number(v, f"{where}.nodes.{key}.{k}")) for k, v in row.items() if v != ""}
        return out
    if isinstance(nodes, Mapping) and nodes:
        for key, row in nodes.items():
            if not isinstance(row, Mapping):
                raise ModelFileError(f"{where}.nodes.{key} must be a table {{ tangent = \"u0\", normal = \"u1\", "
                                     "... }")
            unknown = sorted(set(row) - set(SET_COLUMNS[1:]))
            if unknown:
                raise ModelFileError(f"{where}.nodes.{key}: unknown key(s) {', '.join(unknown)}; valid keys are "
                                     f"{', '.join(SET_COLUMNS[1:])}")
        return {str(k): dict(v) for k, v in nodes.items()}
    raise ModelFileError(f"{where}.nodes is missing; give nodes = \"contact_nodes.csv\" (columns node, tangent, "
                         "normal, "
                         "gap, …) or a table of the nodes")


def contact_set(name: str, table: Mapping, nodes: Mapping, names: Mapping[str, int]) -> ContactSet:
    """The structure of a set (its nodes' dofs), checked; the numbers are slotted by the caller."""
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    where = f"contact_set.{name}"
    check_name(name, f"{where}: the set's name")
    n = len(names)
    unilateral = "normal" in table
    sign = table.get("normal_sign", 1.0)
    if isinstance(sign, bool) or sign not in (1, -1, 1.0, -1.0):
        raise ModelFileError(f"{where}.normal_sign = {_short(sign)} must be 1 or -1 (g = gap + sign × the normal dof)")
    dims = {2 if "tangent2" in row else 1 for row in nodes.values()}
    if len(dims) != 1:
        raise ModelFileError(f"{where}.nodes: give every node a tangent2 (2-D contacts) or none (1-D)")
    dim = dims.pop()
    tangent, gap_gradient, contact_names = [], [], []
    for key, row in nodes.items():
        at = f"{where}.nodes.{key}"
        columns = [dof_index(names, row.get(c), f"{at}.{c}") for c in ("tangent", "tangent2")[:dim]]
        tangent.append(sp.csr_matrix((np.ones(dim), (np.arange(dim), columns)), shape=(dim, n)))
        if unilateral:
            normal = dof_index(names, row.get("normal"), f"{at}.normal")
            gap_gradient.append(sp.csr_matrix(([float(sign)], ([0], [normal])), shape=(1, n)))
        elif "normal" in row:
            raise ModelFileError(f"{at}.normal is a unilateral contact's; give the set a [{where}.normal] table, or "
                                 "leave the normal column out for contacts pressed by normal_force")
        label = row.get("name", f"{name}_{key}")
        if not isinstance(label, str):
            raise ModelFileError(f"{at}.name = {_short(label)} must be a string")
        check_text(label, f"{at}.name")
        contact_names.append(label)
    per_node = frozenset(k for k in ("gap", "drive", "drive2", "normal_force") if any(k in r for r in nodes.values()))
    for key in per_node & {"gap", "drive", "normal_force"}:
        if key in table:
            raise ModelFileError(f"{where}: {key} is given both for the set and per node; give it in one place")
        if not all(key in r for r in nodes.values()):
            raise ModelFileError(f"{where}.nodes: {key} is given for some nodes only; give it for every node or for "
                                 "the set")
    return ContactSet(name=name, nodes=tuple(nodes), contact_names=tuple(contact_names), dim=dim,
                      unilateral=unilateral, tangent=tuple(tangent),
                      gap_gradient=tuple(gap_gradient) if unilateral else None, per_node=per_node)
