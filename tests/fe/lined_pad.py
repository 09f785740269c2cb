"""A pad of two materials on a belt, assembled with numpy and scipy alone (independent of stickslip).

A stiff backing plate (``E_plate``) clamped along its top, and one row of soft friction material
(``E_lining``) under it whose bottom nodes are the contact nodes on a belt — a brake pad's steel
backplate and lining, as plane-stress bilinear quadrilaterals (``fe_models.q4_element``). The
lining is the only compliance that the contact nodes feel at low frequency: the motions that
stick-slip, slip and lift-off excite are those of the contact nodes on the lining, while the
plate's modes lie a factor √(E_plate/E_lining) higher. A reduction that keeps the contact DOFs and
truncates the plate's modes is then a genuine reduction whose error falls with that separation.

Damping: C = β K_lining (the lining's stiffness alone; the plate undamped), written as a matrix
file, so that the plate's fast modes are not made stiff for an explicit integrator by a stiffness-
proportional damping of their own.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .fe_models import FEModel, q4_element

__all__ = ["lined_pad"]


def _assemble(nx: int, ny: int, element) -> sp.csr_matrix:
    """Sum of element matrices ``element(j)`` (8 × 8, row j of elements) over the nx × ny grid, top row clamped."""
    cols = nx + 1
    n = 2 * cols * ny
    rows, columns, values = [], [], []
    for j in range(ny):
        Ae = element(j)
        for i in range(nx):
            corners = np.array([j * cols + i, j * cols + i + 1, (j + 1) * cols + i + 1, (j + 1) * cols + i])
            dofs = np.stack([2 * corners, 2 * corners + 1], axis=1).ravel()
            r, c = np.repeat(dofs, 8), np.tile(dofs, 8)
            keep = (r < n) & (c < n)
            rows.append(r[keep])
            columns.append(c[keep])
            values.append(Ae.ravel()[keep])
    return sp.coo_matrix((np.concatenate(values), (np.concatenate(rows), np.concatenate(columns))),
                         shape=(n, n)).tocsr()


def lined_pad(nx: int = 8, ny: int = 8, *, length: float = 0.1, height: float = 0.02, thickness: float = 0.01,
              lining: float = 0.004, E_plate: float = 2e11, E_lining: float = 1e7, nu: float = 0.3, rho: float = 2000.0,
              beta: float = 2e-6, contact_stiffness: float = 1e6, preload: float = 3e-5, speed: float = 0.05,
              mu_k: float = 0.3, delta_mu: float = 0.2, lumped: bool = True, name: str = "lined-pad") -> FEModel:
    """The lined pad (module docstring): nx × ny elements, the bottom row the lining (``lining`` thick,
    the plate's ny − 1 rows share the rest of ``height``); SI units.

    Dofs ``u0 … u{n-1}`` as :func:`fe_models.pad_on_belt` numbers them (node (i, j) from the bottom
    left has u_x = u[2 k], u_y = u[2 k + 1], k = j (nx + 1) + i); n = 2 (nx + 1) ny; one compliant
    contact per bottom node (tangent its x dof, gap g = −preload + u_y), Coulomb friction.
    """
    a, b = length / nx, (height - lining) / (ny - 1)
    soft = q4_element(a, lining, E_lining, nu, rho, thickness)
    hard = q4_element(a, b, E_plate, nu, rho, thickness)
    K = _assemble(nx, ny, lambda j: (soft if j == 0 else hard)[0])
    M = _assemble(nx, ny, lambda j: (soft if j == 0 else hard)[1])  # one density
    if lumped:  # row sums on the diagonal, as explicit FE codes lump their masses
        M = sp.diags(np.asarray(M.sum(axis=1)).ravel(), format="csr")
    C = beta * _assemble(nx, ny, lambda j: soft[0] if j == 0 else np.zeros((8, 8)))
    cols = nx + 1
    bottom = np.arange(cols)
    nodes = np.arange(cols * (ny + 1))
    n = 2 * cols * ny
    row = nodes // cols
    coordinates = np.stack([(nodes % cols) * a, np.where(row == 0, 0.0, lining + (row - 1) * b), np.zeros(len(nodes))],
                           axis=1)
    return FEModel(name=name, mass=M, stiffness=K, rayleigh=None, damping=C.tocsr(), tangent_dof=2 * bottom,
                   normal_dof=2 * bottom + 1, gap=np.full(cols, -preload), drive=speed, node_ids=bottom + 1,
                   contact={"law": "compliant", "stiffness": contact_stiffness, "damping": 0.0},
                   friction={"law": "coulomb", "mu_k": mu_k, "delta_mu": delta_mu}, coordinates=coordinates,
                   ids=nodes + 1, dof_node=np.arange(n) // 2, dof_component=np.arange(n) % 2)
