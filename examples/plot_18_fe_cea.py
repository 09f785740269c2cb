"""
Complex eigenvalue analysis of a finite-element pad on a belt
=============================================================

A brake pad meshed with `scikit-fem <https://scikit-fem.readthedocs.io>`_ (plane stress, bilinear
quadrilaterals): a steel backing plate clamped at its back, on a soft friction lining whose face
is pressed onto a belt that moves along it. Each node of the face is a compliant contact with
Coulomb friction. Steady sliding is one sparse solve; its linearisation K_t = K + WᵀkW + K_f has
the unsymmetric friction part K_f, so as the friction coefficient grows two frequencies approach,
merge and one pair of eigenvalues leaves the imaginary axis: mode coupling, the mechanism of brake
squeal. Here: the complex eigenvalue analysis (CEA) of the band against μ (the mode-coupling
diagram), the unstable mode's shape, Craig–Bampton models reduced to the contact nodes, a few
modes and a block of residual vectors, checked against the full one, and the reduced model's
transient, checked against the full model's own transient: the flutter grows from steady sliding
until the contact nodes stick, slip and lift off.
"""

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla
import skfem
from skfem.helpers import dot
from skfem.models.elasticity import lame_parameters, linear_elasticity

from stickslip import load_model, simulate
from stickslip.model.friction import FrictionLaw
from stickslip.model.sparse_form import NodeMap, SparseForm
from stickslip.reduction import reduce_model, reduction_report, write_model_file
from stickslip.stability import stability
from stickslip.stability.mode_coupling import mode_coupling, with_friction

# 10 cm long, a 10 mm lining (one row of elements) under a 10 mm steel plate (two rows), 1 cm thick
length, lining, height, thickness = 0.1, 0.01, 0.02, 0.01  # [m]
mesh = skfem.MeshQuad.init_tensor(np.linspace(0, length, 21), np.array([0.0, lining, 0.015, height]))
element = skfem.ElementVector(skfem.ElementQuad1())
basis = skfem.Basis(mesh, element)
in_lining = mesh.p[1, mesh.t].mean(axis=0) < lining
materials = {"lining": (3e7, 2000.0, np.flatnonzero(in_lining)),  # E [Pa], ρ [kg/m³], its elements
             "plate": (2e11, 7800.0, np.flatnonzero(~in_lining))}


@skfem.BilinearForm
def unit_mass(u, v, w):
    return dot(u, v)


K_of, M_of = {}, {}
for name, (E, rho, elements) in materials.items():
    lam, mu_lame = lame_parameters(E, 0.3)
    lam = 2 * lam * mu_lame / (lam + 2 * mu_lame)  # plane stress
    part = skfem.Basis(mesh, element, elements=elements)
    K_of[name] = skfem.asm(linear_elasticity(lam, mu_lame), part) * thickness
    M_of[name] = skfem.asm(unit_mass, part) * (rho * thickness)
K = K_of["lining"] + K_of["plate"]
# lumped masses (row sums on the diagonal, as explicit FE codes lump them): a step in a contact
# force then accelerates the contact node alone, which a reduction to the contact nodes keeps
M = sp.diags(np.asarray((M_of["lining"] + M_of["plate"]).sum(axis=1)).ravel(), format="csr")
print(f"{mesh.p.shape[1]} nodes, {K.shape[0]} dofs")

# %%
# The model as sparse arrays: the back (top) clamped, each node of the face (bottom) on the belt,
# which moves at 5 cm/s along x and is pressed 30 µm into the pad (gap g0 = −3e-5 m, contact
# stiffness 3e5 N/m per node, g = g0 + u_y closed while g ≤ 0), Coulomb μk = 0.3 and μs = μk + 0.2.
# Damping: 2e-7 s times the lining's stiffness (the plate's own modes undamped).
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
    damping=(2e-7 * K_of["lining"][keep][:, keep]).tocsr(), stiffness=K[keep][:, keep].tocsr(), force=np.zeros(n),
    free=np.ones(n, bool), tangent=unit, row_start=np.arange(nc + 1), drive=np.full(nc, 0.05),
    normal_force=np.zeros(nc), normal_gradient=sp.csr_matrix((nc, n)), normal_rate_gradient=sp.csr_matrix((nc, n)),
    unilateral=np.ones(nc, bool), normal_law=np.array(["compliant"] * nc), gap=np.full(nc, -3e-5),
    gap_gradient=normal, contact_stiffness=np.full(nc, 3e5), contact_damping=np.zeros(nc), restitution=np.zeros(nc),
    friction=(FrictionLaw("coulomb", mu_k=0.3, delta_mu=0.2),) * nc, contact_names=tuple(f"c{c}" for c in range(nc)),
    nodes=NodeMap(ids=np.arange(mesh.p.shape[1]), coordinates=np.vstack([mesh.p, np.zeros(mesh.p.shape[1])]).T,
                  node=node[keep], component=component[keep],
                  cells=(("quad", mesh.t.T[:, ::-1]),)),  # the elements, corners counter-clockwise as VTK's
    slip_band=5e-4)

