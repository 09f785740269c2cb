"""A sparse form written as a model file: the TOML, its matrices as ``.npz`` and its nodes as CSV.

``OUT.toml`` names its coordinates, points at ``OUT_M.npz``, ``OUT_K.npz``, ``OUT_C.npz``
(``scipy.sparse.save_npz``) and ``OUT_nodes.csv`` beside it, and states each contact as a
``[[contact]]`` table with its rows as sparse tables (docs/models.md, finite-element models), so
that every tool reads it as any model file.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..files import refuse_output, write_output
from ..model.sparse_form import COMPONENTS, SparseForm
from .bases import ReductionError

__all__ = ["write_model_file", "output_paths"]


def output_paths(path) -> dict[str, Path]:
    """The files a model file ``path`` (``.toml``) is written as: ``{"model", "M", "K", "C", "nodes"}``."""
    path = Path(path)
    stem = path.with_suffix("")
    return {"model": path, "M": Path(f"{stem}_M.npz"), "K": Path(f"{stem}_K.npz"), "C": Path(f"{stem}_C.npz"),
            "nodes": Path(f"{stem}_nodes.csv")}


def _table(row: sp.csr_matrix, names) -> dict:
    row = sp.csr_matrix(row)
    return {names[j]: float(v) for j, v in zip(row.indices, row.data) if v != 0.0}


def _contacts(form: SparseForm) -> list[dict]:
    names, out = form.dofs, []
    G, W = sp.csr_matrix(form.tangent), sp.csr_matrix(form.gap_gradient)
    nq, nv = sp.csr_matrix(form.normal_gradient), sp.csr_matrix(form.normal_rate_gradient)
    for c in range(form.nc):
        law = form.friction[c]
        if law.law == "user":
            raise ReductionError(f"contact {c} ({form.contact_names[c]}) has a user friction law, which a model file "
                                 "cannot state; use the reduced model from Python (reduce_model(...).form)")
        rows = form.rows(c)
        table = {"name": form.contact_names[c], "tangent": [_table(G[r], names) for r in range(rows.start, rows.stop)],
                 "drive": [float(w) for w in form.drive[rows]]}
        if form.unilateral[c]:
            normal = ({"law": "rigid", "restitution": float(form.restitution[c])} if form.normal_law[c] == "rigid"
                      else {"law": "compliant", "stiffness": float(form.contact_stiffness[c]),
                            "damping": float(form.contact_damping[c])})
            table.update(gap=float(form.gap[c]), gap_gradient=_table(W[c], names), normal=normal)
        else:
            table["normal_force"] = float(form.normal_force[c])
            for key, rows_ in (("normal_gradient", nq), ("normal_rate_gradient", nv)):
                if rows_[c].nnz:
                    table[key] = _table(rows_[c], names)
        table["friction"] = law.to_dict()
        out.append(table)
    return out


def _nodes_csv(form: SparseForm) -> str | None:
    """The nodes that carry a coordinate of ``form``, with their dofs' names (None without nodes)."""
    nodes = form.nodes
    if nodes is None or not np.any(nodes.node >= 0):
        return None
    used = np.unique(nodes.node[nodes.node >= 0])
    comps = sorted({int(c) for c in nodes.component[nodes.node >= 0]})
    names = {(int(nd), int(cp)): form.dofs[j] for j, (nd, cp) in enumerate(zip(nodes.node, nodes.component)) if nd >= 0}
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["node", "x", "y", "z"] + [f"dof_{COMPONENTS[c]}" for c in comps])
    for k in used:
        writer.writerow([int(nodes.ids[k]), *(repr(float(v)) for v in nodes.coordinates[k]),
                         *(names.get((int(k), c), "") for c in comps)])
    return buffer.getvalue()


def write_model_file(form: SparseForm, path, *, overwrite: bool = False, description: str = "",
                     inputs: dict | None = None) -> list[Path]:
    """Write ``form`` as the model file ``path`` (``.toml``) and its matrix and node files beside it.

    Every output is refused before anything is written when it exists (without ``overwrite``) or
    is one of ``inputs`` (``{option: path}`` of the files the caller read).

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    OutputError
        An output that exists (without ``overwrite``) or is a folder.
    ReductionError
        A contact with a user friction law.
    """
    import tomli_w

    paths = output_paths(path)
    nodes_text = _nodes_csv(form)
    if nodes_text is None:
        paths.pop("nodes")
    for flag, target in paths.items():
        refuse_output(target, overwrite=overwrite, inputs=inputs, flag="--out" if flag == "model" else
                      f"--out ({target.name})")
    spec = {"name": form.name, "description": description, "dofs": list(form.dofs),
            "mass": paths["M"].name, "stiffness": paths["K"].name, "damping": paths["C"].name}
    force = {form.dofs[j]: float(v) for j, v in enumerate(form.force) if v != 0.0}
    if force:
        spec["force"] = force
    if nodes_text is not None:
        spec["nodes"] = paths["nodes"].name
    spec["slip_band"] = float(form.slip_band)
    spec["contact"] = _contacts(form)
    written = []
    for key, matrix in (("M", form.mass), ("K", form.stiffness), ("C", form.damping)):
        write_output(paths[key], lambda tmp, A=matrix: _save_npz(tmp, A), overwrite=overwrite, flag="--out",
                     inputs=inputs)
        written.append(paths[key])
    if nodes_text is not None:
        write_output(paths["nodes"], lambda tmp: Path(tmp).write_text(nodes_text), overwrite=overwrite, flag="--out",
                     inputs=inputs)
        written.append(paths["nodes"])
    write_output(paths["model"], lambda tmp: Path(tmp).write_text(tomli_w.dumps(spec)), overwrite=overwrite,
                 inputs=inputs)
    return written + [paths["model"]]


def _save_npz(tmp, matrix) -> None:
    """``save_npz`` to exactly ``tmp`` (numpy appends ``.npz`` to a name without it)."""
    with open(tmp, "wb") as fh:
        sp.save_npz(fh, sp.csr_matrix(matrix))
