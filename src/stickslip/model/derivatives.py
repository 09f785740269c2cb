"""Derivatives of the one right-hand side, by complex step: nothing is differentiated by hand.

The generic physics (:mod:`stickslip.model.physics`) runs on complex states. With a perturbation
i h along state j and h = :data:`~stickslip.model.physics.COMPLEX_STEP` = 1e-150, every product
of two perturbations is ~1e-300 relative and vanishes, so Im f(s + i h e_j)/h = ∂f/∂s_j exactly
up to round-off (Squire & Trapp 1998; Martins, Sturdza & Alonso 2003): no truncation error, no
cancellation, and no second copy of the equations that could drift from the simulator's.
Inside a complex evaluation the stick multiplier's velocity bias Ġ q̇ − ẇ is itself a central
difference (relative error ~1e-10; zero for constant kinematics).

The slip direction inside the low-speed band is found by a Newton iteration on real numbers
and is therefore not differentiated here; Jacobians are taken in exact slip (above the band) and
in stick, which is what stability and the variational equations of orbits need.
"""

from __future__ import annotations

import numpy as np

from .jit import inlined_kernel
from .kinematics import model_sizes
from .physics import COMPLEX_STEP, rhs

__all__ = ["state_jacobian", "state_jacobian_from_python", "acceleration_jacobian"]


@inlined_kernel
def state_jacobian(s, cst, md, J, z, dz):
    """J = ∂f/∂s (2n × 2n) of the right-hand side in the modes of ``cst`` at the float state ``s``.

    ``z``, ``dz``: complex work arrays of length ≥ 2n (+2 if ``s`` carries the work accumulators).
    Columns of locked DOFs are computed like the others (they multiply zero rows of M⁻¹).
    """
    n = model_sizes(md.kin, md.m)[0]
    n2 = 2 * n
    for i in range(z.shape[0]):
        z[i] = s[i] if i < s.shape[0] else 0.0
    for j in range(n2):
        z[j] = complex(s[j], COMPLEX_STEP)
        rhs(z, cst, md, dz)
        for i in range(n2):
            J[i, j] = dz[i].imag / COMPLEX_STEP
        z[j] = s[j]


def state_jacobian_from_python(s: np.ndarray, cst: np.ndarray, md) -> np.ndarray:
    """:func:`state_jacobian` for a caller in Python: the same complex steps of the right-hand side
    (an api kernel, called from here), so the same matrix bit for bit, without compiling a kernel
    of its own (its module would carry the complex physics' code again: ~1.3 s of a cold
    ``stability``).

    Parameters
    ----------
    s : ndarray (2n,)
        Float state [q, q̇].
    cst : ndarray
        Contact states (the modes the Jacobian is taken in).
    md : ModelData

    Returns
    -------
    J : ndarray (2n, 2n)
        ∂f/∂s.
    """
    s = np.ascontiguousarray(s, dtype=np.float64)
    n2 = s.shape[0]
    z = s.astype(np.complex128)
    dz = np.zeros(n2, dtype=np.complex128)
    J = np.empty((n2, n2))
    for j in range(n2):
        z[j] = complex(s[j], COMPLEX_STEP)
        rhs(z, cst, md, dz)
        J[:, j] = dz.imag / COMPLEX_STEP
        z[j] = s[j]
    return J


@inlined_kernel
def acceleration_jacobian(q, cst, md, Jqq, acc, z, dz):
    """∂q̈/∂q (n × n) at rest (q̇ = 0) into ``Jqq`` and the accelerations q̈ (n,) there into ``acc``.

    The Newton matrix of the steady-sliding equilibrium f0 − K q + Σ G_cᵀ F_c(q, 0) = 0.
    ``z``, ``dz``: complex work arrays of length 2n.
    """
    n = model_sizes(md.kin, md.m)[0]
    for i in range(z.shape[0]):
        z[i] = 0.0
    for j in range(n):
        z[j] = q[j]
    for j in range(n):
        z[j] = complex(q[j], COMPLEX_STEP)
        rhs(z, cst, md, dz)
        for i in range(n):
            Jqq[i, j] = dz[n + i].imag / COMPLEX_STEP
            acc[i] = dz[n + i].real
        z[j] = q[j]
