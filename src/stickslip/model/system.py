"""Assemble parameters and a variant into the flat arrays the compiled kernels take."""

from __future__ import annotations

import dataclasses

import numpy as np

from . import kernels
from .parameters import FRICTION_LAWS, Parameters
from .variants import Variant, resolve_variant

__all__ = ["System", "assemble"]


@dataclasses.dataclass(frozen=True)
class System:
    """Parameters and variant packed for the kernels.

    Attributes
    ----------
    params : Parameters
    variant : Variant
    minv, damp, stiff : ndarray, shape (6,)
        Inverse masses [1/kg, 1/(kg m^2)], damping and stiffness of q, zero for locked DOFs.
    p : ndarray, shape (7,)
        Contact and friction data indexed by ``kernels.P_*``.
    """

    params: Parameters
    variant: Variant
    minv: np.ndarray
    damp: np.ndarray
    stiff: np.ndarray
    p: np.ndarray

    @property
    def mass(self) -> np.ndarray:
        """Diagonal of M (6,), with ``inf`` for locked DOFs."""
        with np.errstate(divide="ignore"):
            return np.where(self.minv > 0, 1.0 / np.where(self.minv > 0, self.minv, 1.0), np.inf)


def assemble(params: Parameters, model="full", slip_band: float = kernels.DEFAULT_SLIP_BAND) -> System:
    """Pack ``params`` and the model variant into kernel arrays (see :mod:`stickslip.model.kernels`).

    ``slip_band`` [m/s] is the low-speed band of the slip direction (``kernels.DEFAULT_SLIP_BAND``).
    """
    variant = resolve_variant(model)
    P = params
    mass = np.array([P.m_p, P.m_p, P.m_d, P.m_d, P.J_p, P.J_d])
    damp = np.array([P.c_px, P.c_py, P.c_dx, P.c_dy, P.c_pphi, P.c_dpsi])
    stiff = np.array([P.k_px, P.k_py, P.k_dx, P.k_dy, P.k_pphi, P.k_dpsi])
    mask = variant.mask
    minv = np.where(mask, 1.0 / mass, 0.0)
    p = np.zeros(kernels.N_P)
    p[kernels.P_R] = P.r
    p[kernels.P_N] = P.N
    p[kernels.P_OMEGA] = P.Omega
    p[kernels.P_MU_K] = P.mu_k
    p[kernels.P_DELTA_MU] = P.delta_mu
    p[kernels.P_ALPHA] = P.alpha
    p[kernels.P_LAW] = float(FRICTION_LAWS.index(P.friction_law))
    p[kernels.P_SLIP_BAND] = slip_band
    return System(P, variant, minv, np.where(mask, damp, 0.0), np.where(mask, stiff, 0.0), p)
