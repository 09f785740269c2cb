"""Periodic orbits (shooting, Floquet multipliers) and Lyapunov exponents of stick-slip motion.

==========================  ==============================================================
``periodic_orbit``          Newton shooting on a Poincaré section → ``PeriodicOrbit``
``PeriodicOrbit``           state on the section, period, stick phases, Floquet multipliers
``Section``                 a Poincaré section (``"max"``, ``"<dof>_max"``, ``(dof, level)``)
``lyapunov_exponent``       largest Lyapunov exponent (Benettin) → ``LyapunovResult``
``lyapunov_spectrum``       all Lyapunov exponents (variational + saltation + QR) → ``LyapunovSpectrum``
``monodromy``               monodromy matrix of an orbit, saltation or FD → ``Monodromy``
``flow_jacobian``           linearised flow ∂Φ(s0, t)/∂s0 across transitions → ``FlowJacobian``
``OrbitError``              shooting or Lyapunov computation failed (message says why)
==========================  ==============================================================
"""

from .. import _startup
from ..errors import OrbitError

#: Public name → the module that defines it, imported on first use (:func:`stickslip._startup.export_on_first_use`).
_EXPORTS = {
    **dict.fromkeys(["FlowJacobian", "flow_jacobian"], ".linear_flow"),
    **dict.fromkeys(["LyapunovResult", "LyapunovSpectrum", "lyapunov_exponent", "lyapunov_spectrum"], ".lyapunov"),
    **dict.fromkeys(["Monodromy", "monodromy"], ".problem"),
    **dict.fromkeys(["Section", "resolve_section"], ".section"),
    **dict.fromkeys(["PeriodicOrbit", "periodic_orbit"], ".shooting"),
}

__all__ = ["periodic_orbit", "PeriodicOrbit", "Section", "resolve_section", "lyapunov_exponent",
           "LyapunovResult", "lyapunov_spectrum", "LyapunovSpectrum", "monodromy", "Monodromy",
           "flow_jacobian", "FlowJacobian", "OrbitError"]

_startup.export_on_first_use(__name__, _EXPORTS)
