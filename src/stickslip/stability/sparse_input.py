"""The sparse ingredients of a model with constant contact kinematics, as the sparse stability path reads them.

A model's sparse form (``FrictionModel.sparse_form()``) holds M, C, K as sparse matrices and its
contacts as stacked tables: the tangent rows G (R, n) with ``row_start`` (nc + 1,), the drives w
(R,), the prescribed normal loads N = N0 + n·q + n_v·q̇ (``normal_force`` (nc,),
``normal_gradient`` and ``normal_rate_gradient`` (nc, n)) and, for unilateral contacts, the gap
g = g0 + W·q with its normal law (``gap``, ``gap_gradient`` (nc, n), ``contact_stiffness``,
``contact_damping``). :func:`sparse_form` takes a model that has one, a form itself, or a dense
:class:`~stickslip.model.FrictionModel` with constant kinematics, whose form it builds from the
dense fields (the same numbers, in sparse matrices).

:func:`normal_rows` turns both kinds of normal force into one affine law per contact, the normal
force of a closed contact at rest and in motion: N = N0 + n·q + n_v·q̇, with N0 = −k g0,
n = −k W, n_v = −c W for a compliant contact (its force Wᵀλ on the coordinates apart).
"""

from __future__ import annotations

import types

import numpy as np
import scipy.sparse as sp

from ..errors import ModelError

__all__ = ["sparse_form", "is_sparse_model", "normal_rows", "NormalRows"]


def is_sparse_model(model) -> bool:
    """Whether ``model`` is stated with sparse matrices (a sparse form, or a model whose mass is sparse)."""
    if hasattr(model, "row_start"):
        return True
    return sp.issparse(getattr(model, "mass", None))


def sparse_form(model):
    """The sparse form of ``model`` (module docstring).

    Raises
    ------
    ModelError
        For a model whose contact kinematics are not constant (the plates): the sparse path needs
        constant G and w.
    """
    if hasattr(model, "row_start"):
        return model
    if hasattr(model, "sparse_form"):
        return model.sparse_form()
    return _form_of_dense(model)


def _form_of_dense(model):
    """The sparse form of a dense model with constant kinematics (the same numbers)."""
    if not model.constant_kinematics:
        raise ModelError(f"model {model.name!r} has contact kinematics that change with q (its frame is computed); "
                         "the sparse stability path needs constant tangent rows and drives (a model file)")
    n, contacts = model.n, model.contacts
    tangent = [np.atleast_2d(np.asarray(c.tangent, float)) for c in contacts]
    row_start = np.concatenate([[0], np.cumsum([g.shape[0] for g in tangent])]).astype(np.int64)

    def rows(key):
        return sp.csr_matrix(np.array([np.zeros(n) if getattr(c, key) is None else np.asarray(getattr(c, key), float)
                                       for c in contacts]))

    unilateral = np.array([c.unilateral for c in contacts])
    law = np.array([c.normal.law if c.unilateral else "prescribed" for c in contacts])
    return types.SimpleNamespace(
        dofs=tuple(model.dofs), mass=sp.csr_matrix(model.mass), damping=sp.csr_matrix(model.damping),
        stiffness=sp.csr_matrix(model.stiffness), force=np.asarray(model.force, float), free=np.asarray(model.free),
        tangent=sp.csr_matrix(np.vstack(tangent)), row_start=row_start,
        drive=np.concatenate([np.asarray(c.drive, float).reshape(-1) for c in contacts]),
        normal_force=np.array([c.normal_force for c in contacts], float),
        normal_gradient=rows("normal_gradient"), normal_rate_gradient=rows("normal_rate_gradient"),
        unilateral=unilateral, normal_law=law, gap=np.array([c.gap for c in contacts], float),
        gap_gradient=rows("gap_gradient"),
        contact_stiffness=np.array([c.normal.stiffness if c.unilateral else 0.0 for c in contacts]),
        contact_damping=np.array([c.normal.damping if c.unilateral else 0.0 for c in contacts]),
        restitution=np.array([c.normal.restitution if c.unilateral else 0.0 for c in contacts]),
        friction=tuple(c.friction for c in contacts), contact_names=tuple(model.contact_names), nodes=None,
        units=dict(model.units), slip_band=model.slip_band, name=model.name,
    )


class NormalRows(types.SimpleNamespace):
    """Each contact's normal force while closed, N = N0 + n·q + n_v·q̇, and its gap's force on q.

    Attributes
    ----------
    N0 : ndarray (nc,)
        [N].
    n_q, n_v : csr_matrix (nc, n)
        ∂N/∂q [N/m], ∂N/∂q̇ [N s/m].
    W : csr_matrix (nc, n)
        Gap gradients of the compliant contacts (zero rows for pressed ones): λ acts on q as Wᵀλ.
    k, c : ndarray (nc,)
        Contact stiffness and damping (0 for pressed contacts).
    """


def normal_rows(form) -> NormalRows:
    """The affine normal force of every contact while closed (module docstring).

    Raises
    ------
    ModelError
        For a rigid contact: its normal force is a multiplier, which the sparse path does not take.
    """
    uni = np.asarray(form.unilateral, bool)
    laws = np.asarray(form.normal_law)
    rigid = np.flatnonzero(uni & (laws == "rigid"))
    if rigid.size:
        c = int(rigid[0])
        raise ModelError(f"contact {c} ({form.contact_names[c]}) is rigid: the sparse stability path takes pressed and "
                         "compliant contacts; give it a contact stiffness (law = \"compliant\")")
    k = np.where(uni, np.asarray(form.contact_stiffness, float), 0.0)
    c = np.where(uni, np.asarray(form.contact_damping, float), 0.0)
    W = sp.diags(uni.astype(float)) @ sp.csr_matrix(form.gap_gradient)
    pressed = sp.diags((~uni).astype(float))
    n_q = pressed @ sp.csr_matrix(form.normal_gradient) - sp.diags(k) @ W
    n_v = pressed @ sp.csr_matrix(form.normal_rate_gradient) - sp.diags(c) @ W
    N0 = np.where(uni, -k * np.asarray(form.gap, float), np.asarray(form.normal_force, float))
    return NormalRows(N0=N0, n_q=sp.csr_matrix(n_q), n_v=sp.csr_matrix(n_v), W=sp.csr_matrix(W), k=k, c=c)
