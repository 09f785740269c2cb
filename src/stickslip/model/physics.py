"""The physics of every friction-contact model, written once, compiled per kinematics class.

    M q̈ = f0 − C q̇ − K q + Σ_c G_c(q)ᵀ F_c + Σ_u W_uᵀ λ_u,     v_c = G_c(q) q̇ − w_c(q)

with, for each contact c (1-D or 2-D slip velocity v_c, normal force N_c, friction law μ), and
for each closed unilateral contact u its normal force λ_u = N_u on the coordinates
(:mod:`stickslip.model.normal`; an open one carries neither normal nor friction force):

* slip: F_c = −μ(|v_c|) N_c e_c with e_c = v_c/|v_c| above the low-speed band, inside it the
  quasi-static direction (:func:`~stickslip.model.forces.quasi_static_direction`) for 2-D contacts
  and the stored one for 1-D contacts;
* stick: F_c is the Lagrange multiplier that keeps v_c = 0. The multipliers of all sticking
  contacts S are solved together from dv_S/dt = G_S q̈ + h_S = 0:

      (G_S M⁻¹ G_Sᵀ) F_S = −(h_S + G_S M⁻¹ f),   h = Ġ q̇ − ẇ   (the velocity bias)

  minimal-norm when G_S M⁻¹ G_Sᵀ is rank-deficient (:func:`~stickslip.model.linalg.solve_psd`),
  e.g. the plates' Model 4. The bias h is the derivative of v along q̇ at fixed q̇, taken by complex
  step of the model's frame (exact to round-off; zero for constant kinematics).

The kernels are generic in the number type: the same code runs on ``float64`` states (the
simulators) and on ``complex128`` states (Jacobians by complex step, :mod:`stickslip.model.derivatives`).
Branches read real parts only and no ``abs`` touches the state, so the complex step stays exact;
inside a complex evaluation the bias h is a central difference instead
(:func:`~stickslip.model.frames.frame_with_bias`).

This module holds the right-hand side (:func:`rhs`) and the per-contact queries the integrators
ask between steps (forces, stick margin, slip velocity and direction, the projection onto stick).
Their parts live below it: the contact modes and the packed model's accessors in
:mod:`stickslip.model.model_data`, the minimal-norm solves in :mod:`stickslip.model.linalg`, the
frames and velocity bias in :mod:`stickslip.model.frames`, the friction forces in
:mod:`stickslip.model.forces`. The names of those that other modules use as ``physics.NAME``
(the mode codes first) are imported here and listed in ``__all__``.

Common arguments: ``s`` the state [q, q̇] (entries from 2n on are carried along: the integrators
keep the work of friction and damping there); ``cst`` (4 nc,) each contact's integration state
[mode, ex, ey, τ] (:data:`MODE_SLIP` …; the stored slip direction); ``md`` the model
(:class:`~stickslip.model.bundle.ModelData`). Work arrays live on each kernel's stack
(:mod:`stickslip.model.stack`).
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import overload

from . import csmath as csm
from .bundle import CST, H_BAND
from .forces import general_forces, quasi_static_direction, sliding_forces, sliding_friction
from .frames import (COMPLEX_STEP, add_contact_force, add_force_of, contact_velocity, frame_velocity, frame_with_bias,
                     heap_velocity_and_rate)
from .jit import KERNEL_OPTIONS, api_kernel, inlined_kernel, kernel, standalone
from .kinematics import contact_dim, contact_frame, model_sizes, unilateral_kernel
from .linalg import RANK_TOL, solve_psd, solve_psd_2x2, solve_stick_system
from .model_data import (MODE_SLIP, MODE_SLIP_EXACT, MODE_SLIP_QUASI_STATIC, MODE_STICK, SPEED_FLOOR,
                         apply_inverse_mass, damping_power, gram_row, inverse_mass_of, inverse_mass_of_row, is_stick,
                         kinetic_coefficient, kinetic_energy, law_row, static_limit)
from .normal import MODE_OPEN, any_rigid_closed, contact_indicator, gap_and_rate, is_open, is_rigid, is_unilateral, normal_in_mode
from .stack import DOFS, ONE, ROWS, TWO, kinematics_class, on_heap, work_matrix, work_vectors
from .stick import heap_projection, solve_stick_rows, stick_rows

__all__ = ["MODE_SLIP", "MODE_STICK", "MODE_SLIP_EXACT", "MODE_SLIP_QUASI_STATIC", "MODE_OPEN", "SPEED_FLOOR", "RANK_TOL",
           "indicator", "gap", "unilateral", "rigid", "rigid_pivot", "is_open", "normal_force_of",
           "rhs", "rhs_body", "general_rhs", "rhs_and_forces", "contact_forces", "normal_force", "stick_margin",
           "stick_margins", "stick_forces", "project_velocities", "slip_velocity",
           "slip_velocity_and_rate", "slip_direction", "band_direction", "static_limit", "kinetic_energy", "solve_psd",
           "solve_psd_2x2", "contact_dim", "frame_with_bias", "COMPLEX_STEP",
           # used by the orbits' variational kernels (orbits/var_kernels.py)
           "general_forces", "solve_stick_rows", "quasi_static_direction", "add_contact_force", "apply_inverse_mass",
           "is_stick", "law_row", "kinetic_coefficient"]


# ----------------------------------------------------------------------------- derivative
@inlined_kernel
def write_derivative(s, md, n, nc, diagonal, v, w, F, f, ds):
    """ds = [q̇, M⁻¹ f]; with room, the friction power Σ F_c·(G_c q̇) = Σ F_c·(v_c + w_c) and the
    damping power −q̇ᵀ C q̇ [W] at 2n, 2n + 1 (integrated, they close the energy balance).

    Pass ``ds`` as one array variable: inlined into a caller that picks ``ds`` by a branch
    (``a if c else b``), numba mistook its length and the powers went unwritten."""
    m = md.m
    for i in range(n):
        ds[i] = s[n + i]
    inverse_mass_of(md.kin, m, n, diagonal, f, ds[n:2 * n])
    if ds.shape[0] >= 2 * n + 2:
        power = csm.zero(s[0])
        for i in range(2 * nc):
            power += F[i] * (v[i] + w[i])
        ds[2 * n] = power
        ds[2 * n + 1] = damping_power(md.kin, s, m, n, diagonal)


@standalone
@kernel
def general_rhs(s, cst, md, ds):
    """:func:`rhs` for any mix of modes (the path of stick and of the low-speed band)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    w, v, N, h, F, f = work_vectors(md.kin, 6, s)
    general_forces(s, cst, md, G, w, v, N, h, F, f)
    write_derivative(s, md, n, nc, diagonal, v, w, F, f, ds)


