"""Compiled variational equations of any friction-contact model, and the gradients of its events.

The linearised flow of a smooth segment (every contact in a fixed mode) is Φ̇ = J(s) Φ with J the
Jacobian of the generic right-hand side :func:`stickslip.model.physics.rhs`: J Φ is its directional
complex step along each column of Φ (as :func:`stickslip.model.derivatives.state_jacobian` takes it
along each state), or, while a 2-D contact slips inside the low-speed band, that at the quasi-static
direction (found by a Newton iteration on real
numbers, which the complex step does not see) plus the turn of that direction with the state, by the
implicit function theorem on its defining residual g(θ, s) = 0 (:func:`direction_gradient`, the
complex step of g at fixed θ). Nothing is differentiated by hand, so every model the simulator runs
has its variational equations.

:func:`integrate_segment` integrates y = [s (2n), Φ (2n × 2n, row-major)] with Dormand–Prince 5(4)
and stops at the first event of any contact (:data:`EV_MARGIN`, :data:`EV_ZERO`, :data:`EV_ARRIVE`,
:data:`EV_BAND`), located on the dense output. :func:`contact_gradients` gives the complex-step
gradients ∂v_c/∂s, ∂F_c/∂s, ∂N_c/∂s of one contact, from which the saltation matrices are built
(:mod:`.saltation`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..integrate import contacts as E
from ..integrate import dormand_prince as DP
from ..model import csmath as csm
from ..model import physics as P
from ..model.bundle import CST, H_BAND
from ..model.frames import add_force_of
from ..model.jit import api_kernel, inlined_kernel, kernel, loop, standalone
from ..model.kinematics import contact_dim, model_sizes
from ..model.stack import DOFS, ROWS, work_matrix, work_vectors

__all__ = ["EV_NONE", "EV_MARGIN", "EV_ZERO", "EV_ARRIVE", "EV_BAND", "EV_GAP", "SegmentEvents", "integrate_segment",
           "variational_rhs", "contact_gradients", "indicator_gradient", "event_value"]

#: Per-contact event kinds of a segment. Each event function starts positive; the event is its
#: first zero. ``EV_MARGIN``: μs N_c − |F_c| of a sticking contact (breakaway).
#: ``EV_ZERO``: e·v_c of a slipping 1-D contact along its stored direction e (arrival at v_c = 0).
#: ``EV_ARRIVE``: |v_c| − level of a 2-D contact slipping with the exact direction (the approach to
#: stick is stopped at a small speed, see :mod:`.saltation`). ``EV_BAND``: level − |v_c| of a 2-D
#: contact slipping with the quasi-static direction (leaving the low-speed band). ``EV_GAP``: the
#: open/closed indicator of a unilateral contact (:func:`stickslip.model.physics.indicator`); its
#: events sit at index nc + c of the event arrays, beside contact c's tangential one at c.
EV_NONE = 0
EV_MARGIN = 1
EV_ZERO = 2
EV_ARRIVE = 3
EV_BAND = 4
EV_GAP = 5

#: Points per step at which the dense output is checked for an event (as the event integrator).
EV_CHECKS = 4
#: Event instants are located on the dense output to this time [s].
EV_TIME_TOL = 1e-13


@kernel
def event_value(kind, c, s, level, e0, cst, md):
    """Event function of contact ``c`` of ``kind`` at the state ``s`` (module constants; for
    ``EV_GAP``, ``c`` is nc + the contact)."""
    if kind == EV_MARGIN:
        return P.stick_margin(s, cst, c, md)
    if kind == EV_GAP:
        return P.indicator(s, cst, c - model_sizes(md.kin, md.m)[1], md)
    v0, v1 = P.slip_velocity(s, c, md)
    if kind == EV_ZERO:
        return v0 * e0
    speed = math.sqrt(v0 * v0 + v1 * v1)
    if kind == EV_ARRIVE:
        return speed - level
    if kind == EV_BAND:
        return level - speed
    return 1.0


@standalone
@kernel
def direction_residual(s, cst, c, md, ct, st):
    """(g, ∂g/∂θ, μN, k) of 2-D contact ``c`` slipping inside the low-speed band at the direction
    e = (ct, st) = (cos θ, sin θ): g = e × A (μ(|v|) N e + F_s), whose stable root is the quasi-static
    direction (:func:`stickslip.model.physics.quasi_static_direction`), A = G_c M⁻¹ G_cᵀ, F_s the force
    that would hold the contact with the other sticking contacts; k the stick rows (the direction is
    quasi-static only for k = 2, no other contact sticking). Generic in the number type of ``s``."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    G = work_matrix(md.kin, ROWS, DOFS, s)
    A = work_matrix(md.kin, ROWS, ROWS, s)
    w, v, N, h, F, f = work_vectors(md.kin, 6, s)
    P.general_forces(s, cst, md, G, w, v, N, h, F, f)
    for c2 in range(nc):  # solve again with this contact held: remove the forces to be solved
        if P.is_stick(cst, c2) or c2 == c:
            add_force_of(md.kin, c2, G[2 * c2:2 * c2 + 2], contact_dim(md.kin, m, n, c2), n, -F[2 * c2], -F[2 * c2 + 1],
                         f)
    P.frame_with_bias(s, c, md, G[2 * c:2 * c + 2], w[2 * c:2 * c + 2], h[2 * c:2 * c + 2])
    k, a00, a01, a11 = P.solve_stick_rows(s, md, n, nc, diagonal, cst, c, G, h, f, F, A)
    speed = csm.sqrt(v[2 * c] * v[2 * c] + v[2 * c + 1] * v[2 * c + 1])
    muN = P.kinetic_coefficient(md, n, c, speed) * N[c]
    wx = a00 * F[2 * c] + a01 * F[2 * c + 1]
    wy = a01 * F[2 * c] + a11 * F[2 * c + 1]
    c2 = ct * ct - st * st
    s2 = 2.0 * ct * st
    g = muN * (a01 * c2 + 0.5 * (a11 - a00) * s2) + (ct * wy - st * wx)
    dg = muN * (-2.0 * a01 * s2 + (a11 - a00) * c2) - (ct * wx + st * wy)
    return g, dg, muN, k


