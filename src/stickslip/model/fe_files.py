"""Matrix files of finite-element codes: read whole, bounded, into scipy.sparse CSR matrices.

A model file names a matrix file by its path, relative to the model file (``mass = "M.mtx"``),
with ``:NAME`` for a file that holds several matrices (``"K.mat:K"``, ``"model.op4:KAAX"``), or as a
table ``{ file = "M.mtx", matrix = "KAAX", scale = 1.0, format = "abaqus" }``. The format follows
from the file's suffix (``format`` overrides it):

=================  ===================================================================================
``.mtx``           Matrix Market (``%%MatrixMarket`` on its first line; ``scipy.io.mmread``), else an
                   Abaqus text file (below)
``.npz``           ``scipy.sparse.save_npz``; with ``:NAME``, the array NAME of a ``numpy.savez`` file
``.mat``           MATLAB up to v7 (``scipy.io.loadmat``); ``:NAME`` the variable (needed when the file
                   holds several); v7.3 files are HDF5 and are refused with the fix
``.op4``           Nastran OUTPUT4, ASCII or binary (pyNastran, installed apart: docs/models.md); ``:NAME`` the matrix
``.pch``, ``.dmig``  Nastran DMIG cards (a punch file of ``PARAM,EXTOUT,DMIGPCH``, or bulk data):
                   small, large (``DMIG*``) or free (comma) fields, real matrices (TIN 1, 2);
                   ``:NAME`` the matrix; IFO 6 (symmetric) gives one triangle, mirrored here
``abaqus``         Abaqus text matrices: ``*MATRIX GENERATE`` / ``*MATRIX OUTPUT`` (FORMAT=MATRIX
                   INPUT: lines ``row node, row dof, column node, column dof, value``; FORMAT=COORDINATE:
                   ``row, column, value``) and ``*SUBSTRUCTURE MATRIX OUTPUT, OUTPUT FILE=USER DEFINED``
                   (a ``*USER ELEMENT, LINEAR`` with its dofs and ``*MATRIX, TYPE=STIFFNESS`` / ``MASS``;
                   ``:NAME`` is ``STIFFNESS`` or ``MASS``)
=================  ===================================================================================

Abaqus gives a symmetric matrix as one triangle (or the full square); a file whose off-diagonal
entries all lie in one triangle is read as the triangle of a symmetric matrix and mirrored
(``symmetric = false`` in the file's table reads it as it stands). A user element's symmetric
matrix is its lower triangle row by row (the upper column by column, as the results file's
records 1011 and 1021 store it), an ``UNSYMM`` one the full matrix column by column.

Matrices indexed by node and component (Abaqus' node-based lines and user elements, DMIG) carry
their *labels*, (node, component) per row in ascending order: the model file's ``dofs = { from =
"stiffness" }`` names the dofs after them (``n12_1``) and aligns the other labelled matrices to
them.

Every read is bounded: the file must be a regular file (a folder, a pipe or a device is refused
before a byte is read), at most :data:`MAX_MATRIX_FILE_BYTES`, and its estimated memory while
read (:func:`stickslip.memory.matrix_file_bytes`) must fit in the memory available. Each error is
one :class:`~stickslip.errors.ModelFileError` line naming the key, the file and the fix.
"""

from __future__ import annotations

import dataclasses
import hashlib
import io
import re
import zipfile
from pathlib import Path

import numpy as np
# scipy.sparse is imported in the functions that use it: a dense model (the two plates, most model
# files) never needs it, and its import costs every command's start-up time.

from ..errors import ModelFileError
from ..inputs import read_regular_file, regular_file_size
from ..memory import check_memory, format_bytes, matrix_file_bytes

__all__ = ["MatrixData", "read_matrix", "split_reference", "FORMATS", "MAX_MATRIX_FILE_BYTES", "file_digest"]

#: Largest matrix file read [bytes] (beside the memory check): 64 GiB.
MAX_MATRIX_FILE_BYTES = 64 * 2**30