# %%
# The mode-coupling diagram: every eigenvalue with :math:`|\operatorname{Im}\,\lambda|` ≤ 6.3e4 rad/s
# (10 kHz) for μ from 0 to 0.5, each a CEA of the full model; the onsets (Re λ through 0) are located
# by root finding (to 1e-3 here; the default is 1e-10). The band holds the face nodes' modes on the
# lining and their springs (1.7–6.9 kHz); the steel plate's modes lie from 64 kHz up.
coupling = mode_coupling(pad, np.linspace(0.0, 0.5, 11), 6.3e4, xtol=1e-3)
for onset in coupling.onsets:
    print(f"onset at μ = {onset['mu']:.4f}, {onset['angular_frequency'] / (2 * np.pi):.0f} Hz")
coupling.plot(hz=True)

# %%
# At μ = 0.45, past the first onset: the band's least stable eigenvalues (of the full model, each
# with its backward error on the full pencil) and the shape of the unstable mode on the mesh
# (``result.write_vtk("modes.vtu")`` writes it for ParaView): the face nodes at the trailing end,
# where the belt leaves the pad, slide and press into the lining; the steel plate hardly moves.
sliding = with_friction(pad, 0.45)
result = stability(sliding, max_frequency=6.3e4)
for row in result.modes()[:6]:
    print(f"{row['growth_rate']:10.2f} 1/s  {row['angular_frequency'] / (2 * np.pi):8.1f} Hz  "
          f"backward error {row['backward_error']:.1e}")

from stickslip.plot.fe import plot_mode_shape  # noqa: E402

plot_mode_shape(result, scale=0.05)

# %%
# Craig–Bampton models keep the 42 contact dofs and the two lowest fixed-interface modes (the
# plate's, at 64 and 65 kHz: nine times the top of the contact nodes' band), alone and with one block of
# residual vectors (``reduce_model(..., residual=1)``, ``stickslip reduce --residual 1``: the
# interior's static response to the contact nodes' accelerations, one per contact dof). Their
# eigenvalues of the band, against the full model's:
folder = Path(tempfile.mkdtemp())
write_model_file(sliding, folder / "pad.toml")
reduced = {}
for residual in (0, 1):
    cb = reduce_model(sliding, method="craig-bampton", modes=2, residual=residual)
    write_model_file(cb.form, folder / f"pad_cb{residual}.toml")
    reduced[residual] = cb, load_model(str(folder / f"pad_cb{residual}.toml"))
    report = reduction_report(sliding, cb.form, 6.3e4)
    print(f"modes at {', '.join(f'{f / 2e3 / np.pi:.1f}' for f in cb.frequencies)} kHz, {residual} block(s) of "
          f"residual vectors: {n} dofs → {cb.form.n}; largest relative error of the band's eigenvalues "
          f"{report.max_error:.1e}")

# %%
# The transients at μ = 0.45 (model files, as ``stickslip reduce`` writes them, which the compiled
# tools take as any model: docs/fe.md). Each starts from steady sliding moved 0.3 µm along the
# unstable mode: its contact dofs' part, the interior following statically (u_i = −K_ii⁻¹ K_ib u_b),
# a state that the full and the reduced models hold alike. The full model runs its first 2.2 ms,
# through the first sticks, slips and lift-offs; the reduced ones are compared with it sample by
# sample: the contact dofs' largest difference relative to their largest range over the window
# (displacements and velocities), and the stick and open flags of every contact at every sample.
# A truncated basis holds the transient here because the masses are lumped and the plate's modes lie
# far above the contact nodes' band; with a consistent mass matrix, or modes inside the band, none
# comes near (docs/fe.md, "A truncated basis against the full transient").
full = load_model(str(folder / "pad.toml"))
boundary = reduced[0][0].boundary
interior = np.setdiff1d(np.arange(n), boundary)
shape = result.mode_shapes[0].real[boundary]  # the unstable mode (largest real part) on the contact dofs
shape /= np.abs(shape).max()
lift = sla.spsolve(pad.stiffness[interior][:, interior].tocsc(), -(pad.stiffness[interior][:, boundary] @ shape))
kick = np.zeros(2 * n)
kick[boundary], kick[interior] = 3e-7 * shape, 3e-7 * lift
tolerances, window, rate = dict(rtol=1e-9, atol=1e-14), 2.2e-3, 2e5
full_run = simulate(full, window, ic="equilibrium", perturbation=kick, sample_rate=rate, **tolerances)
print(f"full: {full.n} dofs, {full_run.stats.accepted_steps} steps, {len(full_run.transitions.time)} transitions")


