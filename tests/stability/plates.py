"""The plates' numbers as arrays, for the tests that write the paper's equations out in numpy."""

from types import SimpleNamespace

import numpy as np

from stickslip.model import resolve_variant, two_plates


def plate_arrays(params, variant="full") -> SimpleNamespace:
    """``model`` (the FrictionModel), ``params``, ``variant``, and the diagonals ``mass``, ``minv``
    (0 on locked DOFs) and ``stiff`` of q = [x1, y1, x2, y2, φ, ψ] (Table 1's names)."""
    v = resolve_variant(variant)
    P = params
    mass = np.array([P.m_p, P.m_p, P.m_d, P.m_d, P.J_p, P.J_d])
    stiff = np.array([P.k_px, P.k_py, P.k_dx, P.k_dy, P.k_pphi, P.k_dpsi])
    return SimpleNamespace(model=two_plates(P, variant),
                           params=P, variant=v, mass=mass, minv=np.where(v.mask, 1.0 / mass, 0.0),
                           stiff=np.where(v.mask, stiff, 0.0))
