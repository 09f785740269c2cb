"""The typed bundle through which a model reaches the compiled kernels.

A model arrives in compiled code as one :class:`ModelData` = (``m``, ``kin``, ``law``):

``m``    one flat float64 array holding every number of the model, so that a kernel call passes
         one array descriptor instead of a dozen;
``kin``  the model's kinematics data, a NamedTuple whose *class* selects the contact frame at
         compile time (:mod:`stickslip.model.kinematics`);
``law``  the model's user friction law, a NamedTuple whose class selects its compiled function
         (:mod:`stickslip.model.friction`; :class:`~stickslip.model.friction.NoUserLaw` if none).

Layout of ``m`` (n DOFs, nc contacts). Block offsets follow from n alone (:func:`offsets`), so
that for kinematics classes that fix n the compiler folds them to constants:

========================  =========================================================================
header (``HEADER`` slots)  n, nc, diagonal flag (M, C, K all diagonal), low-speed band [m/s],
                           constant-kinematics flag (G, w independent of q), unilateral flag
                           (some contact has a gap instead of a prescribed load), rigid flag
                           (some unilateral contact has the rigid normal law)
M⁻¹ (n × n)                row-major; rows and columns of locked DOFs are 0
M (n × n)                  for the kinetic energy
C, K (n × n each)          damping, stiffness (K may be non-symmetric)
f0 (n)                     constant generalised force
free (n)                   1.0 for a free DOF, 0.0 for a locked one
contacts (nc blocks)       block width ``contact_width(n)``: dim (1 or 2), N0 [N], the friction law
                           row (:mod:`stickslip.model.friction`), the normal law (prescribed,
                           compliant, rigid), gap g0, normal stiffness k, damping c and
                           restitution e, the constant tangent rows G (2 × n), drive w (2),
                           normal force gradients n (n) and n_v (n), gap gradient W (n)
========================  =========================================================================
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from .friction import LAW_WIDTH, NoUserLaw
from .jit import formula

__all__ = ["ModelData", "pack", "offsets", "contact_offsets", "gap_offset", "contact_width", "contact_state",
           "CST", "HEADER", "H_N", "H_NC", "H_DIAGONAL", "H_BAND", "H_CONSTANT", "H_UNILATERAL", "H_RIGID", "C_DIM", "C_N0",
           "C_LAW", "C_NORMAL_LAW", "C_GAP", "C_NORMAL_K", "C_NORMAL_C", "C_RESTITUTION", "C_G",
           "NORMAL_PRESCRIBED", "NORMAL_COMPLIANT", "NORMAL_RIGID", "NORMAL_LAWS"]

H_N, H_NC, H_DIAGONAL, H_BAND, H_CONSTANT, H_UNILATERAL, H_RIGID = range(7)
HEADER = 8

#: Numbers per contact in the integration state ``cst``: mode, stored slip direction (ex, ey), and
#: the extrapolated time to v = 0 at the start of the last step of an approach (∞ otherwise).
CST = 4

C_DIM = 0
C_N0 = 1
C_LAW = 2
C_NORMAL_LAW = C_LAW + LAW_WIDTH  # NORMAL_PRESCRIBED, NORMAL_COMPLIANT or NORMAL_RIGID
C_GAP = C_NORMAL_LAW + 1          # g0 of g = g0 + W·q
C_NORMAL_K = C_GAP + 1            # compliant: contact stiffness k
C_NORMAL_C = C_NORMAL_K + 1       # compliant: contact damping c
C_RESTITUTION = C_NORMAL_C + 1    # rigid: Newton's restitution coefficient e
C_G = C_RESTITUTION + 1

#: Normal laws of a contact: a prescribed load N = N0 + n·q + n_v·q̇ (always pressed), a compliant
#: unilateral contact λ = max(0, −k g − c ġ) (g < 0), a rigid unilateral contact (g ≥ 0, λ ≥ 0, g λ = 0).
NORMAL_PRESCRIBED, NORMAL_COMPLIANT, NORMAL_RIGID = 0, 1, 2
NORMAL_LAWS = {"prescribed": NORMAL_PRESCRIBED, "compliant": NORMAL_COMPLIANT, "rigid": NORMAL_RIGID}


class ModelData(NamedTuple):
    """A model as the compiled kernels take it: flat numbers ``m``, kinematics data ``kin`` and the
    user friction law ``law``."""

    m: np.ndarray
    kin: Any
    law: Any = NoUserLaw()


@formula
def contact_width(n):
    """Numbers in one contact block of a model with n DOFs."""
    return C_G + 5 * n + 2


@formula
def offsets(n):
    """Offsets of (M⁻¹, M, C, K, f0, free, contact 0) in ``m`` for a model with n DOFs."""
    nn = n * n
    o_minv = HEADER
    o_force = HEADER + 4 * nn
    return o_minv, o_minv + nn, o_minv + 2 * nn, o_minv + 3 * nn, o_force, o_force + n, o_force + 2 * n


@formula
def gap_offset(n, c):
    """Offset of contact ``c``'s gap gradient W (n) in ``m``."""
    return contact_offsets(n, c)[3] + n