#: Formats by name, and the suffixes that select them.
FORMATS = {"mtx": (".mtx",), "npz": (".npz",), "mat": (".mat",), "op4": (".op4",), "dmig": (".pch", ".dmig"),
           "abaqus": ()}


@dataclasses.dataclass(frozen=True, eq=False)
class MatrixData:
    """A matrix read from a file: CSR, its (node, component) labels per row and column where the
    format gives them (ascending), and the SHA-256 of the file's bytes."""

    matrix: sp.csr_matrix
    labels: tuple[tuple[int, int], ...] | None
    sha256: str


def split_reference(text: str) -> tuple[str, str | None]:
    """``"K.mat:KAAX"`` → (``"K.mat"``, ``"KAAX"``); a path without ``:NAME`` → (path, None)."""
    head, sep, tail = text.rpartition(":")
    if sep and tail and "/" not in tail and "\\" not in tail and "." in head:
        return head, tail
    return text, None


def file_digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def format_of(path: Path, fmt: str | None, where: str) -> str:
    """The format of ``path``: ``fmt`` when given, else from its suffix."""
    if fmt is not None:
        if fmt not in FORMATS:
            raise ModelFileError(f"{where}.format = {fmt!r} is not a matrix format; choose one of {', '.join(FORMATS)}")
        return fmt
    suffix = path.suffix.lower()
    for name, suffixes in FORMATS.items():
        if suffix in suffixes:
            return name
    raise ModelFileError(f"{where}: {path.name} has no known matrix suffix; give a .mtx (Matrix Market or Abaqus), "
                         ".npz, .mat, .op4 or .pch (DMIG) file, or state its format, e.g. { file = ..., format = "
                         "\"abaqus\" }")


def read_matrix(path: Path, where: str, name: str | None = None, fmt: str | None = None,
                symmetric: bool = True) -> MatrixData:
    """Read the matrix file ``path`` (module docstring) for the model file's key ``where``.

    Raises
    ------
    ModelFileError
        One line: the file is missing, not a regular file, too large for memory, not of its
        format, holds no such matrix, or has a non-finite entry.
    """
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    kind = format_of(path, fmt, where)
    what = f"{where}: matrix file"
    size = regular_file_size(path, what, ModelFileError)
    unpacked = _npz_unpacked(path, size) if kind == "npz" else None
    advice = ("free memory (its arrays are read whole, unpacked)" if kind == "npz" else
              "free memory, or give the matrix in a compact binary format (.npz)")
    check_memory(matrix_file_bytes(size, unpacked), f"reading {where} from {path.name} ({format_bytes(size)})", advice)
    data = read_regular_file(path, MAX_MATRIX_FILE_BYTES, what, ModelFileError)
    where = f"{where}: {path.name}"
    try:
        if kind == "mtx" and data.lstrip()[:14].lower() != b"%%matrixmarket":
            kind = "abaqus"
        reader = {"mtx": _matrix_market, "npz": _npz, "mat": _mat, "op4": _op4, "dmig": _dmig, "abaqus": _abaqus}[kind]
        matrix, labels = reader(data, name, where, path=path, symmetric=symmetric)
    except ModelFileError:
        raise
    except (ValueError, TypeError, KeyError, IndexError, OSError, EOFError, zipfile.BadZipFile,
            NotImplementedError, UnicodeDecodeError) as exc:
        raise ModelFileError(f"{where} cannot be read as {_NAMES[kind]} ({_brief(exc)}); check the file and its "
                             "format") from None
    matrix = sp.csr_matrix(matrix, dtype=float)
    if matrix.ndim != 2:
        raise ModelFileError(f"{where} holds no matrix; give a file of one two-dimensional matrix")
    matrix.sum_duplicates()
    if not np.isfinite(matrix.data).all():
        raise ModelFileError(f"{where} has a non-finite entry (nan or inf); give finite numbers")
    return MatrixData(matrix=matrix, labels=labels, sha256=file_digest(data))


_NAMES = {"mtx": "Matrix Market", "npz": "a scipy.sparse .npz", "mat": "a MATLAB file", "op4": "Nastran OP4",
          "dmig": "Nastran DMIG cards", "abaqus": "an Abaqus matrix"}


