"""What a basin-stability study computes: the model, the parameter values, the states and the options.

:class:`BasinSpec` is plain data with a digest of everything that determines the results, so
that a study killed and started again with the same arguments resumes its own journal and a
different study on the same output is refused.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from typing import Sequence

import numpy as np

from ..errors import BasinError
from .context import model_key
from .early import Options, row_width
from .states import MAX_STATES, StateSpec, split_fields

__all__ = ["BasinSpec", "build_spec", "parse_param"]


@dataclasses.dataclass(frozen=True)
class BasinSpec:
    """A basin-stability study.

    Attributes
    ----------
    model_key : str
        The base model's description (JSON, :func:`.context.model_key`).
    n_dofs : int
        Its number of coordinates n (states have 2n entries).
    state_names : tuple of str
    param : str or None
        The ``--set`` path varied (``contact.0.drive``, ``N``), or None for one model.
    values : tuple of float
        The parameter's values (empty without ``param``).
    states : StateSpec
    options : Options
    """

    model_key: str
    n_dofs: int
    state_names: tuple
    param: str | None
    values: tuple
    states: StateSpec
    options: Options

    @property
    def n_params(self) -> int:
        """Number of models (parameter values; 1 without a parameter)."""
        return max(len(self.values), 1)

    @property
    def n_states(self) -> int:
        """Initial states per model."""
        return self.states.size

    @property
    def size(self) -> int:
        """States to classify in all: n_params × n_states (flat index p · n_states + i)."""
        return self.n_params * self.n_states

    @property
    def row_width(self) -> int:
        return row_width(self.n_dofs)

    def to_json(self) -> str:
        """Everything that determines the results, as JSON."""
        return json.dumps({"model": json.loads(self.model_key), "param": self.param, "values": list(self.values),
                           "states": json.loads(self.states.to_json()), "options": dataclasses.asdict(self.options)},
                          sort_keys=True)

    @property
    def digest(self) -> str:
        """SHA-256 of :meth:`to_json` (with the format's major version)."""
        return hashlib.sha256(("basins-1:" + self.to_json()).encode()).hexdigest()


def parse_param(text: str) -> tuple[str, list[float]]:
    """``"contact.0.drive=0.8:2:13"`` → (path, 13 values from 0.8 to 2 inclusive).

    Raises
    ------
    BasinError
        One line naming the fix.
    """
    example = "--param contact.0.drive=0.8:2:13"
    name, parts = split_fields(text, "--param", "PATH=LO:HI:K", "give PATH=LO:HI:K (K values from LO to HI)", 3,
                               example)
    try:
        lo, hi, k = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise BasinError(f"--param {text}: LO and HI must be numbers and K an integer; e.g. {example}") from None
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise BasinError(f"--param {text}: LO and HI must be finite numbers")
    if lo >= hi:
        raise BasinError(f"--param {text}: LO must be < HI")
    if not 2 <= k <= MAX_STATES:
        raise BasinError(f"--param {text}: K must be 2 … {MAX_STATES} values")
    return name, np.linspace(lo, hi, k).tolist()


def _check_options(options: Options) -> None:
    for name in ("t_end", "rtol", "atol", "match_rtol"):
        value = getattr(options, name)
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise BasinError(f"{name.replace('_', '-')} = {value!r} must be a finite number > 0")
    if not 1e-13 <= options.rtol <= 0.1:
        raise BasinError(f"rtol = {options.rtol} is outside [1e-13, 0.1]; give a value in range")
    if options.match_rtol >= 1.0:
        raise BasinError(f"match-rtol = {options.match_rtol} must be < 1 (a fraction of the amplitude and period)")
    if int(options.max_steps) < 1:
        raise BasinError(f"max-steps = {options.max_steps} must be >= 1")


def build_spec(model, states: StateSpec, *, param: str | None = None, values: Sequence[float] = (),
               options: Options | None = None, key: str | None = None) -> BasinSpec:
    """A checked :class:`BasinSpec` (``values`` empty without ``param``)."""
    options = options or Options()
    _check_options(options)
    values = tuple(float(v) for v in values)
    if (param is None) != (not values):
        raise BasinError("give a parameter path together with its values (--param PATH=LO:HI:K)")
    if any(not math.isfinite(v) for v in values):
        raise BasinError(f"--param {param}: values must be finite numbers")
    return BasinSpec(key or model_key(model), model.n, tuple(model.state_names), param, values, states, options)
