"""The sparse ingredients of a model with constant contact kinematics, as the sparse stability path reads them.

A model's sparse form (:class:`~stickslip.model.sparse_form.SparseForm`, ``FrictionModel.sparse_form()``)
holds M, C, K as sparse matrices and its contacts as stacked tables; dense library models have one
too, so the sparse path can be checked against the dense one on them.

:func:`normal_rows` turns both kinds of normal force into one affine law per contact, the normal
force of a closed contact at rest and in motion: N = N0 + n·q + n_v·q̇, with N0 = −k g0,
n = −k W, n_v = −c W for a compliant contact (its force Wᵀλ on the coordinates apart).
"""

from __future__ import annotations

import types

import numpy as np
import scipy.sparse as sp

from ..errors import ModelError
from ..model.sparse_form import SparseForm

__all__ = ["sparse_form", "is_sparse_model", "normal_rows", "NormalRows"]


def is_sparse_model(model) -> bool:
    """Whether ``model`` is stated with sparse matrices (a sparse form, or a model too large for dense arrays)."""
    return isinstance(model, SparseForm) or not getattr(model, "dense", True)


def sparse_form(model) -> SparseForm:
    """The sparse form of ``model`` (a :class:`~stickslip.model.sparse_form.SparseForm` itself, or any
    :class:`~stickslip.model.FrictionModel` with constant contact kinematics).

    Raises
    ------
    ModelError
        For a model whose contact kinematics are not constant (the plates).
    """
    return model if isinstance(model, SparseForm) else model.sparse_form()


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
    N0, n_q, n_v = form.closed_normal()
    W = sp.diags(uni.astype(float)) @ sp.csr_matrix(form.gap_gradient)
    return NormalRows(N0=N0, n_q=n_q, n_v=n_v, W=sp.csr_matrix(W), k=k, c=c)
