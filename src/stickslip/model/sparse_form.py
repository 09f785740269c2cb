"""A constant-kinematics model as sparse arrays: what the sparse numerics (steady sliding, complex
eigenvalues, reduction) take, for models of any size.

    M q̈ = f0 − C q̇ − K q + Gᵀ F + Wᵀ λ,    v = G q̇ − w,    N = N0 + n·q + n_v·q̇,    g = g0 + W q

:class:`SparseForm` holds every ingredient of a :class:`~stickslip.model.system_model.FrictionModel`
whose contact frames are constant (model files, dense or sparse; not the plates, whose G depends
on q), with every contact's rows stacked:

==========================  =======================================================================
``dofs``                    the n coordinate names
``mass``, ``damping``,      M, C, K: ``scipy.sparse.csr_matrix`` (n, n) [kg, N s/m, N/m or the
``stiffness``               dofs' own units]; K may be non-symmetric
``force``                   f0 (n,)
``free``                    (n,) bool; locked dofs never move
``tangent``                 G: csr (R, n), every contact's tangent rows stacked; contact c owns rows
                            ``row_start[c]:row_start[c + 1]`` (1 or 2 rows)
``row_start``               (nc + 1,) int
``drive``                   w (R,) [m/s]: v = G q̇ − w
``normal_force``            N0 (nc,) [N] of the pressed contacts (0 for a unilateral one)
``normal_gradient``,        n, n_v: csr (nc, n) of N = N0 + n·q + n_v·q̇ of the pressed contacts
``normal_rate_gradient``    (zero rows for a unilateral one, whose normal force comes from its gap)
``unilateral``              (nc,) bool: the contact states a gap and a normal law
``normal_law``              (nc,) str: ``""`` (pressed), ``"compliant"`` or ``"rigid"``
``gap``, ``gap_gradient``   g0 (nc,) [m] and W: csr (nc, n) of g = g0 + W q (0 and zero rows for a
                            pressed contact)
``contact_stiffness``,      k [N/m], c [N s/m] of a compliant contact, λ = max(0, −k g − c ġ);
``contact_damping``,        e [-], Newton's restitution of a rigid one (each (nc,), 0 where it does
``restitution``             not apply)
``friction``                tuple of :class:`~stickslip.model.friction.FrictionLaw`, one per contact;
                            :meth:`SparseForm.mu` and :meth:`SparseForm.dmu` evaluate μ(|v|) and
                            dμ/d|v| in Python (:func:`friction_value`, :func:`friction_slope`)
``contact_names``           tuple of nc names
``nodes``                   :class:`NodeMap` (coordinates and each dof's node), or None
``units``                   the model's units (dofs and parameters) where it gives them
``slip_band``               the low-speed band of the 2-D slip direction [m/s]
==========================  =======================================================================

:meth:`SparseForm.closed_normal` gives the normal force of every contact as affine in the state
with each compliant contact taken closed (N = −k g0 − k W q − c W q̇), the form in which steady
sliding and its linearisation take it. ``FrictionModel.sparse_form()`` builds the form (dense
library models included, so that the sparse numerics can be checked against the dense path).
"""

from __future__ import annotations

import dataclasses
from typing import Mapping

import numpy as np
# scipy.sparse is imported in the functions that use it: a dense model (the two plates, most model
# files) never needs it, and its import costs every command's start-up time.

from ..errors import ModelError
from .friction import _USER_LAWS, FrictionLaw
from .matrices import is_sparse

__all__ = ["SparseForm", "NodeMap", "sparse_form", "friction_value", "friction_slope", "COMPONENTS", "CELL_NODES"]

#: Component codes of :attr:`NodeMap.component`: translations along x, y, z, then rotations about them.
COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")

#: Element (cell) types of :attr:`NodeMap.cells` and their numbers of nodes: VTK's cells by meshio's
#: names, their nodes in VTK's order (corners counter-clockwise, bottom face before top face; the
#: mid-side nodes of the quadratic ones after the corners).
CELL_NODES = {"vertex": 1, "line": 2, "triangle": 3, "quad": 4, "tetra": 4, "pyramid": 5, "wedge": 6,
              "hexahedron": 8, "line3": 3, "triangle6": 6, "quad8": 8, "tetra10": 10, "wedge15": 15,
              "hexahedron20": 20}