def agreement(run, model):
    """Largest difference of the contact dofs' displacements and velocities from the full run over
    its window, each relative to the largest range (max − min over the window) of a contact dof's
    displacement or velocity there, and whether the flags are the same at every sample."""
    k, nb = full_run.t.size, boundary.size
    assert np.allclose(run.t[:k], full_run.t, rtol=0, atol=1e-12)  # the same sample times
    errors = []
    for ours, theirs in ((run.states[:k, :nb], full_run.states[:, boundary]),
                         (run.states[:k, model.n:model.n + nb], full_run.states[:, n + boundary])):
        errors.append(float(np.abs(ours - theirs).max() / np.ptp(theirs, axis=0).max()))
    same = np.array_equal(run.stick[:k], full_run.stick) and np.array_equal(run.open[:k], full_run.open)
    return errors, same


runs = {}
for residual, (cb, model) in reduced.items():
    start = np.zeros(2 * model.n)
    start[:boundary.size] = kick[boundary]  # η = 0: the interior follows statically
    t_end = 8e-3 if residual == 1 else window  # the model shown runs on, past the full run's window
    runs[residual] = simulate(model, t_end, ic="equilibrium", perturbation=start, sample_rate=rate, **tolerances)
    (q_error, v_error), same = agreement(runs[residual], model)
    print(f"{model.n} dofs ({residual} block(s) of residual vectors) against the full model over "
          f"{1e3 * window:.1f} ms: displacements {q_error:.1e}, velocities {v_error:.1e} of their ranges; "
          f"same stick/slip/open flags: {same}")

# %%
# The 86-DOF model's run over 8 ms, the full model's first 2.2 ms dashed: the unstable pair grows
# until, after about 1.6 ms, the nodes of the face stick to the belt, slip and lift off it in turn.
run, model = runs[1], reduced[1][1]
print(f"{model.n} dofs, {model.n_contacts} contacts: {run.status}, {run.stats.accepted_steps} steps, "
      f"{len(run.transitions.time)} transitions")
state = np.where(run.open, 2, np.where(run.stick, 1, 0))  # slip 0, stick 1, open 2
# the colour bar in a column of its own, so that both time axes keep the same extent
fig, ((ax_u, blank), (ax_s, ax_bar)) = plt.subplots(2, 2, figsize=(8, 6), width_ratios=(1.0, 0.03),
                                                    layout="constrained")
blank.set_axis_off()
ax_s.sharex(ax_u)
for c in (0, 10, 20):  # the face's ends and middle: each node's displacement along the belt
    j = int(unit.indices[c])  # its dof in the full model, and in the reduced one (the boundary first)
    ax_u.plot(1e3 * run.t, 1e6 * run.states[:, int(np.searchsorted(boundary, j))], label=model.contact_names[c])
    ax_u.plot(1e3 * full_run.t, 1e6 * full_run.states[:, j], "--", color="k", lw=0.8)
ax_u.plot([], [], "--", color="k", lw=0.8, label="full model")
ax_u.set_ylabel("displacement [µm]")
ax_u.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncols=4, frameon=False)  # above the axes
ax_u.tick_params(labelbottom=False)
image = ax_s.imshow(state.T, aspect="auto", interpolation="nearest", origin="lower", cmap="viridis", vmin=0, vmax=2,
                    extent=(1e3 * run.t[0], 1e3 * run.t[-1], -0.5, model.n_contacts - 0.5))
ax_s.set_xlabel("time [ms]")
ax_s.set_ylabel("contact node")
fig.colorbar(image, cax=ax_bar, ticks=[0, 1, 2]).ax.set_yticklabels(["slip", "stick", "open"])
plt.show()
