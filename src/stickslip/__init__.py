"""stickslip: exact stick-slip simulation and analysis of friction-contact systems.

==========================  ==============================================================
``FrictionModel``           a friction-contact model (``Contact``, ``FrictionLaw``): every tool takes one
``load_model``              a library model by name (``belt``, ``hoffmann``, ...) or a model file (TOML)
``Parameters``              the two plates' parameters (paper Table 1), validated, TOML I/O
``two_plates``              the two plates as a model: ``two_plates(params, "rotation")`` (Models 1–4)
``simulate``                run a simulation, returns a ``Trajectory``
``attractor``               what a run settles to, honestly (``simulate_until_settled``: run until it does;
                            ``run_summary``: verdict, window and cost as one dict)
``basin_stability``         fractions of initial states reaching each attractor, with standard errors
``Trajectory``              typed result: samples, modes, forces, transitions, ``.to_xarray()``
``load_trajectory``         read a run written with ``Trajectory.to_netcdf``
``equilibrium``             steady-sliding equilibrium (Eq. 14)
``stability``               linear stability of steady sliding (Eq. 15), returns ``StabilityResult``
``stability_map``           (N, Ω) stability map with boundary by root finding (Figs. 3, 4)
``classify``                the signal's verdict on a window: equilibrium / periodic / unsettled, stick fraction
``OUTCOMES``                what a run settles to, the one vocabulary of runs, sweeps and basin studies
``find_peaks``              peaks of φ located as events (φ̇ = 0, φ̈ < 0)
``intensity``               intensity index I of Eq. (16)
``sweep``                   parameter grids → resumable NetCDF of reductions (serial, processes, dask)
``regions``                 bistability regions I/II/III (Fig. 8) and stick-slip domains (Fig. 9)
``periodic_orbit``          periodic orbit by shooting on a Poincaré section, Floquet multipliers
``monodromy``               monodromy matrix of an orbit (variational equations + saltation, or FD)
``flow_jacobian``           linearised flow ∂Φ(s0, t)/∂s0 across stick↔slip transitions
``lyapunov_exponent``       largest Lyapunov exponent (Benettin, across events)
``lyapunov_spectrum``       all Lyapunov exponents (variational equations + saltation + QR)
``continue_orbit``          pseudo-arclength continuation of periodic orbits in one parameter
``fold_curve``              end of the stick-slip branch (edge of Region II) over N
``MODELS``                  the paper's Models 1–4 as free DOFs
==========================  ==============================================================

Every function that runs a model takes it as one argument, ``model``: a ``FrictionModel``, a
library name or model file path, or the plates' ``Parameters`` (the plates in a variant:
``two_plates(params, "rotation")``).

Every public name is imported on first use (PEP 562): ``import stickslip`` loads neither numpy
nor numba, so that the command line's ``--version`` and ``--help`` answer at once.
"""

from . import _startup  # first: Ctrl-C held during the import; NUMBA_NUM_THREADS made valid before numba loads

_startup.hold()

#: Public names imported on first access, by the module that defines them.
_LAZY = {
    **dict.fromkeys(["OUTCOMES", "Classification", "classify", "find_peaks", "intensity"], ".analysis"),
    **dict.fromkeys(["simulate"], ".integrate.driver"),
    **dict.fromkeys(["Trajectory", "load_trajectory"], ".integrate.result"),
    **dict.fromkeys(["Parameters"], ".model.parameters"),
    **dict.fromkeys(["DOF_NAMES", "MODELS", "STATE_NAMES"], ".model.variants"),
    **dict.fromkeys(["FrictionModel", "Contact", "FrictionLaw", "ModelError", "load_model", "two_plates"], ".model"),
    **dict.fromkeys(["basin_stability", "BasinResult"], ".basins"),
    **dict.fromkeys(["attractor", "simulate_until_settled", "Attractor", "SettledRun", "run_summary"], ".attractors"),
    **dict.fromkeys(["StabilityMap", "StabilityResult", "load_stability_map", "stability", "stability_map"],
                    ".stability"),
    **dict.fromkeys(["EquilibriumError", "equilibrium"], ".stability.equilibrium"),
    **dict.fromkeys(["RegionMap", "SweepError", "SweepResult", "load_region_map", "load_sweep", "regions", "sweep"],
                    ".sweep"),
    **dict.fromkeys(["LyapunovResult", "LyapunovSpectrum", "OrbitError", "PeriodicOrbit", "Monodromy",
                     "FlowJacobian", "flow_jacobian", "lyapunov_exponent", "lyapunov_spectrum", "monodromy",
                     "periodic_orbit"], ".orbits"),
    **dict.fromkeys(["Branch", "ContinuationError", "FoldCurve", "SpecialPoint", "continue_orbit", "fold_curve",
                     "load_branch", "unstable_cycle"], ".orbits.continuation"),
}


# public functions named like a subpackage (``stickslip.stability``, ``stickslip.sweep``) stay the
# functions when the subpackage is imported; before the imports below
_startup.export_on_first_use(__name__, _LAZY)

from ._version import __version__  # noqa: E402
from .errors import FileFormatError, ParameterError, SimulationError, StickSlipError, VariantError  # noqa: E402
from .results import Plottable  # noqa: E402


def _draw(result, **kwargs):
    """A result's figure (:meth:`stickslip.results.Plottable.plot`): the plot layer, and matplotlib
    with it, is imported only when a figure is asked for."""
    from .plot import figure

    return figure(result, **kwargs)


Plottable.draw = staticmethod(_draw)

_startup.release()  # a Ctrl-C held during the import is raised here


__all__ = [
    "__version__", "StickSlipError",
    "FrictionModel", "Contact", "FrictionLaw", "ModelError", "load_model", "two_plates",
    "basin_stability", "BasinResult", "attractor", "simulate_until_settled", "Attractor", "SettledRun", "run_summary",
    "Parameters", "ParameterError",
    "simulate", "SimulationError",
    "Trajectory", "load_trajectory", "FileFormatError",
    "equilibrium", "EquilibriumError",
    "stability", "StabilityResult", "stability_map", "StabilityMap", "load_stability_map",
    "classify", "Classification", "find_peaks", "intensity", "OUTCOMES",
    "sweep", "SweepResult", "SweepError", "load_sweep", "regions", "RegionMap", "load_region_map",
    "periodic_orbit", "PeriodicOrbit", "monodromy", "Monodromy", "flow_jacobian", "FlowJacobian", "OrbitError",
    "lyapunov_exponent", "LyapunovResult", "lyapunov_spectrum", "LyapunovSpectrum",
    "continue_orbit", "Branch", "SpecialPoint", "fold_curve", "FoldCurve", "unstable_cycle", "load_branch",
    "ContinuationError",
    "MODELS", "DOF_NAMES", "STATE_NAMES", "VariantError",
]
