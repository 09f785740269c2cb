"""The generic physics, compiled for the plates' kinematics, against the paper's equations written
out here in plain numpy (an independent implementation of paper Eqs. 1–10): the right-hand side
with its work rates in every mode, the friction force and the slip velocity at random states
agree to round-off.

The reference shares no code with the package: the relative velocity is Eqs. (5)–(9) (the
contact-point velocities of both plates), the generalised friction forces are the right-hand
sides of Eq. (1), the stick force solves J M⁻¹ Jᵀ F = −(h + J M⁻¹ f) with J = ∂v_r/∂q̇ taken
column by column from Eq. (9) and h = (∂v_r/∂q) q̇ by a complex step of Eq. (9), the friction law
is Eq. (4), and inside the low-speed band the slip direction is checked to be a stable root of
the direction dynamics e × A (μ N e + F_s) = 0 (found here by a scan of the angle).
"""

from __future__ import annotations

import numpy as np
import pytest

import stickslip
from stickslip.model import physics as P
from stickslip.model.bundle import contact_state
from stickslip.model.library import two_plates

MODES = {"slip": P.MODE_SLIP, "stick": P.MODE_STICK, "exact": P.MODE_SLIP_EXACT, "band": P.MODE_SLIP_QUASI_STATIC}
FREE = {"full": [1, 1, 1, 1, 1, 1], "x": [1, 0, 1, 0, 1, 1], "y": [0, 1, 0, 1, 1, 1], "rotation": [0, 0, 0, 0, 1, 1]}


class Plates:
    """Paper Eqs. (1)–(10) for the parameters ``p`` with the DOFs ``free`` (locked ones never move)."""

    def __init__(self, p: stickslip.Parameters, free):
        self.p = p
        self.free = np.asarray(free, dtype=bool)
        mass = np.array([p.m_p, p.m_p, p.m_d, p.m_d, p.J_p, p.J_d])
        self.minv = np.where(self.free, 1.0 / mass, 0.0)
        self.c = np.array([p.c_px, p.c_py, p.c_dx, p.c_dy, p.c_pphi, p.c_dpsi])
        self.k = np.array([p.k_px, p.k_py, p.k_dx, p.k_dy, p.k_pphi, p.k_dpsi])

    def basis(self, q):
        """e_n1 (Eq. 7), e_n2 (Eq. 8) and R (Eq. 2) at the positions q (real or complex)."""
        x1, y1, x2, y2, phi, _ = q
        r = self.p.r
        X = x1 - x2 + r * np.cos(phi)
        Y = y1 - y2 + r * np.sin(phi)
        R = np.sqrt(X * X + Y * Y)
        return np.array([-np.sin(phi), np.cos(phi)]), np.array([-Y / R, X / R]), R

    def relative_velocity(self, q, qd):
        """v_r = v_c^p − v_c^d, Eqs. (5)–(9)."""
        en1, en2, R = self.basis(q)
        vp = np.array([qd[0], qd[1]]) + qd[4] * self.p.r * en1
        vd = np.array([qd[2], qd[3]]) + (self.p.Omega + qd[5]) * R * en2
        return vp - vd

    def generalised_force(self, q, F):
        """The right-hand sides of Eq. (1) for the friction force F."""
        en1, en2, R = self.basis(q)
        return np.array([F[0], F[1], -F[0], -F[1], self.p.r * F @ en1, -R * F @ en2])

    def mu(self, speed):
        """Eq. (4), or μk for the Coulomb law."""
        if self.p.friction_law == "coulomb":
            return self.p.mu_k
        return self.p.mu_k + self.p.delta_mu * np.exp(-self.p.alpha * speed)

    def passive(self, q, qd):
        """−C q̇ − K q on the free DOFs."""
        return np.where(self.free, -self.c * qd - self.k * q, 0.0)

    def constraint(self, q, qd):
        """J = ∂v_r/∂q̇ (2 × 6, column by column from Eq. 9) and h = (∂v_r/∂q) q̇ (complex step)."""
        J = np.column_stack([self.relative_velocity(q, e) - self.relative_velocity(q, 0 * e) for e in np.eye(6)])
        eps = 1e-30
        h = self.relative_velocity(q + 1j * eps * qd, qd.astype(complex)).imag / eps
        return J, h

    def stick_force(self, q, qd):
        """The friction force that keeps v_r = 0: J M⁻¹ Jᵀ F = −(h + J M⁻¹ f), minimal norm."""
        J, h = self.constraint(q, qd)
        A = J @ np.diag(self.minv) @ J.T
        return np.linalg.pinv(A, rcond=1e-10, hermitian=True) @ -(h + J @ (self.minv * self.passive(q, qd))), A

    def derivative(self, q, qd, F):
        """ds/dt with the work rates: [q̇, M⁻¹(f + Q(F)), Q(F)·q̇, −q̇ᵀ C q̇]."""
        Q = self.generalised_force(q, F)
        acc = self.minv * (self.passive(q, qd) + Q)
        return np.concatenate([np.where(self.free, qd, 0.0), acc, [Q @ qd, -(self.c * qd) @ qd]])

    def project(self, q, qd):
        """q̇ moved onto v_r = 0 in the M-metric (to build states inside the low-speed band)."""
        J, _ = self.constraint(q, qd)
        A = J @ np.diag(self.minv) @ J.T
        return qd - self.minv * (J.T @ (np.linalg.pinv(A, rcond=1e-10, hermitian=True) @ self.relative_velocity(q, qd)))


