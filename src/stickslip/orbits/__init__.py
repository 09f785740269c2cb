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

from ..errors import OrbitError
from .linear_flow import FlowJacobian, flow_jacobian
from .lyapunov import LyapunovResult, LyapunovSpectrum, lyapunov_exponent, lyapunov_spectrum
from .problem import Monodromy, monodromy
from .section import Section, resolve_section
from .shooting import PeriodicOrbit, periodic_orbit

__all__ = ["periodic_orbit", "PeriodicOrbit", "Section", "resolve_section", "lyapunov_exponent",
           "LyapunovResult", "lyapunov_spectrum", "LyapunovSpectrum", "monodromy", "Monodromy",
           "flow_jacobian", "FlowJacobian", "OrbitError"]