@formula
def contact_offsets(n, c):
    """(o, o_w, o_nq, o_nv): offsets of contact ``c``'s block, its drive w and its normal gradients."""
    o = HEADER + 4 * n * n + 2 * n + c * contact_width(n)
    ow = o + C_G + 2 * n
    return o, ow, ow + 2, ow + 2 + n


def pack(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray, force: np.ndarray, free: np.ndarray,
         contacts: list[dict], slip_band: float, constant_kinematics: bool) -> np.ndarray:
    """Build the data array ``m`` (layout in the module docstring).

    Parameters
    ----------
    mass, damping, stiffness : ndarray (n, n)
        M (symmetric positive definite on the free DOFs), C, K.
    force : ndarray (n,)
        Constant generalised force f0.
    free : ndarray (n,) of bool
        Free DOFs; locked ones get zero rows and columns in M⁻¹ (they never move).
    contacts : list of dict
        Per contact: ``dim`` (1 or 2), ``N0``, ``law_row`` (LAW_WIDTH,), and for constant kinematics
        ``G`` (dim, n), ``w`` (dim,), ``n_q`` (n,), ``n_v`` (n,) (zeros where absent); a unilateral
        contact also ``normal_law`` (a ``NORMAL_*`` code), ``gap`` g0, ``W`` (n,), ``k``, ``c``, ``e``.
    slip_band : float
        Low-speed band [m/s].
    constant_kinematics : bool
        Whether G and w are constant.
    """
    mass = np.asarray(mass, dtype=float)
    n = mass.shape[0]
    nc = len(contacts)
    free = np.asarray(free, dtype=bool)
    minv = np.zeros((n, n))
    idx = np.flatnonzero(free)
    minv[np.ix_(idx, idx)] = np.linalg.inv(mass[np.ix_(idx, idx)])
    mats = [minv, mass, np.asarray(damping, float), np.asarray(stiffness, float)]
    diagonal = all(np.count_nonzero(a - np.diag(np.diag(a))) == 0 for a in mats)
    cw = contact_width(n)
    m = np.zeros(HEADER + 4 * n * n + 2 * n + nc * cw)
    m[H_N] = n
    m[H_NC] = nc
    m[H_DIAGONAL] = 1.0 if diagonal else 0.0
    m[H_BAND] = slip_band
    m[H_CONSTANT] = 1.0 if constant_kinematics else 0.0
    m[H_UNILATERAL] = 1.0 if any(spec.get("normal_law", NORMAL_PRESCRIBED) != NORMAL_PRESCRIBED
                                 for spec in contacts) else 0.0
    m[H_RIGID] = 1.0 if any(spec.get("normal_law", NORMAL_PRESCRIBED) == NORMAL_RIGID for spec in contacts) else 0.0
    o_minv, o_mass, o_damp, o_stiff, o_force, o_free, _ = offsets(n)
    for o, a in zip((o_minv, o_mass, o_damp, o_stiff), mats):
        m[o:o + n * n] = a.ravel()
    m[o_force:o_force + n] = np.asarray(force, float)
    m[o_free:o_free + n] = free.astype(float)
    for c, spec in enumerate(contacts):
        o, ow, onq, onv = contact_offsets(n, c)
        dim = int(spec["dim"])
        m[o + C_DIM] = dim
        m[o + C_N0] = spec["N0"]
        m[o + C_LAW:o + C_LAW + LAW_WIDTH] = spec["law_row"]
        if "G" in spec:
            G = np.zeros((2, n))
            G[:dim] = np.asarray(spec["G"], float).reshape(dim, n)
            m[o + C_G:ow] = G.ravel()
            m[ow:ow + dim] = np.asarray(spec["w"], float).reshape(dim)
        m[onq:onv] = np.asarray(spec.get("n_q", np.zeros(n)), float)
        m[onv:onv + n] = np.asarray(spec.get("n_v", np.zeros(n)), float)
        m[o + C_NORMAL_LAW] = spec.get("normal_law", NORMAL_PRESCRIBED)
        m[o + C_GAP] = spec.get("gap", 0.0)
        m[o + C_NORMAL_K] = spec.get("k", 0.0)
        m[o + C_NORMAL_C] = spec.get("c", 0.0)
        m[o + C_RESTITUTION] = spec.get("e", 0.0)
        og = onv + n
        m[og:og + n] = np.asarray(spec.get("W", np.zeros(n)), float)
    return m


def contact_state(m: np.ndarray) -> np.ndarray:
    """A fresh per-contact integration state (CST nc,: mode, ex, ey, τ per contact), slipping along +x."""
    cst = np.zeros(CST * int(m[H_NC]))
    cst[1::CST] = 1.0
    cst[3::CST] = np.inf
    return cst