@inlined_kernel
def band_correction(s, cst, md, n2, Phi, out, z, gq):
    """Add to ``out`` (2n × k) the turn of the quasi-static direction of every 2-D contact inside the
    low-speed band along the variations ``Phi`` (2n × k): out += [0; M⁻¹ G_cᵀ ∂F_c/∂θ] (∇θ · Φ), with
    ∇θ · Φ[:, k] = −(∂g/∂s · Φ[:, k]) / (∂g/∂θ) (directional complex step of g at fixed θ), where the
    direction is quasi-static (k = 2 stick rows and ∂g/∂θ > 0, as the kernel's Newton iteration
    requires; elsewhere the kernel keeps the stored direction and the complex step alone is exact).
    ``z`` (2n,) complex, ``gq`` (n,) float work."""
    m = md.m
    n, nc, diagonal = model_sizes(md.kin, m)
    band = m[H_BAND]
    for c in range(nc):
        mode = np.int64(cst[CST * c])
        if mode == P.MODE_STICK or mode == P.MODE_SLIP_EXACT or contact_dim(md.kin, m, n, c) != 2:
            continue
        v0, v1 = P.slip_velocity(s, c, md)
        speed = math.sqrt(v0 * v0 + v1 * v1)
        if mode == P.MODE_SLIP and speed > band:
            continue
        ct, st = P.band_direction(s, cst, c, md, speed)
        g, dg, muN, k = direction_residual(s, cst, c, md, ct, st)
        if k != 2 or not dg > 0.0:
            continue
        # ∂F/∂θ = −μN (−sin θ, cos θ); its generalised force G_cᵀ ∂F/∂θ, through M⁻¹
        for i in range(n2):
            z[i] = s[i]
        for j in range(n):
            z[n + j] = complex(s[n + j], 1.0)
            a0, a1 = P.slip_velocity(z, c, md)  # linear in q̇: Im is the column G_c[:, j]
            gq[j] = muN * st * a0.imag - muN * ct * a1.imag
            z[n + j] = s[n + j]
        acc, = work_vectors(md.kin, 1, s)
        P.apply_inverse_mass(m, n, diagonal, gq, acc)
        for col in range(Phi.shape[1]):
            for j in range(n2):
                z[j] = complex(s[j], P.COMPLEX_STEP * Phi[j, col])
            gz = direction_residual(z, cst, c, md, ct, st)[0]
            dtheta = -(gz.imag / P.COMPLEX_STEP) / dg
            for i in range(n):
                out[n + i, col] += acc[i] * dtheta


