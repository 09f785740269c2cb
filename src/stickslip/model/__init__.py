"""The two-plate model: parameters, variants (locked DOFs), friction laws, compiled kernels."""

from .parameters import FRICTION_LAWS, ParameterError, Parameters
from .system import System, assemble
from .variants import DOF_NAMES, MODELS, STATE_NAMES, Variant, resolve_variant

__all__ = ["Parameters", "ParameterError", "FRICTION_LAWS", "System", "assemble",
           "Variant", "resolve_variant", "MODELS", "DOF_NAMES", "STATE_NAMES"]
