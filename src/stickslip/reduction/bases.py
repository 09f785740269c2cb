"""Reduced models of sparse friction models: Craig–Bampton and modal truncation, the contact DOFs kept.

Both keep the *boundary* DOFs b — every DOF that a contact's rows touch (tangent rows, gap and
normal-force gradients) and every loaded DOF (f0 ≠ 0) — as physical coordinates, and replace the
interior DOFs i by a few modal amplitudes η:

    u = T [u_b; η],   T = [[I, 0], [Ψ, Φ]],   Ψ = −K_ii⁻¹ K_ib   (static constraint modes)

``craig-bampton`` (Craig & Bampton 1968; with the contact DOFs as its boundary, Coudeyras, Sinou &
Nacivet 2009): Φ the fixed-interface modes of (K_ii, M_ii) below a frequency or the first m.
``modal``: Φ the interior part Φ_i − Ψ Φ_b of the free modes of the whole structure in contact
(K + Wᵀ k W, M) — modal truncation with the contact DOFs kept, the residual flexibility of the
truncated modes carried by the static modes Ψ.

``residual`` blocks of *residual vectors* may be added to Φ (either method): the interior's static
response to the inertia load of a unit boundary acceleration, X₁ = K_ii⁻¹ (M_ii Ψ + M_ib), then
X_{k+1} = K_ii⁻¹ M_ii X_k (a Krylov sequence of the boundary's inertia load), each block
M_ii-orthogonalised against Φ and the blocks before it. The truncated modes' part of the interior
motion driven by the boundary is, to leading order in (ω/ω_c)², the static response the first block
holds; each further block carries the next order (the second-order and Krylov-augmented
Craig–Bampton bases of the literature). They cost one pair of triangular solves of K_ii per block
and boundary DOF.

The contacts touch only boundary DOFs and the η columns of T vanish there, so every contact row
re-expressed on the reduced coordinates (G T, W T, n T) is the same row on the same named DOFs:
the reduced model is a model like any other (:class:`~stickslip.model.sparse_form.SparseForm`;
written as a model file by :mod:`.model_writer`). M_r = Tᵀ M T, C_r = Tᵀ C T, K_r = Tᵀ K T,
f_r = Tᵀ f0 are dense (r × r, r = |b| + m), the basis T is dense (n × r): its memory is checked
first.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp

from ..errors import StickSlipError
from ..memory import check_memory, format_bytes
from ..model.matrices import arpack_start
from ..model.sparse_form import NodeMap, SparseForm
from ..stability.modal_cea import lowest_modes
from ..stability.sparse_input import sparse_form
from ..stability.sparse_sliding import factorize

__all__ = ["ReductionError", "Reduced", "reduce_model", "boundary_dofs", "METHODS"]

METHODS = ("craig-bampton", "modal")


class ReductionError(StickSlipError, ValueError):
    """A reduction that cannot be made as asked (no interior left, no mode below the frequency, ...)."""


@dataclasses.dataclass(frozen=True, eq=False)
class Reduced:
    """A reduced model and how it was made.

    Attributes
    ----------
    form : SparseForm
        The reduced model (r coordinates: the boundary DOFs by their names, then ``eta0`` …).
    method : str
    boundary : ndarray of int
        The kept DOFs (indices into the full model's dofs).
    frequencies : ndarray (m,)
        Angular frequencies of the modes kept [rad/s].
    residual : int
        The residual vectors added after the modes (coordinates ``eta{m}`` on).
    """

    form: SparseForm
    method: str
    boundary: np.ndarray
    frequencies: np.ndarray
    residual: int = 0


def boundary_dofs(form: SparseForm) -> np.ndarray:
    """Every free DOF that a contact's rows or the force touch, ascending."""
    touched = np.zeros(form.n, bool)
    for rows in (form.tangent, form.gap_gradient, form.normal_gradient, form.normal_rate_gradient):
        touched[sp.csr_matrix(rows).indices] = True
    touched |= np.asarray(form.force) != 0.0
    return np.flatnonzero(touched & np.asarray(form.free, bool))


def _interior_modes(form: SparseForm, method: str, b, i, Psi, modes, max_frequency):
    """Φ (n_i, m) and the modes' angular frequencies."""
    K, M = _sym(form.stiffness), sp.csr_matrix(form.mass)
    if method == "craig-bampton":
        Kp, Mp = K[i][:, i], M[i][:, i]
    else:
        W, k = sp.csr_matrix(form.gap_gradient), np.where(form.normal_law == "compliant", form.contact_stiffness, 0.0)
        free = np.flatnonzero(form.free)
        Kp, Mp = (K + W.T @ sp.diags(k) @ W)[free][:, free], M[free][:, free]
    if max_frequency is None:
        max_frequency = _frequency_of_mode(Kp, Mp, modes)
    omega, V, _ = lowest_modes(sp.csr_matrix(Kp), sp.csr_matrix(Mp), max_frequency)
    if modes is not None:
        omega, V = omega[:modes], V[:, :modes]
    if method == "craig-bampton":
        return V, omega
    # the free modes' interior part, with the static modes carrying their boundary motion
    position = np.searchsorted(np.flatnonzero(form.free), b)
    inner = np.searchsorted(np.flatnonzero(form.free), i)
    Phi = V[inner] - Psi @ V[position]
    G = Phi.T @ (Mp[inner][:, inner] @ Phi)  # M-orthonormalise the η columns (their span unchanged)
    w, U = np.linalg.eigh(0.5 * (G + G.T))
    keep = w > 1e-12 * w.max()
    return Phi @ (U[:, keep] / np.sqrt(w[keep])), omega


def _residual_vectors(Mii, solve, load, Phi, blocks: int) -> np.ndarray:
    """``blocks`` blocks of the Krylov sequence K_ii⁻¹ load, (K_ii⁻¹ M_ii)ᵏ K_ii⁻¹ load, each
    M_ii-orthonormalised against Φ and the blocks before it (module docstring); (n_i, ≤ blocks · nb)."""
    basis, X = Phi, np.asarray(load)
    for _ in range(blocks):
        X = solve(X)
        scale = np.max(np.einsum("ij,ij->j", X, Mii @ X), initial=0.0)  # the largest M-norm² before projection
        for _ in range(2):  # twice: the blocks are nearly parallel to the modes kept, and to round-off
            X = X - basis @ (basis.T @ (Mii @ X))  # M-orthogonal to the basis
            G = X.T @ (Mii @ X)
            w, U = np.linalg.eigh(0.5 * (G + G.T))
            keep = w > 1e-10 * scale  # directions the basis holds already (to round-off) are dropped
            X = X @ (U[:, keep] / np.sqrt(w[keep]))  # M-orthonormal within the block
            scale = 1.0
        if not X.shape[1]:
            break
        basis = np.hstack([basis, X])
        X = Mii @ X
    return basis[:, Phi.shape[1]:]


def _frequency_of_mode(K, M, modes: int) -> float:
    """An angular frequency just above the ``modes``-th mode of (K, M) [rad/s]."""
    from scipy.sparse.linalg import LinearOperator, eigsh

    n = K.shape[0]
    if modes >= n - 1:
        raise ReductionError(f"--modes {modes}: the reduced part has {n} DOFs; give fewer modes")
    lu = factorize(K, pivot=0.0)
    op = LinearOperator((n, n), matvec=lambda x: lu.solve(np.asarray(x).reshape(-1)), dtype=float)
    w2 = np.sort(eigsh(sp.csr_matrix(K), k=modes + 1, M=sp.csr_matrix(M), sigma=0.0, OPinv=op, which="LM",
                       v0=arpack_start(n), return_eigenvectors=False))
    return float(np.sqrt(0.5 * (w2[modes - 1] + w2[modes])))


def _sym(A) -> sp.csr_matrix:
    A = sp.csr_matrix(A)
    return sp.csr_matrix(0.5 * (A + A.T))


def reduce_model(model, *, method: str = "craig-bampton", modes: int | None = None,
                 max_frequency: float | None = None, residual: int = 0) -> Reduced:
    """The reduced model of ``model`` (module docstring).

    Parameters
    ----------
    model : FrictionModel or SparseForm
    method : {"craig-bampton", "modal"}
    modes : int, optional
        The number of modes kept.
    max_frequency : float, optional
        Keep every mode below this angular frequency [rad/s] (with ``modes``: at most that many).
    residual : int
        Blocks of residual vectors added to the modes (module docstring), each at most one
        coordinate per boundary DOF; 0: the modes alone.

    Raises
    ------
    ReductionError
        An unknown method, neither ``modes`` nor ``max_frequency``, a negative ``residual``, a model
        without interior DOFs.
    MemoryLimitError
        When the basis does not fit in memory.
    """
    if method not in METHODS:
        raise ReductionError(f"method {method!r}: choose one of {', '.join(METHODS)}")
    if modes is None and max_frequency is None:
        raise ReductionError("give the modes to keep: a count (--modes) or a frequency (--max-frequency, rad/s)")
    if residual < 0:
        raise ReductionError(f"--residual {residual} must be >= 0 (blocks of residual vectors)")
    form = sparse_form(model)
    b = boundary_dofs(form)
    free = np.flatnonzero(form.free)
    i = np.setdiff1d(free, b)
    if i.size == 0:
        raise ReductionError(f"model {form.name!r}: every free DOF is a contact or loaded DOF; nothing to reduce")
    r_guess = b.size * (1 + residual) + (modes or 0)
    check_memory(8.0 * 3 * free.size * max(r_guess, b.size + 1), f"the reduction basis of model {form.name!r} "
                 f"({free.size} DOFs, {b.size} kept)",
                 lambda memory: f"keep fewer contact and loaded DOFs (the basis takes 24 bytes per DOF and kept "
                                f"coordinate; {format_bytes(memory)} available)")
    K = _sym(form.stiffness)
    lu = factorize(K[i][:, i], pivot=0.0)
    Psi = -lu.solve(np.asarray(K[i][:, b].toarray()))
    Phi, omega = _interior_modes(form, method, b, i, Psi, modes, max_frequency)
    if residual:
        M = sp.csr_matrix(form.mass)
        Mii = _sym(M[i][:, i])
        extra = _residual_vectors(Mii, lu.solve, Mii @ Psi + M[i][:, b].toarray(), Phi, residual)
        Phi = np.hstack([Phi, extra])
    return Reduced(form=_reduced_form(form, b, i, Psi, Phi, method), method=method, boundary=b, frequencies=omega,
                   residual=Phi.shape[1] - omega.size)


def _reduced_form(form: SparseForm, b, i, Psi, Phi, method) -> SparseForm:
    """The reduced SparseForm: matrices Tᵀ A T, contacts on the kept DOFs (module docstring)."""
    nb, m = b.size, Phi.shape[1]
    T = np.zeros((form.n, nb + m))
    T[b, np.arange(nb)] = 1.0
    T[i, :nb] = Psi
    T[i, nb:] = Phi

    def project(A):  # Tᵀ M T symmetric to round-off: symmetrised (M must be symmetric to 1e-12)
        return sp.csr_matrix(T.T @ (sp.csr_matrix(A) @ T))

    def rows(A):  # G T = G_b on the kept DOFs, 0 on the η (contacts touch no interior DOF)
        return sp.hstack([sp.csr_matrix(A)[:, b], sp.csr_matrix((A.shape[0], m))], format="csr")

    names = tuple(form.dofs[j] for j in b) + tuple(f"eta{k}" for k in range(m))
    nodes = None
    if form.nodes is not None:
        nodes = NodeMap(ids=form.nodes.ids, coordinates=form.nodes.coordinates,
                        node=np.concatenate([form.nodes.node[b], -np.ones(m, int)]),
                        component=np.concatenate([form.nodes.component[b], -np.ones(m, int)]),
                        cells=form.nodes.cells)
    return SparseForm(
        name=f"{form.name}-{method}", dofs=names, mass=_sym(project(form.mass)), damping=project(form.damping),
        stiffness=project(form.stiffness), force=T.T @ np.asarray(form.force, float), free=np.ones(nb + m, bool),
        tangent=rows(form.tangent), row_start=form.row_start, drive=form.drive, normal_force=form.normal_force,
        normal_gradient=rows(form.normal_gradient), normal_rate_gradient=rows(form.normal_rate_gradient),
        unilateral=form.unilateral, normal_law=form.normal_law, gap=form.gap, gap_gradient=rows(form.gap_gradient),
        contact_stiffness=form.contact_stiffness, contact_damping=form.contact_damping,
        restitution=form.restitution, friction=form.friction, contact_names=form.contact_names, nodes=nodes,
        units={k: v for k, v in form.units.items() if k not in form.dofs}, slip_band=form.slip_band)
