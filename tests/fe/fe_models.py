"""Finite-element test models, assembled here with numpy and scipy alone (independent of stickslip).

Two families, each a :class:`FEModel` (sparse M, K, optional Rayleigh damping, contact nodes,
node coordinates) that :meth:`FEModel.write` saves as matrix files and a model file:

``pad_on_belt(nx, ny, ...)``
    A 2-D plane-stress pad of bilinear quadrilaterals (Q4, 2 × 2 Gauss points, consistent mass),
    nx × ny elements, its top face clamped (those nodes have no dofs), its bottom face on a belt
    moving along +x at ``speed``: one 1-D contact per bottom node, tangent its x dof, gap
    g = g0 + u_y (closed while g ≤ 0; ``preload`` > 0 presses the belt into the pad by that much,
    g0 = −preload) with a compliant normal law, or a prescribed load. Dofs ``u0 … u{n-1}``:
    node (i, j) (column i = 0 … nx, row j = 0 … ny − 1 from the bottom) has u_x = u[2 k], u_y =
    u[2 k + 1], k = j (nx + 1) + i; node ids k + 1. n = 2 (nx + 1) ny: 10×4 elements 88 dofs,
    250×100 50 200 dofs, 500×100 100 200 dofs.

``belt_with_modes(modes, ...)``
    The library's mass on a belt (bSTAB's friction case: unit mass, damping 0.1, stiffness 1, a
    pressed contact of N = 1 with exponential friction, belt speed 1.5) as dof ``u0``, beside
    ``modes`` modal coordinates that nothing forces or couples (unit masses, frequencies ω_r spread
    over [2, 9] rad/s, damping ratio ``zeta``): a model of 1 + modes dofs whose motions are the
    belt's with the modes at rest, and whose Floquet multipliers add to the belt's the
    closed-form exp(λ_r T), λ_r = −ζ ω_r ± i ω_r √(1 − ζ²), of each mode.

``bar_chain(n, ...)``
    n equal masses m in a chain of equal springs k, the first tied to the wall, one 1-D pressed
    contact on the last mass. Its undamped natural frequencies are in closed form
    (:meth:`FEModel.closed_form_frequencies`): ω_r = 2 √(k/m) sin((2r − 1) π / (2 (2n + 1))).

:meth:`FEModel.write` writes ``M``, ``K`` (and ``C`` unless Rayleigh) as Matrix Market (``mtx``),
scipy.sparse ``npz`` or MATLAB ``mat`` files, a ``nodes.csv`` of coordinates with each node's dofs,
the contact nodes as a ``[contact_set]`` with a CSV (``contacts="set"``), the same set with its
nodes inline (``"set-inline"``) or one ``[[contact]]`` table each with sparse rows (``"tables"``),
and the model file ``model.toml`` beside them; :meth:`FEModel.inline_spec` is the same model with
every matrix written out as TOML lists (small models), to compare the two readings.

Used by tests/fe and by the sparse numerics' tests (complex eigenvalues, reduction).
"""

from __future__ import annotations

import csv
import dataclasses
from pathlib import Path

import numpy as np
import scipy.io
import scipy.sparse as sp
import tomli_w

__all__ = ["FEModel", "pad_on_belt", "bar_chain", "q4_element", "belt_with_modes", "one_contact"]


