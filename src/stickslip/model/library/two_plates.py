"""The two plates of the paper as a :class:`~stickslip.model.FrictionModel` (paper Eqs. 1–9).

q = [x1, y1, x2, y2, φ, ψ]: the upper plate's centre (x1, y1) and rotation φ, the lower plate's
centre (x2, y2) and rotation ψ relative to its drive Ω t. M, C and K are diagonal (Table 1);
the one 2-D contact has the kinematics of :mod:`.plate_kinematics`; the normal force is the
preload N; the friction law is Eq. (4) (or Coulomb). The paper's Models 1–4 free subsets of the
DOFs (:mod:`stickslip.model.variants`): a locked DOF gets zero inverse mass and never moves.
"""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from ..catalog import TWO_PLATES as NAME
from ..catalog import TWO_PLATES_DESCRIPTION
from ..friction import FrictionLaw
from ..parameters import PARAMETER_UNITS, Parameters
from ..system_model import DEFAULT_SLIP_BAND, Contact, FrictionModel, NamedState
from ..variants import DOF_NAMES, resolve_variant
from .plate_kinematics import PlateKinematics

__all__ = ["two_plates", "NAME", "is_plates", "plates_parameters"]

_UNITS = {"x1": "m", "y1": "m", "x2": "m", "y2": "m", "phi": "rad", "psi": "rad", **PARAMETER_UNITS}


def two_plates(params: Parameters | None = None, variant="full", slip_band: float = DEFAULT_SLIP_BAND) -> FrictionModel:
    """The two plates as a model: what every function's ``model`` takes for the plates in a variant.

    Parameters
    ----------
    params : Parameters, optional
        The plates' parameters (default Table 1 at N = 50 N, Ω = 5 rad/s).
    variant : str, iterable of DOF names or Variant
        The free DOFs: ``full`` (Model 1, default), ``x`` (2), ``y`` (3), ``rotation`` (4), or the
        DOFs to free (``"phi"``: the upper plate's rotation alone, the belt case).
    slip_band : float
        Low-speed band of the 2-D slip direction [m/s].

    Returns
    -------
    FrictionModel
    """
    P = Parameters() if params is None else params
    v = resolve_variant(variant)
    mass = np.diag([P.m_p, P.m_p, P.m_d, P.m_d, P.J_p, P.J_d])
    damping = np.diag([P.c_px, P.c_py, P.c_dx, P.c_dy, P.c_pphi, P.c_dpsi])
    stiffness = np.diag([P.k_px, P.k_py, P.k_dx, P.k_dy, P.k_pphi, P.k_dpsi])
    law = FrictionLaw(P.friction_law, P.mu_k, P.delta_mu, P.alpha)
    contact = Contact(dim=2, friction=law, normal_force=P.N, name="plates")

    far = np.zeros(12)
    if v.mask[DOF_NAMES.index("y1")]:
        # q = 0: X = r, Y = 0 and v_r = (ẋ1 − ẋ2, ẏ1 − ẏ2 + r φ̇ − Ω r) (Eq. 9) vanishes for ẏ1 = Ω r
        far[6 + DOF_NAMES.index("y1")] = P.Omega * P.r
    else:
        far[6 + DOF_NAMES.index("phi")] = P.Omega
    starts = {"far": NamedState(far, "q = 0 with the upper plate carried along by the lower plate's surface "
                                     "(v_r = 0 at t = 0): ẏ1 = Ω r when y1 is free, else φ̇ = Ω")}

    def builder(values: Mapping[str, Any]) -> FrictionModel:
        values = dict(values)
        var = values.pop("variant", v.name)
        return two_plates(Parameters.from_dict(values), var, slip_band)

    return FrictionModel(
        name=NAME, dofs=DOF_NAMES, mass=mass, damping=damping * v.mask, stiffness=stiffness * v.mask,
        force=np.zeros(6), contacts=(contact,), kinematics=PlateKinematics(P.r, P.Omega), free=v.mask,
        parameters={**P.to_dict(), "variant": v.name}, builder=builder, source=f"library:{NAME}",
        units=_UNITS, slip_band=slip_band, observed="phi", starts=starts, label=v.name, headline=("N", "Omega"),
        steady_hint=_steady_hint, description=TWO_PLATES_DESCRIPTION,
    )


def is_plates(model: FrictionModel) -> bool:
    """Whether ``model`` is the two plates (any variant, any parameters)."""
    return model.name == NAME


def plates_parameters(model: FrictionModel) -> Parameters | None:
    """The plates' :class:`~stickslip.model.parameters.Parameters` of ``model`` (None for other models)."""
    if not is_plates(model):
        return None
    values = dict(model.parameters)
    values.pop("variant", None)
    return Parameters.from_dict(values)


def _steady_hint(model: FrictionModel, q) -> str:
    """Why steady sliding may not exist near ``q`` (Eq. 14): the friction load drags the contact
    point onto the centre of the lower plate, where the branch of equilibria folds."""
    r = model.parameters["r"]
    if not all(math.isfinite(x) for x in q):
        return ""
    R = math.hypot(q[0] - q[2] + r * math.cos(q[4]), q[1] - q[3] + r * math.sin(q[4]))
    if R >= 0.5 * r:
        return ""
    return (f"the iterate has the contact point at R = {R:.3g} m from the centre O2 (r = {r:g} m): the friction "
            "load mu N drags the contact point onto the centre of the lower plate and steady sliding does not exist "
            "beyond that load (a fold of Eq. 14); reduce N or mu")
