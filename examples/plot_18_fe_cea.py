"""
Complex eigenvalue analysis of a finite-element pad on a belt
=============================================================

A brake pad meshed with `scikit-fem <https://scikit-fem.readthedocs.io>`_ (plane stress, bilinear
quadrilaterals) is clamped at its back and pressed onto a belt that moves along its face. Each
node of the face is a compliant contact with Coulomb friction. Steady sliding is one sparse
solve; its linearisation K_t = K + WᵀkW + K_f has the unsymmetric friction part K_f, so as the
friction coefficient grows two frequencies approach, merge and one pair of eigenvalues leaves
the imaginary axis: mode coupling, the mechanism of brake squeal. Here: the complex eigenvalue
analysis (CEA) of the band against μ (the mode-coupling diagram), the unstable mode's shape,
a Craig–Bampton model reduced to the contact nodes and a few modes, checked against the full one,
and that reduced model's transient: the flutter grows from steady sliding until the contact nodes
stick, slip and lift off.
"""

# %%
import dataclasses
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import scipy.sparse as sp
import skfem
from skfem.helpers import dot
from skfem.models.elasticity import lame_parameters, linear_elasticity

from stickslip import load_model, simulate
from stickslip.model.friction import FrictionLaw
from stickslip.model.sparse_form import NodeMap, SparseForm
from stickslip.reduction import reduce_model, reduction_report, write_model_file
from stickslip.stability import stability
from stickslip.stability.mode_coupling import mode_coupling, with_friction

length, height, thickness = 0.1, 0.02, 0.01  # [m]
E, nu, rho = 1e9, 0.3, 2000.0  # [Pa], [-], [kg/m³]
mesh = skfem.MeshQuad.init_tensor(np.linspace(0, length, 21), np.linspace(0, height, 5))
basis = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementQuad1()))
lam, mu_lame = lame_parameters(E, nu)
lam = 2 * lam * mu_lame / (lam + 2 * mu_lame)  # plane stress


@skfem.BilinearForm
def mass(u, v, w):
    return rho * dot(u, v)


K = skfem.asm(linear_elasticity(lam, mu_lame), basis) * thickness
M = skfem.asm(mass, basis) * thickness
print(f"{mesh.p.shape[1]} nodes, {K.shape[0]} dofs")

# %%
# The model as sparse arrays: the back (top) clamped, each node of the face (bottom) on the belt,
# which moves at 0.5 m/s along x and is pressed 10 µm into the pad (gap g0 = −1e-5 m, contact
# stiffness 1e8 N/m per node, g = g0 + u_y closed while g ≤ 0).
x_dof, y_dof = basis.nodal_dofs
face = np.flatnonzero(mesh.p[1] == 0.0)
back = np.flatnonzero(mesh.p[1] == height)
keep = np.setdiff1d(np.arange(K.shape[0]), np.concatenate([x_dof[back], y_dof[back]]))
where = -np.ones(K.shape[0], int)
where[keep] = np.arange(keep.size)
n, nc = keep.size, face.size
unit = sp.csr_matrix((np.ones(nc), (np.arange(nc), where[x_dof[face]])), shape=(nc, n))
normal = sp.csr_matrix((np.ones(nc), (np.arange(nc), where[y_dof[face]])), shape=(nc, n))
node, component = np.zeros(K.shape[0], int), np.zeros(K.shape[0], int)
node[x_dof], node[y_dof], component[y_dof] = np.arange(x_dof.size), np.arange(y_dof.size), 1
pad = SparseForm(
    name="skfem-pad", dofs=tuple(f"u{i}" for i in range(n)), mass=M[keep][:, keep].tocsr(),
    damping=(1e-6 * K[keep][:, keep]).tocsr(), stiffness=K[keep][:, keep].tocsr(), force=np.zeros(n),
    free=np.ones(n, bool), tangent=unit, row_start=np.arange(nc + 1), drive=np.full(nc, 0.5),
    normal_force=np.zeros(nc), normal_gradient=sp.csr_matrix((nc, n)), normal_rate_gradient=sp.csr_matrix((nc, n)),
    unilateral=np.ones(nc, bool), normal_law=np.array(["compliant"] * nc), gap=np.full(nc, -1e-5),
    gap_gradient=normal, contact_stiffness=np.full(nc, 1e8), contact_damping=np.zeros(nc), restitution=np.zeros(nc),
    friction=(FrictionLaw("coulomb", mu_k=0.3, delta_mu=0.0),) * nc, contact_names=tuple(f"c{c}" for c in range(nc)),
    nodes=NodeMap(ids=np.arange(mesh.p.shape[1]), coordinates=np.vstack([mesh.p, np.zeros(mesh.p.shape[1])]).T,
                  node=node[keep], component=component[keep],
                  cells=(("quad", mesh.t.T[:, ::-1]),)),  # the elements, corners counter-clockwise as VTK's
    slip_band=5e-4)

