"""The model library: friction-contact models by name, and model files by path.

========================  ==========================================================================
``two-plates``            the paper's two rigid plates (default; :mod:`.two_plates`)
``belt``                  1-DOF mass on a moving belt, the bSTAB friction case (``belt.toml``)
``clearance-oscillator``  the belt with a frictionless stop at a clearance (``clearance_oscillator.toml``)
``hoffmann``              2-DOF mode-coupling (flutter) model (``hoffmann.toml``)
``impact-oscillator``     mass bouncing on a rigid moving stop (``impact_oscillator.toml``)
``popp-stelter``          two masses on one belt, two contacts (``popp_stelter.toml``)
``slider-belt``           2-DOF slider on a belt, contact opens and closes (``slider_belt.toml``)
``sprag-slip``            tilted beam on a belt: no steady sliding above μ* (``sprag_slip.toml``)
========================  ==========================================================================

Library models stated as model files live beside this module as TOML; ``stickslip models``
lists them (:mod:`stickslip.model.catalog`: names and descriptions, read without building a
model). :func:`load_model` accepts a library name or the path of a model file.
"""

from __future__ import annotations

from pathlib import Path

from ...errors import ModelError
from ..catalog import LIBRARY_FOLDER, TWO_PLATES, library, library_names
from ..model_file import load_model_file, model_from_spec
from ..parameters import Parameters
from ..system_model import DEFAULT_SLIP_BAND, FrictionModel
from ..variants import MODELS
from .two_plates import two_plates

__all__ = ["load_model", "library", "library_names", "two_plates", "TWO_PLATES", "describe_system", "system_from_description",
           "resolve_model", "plates_variant"]

#: This package's folder, where its model files live.
HERE = LIBRARY_FOLDER

def load_model(name: str | Path | FrictionModel = TWO_PLATES) -> FrictionModel:
    """A library model by name (``two-plates``, ``belt``, ...), a variant of the plates by name, or
    a model file by path.

    Parameters
    ----------
    name : str, Path or FrictionModel
        A library name (``stickslip models`` lists them: ``two-plates``, ``belt``, ``clearance-oscillator``,
        ``hoffmann``, ``impact-oscillator``, ``popp-stelter``, ``slider-belt``, ``sprag-slip``), a variant of
        the two plates with Table 1
        parameters (``full``, ``x``, ``y``, ``rotation``, :func:`plates_variant`), the path of a
        model file (``.toml``), or a model, returned as it is. Default: the two plates with Table 1
        parameters.

    Returns
    -------
    FrictionModel

    Raises
    ------
    ModelError
        On an unknown name, naming the library's models; on a model file that does not hold a
        valid model, naming the key and the fix.
    """
    if isinstance(name, FrictionModel):
        return name
    text = str(name)
    variant = plates_variant(text) if not isinstance(name, Path) else None
    if variant is not None:
        return two_plates(None, variant)
    path = HERE / (text.replace("-", "_") + ".toml")
    if "/" not in text and not text.endswith(".toml") and path.is_file():
        return load_model_file(path, source=f"library:{text}")
    if text.endswith(".toml") or Path(text).exists() or Path(text).is_symlink():
        return load_model_file(text)  # refuses what is not a regular file (a folder, a pipe, a device)
    raise ModelError(f"unknown model {text!r}; choose one of {', '.join(library())}, a plates variant "
                     f"({', '.join(MODELS)}) or a model file (.toml)")


def resolve_model(model=None, slip_band: float | None = None) -> FrictionModel:
    """The model a simulation or analysis runs on: what every public function's ``model`` names.

    Parameters
    ----------
    model : FrictionModel, Parameters, str, Path or None
        A model (the plates in a variant: ``two_plates(params, "rotation")``); the plates'
        :class:`Parameters` (all six DOFs free); a library name, a variant of the plates with
        Table 1 parameters or a model file path (:func:`load_model`, as ``--model`` takes it);
        None for the plates with Table 1 parameters.
    slip_band : float, optional
        Low-speed band [m/s]; default the model's own.

    Raises
    ------
    ModelError
        For anything else, or an unknown name (naming the choices).
    """
    variant = plates_variant(model) if isinstance(model, str) else None
    if model is None or isinstance(model, Parameters) or variant is not None:  # the band also in the plates' builder
        params = model if isinstance(model, Parameters) else None
        system = two_plates(params, variant or "full", DEFAULT_SLIP_BAND if slip_band is None else slip_band)
    elif isinstance(model, (FrictionModel, str, Path)):
        system = load_model(model)
    else:
        raise ModelError(f"expected a model: a FrictionModel, the plates' Parameters, a library name or a model file; "
                         f"got {type(model).__name__} (the plates in a variant: two_plates(params, 'rotation'))")
    return system if slip_band is None else system.with_slip_band(slip_band)


def plates_variant(text: str) -> str | None:
    """The plates' variant that ``text`` names (``full``, ``x``, ``y``, ``rotation``, DOF names, or
    ``two-plates`` for ``full``), or None when it names another model (library name or file)."""
    text = text.strip()
    if text == TWO_PLATES:
        return "full"
    if text in MODELS or text.removeprefix("custom:").split(",")[0].strip() in ("x1", "y1", "x2", "y2", "phi", "psi"):
        return text
    return None


def describe_system(system: FrictionModel) -> dict:
    """What :func:`system_from_description` needs to rebuild ``system`` (JSON-ready)."""
    out = {"name": system.name, "source": system.source, "parameters": dict(system.parameters),
           "slip_band": system.slip_band, "dofs": list(system.dofs)}
    if system.spec is not None:
        out["spec"] = system.spec
    return out


def system_from_description(desc: dict) -> FrictionModel:
    """Rebuild a model written into a result file (:func:`describe_system`)."""
    slip_band = float(desc.get("slip_band", DEFAULT_SLIP_BAND))
    if desc.get("name") == TWO_PLATES:
        values = dict(desc["parameters"])
        variant = values.pop("variant", "full")
        return two_plates(Parameters.from_dict(values), variant, slip_band)
    if "spec" in desc:
        return model_from_spec(desc["spec"], source=desc.get("source", "python"), name=desc["name"]).with_slip_band(slip_band)
    raise ModelError(f"the file's model {desc.get('name')!r} was defined in Python and cannot be rebuilt from the "
                     "file; pass it as model= when loading")
