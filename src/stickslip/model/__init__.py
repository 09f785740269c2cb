"""Friction-contact models: the model interface, model files, the library, friction laws,
contact kinematics and the compiled physics written once for all of them."""

from ..errors import ModelError, ModelFileError, ParameterError
from .friction import FrictionLaw
from .kinematics import ConstantKinematics, register_kinematics
from .library import library, load_model, resolve_model, two_plates
from .model_file import load_model_file, model_from_spec
from .parameters import FRICTION_LAWS, Parameters
from .system_model import Contact, FrictionModel
from .variants import DOF_NAMES, MODELS, STATE_NAMES, Variant, resolve_variant

__all__ = ["FrictionModel", "Contact", "FrictionLaw", "ModelError", "ModelFileError", "load_model", "load_model_file",
           "model_from_spec", "library", "resolve_model", "two_plates", "register_kinematics", "ConstantKinematics",
           "Parameters", "ParameterError", "FRICTION_LAWS",
           "Variant", "resolve_variant", "MODELS", "DOF_NAMES", "STATE_NAMES"]
