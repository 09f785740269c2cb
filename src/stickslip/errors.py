"""Every error of stickslip whose message tells the user what to change.

Every error that is the user's to fix (bad input, a file that is not ours, an option out of
range, a computation that cannot be done for the given model) derives from
:class:`StickSlipError`. The command line maps this one base to a single line on stderr and
exit code 2; anything else is a bug and keeps its traceback. Subclasses also derive from the
builtin they refine (``ValueError``, ``RuntimeError``, ``TypeError``), so ``except ValueError``
keeps working. They live here, below every layer, so that any module can raise or catch any of
them without importing the module that raises it.

=======================  ======================================================================
``ModelError``           a model that cannot be built as stated (``ModelFileError``: a model file)
``ExpressionError``      an expression of named parameters that cannot be parsed or evaluated
``ParameterError``       a parameter of the two plates that cannot describe them
``FrictionLawError``     an unknown or invalid friction law
``VariantError``         an unknown variant (set of free DOFs) of the two plates
``KinematicsError``      a kinematics object whose class was not registered
``EquilibriumError``     no steady sliding found
``SimulationError``      invalid simulation options, or a run that could not finish
``OrbitError``           a periodic orbit or Lyapunov exponent that could not be computed
                         (``SteadySlidingOrbitError``: shooting that converged onto steady
                         sliding; ``ContinuationError``: a branch that could not start or go on;
                         ``SteadySlidingError``: one whose start is steady sliding)
``SweepError``           an invalid sweep, or an output of another sweep
``WorkersError``         a worker count outside 1 … the CPUs available
``SchedulerError``       a dask scheduler that is malformed or unreachable
``BasinError``           an invalid basin-stability study
``FileFormatError``      a file that is not a stickslip result of a readable format
``LockError``            another process writes the same output
``WriteError``           a file that could not be written (``DiskFullError``: a full disk or file size limit)
``OutputError``          an output that must not be written (exists, a folder, an input)
``JournalError``         a journal of other settings, corrupt, or of an earlier format
``MemoryLimitError``     work whose estimated memory exceeds what is available (``stickslip.memory``)
=======================  ======================================================================
"""

from __future__ import annotations

__all__ = ["StickSlipError", "ModelError", "ModelFileError", "ParameterError", "FrictionLawError", "VariantError",
           "KinematicsError", "ExpressionError", "EquilibriumError", "SimulationError", "OrbitError",
           "SteadySlidingOrbitError", "ContinuationError", "SteadySlidingError", "SweepError",
           "WorkersError", "SchedulerError", "BasinError", "FileFormatError", "LockError", "WriteError", "DiskFullError",
           "OutputError", "JournalError", "MemoryLimitError"]


class StickSlipError(Exception):
    """Base of every stickslip error whose message tells the user what to change."""


class ModelError(StickSlipError, ValueError):
    """A model that cannot be built as stated (the message names the entry and the fix)."""


class ModelFileError(ModelError):
    """A model file that cannot be read as a model (the message names the key and the fix)."""


class ExpressionError(StickSlipError, ValueError):
    """An expression of a model file that cannot be parsed or evaluated (the message says why,
    without the key: the model file adds it)."""


class ParameterError(StickSlipError, ValueError):
    """A parameter value or file that cannot describe the physical model."""


class FrictionLawError(StickSlipError, ValueError):
    """A friction law that cannot be used (unknown name, negative coefficient, ...)."""


class VariantError(StickSlipError, ValueError):
    """An unknown model name or DOF."""


class KinematicsError(StickSlipError, TypeError):
    """A kinematics object whose class was not registered."""


class EquilibriumError(StickSlipError, RuntimeError):
    """No steady-sliding equilibrium could be found."""


class SimulationError(StickSlipError, ValueError):
    """Invalid simulation options, or a run that could not finish."""


class OrbitError(StickSlipError, RuntimeError):
    """A periodic orbit or Lyapunov exponent could not be computed (the message says why)."""


class SteadySlidingOrbitError(OrbitError):
    """Shooting converged onto steady sliding (the equilibrium solves the shooting equations for
    any period), not a cycle."""


class ContinuationError(OrbitError):
    """Continuation could not start or go on (the message says why)."""


class SteadySlidingError(ContinuationError):
    """The start orbit of a continuation is steady sliding (the equilibrium solves the shooting
    equations for any period), not a cycle. ``param`` and ``value``: where."""

    def __init__(self, param: str, value: float):
        self.param, self.value = param, float(value)
        super().__init__(f"converged to steady sliding at {param} = {value:.6g}: the start is the equilibrium, "
                         "not a cycle; start from a state on the cycle (or a run that ends on it)")

    def __reduce__(self):
        return type(self), (self.param, self.value)


class SweepError(StickSlipError, ValueError):
    """An invalid sweep definition, or an output that belongs to another sweep."""


class WorkersError(SweepError):
    """More worker processes than CPUs, or fewer than one."""


class SchedulerError(SweepError):
    """The dask scheduler address is malformed or cannot be reached."""


class BasinError(StickSlipError, ValueError):
    """An invalid basin-stability study (states, options), or an output of another study."""


class FileFormatError(StickSlipError, ValueError):
    """A file that is not a stickslip result: missing, foreign, truncated or of another version."""


class LockError(StickSlipError, RuntimeError):
    """Another process is writing the same output."""


class WriteError(StickSlipError, RuntimeError):
    """A file could not be written: the disk or the file size limit is full, or its folder takes no files."""


class DiskFullError(WriteError):
    """The disk, a quota or the file size limit is full."""


class OutputError(StickSlipError, ValueError):
    """An output that must not be written: an existing file without overwrite, a folder, or an input."""


class JournalError(StickSlipError, ValueError):
    """A journal that cannot be resumed: of other settings or kind, of an earlier format, or corrupt."""


class MemoryLimitError(StickSlipError, MemoryError):
    """Work refused before it allocates: its estimated memory exceeds what is available (the
    message gives the estimate and a setting that fits)."""
