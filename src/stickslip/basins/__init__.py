"""Basin stability with exact stick: which attractor each initial state reaches, and how often.

>>> from stickslip.basins import basin_stability, box
>>> from stickslip.model.library import load_model
>>> belt = load_model("belt")
>>> res = basin_stability(belt, box(belt, {"x": (-2, 2), "dx": (-2, 2)}, n=1000), t_end=500)
>>> res.fractions, res.standard_errors, res.attractors()

Layers: :mod:`.states` (the initial states), :mod:`.context` (per model: steady sliding, its
stability, the linear flow), :mod:`.cycles` (phase-independent features and matching),
:mod:`.early` (one state, integrated in chunks until its attractor is known), :mod:`.spec`,
:mod:`.store` (journal and NetCDF), :mod:`.result` (labels, attractor table, fractions) and
:mod:`.engine` (batches on an executor). ``docs/basins.md`` describes the method.
"""

from ..errors import BasinError
from .early import DECIDED, Options
from .engine import basin_stability, load_result
from .result import BasinResult
from .spec import parse_param
from .states import StateSpec, box, from_csv, grid, parse_range
from .store import load_basins

__all__ = ["basin_stability", "load_result", "load_basins", "BasinResult", "BasinError", "StateSpec", "box", "grid",
           "from_csv", "parse_range", "parse_param", "Options", "DECIDED"]