@inlined_kernel
def rhs_body(s, cst, md, ds):
    """Body of :func:`rhs`, inlined into the integrators' stage loops.

    The common case, every contact sliding outside the low-speed band, is computed here on
    stack arrays (kept in registers); stick and the band go to :func:`general_rhs`.
    """
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    w, v, N, F, f = work_vectors(md.kin, 5, s)
    if sliding_forces(s, cst, md, n, nc, diagonal, G, w, v, N, F, f):
        write_derivative(s, md, n, nc, diagonal, v, w, F, f, ds)
    else:
        general_rhs(s, cst, md, ds)


@standalone
@api_kernel
def rhs(s, cst, md, ds):
    """State derivative ds/dt = [q̇, M⁻¹ (f0 − C q̇ − K q + Σ G_cᵀ F_c)] in the modes of ``cst``.

    Writes ds[0:2n] and, when ``ds`` has room, the friction and damping power at 2n, 2n + 1.
    """
    rhs_body(s, cst, md, ds)


# ----------------------------------------------------------------------------- queries
@inlined_kernel
def export_contacts(nc, N, F, v, N_out, F_out, v_out):
    """Copy each contact's normal force, friction force and slip velocity into the caller's arrays."""
    for c in range(nc):
        N_out[c] = N[c]
        for i in range(2):
            F_out[2 * c + i] = F[2 * c + i]
            v_out[2 * c + i] = v[2 * c + i]


@standalone
@api_kernel
def contact_forces(s, cst, md, F_out, N_out, v_out):
    """Each contact's friction force F (2 nc,) [N], normal force N (nc,) [N] and slip velocity
    v (2 nc,) [m/s] at ``s`` in the modes of ``cst`` (contact c at entries 2c, 2c+1 / c)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    w, v, N, h, F, f = work_vectors(md.kin, 6, s)
    if not sliding_friction(s, cst, md, n, nc, G, w, v, N, F):
        general_forces(s, cst, md, G, w, v, N, h, F, f)
    export_contacts(nc, N, F, v, N_out, F_out, v_out)


@kernel
def rhs_and_forces(s, cst, md, ds, F_out, N_out, v_out):
    """:func:`rhs` and :func:`contact_forces` from one evaluation of the frames and forces (the
    fixed-step methods need both at every step end)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    w, v, N, h, F, f = work_vectors(md.kin, 6, s)
    if not sliding_forces(s, cst, md, n, nc, diagonal, G, w, v, N, F, f):
        general_forces(s, cst, md, G, w, v, N, h, F, f)
    write_derivative(s, md, n, nc, diagonal, v, w, F, f, ds)
    export_contacts(nc, N, F, v, N_out, F_out, v_out)


