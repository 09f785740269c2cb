"""The two plates' parameters and variant as flat arrays: the assembled :class:`System`.

The plates' solvers run on their :class:`~stickslip.model.FrictionModel`
(:func:`~stickslip.model.library.two_plates`); :meth:`System.model` gives it. ``System`` keeps the
plates' numbers in arrays for the callers that take them in that form: the inverse masses,
damping and stiffness of q = [x1, y1, x2, y2, φ, ψ] and the contact and friction data ``p``,
indexed by the ``P_*`` constants below.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .library.two_plates import two_plates
from .parameters import FRICTION_LAWS, Parameters
from .system_model import DEFAULT_SLIP_BAND
from .variants import Variant, resolve_variant

__all__ = ["System", "assemble", "P_R", "P_N", "P_OMEGA", "P_MU_K", "P_DELTA_MU", "P_ALPHA", "P_LAW", "P_SLIP_BAND",
           "N_P"]

#: Indices into the contact and friction data ``System.p``: contact radius r [m], normal force N
#: [N], disc speed Ω [rad/s], μk, Δμ, α [s/m], the law (index into ``FRICTION_LAWS``: 0 the
#: exponential law, Eq. 4; 1 Coulomb) and the low-speed band [m/s].
P_R, P_N, P_OMEGA, P_MU_K, P_DELTA_MU, P_ALPHA, P_LAW, P_SLIP_BAND = range(8)
N_P = 8


@dataclasses.dataclass(frozen=True)
class System:
    """Parameters and variant of the two plates packed in arrays.

    Attributes
    ----------
    params : Parameters
    variant : Variant
    minv, damp, stiff : ndarray, shape (6,)
        Inverse masses [1/kg, 1/(kg m^2)], damping and stiffness of q, zero for locked DOFs.
    p : ndarray, shape (N_P,)
        Contact and friction data indexed by the ``P_*`` constants.
    """

    params: Parameters
    variant: Variant
    minv: np.ndarray
    damp: np.ndarray
    stiff: np.ndarray
    p: np.ndarray

    @property
    def slip_band(self) -> float:
        """Low-speed band of the slip direction [m/s]."""
        return float(self.p[P_SLIP_BAND])

    def model(self):
        """The same plates as a :class:`~stickslip.model.FrictionModel` (what the solvers run)."""
        return two_plates(self.params, self.variant, self.slip_band)

    @property
    def mass(self) -> np.ndarray:
        """Diagonal of M (6,), with ``inf`` for locked DOFs."""
        with np.errstate(divide="ignore"):
            return np.where(self.minv > 0, 1.0 / np.where(self.minv > 0, self.minv, 1.0), np.inf)


def assemble(params: Parameters, model="full", slip_band: float = DEFAULT_SLIP_BAND) -> System:
    """Pack ``params`` and the model variant into a :class:`System`.

    ``slip_band`` [m/s] is the low-speed band of the slip direction (``DEFAULT_SLIP_BAND`` of
    :mod:`stickslip.model.system_model`).
    """
    variant = resolve_variant(model)
    P = params
    mass = np.array([P.m_p, P.m_p, P.m_d, P.m_d, P.J_p, P.J_d])
    damp = np.array([P.c_px, P.c_py, P.c_dx, P.c_dy, P.c_pphi, P.c_dpsi])
    stiff = np.array([P.k_px, P.k_py, P.k_dx, P.k_dy, P.k_pphi, P.k_dpsi])
    mask = variant.mask
    minv = np.where(mask, 1.0 / mass, 0.0)
    p = np.zeros(N_P)
    p[P_R] = P.r
    p[P_N] = P.N
    p[P_OMEGA] = P.Omega
    p[P_MU_K] = P.mu_k
    p[P_DELTA_MU] = P.delta_mu
    p[P_ALPHA] = P.alpha
    p[P_LAW] = float(FRICTION_LAWS.index(P.friction_law))
    p[P_SLIP_BAND] = slip_band
    return System(P, variant, minv, np.where(mask, damp, 0.0), np.where(mask, stiff, 0.0), p)