def band_roots(A, Fs, muN):
    """The stable roots (g = 0, dg/dθ > 0) of the direction dynamics g(θ) = e × A (μN e + F_s)."""
    theta = np.linspace(0.0, 2.0 * np.pi, 20001)
    e = np.stack([np.cos(theta), np.sin(theta)])
    w = A @ (muN * e + Fs[:, None])
    g = e[0] * w[1] - e[1] * w[0]
    roots = []
    for i in np.flatnonzero((g[:-1] < 0.0) & (g[1:] >= 0.0)):
        a, b = theta[i], theta[i + 1]
        for _ in range(80):  # bisection on the bracket
            m = 0.5 * (a + b)
            em = np.array([np.cos(m), np.sin(m)])
            wm = A @ (muN * em + Fs)
            if em[0] * wm[1] - em[1] * wm[0] < 0.0:
                a = m
            else:
                b = m
        roots.append(np.array([np.cos(a), np.sin(a)]))
    return roots


@pytest.mark.parametrize("law", ["exponential", "coulomb"])
@pytest.mark.parametrize("variant", ["full", "x", "y", "rotation"])
@pytest.mark.parametrize("mode", list(MODES))
def test_rhs_and_forces_match_the_paper_equations(variant, mode, law):
    params = stickslip.Parameters(N=70.0, Omega=2.0, friction_law=law)
    ref = Plates(params, FREE[variant])
    model = two_plates(params, variant)
    rng = np.random.default_rng(7)
    cst = contact_state(model.data.m)
    cst[0] = MODES[mode]
    checked = 0
    for _ in range(20):
        s = np.zeros(14)
        s[:12] = rng.normal(scale=0.05, size=12) * np.concatenate([ref.free, ref.free])
        q, qd = s[:6], s[6:12]
        if mode == "band":  # inside the low-speed band: a slip velocity below 5e-4 m/s
            qd[:] = ref.project(q, qd) + 1e-5 * rng.normal(size=6) * ref.free
        v = ref.relative_velocity(q, qd)
        speed = np.hypot(*v)
        Fs, A = ref.stick_force(q, qd)
        cst[1], cst[2] = 0.6, 0.8
        if mode == "stick":
            F_ref = Fs
        elif mode in ("slip", "exact"):  # random states slide far above the band: e = v_r/|v_r|
            F_ref = -ref.mu(speed) * params.N * v / speed
        else:  # the stable root of the direction dynamics, the stored direction 0.01 rad from it
            roots = band_roots(A, Fs, ref.mu(speed) * params.N)
            if not roots:
                continue
            e = roots[0]
            cst[1], cst[2] = np.cos(0.01) * e[0] - np.sin(0.01) * e[1], np.sin(0.01) * e[0] + np.cos(0.01) * e[1]
            F_ref = -ref.mu(speed) * params.N * e
        checked += 1
        d_ref = ref.derivative(q, qd, F_ref)
        d_new = np.zeros(14)
        P.rhs(s, cst, model.data, d_new)
        scale = np.max(np.abs(d_ref[:12])) + 1.0
        np.testing.assert_allclose(d_new, d_ref, rtol=0, atol=1e-12 * scale)
        F, N, vv = np.zeros(2), np.zeros(1), np.zeros(2)
        P.contact_forces(s, cst, model.data, F, N, vv)
        np.testing.assert_allclose(F, F_ref, rtol=0, atol=1e-10 * (np.abs(F_ref).sum() + 1.0))
        np.testing.assert_allclose(vv, v, rtol=0, atol=1e-13)
        np.testing.assert_allclose(P.slip_velocity(s, 0, model.data), v, rtol=0, atol=1e-13)
        assert N[0] == params.N
    assert checked >= 10