@standalone
@api_kernel
def stick_forces(s, cst, extra, md, F_out, N_out):
    """Stick multipliers F (2 nc,) [N] of the sticking contacts and contact ``extra`` (≥ 0, or −1),
    the other contacts slipping in their modes; N_out (nc,) the normal forces. Returns the rows."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    A = work_matrix(md.kin, ROWS, ROWS, s)
    w, v, N, h, F, f = work_vectors(md.kin, 6, s)
    general_forces(s, cst, md, G, w, v, N, h, F, f)
    if extra >= 0 and not is_stick(cst, extra):
        # solve again with the extra contact held: remove the forces of the contacts to be solved
        for c in range(nc):
            if is_stick(cst, c) or c == extra:
                dim = contact_dim(md.kin, m, n, c)
                add_force_of(md.kin, c, G[2 * c:2 * c + 2], dim, n, -F[2 * c], -F[2 * c + 1], f)
        frame_with_bias(s, extra, md, G[2 * extra:2 * extra + 2], w[2 * extra:2 * extra + 2],
                        h[2 * extra:2 * extra + 2])
        k = solve_stick_rows(s, md, n, nc, diagonal, cst, extra, G, h, f, F, A)[0]
    else:
        k = stick_rows(md, m, n, nc, cst, np.int64(-1))[0]
    for c in range(nc):
        N_out[c] = N[c]
        F_out[2 * c] = F[2 * c]
        F_out[2 * c + 1] = F[2 * c + 1]
    return k


@inlined_kernel
def stick_margin(s, cst, c, md):
    """μs N_c − |F_c| [N] of sticking contact ``c`` at ``s``: the stick → slip event (paper Eq. 10),
    with the multipliers of all sticking contacts solved together."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    w, v, N, h, F, f = work_vectors(md.kin, 6, s)
    general_forces(s, cst, md, G, w, v, N, h, F, f)  # a call: events only, not the rhs
    return static_limit(m, n, c, N[c]) - math.sqrt(F[2 * c] * F[2 * c] + F[2 * c + 1] * F[2 * c + 1])


@kernel
def stick_margins(s, cst, md, out, at):
    """:func:`stick_margin` of every sticking contact c at ``s`` into ``out[at + c]`` (the others'
    entries untouched): the forces of all contacts solved once, where the margin of each contact
    alone solves them once per contact."""
    m = md.m
    n, nc, _ = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    w, v, N, h, F, f = work_vectors(md.kin, 6, s)
    general_forces(s, cst, md, G, w, v, N, h, F, f)
    for c in range(nc):
        if is_stick(cst, c):
            out[at + c] = static_limit(m, n, c, N[c]) - math.sqrt(F[2 * c] * F[2 * c] + F[2 * c + 1] * F[2 * c + 1])


@api_kernel
def slip_velocity(s, c, md):
    """Slip velocity (v0, v1) of contact ``c`` at ``s`` [m/s] (v1 = 0 for a 1-D contact)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G2 = work_matrix(md.kin, TWO, DOFS, s)
    w2 = work_matrix(md.kin, ONE, TWO, s)[0]
    contact_frame(md.kin, s, c, m, G2, w2)
    return contact_velocity(md.kin, s, n, c, contact_dim(md.kin, m, n, c), G2, w2)


@unilateral_kernel(lambda s, cst, c, md: 1.0 + csm.zero(s[0]))
def contact_event(s, cst, c, md):  # pragma: no cover - compiled only
    """:func:`indicator` (1.0 for pressed-only kinematics, never an event)."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    if is_rigid(md, n, c) and not is_open(cst, c):
        G = work_matrix(md.kin, ROWS, DOFS, s)
        w, v, N, h, F, f = work_vectors(md.kin, 6, s)
        general_forces(s, cst, md, G, w, v, N, h, F, f)
        return N[c]
    return contact_indicator(s, cst, md, n, c)