# %%
# The mode-coupling diagram: every eigenvalue with :math:`|\operatorname{Im}\,\lambda|` ≤ 1.6e5 rad/s
# (25 kHz) for μ from 0 to 0.5, each a CEA of the full model; the onsets (Re λ through 0) are located by root finding
# (to 1e-3 here; the default is 1e-10).
# (Past μ ≈ 0.55 the friction moment lifts the trailing edge of the face off the belt, and steady
# sliding with every contact closed no longer exists: the CEA refuses it, naming the contact.)
coupling = mode_coupling(pad, np.linspace(0.0, 0.5, 11), 1.6e5, xtol=1e-3)
for onset in coupling.onsets:
    print(f"onset at μ = {onset['mu']:.4f}, {onset['angular_frequency'] / (2 * np.pi):.0f} Hz")
coupling.plot(hz=True)

# %%
# At μ = 0.45, past the first onset: the band's eigenvalues (every one of the full model, with its
# backward error on the full pencil) and the shape of the unstable mode on the mesh
# (``result.write_vtk("modes.vtu")`` writes it for ParaView).
result = stability(with_friction(pad, 0.45), max_frequency=1.6e5)
for row in result.modes():
    print(f"{row['growth_rate']:10.2f} 1/s  {row['angular_frequency'] / (2 * np.pi):8.1f} Hz  "
          f"backward error {row['backward_error']:.1e}")

from stickslip.plot.fe import plot_mode_shape  # noqa: E402

plot_mode_shape(result, scale=0.08)

# %%
# Reduced models keep the contact dofs and 12 modes: Craig–Bampton (fixed-interface modes) and
# modal truncation (free modes of the pad in contact, with the static modes of the contact dofs).
# Their eigenvalues of the same band, against the full model's:
for method in ("craig-bampton", "modal"):
    reduced = reduce_model(with_friction(pad, 0.45), method=method, modes=12)
    report = reduction_report(with_friction(pad, 0.45), reduced.form, 1.6e5)
    print(f"{method}: {n} dofs → {reduced.form.n}; largest relative error of the band's eigenvalues "
          f"{report.max_error:.1e}")

# %%
# The Craig–Bampton model's transient at μ = 0.45 (a model file, as ``stickslip reduce`` writes
# it; 21 contact nodes and 54 DOFs, which the compiled tools take as any model: docs/fe.md).
# From steady sliding, perturbed by 1 nm, the unstable pair grows until, after about 4 ms, the
# nodes of the face stick to the belt, slip and lift off it in turn. The contact springs get a
# damping of 30 N s/m here (about 0.1 of critical for a face node on its spring): undamped, the
# nodes bounce on their stiff springs so often that the run stops at a step-size underflow
# after 5 ms.
folder = Path(tempfile.mkdtemp())
damped = dataclasses.replace(with_friction(pad, 0.45), contact_damping=np.full(nc, 30.0))
cb = reduce_model(damped, method="craig-bampton", modes=12)
write_model_file(cb.form, folder / "pad_cb.toml")
model = load_model(str(folder / "pad_cb.toml"))
run = simulate(model, 0.01, ic="equilibrium", perturbation=1e-9, sample_rate=1e5)
print(f"{model.n} dofs, {model.n_contacts} contacts: {run.status}, {run.stats.accepted_steps} steps, "
      f"{len(run.transitions.time)} transitions")
state = np.where(run.open, 2, np.where(run.stick, 1, 0))  # slip 0, stick 1, open 2
# the colour bar in a column of its own, so that both time axes keep the same extent
fig, ((ax_u, blank), (ax_s, ax_bar)) = plt.subplots(2, 2, figsize=(8, 6), width_ratios=(1.0, 0.03),
                                                    layout="constrained")
blank.set_axis_off()
ax_s.sharex(ax_u)
for c in (0, 10, 20):  # the face's ends and middle: each node's displacement along the belt
    j = int(np.flatnonzero(model.contacts[c].tangent[0])[0])
    ax_u.plot(1e3 * run.t, 1e6 * run.states[:, j], label=model.contact_names[c])
ax_u.set_ylabel("displacement [µm]")
ax_u.legend(loc="upper left")
ax_u.tick_params(labelbottom=False)
image = ax_s.imshow(state.T, aspect="auto", interpolation="nearest", origin="lower", cmap="viridis", vmin=0, vmax=2,
                    extent=(1e3 * run.t[0], 1e3 * run.t[-1], -0.5, model.n_contacts - 0.5))
ax_s.set_xlabel("time [ms]")
ax_s.set_ylabel("contact node")
fig.colorbar(image, cax=ax_bar, ticks=[0, 1, 2]).ax.set_yticklabels(["slip", "stick", "open"])
plt.show()
