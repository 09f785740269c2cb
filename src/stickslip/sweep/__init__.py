"""Parameter sweeps: any grid over parameters, models and initial conditions → ``xarray.Dataset``
of reductions (peaks, classification, frequency, intensity, stick fraction), streamed to disk,
resumable, on serial, process-pool or dask executors; bistability regions (Figs. 8, 9)."""

from ..errors import SweepError
from ..parallel import EXECUTORS
from .bistability import RegionMap, load_region_map, regions
from .engine import SweepResult, sweep
from .spec import NAMED_ICS, SweepSpec
from .store import load_sweep

__all__ = ["sweep", "SweepResult", "SweepSpec", "SweepError", "load_sweep", "EXECUTORS", "NAMED_ICS",
           "regions", "RegionMap", "load_region_map"]