@kernel
def indicator(s, cst, c, md):
    """Open/closed indicator of unilateral contact ``c`` in its mode of ``cst``: > 0 while it stays
    closed (open), falls through 0 where it opens (closes) (:func:`~stickslip.model.normal.contact_indicator`;
    a closed rigid contact's is its normal force, the multiplier λ [N])."""
    return contact_event(s, cst, c, md)


@kernel
def rigid_pivot(s, cst, md):
    """Smallest relative pivot of the normal-force system of the closed rigid contacts at ``s``
    (:func:`~stickslip.model.forces.rigid_normal_forces`): ≤ 0 where they have no consistent
    normal force (Painlevé); 1.0 where none is closed."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    if not any_rigid_closed(cst, md, n, nc):
        return 1.0
    G = work_matrix(md.kin, ROWS, DOFS, s)
    w, v, N, h, F, f = work_vectors(md.kin, 6, s)
    return general_forces(s, cst, md, G, w, v, N, h, F, f)


@kernel
def gap(s, c, md):
    """(g, ġ) of unilateral contact ``c`` at ``s`` [m, m/s]."""
    return gap_and_rate(s, md, model_sizes(md.kin, md.m)[0], c)


@kernel
def normal_force_of(s, cst, c, md):
    """Normal force of contact ``c`` at ``s`` in the mode of ``cst`` [N]: a prescribed load, or a
    unilateral contact's λ (0 while open)."""
    m = md.m
    n = model_sizes(md.kin, m)[0]
    if is_rigid(md, n, c) and not is_open(cst, c):  # the multiplier: the forces in the modes of cst
        return contact_event(s, cst, c, md)
    G2 = work_matrix(md.kin, TWO, DOFS, s)
    w2 = work_matrix(md.kin, ONE, TWO, s)[0]
    return normal_in_mode(s, cst, md, n, c, contact_frame(md.kin, s, c, m, G2, w2))


@kernel
def unilateral(c, md):
    """Whether contact ``c`` has a gap instead of a prescribed normal load."""
    return is_unilateral(md, model_sizes(md.kin, md.m)[0], c)


@kernel
def rigid(c, md):
    """Whether contact ``c`` is a rigid unilateral contact (impacts; its normal force a multiplier)."""
    return is_rigid(md, model_sizes(md.kin, md.m)[0], c)


@kernel
def normal_force(s, c, md):
    """Normal force N_c [N] of contact ``c`` at ``s``."""
    G2 = work_matrix(md.kin, TWO, DOFS, s)
    w2 = work_matrix(md.kin, ONE, TWO, s)[0]
    return contact_frame(md.kin, s, c, md.m, G2, w2)


@standalone
@kernel
def slip_velocity_and_rate(s, ds, c, md):
    """(v0, v1, a0, a1): slip velocity of contact ``c`` [m/s] and its rate dv/dt = G q̈ + h [m/s²]
    along the state derivative ``ds`` (h the velocity bias of :func:`frame_with_bias`); for a heap
    kinematics class over its rows' nonzero entries (:func:`~stickslip.model.frames.heap_velocity_and_rate`)."""
    return velocity_and_rate_of(s, ds, c, md)


def velocity_and_rate_of(s, ds, c, md):  # pragma: no cover - resolved by numba (overload below)
    """The body of :func:`slip_velocity_and_rate` for the kinematics class of ``md``."""
    raise NotImplementedError


def _velocity_and_rate_by_frame(s, ds, c, md):
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G2 = work_matrix(md.kin, TWO, DOFS, s)
    wh = work_matrix(md.kin, TWO, TWO, s)
    frame_with_bias(s, c, md, G2, wh[0], wh[1])
    dim = contact_dim(md.kin, m, n, c)
    v0, v1 = frame_velocity(s, n, dim, G2, wh[0])
    a0 = wh[1, 0]
    a1 = wh[1, 1]
    for j in range(n):
        a0 += G2[0, j] * ds[n + j]
        a1 += G2[1, j] * ds[n + j]
    if dim == 1:
        a1 = 0.0
    return v0, v1, a0, a1


@overload(velocity_and_rate_of, jit_options=KERNEL_OPTIONS, inline="always")
def _velocity_and_rate_of(s, ds, c, md):
    if on_heap(kinematics_class(md)):
        return lambda s, ds, c, md: heap_velocity_and_rate(s, ds, c, md)
    return _velocity_and_rate_by_frame


