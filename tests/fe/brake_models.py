"""Finite-element test models of friction-induced vibration, in numpy and scipy.sparse alone.

Structured meshes of bilinear quadrilaterals (2-D plane stress) and trilinear hexahedra (3-D),
isotropic linear elasticity, consistent mass, 2 × 2 (× 2) Gauss points, assembled as sparse
matrices. The models:

* :func:`pad_on_belt_2d`: a pad pressed on a rigid moving belt, its bottom nodes on compliant
  contacts (1-D friction along the belt);
* :func:`pad_on_strip_2d`: a pad pressed on a flexible strip clamped at its ends, node pairs
  between them on compliant contacts (the strip moves under the pad);
* :func:`pad_on_surface_3d`: a 3-D pad on a rigid plane moving under it (2-D friction);
* :func:`pad_on_disc_3d`: a 3-D pad on an annular disc clamped at its hub, node pairs between the
  pad's face and the disc's surface on compliant contacts with 2-D friction (circumferential and
  radial), the disc's rotation in the drive: the brake-squeal set-up.

Each returns a sparse form (the fields of ``FrictionModel.sparse_form()``) or, with ``dense=True``
and few enough DOFs, a :class:`~stickslip.model.FrictionModel` with the same numbers (for the
dense solvers' checks).
"""

from __future__ import annotations

import itertools

import numpy as np
import scipy.sparse as sp

from stickslip.model import FrictionModel
from stickslip.model.friction import FrictionLaw
from stickslip.model.sparse_form import NodeMap, SparseForm
from stickslip.model.system_model import Contact, NormalLaw

__all__ = ["elasticity_matrices", "pad_on_belt_2d", "pad_on_strip_2d", "pad_on_surface_3d", "pad_on_disc_3d",
           "dense_model"]


def _elasticity(dim: int, E: float, nu: float) -> np.ndarray:
    if dim == 2:  # plane stress
        return E / (1 - nu**2) * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(3), np.arange(3)] += 2 * mu
    D[np.arange(3, 6), np.arange(3, 6)] = mu
    return D