@dataclasses.dataclass
class FEModel:
    """An assembled test model (module docstring); n dofs, nc contact nodes.

    Attributes
    ----------
    name : str
    mass, stiffness : scipy.sparse.csr_matrix (n, n)
    rayleigh : (alpha, beta) or None
        C = alpha M + beta K.
    damping : csr (n, n) or None
        An explicit C (written as a matrix file) when ``rayleigh`` is None; None and no Rayleigh: C = 0.
    tangent_dof, normal_dof : ndarray (nc,) of int
        Each contact node's tangent dof and normal dof (gap g = gap + u[normal_dof]).
    gap : ndarray (nc,)
        g0 of each contact [m] (compliant contacts).
    drive : float
        Belt speed [m/s] (every contact's w).
    node_ids : ndarray (nc,) of int
        The contact nodes' ids.
    contact : dict
        ``{"law": "compliant", "stiffness": k, "damping": c}`` or ``{"normal_force": N0}`` (pressed).
    friction : dict
        The contacts' ``[friction]`` table.
    coordinates : ndarray (nodes, 3), ids : ndarray (nodes,), dof_node : ndarray (n,), dof_component : ndarray (n,)
        The mesh: each node's x, y, z, its id, and each dof's node (index) and component (0 x, 1 y).
    force : dict of int → float
        Nonzero entries of f0 by dof index.
    elements : ndarray (elements, 4) of int or None
        The quadrilaterals' corner nodes (indices into ``ids``, counter-clockwise), where the mesh has them.
    """

    name: str
    mass: sp.csr_matrix
    stiffness: sp.csr_matrix
    rayleigh: tuple[float, float] | None
    damping: sp.csr_matrix | None
    tangent_dof: np.ndarray
    normal_dof: np.ndarray
    gap: np.ndarray
    drive: float
    node_ids: np.ndarray
    contact: dict
    friction: dict
    coordinates: np.ndarray
    ids: np.ndarray
    dof_node: np.ndarray
    dof_component: np.ndarray
    force: dict = dataclasses.field(default_factory=dict)
    chain: tuple[int, float, float] | None = None
    elements: np.ndarray | None = None

    @property
    def n(self) -> int:
        return self.mass.shape[0]

    def dof(self, i: int) -> str:
        return f"u{i}"

    @property
    def damping_matrix(self) -> sp.csr_matrix:
        """C as the model means it."""
        if self.rayleigh is not None:
            return (self.rayleigh[0] * self.mass + self.rayleigh[1] * self.stiffness).tocsr()
        return sp.csr_matrix((self.n, self.n)) if self.damping is None else self.damping

    def closed_form_frequencies(self) -> np.ndarray:
        """Natural frequencies [rad/s] of a :func:`bar_chain` (ascending), in closed form."""
        n, m, k = self.chain
        r = np.arange(1, n + 1)
        return 2.0 * np.sqrt(k / m) * np.sin((2 * r - 1) * np.pi / (2 * (2 * n + 1)))

    # ------------------------------------------------------------------ writing
    def _contact_tables(self) -> list[dict]:
        out = []
        for c in range(len(self.tangent_dof)):
            table = {"name": f"c{self.node_ids[c]}", "tangent": [{self.dof(self.tangent_dof[c]): 1.0}],
                     "drive": [self.drive]}
            if "normal_force" in self.contact:
                table["normal_force"] = self.contact["normal_force"]
            else:
                table.update(gap=float(self.gap[c]), gap_gradient={self.dof(self.normal_dof[c]): 1.0},
                             normal=dict(self.contact))
            table["friction"] = dict(self.friction)
            out.append(table)
        return out

    def _set_rows(self) -> list[dict]:
        rows = []
        for c in range(len(self.tangent_dof)):
            row = {"node": int(self.node_ids[c]), "tangent": self.dof(self.tangent_dof[c])}
            if "normal_force" not in self.contact:
                row.update(normal=self.dof(self.normal_dof[c]), gap=float(self.gap[c]))
            rows.append(row)
        return rows

    def _contact_set(self, folder: Path, inline: bool) -> dict:
        rows = self._set_rows()
        if inline:
            nodes = {str(r.pop("node")): r for r in rows}
        else:
            nodes = "contact_nodes.csv"
            with open(folder / nodes, "w", newline="") as fh:
                writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
                writer.writeheader()
                writer.writerows(rows)
        table = {"nodes": nodes, "drive": self.drive}
        if "normal_force" in self.contact:
            table["normal_force"] = self.contact["normal_force"]
        else:
            table["normal"] = dict(self.contact)
        table["friction"] = dict(self.friction)
        return table

    def _write_nodes(self, folder: Path) -> str:
        columns = {0: "dof_x", 1: "dof_y"}
        names = {(int(node), int(comp)): self.dof(i) for i, (node, comp) in
                 enumerate(zip(self.dof_node, self.dof_component))}
        with open(folder / "nodes.csv", "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(["node", "x", "y", "z", "dof_x", "dof_y"])
            for k, (node_id, xyz) in enumerate(zip(self.ids, self.coordinates)):
                writer.writerow([int(node_id), *(repr(float(v)) for v in xyz),
                                 *(names.get((k, comp), "") for comp in columns)])
        return "nodes.csv"

    def _write_elements(self, folder: Path) -> str:
        with open(folder / "elements.csv", "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(["element", "type", "n1", "n2", "n3", "n4"])
            for k, corners in enumerate(self.elements, start=1):
                writer.writerow([k, "quad", *(int(self.ids[c]) for c in corners)])
        return "elements.csv"

    def _write_matrix(self, folder: Path, stem: str, matrix: sp.csr_matrix, fmt: str) -> str:
        if fmt == "mtx":
            scipy.io.mmwrite(str(folder / f"{stem}.mtx"), matrix.tocoo(), precision=17)
            return f"{stem}.mtx"
        if fmt == "npz":
            sp.save_npz(folder / f"{stem}.npz", matrix.tocsr())
            return f"{stem}.npz"
        if fmt == "mat":
            scipy.io.savemat(folder / f"{stem}.mat", {stem: matrix.tocsc()})
            return f"{stem}.mat:{stem}"
        raise ValueError(f"unknown matrix format {fmt!r}")

    def write(self, folder, *, matrix_format: str = "mtx", contacts: str = "set", nodes: bool = True,
              elements: bool = False) -> Path:
        """Write the matrix files, CSVs and ``model.toml`` into ``folder``; returns the model file's path.

        ``contacts``: ``"set"`` (a ``[contact_set.pad]`` with a CSV of its nodes), ``"set-inline"``
        (its nodes as a TOML table), ``"tables"`` (one ``[[contact]]`` each, sparse rows).
        ``elements``: the nodes with an ``elements.csv`` (``nodes = { file, elements }``).
        """
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        spec = {"name": self.name, "dofs": {"count": self.n, "prefix": "u"},
                "mass": self._write_matrix(folder, "M", self.mass, matrix_format),
                "stiffness": self._write_matrix(folder, "K", self.stiffness, matrix_format)}
        if self.rayleigh is not None:
            spec["damping"] = {"rayleigh": list(self.rayleigh)}
        elif self.damping is not None:
            spec["damping"] = self._write_matrix(folder, "C", self.damping, matrix_format)
        if self.force:
            spec["force"] = {self.dof(i): v for i, v in self.force.items()}
        if nodes:
            spec["nodes"] = self._write_nodes(folder)
            if elements:
                spec["nodes"] = {"file": spec["nodes"], "elements": self._write_elements(folder)}
        if contacts == "tables":
            spec["contact"] = self._contact_tables()
        else:
            spec["contact_set"] = {"pad": self._contact_set(folder, contacts == "set-inline")}
        path = folder / "model.toml"
        path.write_text(tomli_w.dumps(spec))
        return path

    def inline_spec(self) -> dict:
        """The same model with every matrix and row written out in full as TOML lists (small models)."""
        n = self.n
        names = [self.dof(i) for i in range(n)]
        dense = lambda a: a.toarray().tolist()  # noqa: E731
        spec = {"name": self.name, "dofs": names, "mass": dense(self.mass), "stiffness": dense(self.stiffness),
                "damping": dense(self.damping_matrix)}
        if self.force:
            f = np.zeros(n)
            for i, v in self.force.items():
                f[i] = v
            spec["force"] = f.tolist()
        contacts = []
        for table in self._contact_tables():
            row = np.zeros(n)
            row[self.tangent_dof[len(contacts)]] = 1.0
            table["tangent"] = [row.tolist()]
            if "gap_gradient" in table:
                W = np.zeros(n)
                W[self.normal_dof[len(contacts)]] = 1.0
                table["gap_gradient"] = W.tolist()
            contacts.append(table)
        spec["contact"] = contacts
        return spec


def q4_element(a: float, b: float, E: float, nu: float, rho: float, thickness: float) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and consistent mass (8 × 8) of a rectangular plane-stress Q4 element a × b [m].

    Nodes counter-clockwise from the lower left, dofs (u_x, u_y) per node; 2 × 2 Gauss points
    (exact for the mass, and for the stiffness of a rectangle).
    """
    D = E / (1.0 - nu * nu) * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])
    corners = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    g = 1.0 / np.sqrt(3.0)
    det = a * b / 4.0
    Ke, Me = np.zeros((8, 8)), np.zeros((8, 8))
    for xi in (-g, g):
        for eta in (-g, g):
            N = 0.25 * (1 + corners[:, 0] * xi) * (1 + corners[:, 1] * eta)
            dN_dx = 0.25 * corners[:, 0] * (1 + corners[:, 1] * eta) * 2.0 / a
            dN_dy = 0.25 * corners[:, 1] * (1 + corners[:, 0] * xi) * 2.0 / b
            B = np.zeros((3, 8))
            B[0, 0::2], B[1, 1::2] = dN_dx, dN_dy
            B[2, 0::2], B[2, 1::2] = dN_dy, dN_dx
            Ke += B.T @ D @ B * thickness * det
            Nm = np.zeros((2, 8))
            Nm[0, 0::2], Nm[1, 1::2] = N, N
            Me += rho * thickness * Nm.T @ Nm * det
    return Ke, Me


def pad_on_belt(nx: int = 10, ny: int = 4, *, length: float = 0.1, height: float = 0.02, thickness: float = 0.01,
                E: float = 1e9, nu: float = 0.3, rho: float = 2000.0, speed: float = 0.5, preload: float = 1e-6,
                contact_stiffness: float = 1e8, contact_damping: float = 0.0, mu_k: float = 0.3,
                delta_mu: float = 0.1, alpha: float | None = None, rayleigh: tuple[float, float] | None = (0.0, 1e-6),
                normal_force: float | None = None, name: str = "pad-on-belt") -> FEModel:
    """The pad on a belt (module docstring): nx × ny Q4 elements; SI units.

    ``normal_force`` given: pressed contacts with that N0 instead of compliant ones. ``alpha``
    given: the exponential friction law, else Coulomb.
    """
    a, b = length / nx, height / ny
    Ke, Me = q4_element(a, b, E, nu, rho, thickness)
    cols = nx + 1
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    i, j = i.ravel(), j.ravel()
    corner_nodes = np.stack([j * cols + i, j * cols + i + 1, (j + 1) * cols + i + 1, (j + 1) * cols + i], axis=1)
    dofs = np.stack([2 * corner_nodes, 2 * corner_nodes + 1], axis=2).reshape(-1, 8)  # (elements, 8)
    n = 2 * cols * ny  # the top row (j = ny) is clamped: its dofs, 2 cols ny and up, are dropped
    rows = np.repeat(dofs, 8, axis=1).ravel()
    columns = np.tile(dofs, (1, 8)).ravel()
    keep = (rows < n) & (columns < n)
    shape = (n, n)
    K = sp.coo_matrix((np.tile(Ke.ravel(), len(dofs))[keep], (rows[keep], columns[keep])), shape=shape).tocsr()
    M = sp.coo_matrix((np.tile(Me.ravel(), len(dofs))[keep], (rows[keep], columns[keep])), shape=shape).tocsr()
    bottom = np.arange(cols)
    contact = ({"normal_force": float(normal_force)} if normal_force is not None else
               {"law": "compliant", "stiffness": contact_stiffness, "damping": contact_damping})
    friction = {"law": "coulomb", "mu_k": mu_k, "delta_mu": delta_mu} if alpha is None else \
        {"law": "exponential", "mu_k": mu_k, "delta_mu": delta_mu, "alpha": alpha}
    nodes = np.arange(cols * (ny + 1))
    coordinates = np.stack([(nodes % cols) * a, (nodes // cols) * b, np.zeros(len(nodes))], axis=1)
    return FEModel(name=name, mass=M, stiffness=K, rayleigh=rayleigh, damping=None, tangent_dof=2 * bottom,
                   normal_dof=2 * bottom + 1, gap=np.full(cols, -preload), drive=speed, node_ids=bottom + 1,
                   contact=contact, friction=friction, coordinates=coordinates, ids=nodes + 1,
                   dof_node=np.arange(n) // 2, dof_component=np.arange(n) % 2, elements=corner_nodes)


def bar_chain(n: int = 8, *, mass: float = 1.0, stiffness: float = 100.0, damping: float = 0.0,
              normal_force: float = 1.0, speed: float = 0.3, mu_k: float = 0.3, delta_mu: float = 0.2,
              alpha: float = 2.0, name: str = "bar-chain") -> FEModel:
    """n masses in a chain of springs, the first tied to the wall, a pressed contact on the last
    (module docstring); ``damping``: an explicit C = damping × (the springs' pattern), written as a file."""
    main = np.full(n, 2.0 * stiffness)
    main[-1] = stiffness
    K = sp.diags([np.full(n - 1, -stiffness), main, np.full(n - 1, -stiffness)], [-1, 0, 1], format="csr")
    M = sp.identity(n, format="csr") * mass
    C = (K * (damping / stiffness)).tocsr() if damping else None
    return FEModel(name=name, mass=M.tocsr(), stiffness=K, rayleigh=None, damping=C,
                   tangent_dof=np.array([n - 1]), normal_dof=np.array([n - 1]), gap=np.zeros(1), drive=speed,
                   node_ids=np.array([n]), contact={"normal_force": normal_force},
                   friction={"law": "exponential", "mu_k": mu_k, "delta_mu": delta_mu, "alpha": alpha},
                   coordinates=np.stack([np.arange(1, n + 1, dtype=float), np.zeros(n), np.zeros(n)], axis=1),
                   ids=np.arange(1, n + 1), dof_node=np.arange(n), dof_component=np.zeros(n, dtype=int),
                   chain=(n, mass, stiffness))


def belt_with_modes(modes: int = 69, *, zeta: float = 0.05, name: str = "belt-with-modes") -> FEModel:
    """The belt with ``modes`` unforced, uncoupled modal coordinates (module docstring)."""
    n = 1 + modes
    omega = np.linspace(2.0, 9.0, modes)
    M = sp.identity(n, format="csr")
    K = sp.diags(np.concatenate([[1.0], omega**2]), format="csr")
    C = sp.diags(np.concatenate([[0.1], 2.0 * zeta * omega]), format="csr")
    return FEModel(name=name, mass=M, stiffness=K, rayleigh=None, damping=C, tangent_dof=np.array([0]),
                   normal_dof=np.array([0]), gap=np.zeros(1), drive=1.5, node_ids=np.array([1]),
                   contact={"normal_force": 1.0}, friction={"law": "exponential", "mu_k": 0.5, "delta_mu": 0.5,
                                                            "alpha": 2.0},
                   coordinates=np.zeros((n, 3)), ids=np.arange(1, n + 1), dof_node=np.arange(n),
                   dof_component=np.zeros(n, dtype=int))


def one_contact(model: FEModel, index: int) -> FEModel:
    """``model`` with only its contact ``index`` (the others removed)."""
    keep = np.array([index])
    return dataclasses.replace(model, tangent_dof=model.tangent_dof[keep], normal_dof=model.normal_dof[keep],
                               gap=model.gap[keep], node_ids=model.node_ids[keep])
