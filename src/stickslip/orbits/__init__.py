"""Periodic orbits (shooting, Floquet multipliers) and Lyapunov exponents of stick-slip motion.

==========================  ==============================================================
``periodic_orbit``          Newton shooting on a Poincaré section → ``PeriodicOrbit``
``PeriodicOrbit``           state on the section, period, stick phases, Floquet multipliers
``Section``                 a Poincaré section (``"phi_max"``, ``("phi", level)``)
``lyapunov_exponent``       largest Lyapunov exponent (Benettin) → ``LyapunovResult``
``OrbitError``              shooting or Lyapunov computation failed (message says why)
==========================  ==============================================================
"""

from .lyapunov import LyapunovResult, lyapunov_exponent
from .section import OrbitError, Section, resolve_section
from .shooting import PeriodicOrbit, periodic_orbit

__all__ = ["periodic_orbit", "PeriodicOrbit", "Section", "resolve_section", "lyapunov_exponent",
           "LyapunovResult", "OrbitError"]