@standalone
@kernel
def variational_rhs(y, cst, md, n2, band, dy, s, z, dz, gq):
    """d/dt of y = [s, Φ]: ṡ = f(s), Φ̇ = J(s) Φ, in the modes of ``cst``.

    J Φ column by column as the directional complex step of the right-hand side,
    J Φ[:, k] = Im f(s + i ε Φ[:, k]) / ε (no Jacobian is formed, no matrix product: one complex
    evaluation a column, as many as the Jacobian would take); ``band``: some 2-D contact slips inside
    the low-speed band, whose direction turn :func:`band_correction` adds. ``s`` (2n,), ``gq`` (n,):
    float work; ``z``, ``dz``: complex work (2n,).
    """
    for i in range(n2):
        s[i] = y[i]
    P.rhs(s, cst, md, dy[:n2])
    Phi = y[n2:].reshape((n2, n2))
    out = dy[n2:].reshape((n2, n2))
    h = P.COMPLEX_STEP
    for k in range(n2):
        nonzero = False
        for i in range(n2):
            z[i] = complex(s[i], h * Phi[i, k])
            nonzero = nonzero or Phi[i, k] != 0.0
        if nonzero:
            P.rhs(z, cst, md, dz)
            for i in range(n2):
                out[i, k] = dz[i].imag / h
        else:
            for i in range(n2):
                out[i, k] = 0.0
    if band:
        band_correction(s, cst, md, n2, Phi, out, z, gq)


class SegmentEvents(NamedTuple):
    """The events a segment watches (:func:`integrate_segment`).

    Attributes
    ----------
    kind : ndarray (nc,) or (2 nc,) int64
        Event kind of each contact (``EV_*``; ``EV_NONE``: not watched), then with unilateral
        contacts the ``EV_GAP`` of each.
    level : ndarray, as ``kind``
        Speed level of ``EV_ARRIVE`` / ``EV_BAND`` [m/s].
    e : ndarray, as ``kind``
        Stored slip direction (±1) of ``EV_ZERO``.
    """

    kind: np.ndarray
    level: np.ndarray
    e: np.ndarray


@standalone
@kernel
def _first_event(events, y, ynew, Q, h, cst, md, n2, g0, work, s):
    """(θ, contact) of the earliest of the :class:`SegmentEvents` ``events`` in the accepted step
    from ``y`` (θ ∈ (0, 1]), or (−1, −1).

    ``g0`` (nc,): the event values at the step start (updated to the step end when none fires).
    """
    ev_kind, ev_level, ev_e = events
    nc = ev_kind.shape[0]
    best = -1.0
    best_c = -1
    for c in range(nc):
        kind = ev_kind[c]
        if kind == EV_NONE:
            continue
        a = 0.0
        ga = g0[c]
        b = -1.0
        gb = 0.0
        for k in range(1, EV_CHECKS + 1):
            th = k / EV_CHECKS
            if k == EV_CHECKS:
                for i in range(n2):
                    s[i] = ynew[i]
            else:
                E.dense_state(y, Q, h, th, work)
                for i in range(n2):
                    s[i] = work[i]
            g = event_value(kind, c, s, ev_level[c], ev_e[c], cst, md)
            if ga > 0.0 and g <= 0.0:
                b = th
                gb = g
                break
            a = th
            ga = g
        if b < 0.0:
            continue
        tol = EV_TIME_TOL / h
        side = np.int64(0)
        for _ in range(E.MAX_REFINEMENTS):
            if gb == 0.0 or (b - a) <= tol:
                break
            cc = E.regula_falsi_point(a, ga, b, gb)
            E.dense_state(y, Q, h, cc, work)
            for i in range(n2):
                s[i] = work[i]
            gc = event_value(kind, c, s, ev_level[c], ev_e[c], cst, md)
            a, ga, b, gb, side = E.illinois_update(a, ga, b, gb, cc, gc, gc > 0.0, side)
        if best < 0.0 or b < best:
            best = b
            best_c = c
    return best, best_c