#: Complex step of a user law's derivative (exact to round-off for a complex-safe law).
_STEP = 1e-20


def friction_value(law: FrictionLaw, speed) -> np.ndarray:
    """μ(|v|) [-] of ``law`` at slip speeds ``speed`` [m/s] (any shape; ``|speed|`` is used)."""
    return law.coefficient(speed)


def friction_slope(law: FrictionLaw, speed) -> np.ndarray:
    """dμ/d|v| [s/m] of ``law`` at slip speeds ``speed`` [m/s] (any shape; the right derivative at 0).

    ``coulomb``: 0; ``exponential``: −α Δμ exp(−α |v|) + μv; ``stribeck``: −2 (|v|/v_s²) Δμ
    exp(−(|v|/v_s)²) + μv; a user law: the complex step of its
    function (a user law is complex-safe by contract, :mod:`stickslip.model.friction`).
    """
    speed = np.abs(np.asarray(speed, dtype=float))
    if law.law == "coulomb":
        return np.zeros_like(speed)
    if law.law == "exponential":
        return -law.alpha * law.delta_mu * np.exp(-law.alpha * speed) + law.mu_v
    if law.law == "stribeck":
        ratio = speed / law.v_s
        return -2.0 * ratio / law.v_s * law.delta_mu * np.exp(-ratio * ratio) + law.mu_v
    mu = _USER_LAWS[type(law.user)].py_func
    return np.vectorize(lambda v: float(np.imag(mu(law.user, complex(v, _STEP)))) / _STEP, otypes=[float])(speed)


@dataclasses.dataclass(frozen=True, eq=False)
class NodeMap:
    """Where each dof sits on the mesh, to draw mode shapes.

    Attributes
    ----------
    ids : ndarray (nn,) of int
        Node ids, as the mesh numbers them.
    coordinates : ndarray (nn, 3)
        x, y, z of each node [m] (z = 0 for a plane mesh).
    node : ndarray (n,) of int
        Index into :attr:`ids` of each dof's node; −1 for a dof on no node (a modal coordinate).
    component : ndarray (n,) of int
        What each dof is at its node: 0, 1, 2 the displacement along x, y, z, 3, 4, 5 the rotation
        about them (:data:`COMPONENTS`); −1 for a dof on no node.
    cells : tuple of (str, ndarray (ne, k) of int)
        The mesh's elements, one block per type (:data:`CELL_NODES`: ``"quad"``, ``"hexahedron"``,
        …): each row the indices into :attr:`ids` of an element's k nodes; empty without elements
        (mode shapes are then drawn on the nodes alone).
    """

    ids: np.ndarray
    coordinates: np.ndarray
    node: np.ndarray
    component: np.ndarray
    cells: tuple = ()

    def __post_init__(self) -> None:
        for key, dtype in (("ids", np.int64), ("coordinates", float), ("node", np.int64), ("component", np.int64)):
            value = np.array(getattr(self, key), dtype=dtype)
            value.setflags(write=False)
            object.__setattr__(self, key, value)
        object.__setattr__(self, "cells", tuple(_cell_block(kind, rows, len(self.ids)) for kind, rows in self.cells))
        nn, n = len(self.ids), len(self.node)
        if self.coordinates.shape != (nn, 3) or self.component.shape != (n,):
            raise ModelError(f"nodes: {nn} node ids need {nn} × 3 coordinates and each of the {n} dofs a component; "
                             f"got {self.coordinates.shape} and {self.component.shape}")
        if len(np.unique(self.ids)) != nn:
            raise ModelError("nodes: node ids must be unique; give each node once")
        if n and (self.node.min() < -1 or self.node.max() >= nn or self.component.min() < -1
                  or self.component.max() >= len(COMPONENTS)):
            raise ModelError(f"nodes: a dof's node index must lie in [-1, {nn}) and its component in [-1, "
                             f"{len(COMPONENTS)}) (x, y, z, rx, ry, rz)")

    def displacement(self, shape: np.ndarray) -> np.ndarray:
        """The nodes' displacements (nn, 3) of a dof vector ``shape`` (n,) (real or complex: a mode
        shape); rotations and dofs on no node are left out."""
        shape = np.asarray(shape)
        out = np.zeros((len(self.ids), 3), dtype=shape.dtype)
        on = (self.node >= 0) & (self.component >= 0) & (self.component < 3)
        out[self.node[on], self.component[on]] = shape[on]
        return out