def _brief(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 100 else text[:97] + "..."


def _npz_unpacked(path: Path, size: int) -> float | None:
    """What a .npz's members take unpacked [bytes] (its zip directory says), None if unreadable."""
    try:
        with zipfile.ZipFile(path) as archive:
            return float(sum(info.file_size for info in archive.infolist()))
    except (OSError, zipfile.BadZipFile, ValueError):
        return None


def _pick(names: list[str], name: str | None, where: str, kind: str):
    """The one matrix of a file, or the one called ``name``."""
    if name is None:
        if len(names) == 1:
            return names[0]
        plural = kind[:-2] + "ices" if kind.endswith("ix") else kind + "s"
        raise ModelFileError(f"{where} holds {len(names)} {plural} ({', '.join(names[:8])}); name one, e.g. "
                             f"\"{where.rsplit(': ', 1)[-1]}:{names[0] if names else 'NAME'}\"")
    if name not in names:
        raise ModelFileError(f"{where} holds no {kind} {name!r}; it holds {', '.join(names[:8]) or 'none'}")
    return name


# ----------------------------------------------------------------------------- formats
def _matrix_market(data: bytes, name, where, **_):
    import scipy.io  # noqa: PLC0415 - scipy.io costs start-up time; used only when a file is read

    if name is not None:
        raise ModelFileError(f"{where} is a Matrix Market file of one matrix; give it without :{name}")
    return scipy.io.mmread(io.BytesIO(data)), None


def _npz(data: bytes, name, where, **_):
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    if name is None:
        return sp.load_npz(io.BytesIO(data)), None
    with np.load(io.BytesIO(data), allow_pickle=False) as arrays:
        key = _pick(list(arrays.files), name, where, "array")
        return np.asarray(arrays[key], dtype=float), None


def _mat(data: bytes, name, where, **_):
    import scipy.io  # noqa: PLC0415 - see _matrix_market

    if data[:128].find(b"MATLAB 7.3") >= 0 or data[:8] == b"\x89HDF\r\n\x1a\n":
        raise ModelFileError(f"{where} is a MATLAB v7.3 (HDF5) file; save it with save(..., '-v7') or write "
                             "Matrix Market (mmwrite)")
    variables = {k: v for k, v in scipy.io.loadmat(io.BytesIO(data)).items() if not k.startswith("__")}
    return variables[_pick(sorted(variables), name, where, "variable")], None


def _op4(data: bytes, name, where, path: Path, **_):
    try:
        from pyNastran.op4.op4 import read_op4  # noqa: PLC0415 - the optional `fe` extra
    except ImportError:
        raise ModelFileError(f"{where}: reading Nastran OP4 needs pyNastran; install it with pip install cpylog "
                             "docopt-ng colorama, then pip install --no-deps pyNastran") from None
    matrices = read_op4(str(path), debug=False, log=None)
    matrix = matrices[_pick(sorted(matrices), name, where, "matrix")]
    if getattr(matrix, "is_complex", False):
        raise ModelFileError(f"{where}: matrix {name or ''} is complex; give the real matrices of the model")
    return matrix.data, None


# ----------------------------------------------------------------------------- Abaqus
_NUMBER = re.compile(r"\s*,\s*|\s+")


def _fields(line: str) -> list[str]:
    return [f for f in _NUMBER.split(line.strip()) if f]


def _abaqus(data: bytes, name, where, symmetric: bool = True, **_):
    text = data.decode("ascii", errors="strict")
    if re.search(r"^\s*\*user\s+element", text, re.IGNORECASE | re.MULTILINE):
        return _user_element(text, name, where)
    if name is not None:
        raise ModelFileError(f"{where} is an Abaqus matrix of one matrix; give it without :{name}")
    rows = [_fields(line) for line in text.splitlines() if line.strip() and not line.lstrip().startswith("*")]
    widths = {len(r) for r in rows}
    if not rows or not widths <= {3, 5} or len(widths) != 1:
        raise ModelFileError(f"{where} is not an Abaqus matrix: each line must hold row node, row dof, column "
                             "node, column dof, value (FORMAT=MATRIX INPUT) or row, column, value (COORDINATE)")
    table = np.array(rows, dtype=float)
    value = table[:, -1]
    if table.shape[1] == 3:
        i, j = table[:, 0].astype(np.int64) - 1, table[:, 1].astype(np.int64) - 1
        n = int(max(i.max(), j.max())) + 1
        labels = None
    else:
        pairs = np.concatenate([table[:, 0:2], table[:, 2:4]]).astype(np.int64)
        unique, index = np.unique(pairs, axis=0, return_inverse=True)
        index = index.reshape(-1)
        i, j = index[:len(rows)], index[len(rows):]
        n = len(unique)
        labels = tuple((int(a), int(b)) for a, b in unique)
    if min(i.min(), j.min()) < 0:
        raise ModelFileError(f"{where}: equation numbers start at 1; fix the file")
    return _mirrored(value, i, j, n, symmetric), labels


def _mirrored(value, i, j, n, symmetric: bool) -> sp.csr_matrix:
    """The matrix of triplets; one triangle of a symmetric matrix (``symmetric``) mirrored."""
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    off = i != j
    if symmetric and off.any() and ((i[off] > j[off]).all() or (i[off] < j[off]).all()):
        value, i, j = np.concatenate([value, value[off]]), np.concatenate([i, j[off]]), np.concatenate([j, i[off]])
    return sp.coo_matrix((value, (i, j)), shape=(n, n)).tocsr()


def _keyword(line: str) -> tuple[str, dict]:
    """``*MATRIX, TYPE=STIFFNESS`` → (``MATRIX``, {``TYPE``: ``STIFFNESS``})."""
    parts = [p.strip() for p in line.strip().lstrip("*").split(",")]
    options = {}
    for part in parts[1:]:
        key, _, value = part.partition("=")
        options[key.strip().upper()] = value.strip().upper()
    return parts[0].upper(), options


def _user_element(text: str, name, where):
    """A linear user element: its dofs per node and its ``*MATRIX`` blocks (module docstring)."""
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    blocks, current, head = {}, None, None
    for line in text.splitlines():
        stripped = line.strip()
        if not stripped or stripped.startswith("**"):
            continue
        if stripped.startswith("*"):
            head = _keyword(stripped)
            current = blocks.setdefault((head[0], head[1].get("TYPE", "")), [])
            continue
        if current is None:
            raise ModelFileError(f"{where}: data before the first keyword; an Abaqus user element starts with "
                                 "*USER ELEMENT")
        current.append(stripped)
    element = next(((key, lines) for key, lines in blocks.items() if key[0] == "USER ELEMENT"), None)
    options = _keyword(next(line for line in text.splitlines() if line.strip().upper().startswith("*USER")))[1]
    nodes = int(options.get("NODES", "0") or 0)
    if element is None or nodes < 1:
        raise ModelFileError(f"{where}: *USER ELEMENT needs NODES=; fix the file")
    labels = _element_labels(element[1], nodes, where)
    matrices = {key[1]: lines for key, lines in blocks.items() if key[0] == "MATRIX"}
    chosen = _pick(sorted(matrices), None if name is None else name.upper(), where, "*MATRIX TYPE")
    values = np.array([float(v) for line in matrices[chosen] for v in _fields(line)])
    n = len(labels)
    if "UNSYMM" in options:
        if len(values) != n * n:
            raise ModelFileError(f"{where}: an UNSYMM matrix of {n} dofs needs {n * n} entries, got {len(values)}")
        matrix = sp.csr_matrix(values.reshape(n, n).T)  # stored column by column
    else:
        if len(values) != n * (n + 1) // 2:
            raise ModelFileError(f"{where}: a symmetric matrix of {n} dofs needs {n * (n + 1) // 2} entries (its lower "
                                 f"triangle), got {len(values)}")
        i, j = np.tril_indices(n)
        order = np.lexsort((j, i))  # row by row: (0,0), (1,0), (1,1), (2,0), ...
        matrix = _mirrored(values, i[order], j[order], n, True)
    order = sorted(range(n), key=lambda k: labels[k])
    permutation = sp.csr_matrix((np.ones(n), (np.arange(n), order)), shape=(n, n))
    return permutation @ matrix @ permutation.T, tuple(labels[k] for k in order)


def _element_labels(lines: list[str], nodes: int, where: str) -> list[tuple[int, int]]:
    """(node position, dof) of each variable: the first line's dofs hold from the first node on,
    each further line ``position, dofs`` from that node on."""
    changes = {1: [int(v) for v in _fields(lines[0])]} if lines else {}
    for line in lines[1:]:
        values = [int(v) for v in _fields(line)]
        changes[values[0]] = values[1:]
    if 1 not in changes or not changes[1]:
        raise ModelFileError(f"{where}: *USER ELEMENT needs the dofs of its first node on its first data line")
    labels, dofs = [], []
    for node in range(1, nodes + 1):
        dofs = changes.get(node, dofs)
        labels += [(node, d) for d in dofs]
    return labels


# ----------------------------------------------------------------------------- Nastran DMIG
_EXPONENT = re.compile(r"(?<=[0-9.])([+-])(?=\d+$)")


def _nastran_float(text: str) -> float:
    """A Nastran real: ``1.5+3``, ``-2.-4``, ``1.0D-3`` and plain Python forms."""
    text = text.strip().upper().replace("D", "E")
    if "E" not in text:
        text = _EXPONENT.sub(r"E\1", text)
    return float(text)


def _cards(text: str):
    """Bulk-data cards as lists of field strings (small, large and free fields; continuations joined)."""
    card = None
    for line in text.splitlines():
        if not line.strip() or line.lstrip().startswith("$"):
            continue
        if "," in line:
            fields = [f.strip() for f in line.split(",")]
            head, data = fields[0], fields[1:]
            if len(data) > 8:  # a free-field line holds 8 data fields, then its continuation mark
                data = data[:8]
        elif line[:8].rstrip().endswith("*") or line.startswith("*"):
            head = line[:8].strip()
            data = [line[k:k + 16].strip() for k in range(8, 72, 16)]
        else:
            head = line[:8].strip()
            data = [line[k:k + 8].strip() for k in range(8, 72, 8)]
        if head and not head.startswith(("+", "*")):
            if card is not None:
                yield card
            card = [head.rstrip("*").upper(), *data]
        elif card is not None:
            card += data
    if card is not None:
        yield card


def _dmig(data: bytes, name, where, **_):
    headers, columns = {}, {}
    for card in _cards(data.decode("ascii", errors="strict")):
        if card[0] != "DMIG":
            continue
        matrix = card[1].upper()
        if card[2] in ("0", "") and matrix not in headers and len(card) > 5 and card[3]:
            headers[matrix] = (int(card[3]), int(card[4]))  # IFO, TIN
            continue
        columns.setdefault(matrix, []).append(card)
    chosen = _pick(sorted(headers), None if name is None else name.upper(), where, "DMIG matrix")
    ifo, tin = headers[chosen]
    if tin not in (1, 2):
        raise ModelFileError(f"{where}: DMIG {chosen} is complex (TIN = {tin}); give the real matrices of the model")
    rows, cols, values = [], [], []
    for card in columns.get(chosen, []):
        column = (int(card[2]), int(card[3] or 0))
        entries = card[5:]
        for k in range(0, len(entries) - 2, 4):
            if entries[k]:
                rows.append((int(entries[k]), int(entries[k + 1] or 0)))
                cols.append(column)
                values.append(_nastran_float(entries[k + 2]))
    labels = sorted(set(rows) | set(cols))
    index = {label: k for k, label in enumerate(labels)}
    i = np.array([index[r] for r in rows], dtype=np.int64)
    j = np.array([index[c] for c in cols], dtype=np.int64)
    return _mirrored(np.array(values), i, j, len(labels), ifo == 6), tuple(labels)
