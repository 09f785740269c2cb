"""Contact kinematics of the two plates (paper Eqs. 2, 8, 9), registered with the compiled physics.

q = [x1, y1, x2, y2, φ, ψ]; the contact point relative to O2 is X = x1 − x2 + r cos φ,
Y = y1 − y2 + r sin φ, and the relative velocity of the upper plate against the lower one
(Eq. 9) is v_r = G q̇ − w with

    G = [[1, 0, −1,  0, −r sin φ,  Y],
         [0, 1,  0, −1,  r cos φ, −X]],     w = Ω (−Y, X),

Gᵀ F giving the right-hand sides of Eq. (1). The normal force is the constant preload N.
"""

from __future__ import annotations

from typing import NamedTuple

from .. import csmath as csm
from ..bundle import C_N0, contact_offsets
from ..jit import kernel
from ..kinematics import register_kinematics

__all__ = ["PlateKinematics", "plate_frame"]


class PlateKinematics(NamedTuple):
    """Kinematics data of the two plates: contact radius r [m] and disc speed Ω [rad/s]."""

    r: float
    Omega: float


@kernel
def plate_frame(kin, s, c, m, G, w):
    """Contact frame of the plates (module docstring); returns the preload N [N]."""
    r = kin.r
    sphi = csm.sin(s[4])
    cphi = csm.cos(s[4])
    X = s[0] - s[2] + r * cphi
    Y = s[1] - s[3] + r * sphi
    G[0, 0] = 1.0
    G[0, 1] = 0.0
    G[0, 2] = -1.0
    G[0, 3] = 0.0
    G[0, 4] = -r * sphi
    G[0, 5] = Y
    G[1, 0] = 0.0
    G[1, 1] = 1.0
    G[1, 2] = 0.0
    G[1, 3] = -1.0
    G[1, 4] = r * cphi
    G[1, 5] = -X
    w[0] = -kin.Omega * Y
    w[1] = kin.Omega * X
    return m[contact_offsets(6, c)[0] + C_N0] + csm.zero(s[0])


register_kinematics(PlateKinematics, plate_frame, ndof=6, ncontacts=1, diagonal=True, dim=2)