@dataclasses.dataclass(frozen=True, eq=False)
class SparseForm:
    """A constant-kinematics model as sparse arrays (module docstring; n dofs, nc contacts, R rows)."""

    name: str
    dofs: tuple[str, ...]
    mass: sp.csr_matrix
    damping: sp.csr_matrix
    stiffness: sp.csr_matrix
    force: np.ndarray
    free: np.ndarray
    tangent: sp.csr_matrix
    row_start: np.ndarray
    drive: np.ndarray
    normal_force: np.ndarray
    normal_gradient: sp.csr_matrix
    normal_rate_gradient: sp.csr_matrix
    unilateral: np.ndarray
    normal_law: np.ndarray
    gap: np.ndarray
    gap_gradient: sp.csr_matrix
    contact_stiffness: np.ndarray
    contact_damping: np.ndarray
    restitution: np.ndarray
    friction: tuple[FrictionLaw, ...]
    contact_names: tuple[str, ...]
    nodes: NodeMap | None = None
    units: Mapping[str, str] = dataclasses.field(default_factory=dict)
    slip_band: float = 0.0

    @property
    def n(self) -> int:
        """Number of coordinates."""
        return len(self.dofs)

    @property
    def nc(self) -> int:
        """Number of contacts."""
        return len(self.contact_names)

    @property
    def dim(self) -> np.ndarray:
        """(nc,) each contact's number of tangent rows (1 or 2)."""
        return np.diff(self.row_start)

    def rows(self, c: int) -> slice:
        """Contact ``c``'s rows of :attr:`tangent` and :attr:`drive`."""
        return slice(int(self.row_start[c]), int(self.row_start[c + 1]))

    @property
    def static_coefficients(self) -> np.ndarray:
        """(nc,) μs of each contact: stick holds while |F| ≤ μs N."""
        return np.array([law.mu_s for law in self.friction])

    def mu(self, c: int, speed) -> np.ndarray:
        """μ(|v|) [-] of contact ``c`` at slip speeds ``speed`` [m/s]."""
        return friction_value(self.friction[c], speed)

    def dmu(self, c: int, speed) -> np.ndarray:
        """dμ/d|v| [s/m] of contact ``c`` at slip speeds ``speed`` [m/s]."""
        return friction_slope(self.friction[c], speed)

    def closed_normal(self) -> tuple[np.ndarray, sp.csr_matrix, sp.csr_matrix]:
        """(N0 (nc,), n csr (nc, n), n_v csr (nc, n)): every contact's normal force N0 + n·q + n_v·q̇
        with each compliant contact closed (N0 = −k g0, n = −k W, n_v = −c W); a rigid contact's
        normal force is a multiplier, not affine in the state: its rows are zero."""
        import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

        compliant = self.normal_law == "compliant"
        k = np.where(compliant, self.contact_stiffness, 0.0)
        c = np.where(compliant, self.contact_damping, 0.0)
        N0 = np.where(self.unilateral, -k * self.gap, self.normal_force) + 0.0  # + 0.0: no −0 for k = 0
        n_q = (self.normal_gradient - sp.diags(k) @ self.gap_gradient).tocsr()
        n_v = (self.normal_rate_gradient - sp.diags(c) @ self.gap_gradient).tocsr()
        return N0, n_q, n_v


