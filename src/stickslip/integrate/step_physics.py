"""Physics queries of the fixed-step methods (AEOM, NAEOM) that the generic kernels do not answer
in one call, built from the generic kernels' parts for a model with one contact (the plates).

* :func:`derivative_under_force`: the state derivative under a given friction force, Eq. (1) with
  F held: NAEOM's stick step holds F constant over a step and solves for it;
* :func:`derivative_and_contact`: the state derivative in the modes of ``cst`` together with the
  contact's friction force, slip velocity and normal force. Every step end needs the derivative
  (the next step's k1), the slip velocity (the slip → stick event) and the force (the samples,
  Eq. 10 in stick), from one evaluation of the frame and forces (``physics.rhs_and_forces``);
* :func:`constraint_metric`: A = G M⁻¹ Gᵀ of the contact, NAEOM's Newton Jacobian v_r(t_n; F)
  ≈ Δt A F;
* :func:`stick_force`: the stick multiplier and the static limit μs N (paper Eq. 10).

Each is generic in the model's kinematics (the frame comes from its kinematics class); the
contact is contact 0. ``stick`` is a contact state (:func:`~stickslip.model.bundle.contact_state`)
whose contact sticks.
"""

from __future__ import annotations

import numpy as np

from ..model import physics as P
from ..model.frames import frame_velocity
from ..model.jit import kernel
from ..model.kinematics import contact_dim, contact_frame, model_sizes
from ..model.model_data import base_force
from ..model.physics import write_derivative
from ..model.stack import DOFS, TWO, work_matrix, work_vectors

__all__ = ["derivative_and_contact", "derivative_under_force", "constraint_metric", "stick_force", "contact_limit"]


@kernel
def derivative_under_force(s, Fx, Fy, md, ds):
    """ds = ds/dt at ``s`` with the contact's friction force held at (Fx, Fy) [N]: Eq. (1) as
    M q̈ = f0 − C q̇ − K q + Gᵀ F, with the work rates when ``ds`` has room."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, TWO, DOFS, s)
    w, v, F, f = work_vectors(md.kin, 4, s)
    contact = np.int64(0)
    contact_frame(md.kin, s, contact, m, G, w)
    dim = contact_dim(md.kin, m, n, contact)
    v0, v1 = frame_velocity(s, n, dim, G, w)
    v[0] = v0
    v[1] = v1
    F[0] = Fx
    F[1] = Fy
    base_force(s, m, n, diagonal, f)
    P.add_contact_force(G, dim, n, Fx, Fy, f)
    write_derivative(s, md, n, np.int64(1), diagonal, v, w, F, f, ds)


@kernel
def derivative_and_contact(s, cst, md, ds, F, N, v):
    """ds = ds/dt at ``s`` in the modes of ``cst`` (as ``physics.rhs``; with the work rates when
    ``ds`` has room); returns (Fx, Fy, vx, vy, N): the friction force [N], slip velocity [m/s]
    and normal force [N] of the contact at ``s``. ``F`` (2,), ``N`` (1,), ``v`` (2,) are work
    arrays (they receive the same)."""
    P.rhs_and_forces(s, cst, md, ds, F, N, v)
    return F[0], F[1], v[0], v[1], N[0]


@kernel
def constraint_metric(s, md):
    """Entries (a11, a12, a22) of A = G M⁻¹ Gᵀ (2×2, symmetric PSD) of the contact at ``s`` [1/kg]."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, TWO, DOFS, s)
    w, mg0, mg1 = work_vectors(md.kin, 3, s)
    contact_frame(md.kin, s, np.int64(0), m, G, w)
    P.apply_inverse_mass(m, n, diagonal, G[0], mg0)
    P.apply_inverse_mass(m, n, diagonal, G[1], mg1)
    a11 = 0.0
    a12 = 0.0
    a22 = 0.0
    for j in range(n):
        a11 += G[0, j] * mg0[j]
        a12 += G[0, j] * mg1[j]
        a22 += G[1, j] * mg1[j]
    return a11, a12, a22


@kernel
def stick_force(s, stick, md, F, N):
    """The stick multiplier (Fx, Fy) [N] of the contact at ``s`` and its static limit μs N [N]
    (Eq. 10): returns (Fx, Fy, limit). ``F`` (2,), ``N`` (1,) are work arrays."""
    P.stick_forces(s, stick, np.int64(-1), md, F, N)
    n = model_sizes(md.kin, md.m)[0]
    return F[0], F[1], P.static_limit(md.m, n, np.int64(0), N[0])


@kernel
def contact_limit(s, md):
    """Static limit μs N [N] of the contact at ``s`` (paper Eq. 10)."""
    n = model_sizes(md.kin, md.m)[0]
    contact = np.int64(0)
    return P.static_limit(md.m, n, contact, P.normal_force(s, contact, md))
