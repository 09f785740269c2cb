"""stickslip: exact 2-D stick-slip simulation of two rigid plates in point frictional contact.

==========================  ==============================================================
``Parameters``              physical parameters (paper Table 1), validated, TOML I/O
``simulate``                run a simulation, returns a ``Trajectory``
``Trajectory``              typed result: samples, modes, forces, transitions, ``.to_xarray()``
``load_trajectory``         read a run written with ``Trajectory.to_netcdf``
``equilibrium``             steady-sliding equilibrium (Eq. 14)
``stability``               linear stability of steady sliding (Eq. 15), returns ``StabilityResult``
``stability_map``           (N, Ω) stability map with boundary by root finding (Figs. 3, 4)
``classify``                steady state: equilibrium / periodic slip / periodic stick-slip / not periodic
``find_peaks``              peaks of φ located as events (φ̇ = 0, φ̈ < 0)
``intensity``               intensity index I of Eq. (16)
``sweep``                   parameter grids → resumable NetCDF of reductions (serial, processes, dask)
``regions``                 bistability regions I/II/III (Fig. 8) and stick-slip domains (Fig. 9)
``periodic_orbit``          periodic orbit by shooting on a Poincaré section, Floquet multipliers
``lyapunov_exponent``       largest Lyapunov exponent (Benettin, across events)
``MODELS``                  the paper's Models 1–4 as free DOFs
==========================  ==============================================================
"""

__version__ = "0.1.0"

from .analysis import Classification, classify, find_peaks, intensity
from .integrate.driver import SimulationError, simulate
from .integrate.result import FileFormatError, Trajectory, load_trajectory
from .model.parameters import ParameterError, Parameters
from .model.variants import DOF_NAMES, MODELS, STATE_NAMES, VariantError
from .orbits import LyapunovResult, OrbitError, PeriodicOrbit, lyapunov_exponent, periodic_orbit
from .stability import StabilityMap, StabilityResult, load_stability_map, stability, stability_map
from .stability.equilibrium import EquilibriumError, equilibrium
from .sweep import RegionMap, SweepError, SweepResult, load_region_map, load_sweep, regions, sweep

__all__ = [
    "__version__",
    "Parameters", "ParameterError",
    "simulate", "SimulationError",
    "Trajectory", "load_trajectory", "FileFormatError",
    "equilibrium", "EquilibriumError",
    "stability", "StabilityResult", "stability_map", "StabilityMap", "load_stability_map",
    "classify", "Classification", "find_peaks", "intensity",
    "sweep", "SweepResult", "SweepError", "load_sweep", "regions", "RegionMap", "load_region_map",
    "periodic_orbit", "PeriodicOrbit", "lyapunov_exponent", "LyapunovResult", "OrbitError",
    "MODELS", "DOF_NAMES", "STATE_NAMES", "VariantError",
]
