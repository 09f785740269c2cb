"""Friction-contact models: the model interface, model files, the library, friction laws,
contact kinematics and the compiled physics written once for all of them."""

from .. import _startup
from ..errors import ModelError, ModelFileError, ParameterError

#: Public name → the module that defines it, imported on first use (:func:`stickslip._startup.export_on_first_use`).
_EXPORTS = {
    **dict.fromkeys(["FrictionLaw"], ".friction"),
    **dict.fromkeys(["ConstantKinematics", "register_kinematics"], ".kinematics"),
    **dict.fromkeys(["library", "load_model", "resolve_model", "two_plates"], ".library"),
    **dict.fromkeys(["load_model_file", "model_from_spec"], ".model_file"),
    **dict.fromkeys(["FRICTION_LAWS", "Parameters"], ".parameters"),
    **dict.fromkeys(["Contact", "FrictionModel"], ".system_model"),
    **dict.fromkeys(["DOF_NAMES", "MODELS", "STATE_NAMES", "Variant", "resolve_variant"], ".variants"),
}

__all__ = ["FrictionModel", "Contact", "FrictionLaw", "ModelError", "ModelFileError", "load_model", "load_model_file",
           "model_from_spec", "library", "resolve_model", "two_plates", "register_kinematics", "ConstantKinematics",
           "Parameters", "ParameterError", "FRICTION_LAWS",
           "Variant", "resolve_variant", "MODELS", "DOF_NAMES", "STATE_NAMES"]

_startup.export_on_first_use(__name__, _EXPORTS)