@standalone
@kernel
def band_direction(s, cst, c, md, speed):
    """Slip direction (e0, e1) of slipping contact ``c`` inside the low-speed band (|v| = ``speed``):
    the quasi-static one for a 2-D contact, the stored one for a 1-D contact."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    ex = cst[CST * c + 1]
    ey = cst[CST * c + 2]
    if contact_dim(md.kin, m, n, c) == 1:
        return ex, 0.0
    G = work_matrix(md.kin, ROWS, DOFS, s)
    A = work_matrix(md.kin, ROWS, ROWS, s)
    w, v, N, h, F, f = work_vectors(md.kin, 6, s)
    general_forces(s, cst, md, G, w, v, N, h, F, f)
    for c2 in range(nc):  # solve again with this contact held: remove the forces to be solved
        if is_stick(cst, c2) or c2 == c:
            add_force_of(md.kin, c2, G[2 * c2:2 * c2 + 2], contact_dim(md.kin, m, n, c2), n, -F[2 * c2], -F[2 * c2 + 1],
                         f)
    frame_with_bias(s, c, md, G[2 * c:2 * c + 2], w[2 * c:2 * c + 2], h[2 * c:2 * c + 2])
    k, a00, a01, a11 = solve_stick_rows(s, md, n, nc, diagonal, cst, c, G, h, f, F, A)
    if k != 2:
        return ex, ey
    muN = kinetic_coefficient(md, n, c, speed) * N[c]
    return quasi_static_direction(a00, a01, a11, F[2 * c], F[2 * c + 1], muN, ex, ey)


@inlined_kernel
def slip_direction(s, cst, c, md, v0, v1):
    """Unit slip direction (e0, e1) of slipping contact ``c`` with slip velocity (v0, v1) at ``s``:
    v/|v| above the low-speed band, inside it :func:`band_direction`."""
    speed = math.sqrt(v0 * v0 + v1 * v1)
    if speed > md.m[H_BAND]:
        return v0 / speed, v1 / speed
    return band_direction(s, cst, c, md, speed)


@standalone
@api_kernel
def project_velocities(s, cst, extra, md):
    """Project q̇ onto v_c = 0 for every sticking contact and contact ``extra`` (≥ 0; −1: none),
    in the M-metric, in place; returns the kinetic energy change [J] (≤ 0).

    Δq̇ = −M⁻¹ G_Sᵀ (G_S M⁻¹ G_Sᵀ)⁺ v_S: the smallest kinetic-energy change that removes v_S, an
    impulsive friction force (a perfectly plastic tangential impact). If ``s`` carries the work
    accumulators (length ≥ 2n + 2) the change is booked as work of friction, so the energy balance
    stays exact. Locked DOFs (zero rows of M⁻¹) are not touched. A heap kinematics class that
    carries W = G M⁻¹ Gᵀ projects with it (:func:`~stickslip.model.stick.heap_project_velocities`).
    """
    delta = heap_projection(s, cst, extra, md)
    if not math.isnan(delta):
        return delta
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    MG = work_matrix(md.kin, ROWS, DOFS, s)
    A = work_matrix(md.kin, ROWS, ROWS, s)
    V = work_matrix(md.kin, ROWS, ROWS, s)
    w, b, x = work_vectors(md.kin, 3, s)
    k = np.int64(0)  # not a literal: numba would compile solve_psd for k = 0 first
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            G2 = G[2 * c:2 * c + 2]
            contact_frame(md.kin, s, c, m, G2, w[2 * c:2 * c + 2])
            dim = contact_dim(md.kin, m, n, c)
            v0, v1 = contact_velocity(md.kin, s, n, c, dim, G2, w[2 * c:2 * c + 2])
            for i in range(dim):
                inverse_mass_of_row(md.kin, m, n, diagonal, G[2 * c + i], MG[k])
                b[k] = v0 if i == 0 else v1
                k += 1
    if k == 0:
        return 0.0
    e_before = kinetic_energy(s, md)
    r = 0
    for c in range(nc):
        if is_stick(cst, c) or c == extra:
            for i in range(contact_dim(md.kin, m, n, c)):
                gram_row(md.kin, G[2 * c + i], MG, k, n, A, r, 0.0)
                r += 1
    solve_stick_system(md.kin, A, b, x, V, k)
    for r in range(k):
        for j in range(n):
            s[n + j] -= MG[r, j] * x[r]
    delta = kinetic_energy(s, md) - e_before
    if s.shape[0] >= 2 * n + 2:
        s[2 * n] += delta
    return delta
