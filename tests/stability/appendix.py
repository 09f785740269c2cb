"""The paper's Appendix (A.2) matrices C_L and K_L, transcribed entry by entry as printed.

Used only as a cross-check of the complex-step linearisation. The printed
entries are kept verbatim here, typos included; ``corrected=True`` applies the
corrections documented in docs/stability.md. Row/column order of the printed matrices is
(x1, y1, x2, y2, φ, ψ), the order of q (the printed M_L = diag(m_p, m_p, J_p, m_d, m_d, J_d)
is itself inconsistent with its C_L and K_L, see docs/stability.md).
"""

from __future__ import annotations

import math

import numpy as np


def appendix_matrices(q, params, corrected=False):
    """C_L and K_L (6×6) of the Appendix at the equilibrium q (order x1, y1, x2, y2, φ, ψ)."""
    P = params
    x1, y1, x2, y2, phi, psi = q
    r, N, Om = P.r, P.N, P.Omega
    dmu, al, mk = P.delta_mu, P.alpha, P.mu_k
    Xe = x1 - x2 + r * math.cos(phi)
    Ye = y1 - y2 + r * math.sin(phi)
    vx = Om * Ye
    vy = -Om * Xe
    v = Om * math.hypot(Xe, Ye)
    mue = mk + dmu * math.exp(-al * v)
    A = al * dmu * math.exp(-al * v) / v**2 + mue / v**3
    s, c = math.sin(phi), math.cos(phi)
    C = np.zeros((6, 6))
    C[0, 0] = P.c_px - N * (A * vx**2 - mue / v)
    C[1, 0] = -N * vx * vy * A
    C[2, 0] = P.c_px - C[0, 0]
    C[3, 0] = -C[1, 0]
    C[4, 0] = N * r * (A * (s * vx**2 - c * vx * vy) - mue * s / v)
    C[5, 0] = N * (A * (Xe * vx * vy - Ye * vx**2) / v**2 + mue * Ye / v)
    C[1, 1] = P.c_py - N * (A * vy**2 - mue / v)
    C[2, 1] = -C[1, 0]
    C[3, 1] = P.c_py - C[1, 1]
    C[4, 1] = N * r * (A * (s * vx * vy - c * vy**2) + mue * c / v)
    C[5, 1] = N * (A * (Xe * vy**2 - Ye * vx * vy) / v**2 - mue * Xe / v)
    C[2, 2] = P.c_dx - C[2, 0]
    C[3, 2] = C[1, 0]
    C[4, 2] = -C[4, 0]
    C[5, 2] = -C[5, 0]
    C[3, 3] = P.c_dy - C[3, 1]
    C[4, 3] = -C[4, 1]
    C[5, 3] = -C[5, 1]
    C[4, 4] = P.c_pphi - N * r * (A * (r * c * vy - r * s * vx) ** 2 - mue / v)
    C[5, 4] = N * r * (A * (c * vy - s * vx) * (Xe * vy - Ye * vx) - mue * (s * Ye + c * Xe) / v)
    C[5, 5] = P.c_dpsi - N * (A * (Xe * vy - Ye * vx) ** 2 - mue * (Xe**2 + Ye**2) / v)
    if corrected:
        # see docs/stability.md, "Appendix entries that disagree": a spurious 1/v_re^2 in C_61 and
        # C_62 (and in C_63 = -C_61, C_64 = -C_62 and the symmetric entries), and a factor r
        # instead of r^2 on the mu_e term of C_55
        C[5, 0] = N * (A * (Xe * vx * vy - Ye * vx**2) + mue * Ye / v)
        C[5, 1] = N * (A * (Xe * vy**2 - Ye * vx * vy) - mue * Xe / v)
        C[5, 2] = -C[5, 0]
        C[5, 3] = -C[5, 1]
        C[4, 4] = P.c_pphi - N * r**2 * (A * (c * vy - s * vx) ** 2 - mue / v)
    for i in range(6):
        for j in range(i):
            C[j, i] = C[i, j]
    K = np.zeros((6, 6))
    K[0, 0] = P.k_px + N * Om * A * vx * vy
    K[0, 1] = -N * Om * (A * vx**2 - mue / v)
    K[0, 2] = P.k_px - K[0, 0]
    K[0, 3] = -K[0, 1]
    K[0, 4] = -N * Om * r * (A * (c * vx**2 + s * vx * vy) - mue * c / v)
    K[0, 5] = 0.0
    K[1, 0] = N * Om * (A * vy**2 - mue / v)
    K[1, 1] = P.k_py - N * Om * A * vx * vy
    K[1, 2] = -K[1, 0]
    K[1, 3] = -K[0, 2]
    K[1, 4] = -N * Om * r * (A * (s * vy**2 + c * vx * vy) - mue * s / v)
    K[1, 5] = 0.0
    K[2, 0] = K[0, 2]
    K[2, 1] = -K[0, 1]
    K[2, 2] = P.k_dx - K[0, 2]
    K[2, 3] = -K[0, 3]
    K[2, 4] = -K[0, 4]
    K[2, 5] = 0.0
    K[3, 0] = -K[1, 0]
    K[3, 1] = K[1, 3]
    K[3, 2] = -K[1, 2]
    K[3, 3] = P.k_dy - K[1, 3]
    K[3, 4] = -K[1, 4]
    K[3, 5] = 0.0
    K[4, 0] = N * Om * r * (A * (c * vy**2 - s * vx * vy) - mue * c / v)
    K[4, 1] = -N * Om * r * (A * (c * vx * vy - s * vx**2) + mue * s / v)
    K[4, 2] = -K[4, 0]
    K[4, 3] = -K[4, 1]
    K[4, 4] = P.k_pphi - N * Om * r * A * (c * vx + s * vy) * (-s * vx + c * vy)
    K[4, 5] = 0.0
    K[5, 0] = -N * Om * (A * (Xe * vy**2 - Ye * vx * vy) - 2 * mue * Xe / v)
    K[5, 2] = -K[5, 0]
    K[5, 1] = N * Om * (A * (Xe * vx * vy - Ye * vx**2) + 2 * mue * Ye / v)
    K[5, 3] = -K[5, 1]
    K[5, 4] = N * Om * r * (A * (c * vx + s * vy) * (Xe * vy - Ye * vx) + 2 * mue * (c * Ye - s * Xe) / v)
    K[5, 5] = P.k_dpsi
    if corrected:
        # K_55: r^2 instead of r on the A term, and the missing term -N r mu_e (cos(phi) v_x +
        # sin(phi) v_y) / v_re from the rotation of e_n1 with phi
        K[4, 4] = (P.k_pphi - N * Om * r**2 * A * (c * vx + s * vy) * (-s * vx + c * vy)
                   - N * r * mue * (c * vx + s * vy) / v)
    return C, K