@loop
def integrate_segment(y0, t0, t1, cst, md, n2, band, rtol, atol, events, max_steps):
    """Dormand–Prince 5(4) on y = [s, Φ] (2n + 4n²,) from ``t0`` towards ``t1`` in the modes of
    ``cst``, stopping at the first event of any contact.

    Parameters
    ----------
    events : SegmentEvents
        The events watched.
    atol : ndarray (2n + 4n²,)
        Absolute tolerances; error control is the RMS of the local error over ``atol + rtol |y|``.

    Returns
    -------
    status : int
        0 reached ``t1``, 1 event, 2 step underflow, 3 ``max_steps``.
    t : float
        Time reached [s].
    y : ndarray
        State and variations there.
    contact : int
        Index of the event in ``events.kind`` (−1 without).
    """
    ev_kind, ev_level, ev_e = events
    n = y0.shape[0]
    nc = ev_kind.shape[0]
    y = y0.copy()
    ynew = np.empty(n)
    ytmp = np.empty(n)
    work = np.empty(n)
    Kst = np.empty((7, n))
    Q = np.empty((n, 4))
    s = np.empty(n2)
    gq = np.empty(n2)
    z = np.empty(n2, dtype=np.complex128)
    dz = np.empty(n2, dtype=np.complex128)
    g0 = np.empty(max(nc, 1))
    for c in range(nc):
        for i in range(n2):
            s[i] = y[i]
        g0[c] = event_value(ev_kind[c], c, s, ev_level[c], ev_e[c], cst, md)
    variational_rhs(y, cst, md, n2, band, Kst[0], s, z, dz, gq)
    t = t0
    h = min(1e-4, t1 - t0)  # the controller grows it ×5 per step
    n_steps = 0
    while t < t1:
        if n_steps >= max_steps:
            return 3, t, y, -1
        n_steps += 1
        h = min(h, t1 - t)
        if h <= 1e-15 * max(1.0, abs(t)):
            return 2, t, y, -1
        for stage in range(1, 6):
            DP.stage_state(y, Kst, h, stage, ytmp)
            variational_rhs(ytmp, cst, md, n2, band, Kst[stage], s, z, dz, gq)
        DP.stage_state(y, Kst, h, np.int64(6), ynew)
        variational_rhs(ynew, cst, md, n2, band, Kst[6], s, z, dz, gq)
        total = 0.0
        for i in range(n):
            sc = atol[i] + rtol * max(abs(y[i]), abs(ynew[i]))
            total += (DP.local_error(Kst, h, i) / sc) ** 2
        err_norm = math.sqrt(total / n)
        if not math.isfinite(err_norm) or err_norm > 1.0:
            h *= 0.2 if not math.isfinite(err_norm) else max(0.2, 0.9 * err_norm ** -0.2)
            continue
        DP.dense_coefficients(Kst, Q)
        theta, c_ev = _first_event(events, y, ynew, Q, h, cst, md, n2, g0, work, s)
        if c_ev >= 0:
            E.dense_state(y, Q, h, theta, work)
            return 1, t + theta * h, work.copy(), c_ev
        for c in range(nc):
            for i in range(n2):
                s[i] = ynew[i]
            g0[c] = event_value(ev_kind[c], c, s, ev_level[c], ev_e[c], cst, md)
        t += h
        for i in range(n):
            y[i] = ynew[i]
            Kst[0, i] = Kst[6, i]
        h *= 5.0 if err_norm == 0.0 else min(5.0, 0.9 * err_norm ** -0.2)
    return 0, t, y, -1


@kernel
def indicator_gradient(s, cst, c, md, n2, out, z):
    """Complex-step gradient ∂φ/∂s (2n,) of unilateral contact ``c``'s open/closed indicator at the
    float state ``s`` in its mode of ``cst`` (``z`` (2n,) complex work)."""
    for i in range(n2):
        z[i] = s[i]
    for j in range(n2):
        z[j] = complex(s[j], P.COMPLEX_STEP)
        out[j] = P.indicator(z, cst, c, md).imag / P.COMPLEX_STEP
        z[j] = s[j]


@standalone
@api_kernel
def contact_gradients(s, cst, c, md, n2, Dv, DF, DN, z, F, N, v):
    """Complex-step gradients of contact ``c`` at the float state ``s`` in the modes of ``cst``:
    ∂v_c/∂s into ``Dv`` (2 × 2n), ∂F_c/∂s into ``DF`` (2 × 2n; the stick multiplier if c sticks),
    ∂N_c/∂s into ``DN`` (2n,). ``z`` (2n,), ``F`` (2 nc,), ``N`` (nc,), ``v`` (2 nc,): complex work."""
    for i in range(n2):
        z[i] = s[i]
    for j in range(n2):
        z[j] = complex(s[j], P.COMPLEX_STEP)
        P.contact_forces(z, cst, md, F, N, v)
        for i in range(2):
            Dv[i, j] = v[2 * c + i].imag / P.COMPLEX_STEP
            DF[i, j] = F[2 * c + i].imag / P.COMPLEX_STEP
        DN[j] = N[c].imag / P.COMPLEX_STEP
        z[j] = s[j]