def _cell_block(kind, rows, nn: int) -> tuple[str, np.ndarray]:
    """One block of :attr:`NodeMap.cells`, checked: a known type, its number of nodes per row, and
    node indices of the mesh."""
    if kind not in CELL_NODES:
        raise ModelError(f"nodes: element type {kind!r} is not one of {', '.join(CELL_NODES)} (VTK's cells by "
                         "meshio's names)")
    rows = np.array(rows, dtype=np.int64)
    k = CELL_NODES[kind]
    if rows.ndim != 2 or rows.shape[1] != k:
        raise ModelError(f"nodes: {kind} elements have {k} nodes each; got rows of shape {rows.shape}")
    if rows.size and (rows.min() < 0 or rows.max() >= nn):
        raise ModelError(f"nodes: an element's node index must lie in [0, {nn}) (the mesh's nodes)")
    rows.setflags(write=False)
    return kind, rows


def _csr(value, shape: tuple[int, int]) -> sp.csr_matrix:
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    out = sp.csr_matrix(value if is_sparse(value) else np.asarray(value, dtype=float).reshape(shape), dtype=float)
    return out


def _stacked(rows: list, n: int) -> sp.csr_matrix:
    """One row per contact (None: a zero row), stacked into csr (nc, n)."""
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    return sp.vstack([sp.csr_matrix((1, n)) if r is None else _csr(r, (1, n)) for r in rows], format="csr") \
        if rows else sp.csr_matrix((0, n))


def sparse_form(model) -> SparseForm:
    """The :class:`SparseForm` of a constant-kinematics :class:`~stickslip.model.system_model.FrictionModel`.

    Raises
    ------
    ModelError
        For a model whose contact frames depend on q (a kinematics class other than the constant ones).
    """
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    if not model.constant_kinematics:
        raise ModelError(f"model {model.name!r} computes its contact frames from q (kinematics "
                         f"{type(model.kinematics).__name__}); the sparse form needs constant tangent rows and drives "
                         "(a model file, or a FrictionModel with tangent= and drive= on each contact)")
    n, contacts = model.n, model.contacts
    frictionless = [name for c, name in zip(contacts, model.contact_names) if c.frictionless]
    if frictionless:
        raise ModelError(f"model {model.name!r}: contact {frictionless[0]} has no friction, which the sparse form "
                         "(finite-element numerics) does not take yet; use the dense tools (stickslip stability "
                         "without --max-frequency), or give the contact a tangent and a friction law")
    dims = [c.dim for c in contacts]
    laws = [c.normal.law if c.unilateral else "" for c in contacts]
    normal = [c.normal for c in contacts]
    return SparseForm(
        name=model.name, dofs=tuple(model.dofs),
        mass=_csr(model.mass, (n, n)), damping=_csr(model.damping, (n, n)), stiffness=_csr(model.stiffness, (n, n)),
        force=np.array(model.force, dtype=float), free=np.array(model.free, dtype=bool),
        tangent=sp.vstack([_csr(c.tangent, (c.dim, n)) for c in contacts], format="csr"),
        row_start=np.concatenate([[0], np.cumsum(dims)]).astype(np.int64),
        drive=np.concatenate([np.asarray(c.drive, dtype=float).reshape(-1) for c in contacts]),
        normal_force=np.array([0.0 if c.unilateral else c.normal_force for c in contacts]),
        normal_gradient=_stacked([c.normal_gradient for c in contacts], n),
        normal_rate_gradient=_stacked([c.normal_rate_gradient for c in contacts], n),
        unilateral=np.array([c.unilateral for c in contacts], dtype=bool),
        normal_law=np.array(laws, dtype=str),
        gap=np.array([c.gap if c.unilateral else 0.0 for c in contacts]),
        gap_gradient=_stacked([c.gap_gradient if c.unilateral else None for c in contacts], n),
        contact_stiffness=np.array([law.stiffness if law is not None else 0.0 for law in normal]),
        contact_damping=np.array([law.damping if law is not None else 0.0 for law in normal]),
        restitution=np.array([law.restitution if law is not None else 0.0 for law in normal]),
        friction=tuple(c.friction for c in contacts), contact_names=tuple(model.contact_names),
        nodes=getattr(model, "nodes", None), units=dict(model.units), slip_band=float(model.slip_band))
