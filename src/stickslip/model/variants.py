"""Model variants as locked degrees of freedom (paper Sect. 4.2.3, Models 1–4).

A locked DOF gets zero inverse mass and a zero state, so the same kernels serve every variant.
Besides the paper's four, any subset of DOFs may be freed, e.g. ``("phi",)``:
the upper plate rotating against a rigidly driven lower plate, the 1-DOF belt oscillator.
"""

from __future__ import annotations

import dataclasses
from typing import Iterable

import numpy as np

from ..errors import VariantError

__all__ = ["DOF_NAMES", "STATE_NAMES", "Variant", "MODELS", "resolve_variant"]

#: Generalised coordinates q, in this order everywhere.
DOF_NAMES = ("x1", "y1", "x2", "y2", "phi", "psi")
#: The 12 states s = [q, dq/dt].
STATE_NAMES = DOF_NAMES + tuple("d" + n for n in DOF_NAMES)

#: Paper Models 1–4 by name: the free DOFs of each.
MODELS: dict[str, tuple[str, ...]] = {
    "full": DOF_NAMES,                       # Model 1: all six DOF
    "x": ("x1", "x2", "phi", "psi"),          # Model 2: translation along x only
    "y": ("y1", "y2", "phi", "psi"),          # Model 3: translation along y only
    "rotation": ("phi", "psi"),              # Model 4: the reduced model, rotation only
}


@dataclasses.dataclass(frozen=True)
class Variant:
    """A set of free DOFs.

    Attributes
    ----------
    name : str
        ``full``, ``x``, ``y``, ``rotation`` or ``custom:<dofs>``.
    free : tuple of str
        Names of the free DOFs, in :data:`DOF_NAMES` order.
    """

    name: str
    free: tuple[str, ...]

    @property
    def mask(self) -> np.ndarray:
        """Boolean array (6,), True where the DOF is free."""
        return np.array([n in self.free for n in DOF_NAMES])

    @property
    def free_indices(self) -> np.ndarray:
        """Indices of the free DOFs in q (6,)."""
        return np.flatnonzero(self.mask)


def resolve_variant(model: "str | Iterable[str] | Variant") -> Variant:
    """Turn a model name or an iterable of DOF names into a :class:`Variant`.

    Parameters
    ----------
    model : str, iterable of str or Variant
        ``"full"`` (Model 1), ``"x"`` (Model 2), ``"y"`` (Model 3), ``"rotation"`` (Model 4),
        a comma-separated list of DOF names such as ``"phi,psi"``, or an iterable of them.
    """
    if isinstance(model, Variant):
        return model
    if isinstance(model, str):
        model = model.removeprefix("custom:")
        if model in MODELS:
            return Variant(model, MODELS[model])
        names = [n.strip() for n in model.split(",") if n.strip()]
    else:
        names = list(model)
    unknown = [n for n in names if n not in DOF_NAMES]
    if unknown or not names:
        raise VariantError(
            f"unknown model {model!r}; use one of {', '.join(MODELS)} "
            f"or a comma-separated list of DOFs from {', '.join(DOF_NAMES)}"
        )
    free = tuple(n for n in DOF_NAMES if n in names)
    for key, dofs in MODELS.items():
        if dofs == free:
            return Variant(key, free)
    return Variant("custom:" + ",".join(free), free)
