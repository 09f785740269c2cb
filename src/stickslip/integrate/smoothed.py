"""Independent reference: smoothed friction integrated by scipy.

The slip law Eq. (3) is regularised as F = −μ(|v_r|) N v_r / √(|v_r|² + ε²), which removes stick
(the regularised solution creeps at |v_r| ~ ε instead) and turns the system into one smooth,
stiff ODE that ``scipy.integrate.solve_ivp`` can integrate. As ε → 0 its solution approaches
the non-smooth one.

This module deliberately shares **no code** with the compiled physics
(:mod:`stickslip.model.physics`): Eq. (1) is written here component by component from the paper,
with the contact kinematics of Eqs. (2), (5)–(9), in plain numpy. Agreement with the ``event``
method is therefore a real cross-check.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ..model.parameters import Parameters
from ..model.variants import resolve_variant

__all__ = ["simulate_smoothed"]


def _rhs_factory(P: Parameters, free: np.ndarray, eps: float):
    m = np.array([P.m_p, P.m_p, P.m_d, P.m_d, P.J_p, P.J_d])
    c = np.array([P.c_px, P.c_py, P.c_dx, P.c_dy, P.c_pphi, P.c_dpsi])
    k = np.array([P.k_px, P.k_py, P.k_dx, P.k_dy, P.k_pphi, P.k_dpsi])
    r, N, Om = P.r, P.N, P.Omega
    coulomb = P.friction_law == "coulomb"

    def rhs(t, s):
        x1, y1, x2, y2, phi, psi = s[:6]
        dx1, dy1, dx2, dy2, dphi, dpsi = s[6:]
        X = x1 - x2 + r * math.cos(phi)          # Eq. (2), (8)
        Y = y1 - y2 + r * math.sin(phi)
        R = math.hypot(X, Y)
        en1 = (-math.sin(phi), math.cos(phi))     # Eq. (7)
        en2 = (-Y / R, X / R)                     # Eq. (8)
        # Eq. (5)-(6): contact-point velocities of the upper plate and the lower plate
        vpx = dx1 + dphi * r * en1[0]
        vpy = dy1 + dphi * r * en1[1]
        vdx = dx2 + (Om + dpsi) * R * en2[0]
        vdy = dy2 + (Om + dpsi) * R * en2[1]
        vx, vy = vpx - vdx, vpy - vdy
        speed = math.hypot(vx, vy)
        mu = P.mu_k if coulomb else P.mu_k + P.delta_mu * math.exp(-P.alpha * speed)  # Eq. (4)
        scale = -mu * N / math.sqrt(speed * speed + eps * eps)
        Fx, Fy = scale * vx, scale * vy
        # Eq. (1)
        forcing = np.array([
            Fx, Fy, -Fx, -Fy,
            r * (Fx * en1[0] + Fy * en1[1]),
            -R * (Fx * en2[0] + Fy * en2[1]),
        ])
        acc = np.where(free, (forcing - c * s[6:] - k * s[:6]) / m, 0.0)
        return np.concatenate([np.where(free, s[6:], 0.0), acc])

    return rhs


def simulate_smoothed(params: Parameters, t_end: float, *, eps: float, variant="full", y0=None,
                      sample_rate: float = 1000.0, method: str = "LSODA", rtol: float = 1e-8,
                      atol: float = 1e-10):
    """Integrate the smoothed-friction model with ``scipy.integrate.solve_ivp``.

    Parameters
    ----------
    params : Parameters
    t_end : float
        Final time [s] (starts at 0).
    eps : float
        Regularisation speed ε [m/s] of v/√(v² + ε²).
    variant : str
        The plates' variant (locked DOFs held at zero).
    y0 : array-like (12,), optional
        Initial state, default at rest and undeformed.
    sample_rate : float
        Output samples per second [Hz].
    method, rtol, atol :
        Passed to ``solve_ivp``.

    Returns
    -------
    t : ndarray (n,)
    states : ndarray (n, 12)
    info : dict
        ``nfev``, ``wall_time_s``, ``status``, ``message``.
    """
    from scipy.integrate import solve_ivp  # imported on use: scipy takes ~0.3 s of every command's start

    if not (eps > 0 and math.isfinite(eps)):
        raise ValueError(f"eps = {eps} must be a finite speed > 0 [m/s]")
    free6 = resolve_variant(variant).mask
    y0 = np.zeros(12) if y0 is None else np.asarray(y0, dtype=float)
    t_eval = np.arange(int(math.floor(t_end * sample_rate + 1e-9)) + 1) / sample_rate
    start = time.perf_counter()
    sol = solve_ivp(_rhs_factory(params, free6, eps), (0.0, t_end), y0, method=method, t_eval=t_eval,
                    rtol=rtol, atol=atol)
    wall = time.perf_counter() - start
    return sol.t, sol.y.T, {"nfev": int(sol.nfev), "wall_time_s": wall, "status": int(sol.status), "message": sol.message}