def _shape(dim: int):
    """Corner signs (nen, dim) of the reference element and its Gauss points (G, dim)."""
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], float) if dim == 2 else np.array(
        [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    gauss = np.array(list(itertools.product([-1, 1], repeat=dim)), float) / np.sqrt(3.0)
    return corners, gauss


def elasticity_matrices(nodes, elements, E, nu, rho, thickness=1.0, chunk=4096):
    """Stiffness and consistent mass (csr, n × n with n = dim × nodes) of linear elasticity.

    Parameters
    ----------
    nodes : ndarray (N, dim)
        Coordinates [m].
    elements : ndarray (Ne, 4) or (Ne, 8)
        Node indices, counter-clockwise (bottom face then top face for hexahedra).
    E, nu, rho : float
        Young's modulus [Pa], Poisson's ratio, density [kg/m³].
    thickness : float
        Plane-stress thickness [m] (2-D).
    """
    dim = nodes.shape[1]
    corners, gauss = _shape(dim)
    nen = corners.shape[0]
    D = _elasticity(dim, E, nu)
    # shape functions and their reference derivatives at the Gauss points
    Nv = np.prod(1 + gauss[:, None, :] * corners[None, :, :], axis=2) / 2**dim  # (G, nen)
    dN = np.empty((gauss.shape[0], nen, dim))
    for j in range(dim):
        others = np.prod(np.delete(1 + gauss[:, None, :] * corners[None, :, :], j, axis=2), axis=2)
        dN[:, :, j] = corners[None, :, j] * others / 2**dim
    rows, cols, kvals, mvals = [], [], [], []
    nstrain = 3 if dim == 2 else 6
    for start in range(0, elements.shape[0], chunk):
        el = elements[start:start + chunk]
        X = nodes[el]  # (e, nen, dim)
        J = np.einsum("ead,gaj->egdj", X, dN)
        detJ = np.linalg.det(J)
        dNdx = np.einsum("gaj,egjd->egad", dN, np.linalg.inv(J))
        B = np.zeros(el.shape[:1] + (gauss.shape[0], nstrain, nen * dim))
        for d in range(dim):
            B[:, :, d, d::dim] = dNdx[:, :, :, d]
        shear = [(0, 1)] if dim == 2 else [(1, 2), (0, 2), (0, 1)]
        for s, (i, j) in enumerate(shear):
            B[:, :, dim + s, i::dim] = dNdx[:, :, :, j]
            B[:, :, dim + s, j::dim] = dNdx[:, :, :, i]
        w = detJ * (thickness if dim == 2 else 1.0)
        DB = np.matmul(D, B).reshape(el.shape[0], -1, nen * dim)  # (e, g·s, j)
        Bw = (B * w[:, :, None, None]).reshape(DB.shape)
        Ke = np.matmul(Bw.transpose(0, 2, 1), DB)
        Ms = rho * np.einsum("ga,gb,eg->eab", Nv, Nv, w, optimize=True)
        Me = np.einsum("eab,ij->eaibj", Ms, np.eye(dim)).reshape(Ke.shape)
        dofs = (el[:, :, None] * dim + np.arange(dim)).reshape(el.shape[0], -1)
        rows.append(np.repeat(dofs, nen * dim, axis=1).ravel())
        cols.append(np.tile(dofs, (1, nen * dim)).ravel())
        kvals.append(Ke.ravel())
        mvals.append(Me.ravel())
    n = nodes.size
    r, c = np.concatenate(rows), np.concatenate(cols)
    K = sp.csr_matrix((np.concatenate(kvals), (r, c)), shape=(n, n))
    M = sp.csr_matrix((np.concatenate(mvals), (r, c)), shape=(n, n))
    return K, M


def _grid(shape, lengths, origin=None):
    """Nodes and elements of a structured box of shape[i] elements with the given lengths."""
    dim = len(shape)
    axes = [np.linspace(0.0, L, s + 1) for s, L in zip(shape, lengths)]
    mesh = np.meshgrid(*axes, indexing="ij")
    nodes = np.stack([m.ravel() for m in mesh], axis=1)
    if origin is not None:
        nodes = nodes + np.asarray(origin, float)
    index = np.arange(nodes.shape[0]).reshape([s + 1 for s in shape])
    if dim == 2:
        i, j = np.meshgrid(np.arange(shape[0]), np.arange(shape[1]), indexing="ij")
        i, j = i.ravel(), j.ravel()
        el = np.stack([index[i, j], index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]], axis=1)
    else:
        i, j, k = (a.ravel() for a in np.meshgrid(*[np.arange(s) for s in shape], indexing="ij"))
        el = np.stack([index[i, j, k], index[i + 1, j, k], index[i + 1, j + 1, k], index[i, j + 1, k],
                       index[i, j, k + 1], index[i + 1, j, k + 1], index[i + 1, j + 1, k + 1], index[i, j + 1, k + 1]],
                      axis=1)
    return nodes, el, index


class _Assembly:
    """Bodies side by side in one coordinate vector, DOFs removed where held, contacts collected."""

    def __init__(self, dim):
        self.dim, self.K, self.M, self.nodes, self.offset, self.elements = dim, [], [], [], 0, []
        self.fixed, self.force, self.contacts = [], [], []

    def body(self, nodes, elements, E, nu, rho, thickness=1.0):
        K, M = elasticity_matrices(nodes, elements, E, nu, rho, thickness)
        base = self.offset
        self.K.append(K)
        self.M.append(M)
        self.nodes.append(nodes)
        self.elements.append(np.asarray(elements) + base)
        self.offset += nodes.shape[0]
        return base

    def dof(self, node, axis):
        return node * self.dim + axis

    def build(self, contact_rows, *, mu, kc, cc, force, name, alpha=0.0, beta=0.0, law=None):
        """The sparse form: contact_rows a list of (tangent rows {dof: coefficient}..., drive, gap row)."""
        K = sp.block_diag(self.K, format="csr")
        M = sp.block_diag(self.M, format="csr")
        n = K.shape[0]
        keep = np.setdiff1d(np.arange(n), np.asarray(self.fixed, int))
        P = sp.csr_matrix((np.ones(keep.size), (keep, np.arange(keep.size))), shape=(n, keep.size))
        K, M = sp.csr_matrix(P.T @ K @ P), sp.csr_matrix(P.T @ M @ P)
        C = sp.csr_matrix(alpha * M + beta * K)
        position = -np.ones(n, int)
        position[keep] = np.arange(keep.size)
        f = np.zeros(n)
        for dof, value in force:
            f[dof] += value
        tr, tc, tv, drive, row_start, gr, gc, gv = [], [], [], [], [0], [], [], []
        for c, (tangents, w, gap_row) in enumerate(contact_rows):
            for t in tangents:
                r = len(drive)
                for dof, value in t.items():
                    if position[dof] >= 0:
                        tr.append(r), tc.append(position[dof]), tv.append(value)
                drive.append(0.0)
            drive[-len(tangents):] = w
            row_start.append(len(drive))
            for dof, value in gap_row.items():
                if position[dof] >= 0:
                    gr.append(c), gc.append(position[dof]), gv.append(value)
        nc, R, k = len(contact_rows), len(drive), keep.size
        friction = law or FrictionLaw("coulomb", mu_k=mu, delta_mu=0.0)
        nodes = np.vstack(self.nodes)
        coordinates = np.hstack([nodes, np.zeros((nodes.shape[0], 3 - self.dim))])
        return SparseForm(
            name=name, dofs=tuple(f"u{i}" for i in range(k)), mass=M, damping=C, stiffness=K, force=f[keep],
            free=np.ones(k, bool), tangent=sp.csr_matrix((tv, (tr, tc)), shape=(R, k)),
            row_start=np.asarray(row_start, np.int64), drive=np.asarray(drive, float), normal_force=np.zeros(nc),
            normal_gradient=sp.csr_matrix((nc, k)), normal_rate_gradient=sp.csr_matrix((nc, k)),
            unilateral=np.ones(nc, bool), normal_law=np.array(["compliant"] * nc), gap=np.zeros(nc),
            gap_gradient=sp.csr_matrix((gv, (gr, gc)), shape=(nc, k)), contact_stiffness=np.full(nc, kc),
            contact_damping=np.full(nc, cc), restitution=np.zeros(nc), friction=(friction,) * nc,
            contact_names=tuple(f"c{c}" for c in range(nc)),
            nodes=NodeMap(ids=np.arange(nodes.shape[0]), coordinates=coordinates, node=keep // self.dim,
                          component=keep % self.dim,
                          cells=(("quad" if self.dim == 2 else "hexahedron", np.vstack(self.elements)),)),
            units={}, slip_band=5e-4)


def pad_on_belt_2d(nx=6, ny=3, *, width=0.04, height=0.012, E=5e9, nu=0.25, rho=2500.0, thickness=0.01,
                   pressure=1e6, kc=5e8, cc=0.0, mu=0.3, speed=1.0, dense=False, law=None):
    """A plane-stress pad (nx × ny elements) pressed by ``pressure`` [Pa] on a rigid belt moving at
    ``speed`` [m/s]; its top is held along the belt; each bottom node on a compliant contact."""
    asm = _Assembly(2)
    nodes, el, index = _grid((nx, ny), (width, height))
    asm.body(nodes, el, E, nu, rho, thickness)
    top = index[:, -1]
    asm.fixed += [asm.dof(i, 0) for i in top]
    share = pressure * width * thickness / nx
    asm.force += [(asm.dof(i, 1), -share * (0.5 if k in (0, nx) else 1.0)) for k, i in enumerate(top)]
    rows = []
    for i in index[:, 0]:
        rows.append(([{asm.dof(i, 0): 1.0}], [speed], {asm.dof(i, 1): 1.0}))
    form = asm.build(rows, mu=mu, kc=kc, cc=cc, force=asm.force, name="pad-on-belt", law=law)
    return dense_model(form) if dense else form


def pad_on_strip_2d(strip=(120, 5), pad=(30, 8), *, length=0.3, depth=0.02, pad_height=0.02,
                    E_strip=2.1e11, E_pad=5e9, rho_strip=7800.0, rho_pad=2500.0, nu=0.3, thickness=0.02,
                    pressure=2e6, kc=5e8, cc=0.0, mu=0.3, speed=1.0, alpha=0.0, beta=0.0):
    """A plane-stress pad pressed on a flexible strip clamped at both ends; node pairs between the
    pad's bottom and the strip's top (the pad centred) on compliant contacts, the strip moving
    under the pad at ``speed`` [m/s]; the pad's elements are as long as the strip's."""
    sx, sy = strip
    px, py = pad
    dx = length / sx
    pad_width = px * dx
    asm = _Assembly(2)
    s_nodes, s_el, s_index = _grid((sx, sy), (length, depth))
    base_s = asm.body(s_nodes, s_el, E_strip, nu, rho_strip, thickness)
    first = (sx - px) // 2
    p_nodes, p_el, p_index = _grid((px, py), (pad_width, pad_height), origin=(first * dx, depth))
    base_p = asm.body(p_nodes, p_el, E_pad, nu, rho_pad, thickness)
    for i in np.concatenate([s_index[0, :], s_index[-1, :]]):
        asm.fixed += [asm.dof(base_s + i, 0), asm.dof(base_s + i, 1)]
    top = p_index[:, -1] + base_p
    asm.fixed += [asm.dof(i, 0) for i in top]
    share = pressure * pad_width * thickness / px
    force = [(asm.dof(i, 1), -share * (0.5 if k in (0, px) else 1.0)) for k, i in enumerate(top)]
    rows = []
    for k in range(px + 1):
        p, s = base_p + p_index[k, 0], base_s + s_index[first + k, -1]
        rows.append(([{asm.dof(p, 0): 1.0, asm.dof(s, 0): -1.0}], [speed], {asm.dof(p, 1): 1.0, asm.dof(s, 1): -1.0}))
    return asm.build(rows, mu=mu, kc=kc, cc=cc, force=force, name="pad-on-strip", alpha=alpha, beta=beta)


def pad_on_surface_3d(shape=(2, 1, 1), *, size=(0.02, 0.01, 0.01), E=5e9, nu=0.25, rho=2500.0, pressure=1e6,
                      kc=5e8, cc=0.0, mu=0.3, velocity=(1.0, 0.3), dense=False):
    """A 3-D pad pressed on a rigid plane moving under it at ``velocity`` (x, y) [m/s]; its top held
    in the plane; each bottom node on a compliant contact with 2-D friction."""
    asm = _Assembly(3)
    nodes, el, index = _grid(shape, size)
    asm.body(nodes, el, E, nu, rho)
    top = index[:, :, -1].ravel()
    asm.fixed += [asm.dof(i, a) for i in top for a in (0, 1)]
    share = pressure * size[0] * size[1] / top.size
    force = [(asm.dof(i, 2), -share) for i in top]
    rows = [([{asm.dof(i, 0): 1.0}, {asm.dof(i, 1): 1.0}], list(velocity), {asm.dof(i, 2): 1.0})
            for i in index[:, :, 0].ravel()]
    form = asm.build(rows, mu=mu, kc=kc, cc=cc, force=force, name="pad-on-surface")
    return dense_model(form) if dense else form


def pad_on_disc_3d(disc=(8, 96, 2), pad=(4, 12, 2), *, radii=(0.06, 0.15), disc_thickness=0.012,
                   pad_thickness=0.01, E_disc=1.25e11, E_pad=5e9, rho_disc=7200.0, rho_pad=2500.0, nu=0.3,
                   pressure=1e6, kc=None, cc=0.0, mu=0.3, omega=10.0, alpha=0.0, beta=0.0):
    """A pad on an annular disc clamped at its hub: disc = (radial, circumferential, through-thickness)
    elements, pad = (radial, circumferential, through-thickness) elements on the disc's outer rim.

    The pad's nodes on its face coincide with the disc's top nodes; each pair is a compliant
    contact (stiffness ``kc`` [N/m], default the pad's axial stiffness per contact) with 2-D
    friction, its tangent rows the circumferential and radial directions, its drive the disc's
    surface speed Ω r [m/s] at ``omega`` [rad/s]. The pad's back is held in its plane and pressed
    by ``pressure`` [Pa]. DOFs: 3 × (nodes) less the hub's and the pad back's in-plane ones.
    """
    nr, nt, nz = disc
    pr, pt, pz = pad
    ri, ro = radii
    asm = _Assembly(3)
    # the disc: a box in (r, θ, z) mapped onto the annulus, θ periodic (the last column joins the first)
    r = np.linspace(ri, ro, nr + 1)
    th = np.arange(nt) * 2 * np.pi / nt
    z = np.linspace(0.0, disc_thickness, nz + 1)
    R, T, Z = np.meshgrid(r, th, z, indexing="ij")
    d_nodes = np.stack([(R * np.cos(T)).ravel(), (R * np.sin(T)).ravel(), Z.ravel()], axis=1)
    d_index = np.arange(d_nodes.shape[0]).reshape(nr + 1, nt, nz + 1)
    i, j, k = (a.ravel() for a in np.meshgrid(np.arange(nr), np.arange(nt), np.arange(nz), indexing="ij"))
    j1 = (j + 1) % nt
    d_el = np.stack([d_index[i, j, k], d_index[i + 1, j, k], d_index[i + 1, j1, k], d_index[i, j1, k],
                     d_index[i, j, k + 1], d_index[i + 1, j, k + 1], d_index[i + 1, j1, k + 1], d_index[i, j1, k + 1]],
                    axis=1)
    base_d = asm.body(d_nodes, d_el, E_disc, nu, rho_disc)
    asm.fixed += [asm.dof(base_d + n, a) for n in d_index[0].ravel() for a in range(3)]
    # the pad: the disc's outer pr radial and pt circumferential elements, pz layers above it
    r0 = nr - pr
    pr_, pth = r[r0:], th[:pt + 1] if pt < nt else th
    pzs = disc_thickness + np.linspace(0.0, pad_thickness, pz + 1)
    R, T, Z = np.meshgrid(pr_, pth, pzs, indexing="ij")
    p_nodes = np.stack([(R * np.cos(T)).ravel(), (R * np.sin(T)).ravel(), Z.ravel()], axis=1)
    p_index = np.arange(p_nodes.shape[0]).reshape(pr + 1, pt + 1, pz + 1)
    i, j, k = (a.ravel() for a in np.meshgrid(np.arange(pr), np.arange(pt), np.arange(pz), indexing="ij"))
    p_el = np.stack([p_index[i, j, k], p_index[i + 1, j, k], p_index[i + 1, j + 1, k], p_index[i, j + 1, k],
                     p_index[i, j, k + 1], p_index[i + 1, j, k + 1], p_index[i + 1, j + 1, k + 1],
                     p_index[i, j + 1, k + 1]], axis=1)
    base_p = asm.body(p_nodes, p_el, E_pad, nu, rho_pad)
    back = base_p + p_index[:, :, -1].ravel()
    asm.fixed += [asm.dof(n, a) for n in back for a in (0, 1)]
    area = 0.5 * (ro**2 - r[r0] ** 2) * (pth[-1] - pth[0])
    force = [(asm.dof(n, 2), -pressure * area / back.size) for n in back]
    if kc is None:
        kc = E_pad * area / pad_thickness / ((pr + 1) * (pt + 1))
    rows = []
    for a in range(pr + 1):
        for b in range(pt + 1):
            p, d = base_p + p_index[a, b, 0], base_d + d_index[r0 + a, b % nt, -1]
            t = th[b % nt]
            et, er = (-np.sin(t), np.cos(t), 0.0), (np.cos(t), np.sin(t), 0.0)
            tangents = [{asm.dof(p, x): et[x] for x in (0, 1)}, {asm.dof(p, x): er[x] for x in (0, 1)}]
            for row, e in zip(tangents, (et, er)):
                row.update({asm.dof(d, x): -e[x] for x in (0, 1)})
            rows.append((tangents, [omega * r[r0 + a], 0.0], {asm.dof(p, 2): 1.0, asm.dof(d, 2): -1.0}))
    return asm.build(rows, mu=mu, kc=kc, cc=cc, force=force, name="pad-on-disc", alpha=alpha, beta=beta)


def dense_model(form) -> FrictionModel:
    """The :class:`FrictionModel` of a small sparse form (the same numbers, dense)."""
    G, W = form.tangent.toarray(), form.gap_gradient.toarray()
    contacts = []
    for c in range(form.row_start.size - 1):
        rows = slice(form.row_start[c], form.row_start[c + 1])
        contacts.append(Contact(dim=rows.stop - rows.start, friction=form.friction[c], tangent=G[rows],
                                drive=form.drive[rows], name=form.contact_names[c],
                                normal=NormalLaw("compliant", stiffness=float(form.contact_stiffness[c]),
                                                 damping=float(form.contact_damping[c])),
                                gap=float(form.gap[c]), gap_gradient=W[c]))
    return FrictionModel(name=form.name, dofs=form.dofs, mass=form.mass.toarray(), damping=form.damping.toarray(),
                         stiffness=form.stiffness.toarray(), force=form.force, contacts=tuple(contacts))
