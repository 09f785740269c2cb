"""Parameter sweeps: any grid over parameters, models and initial conditions → ``xarray.Dataset``
of reductions (peaks, classification, frequency, intensity, stick fraction), streamed to disk,
resumable, on serial, process-pool or dask executors; bistability regions (Figs. 8, 9)."""

from .bistability import RegionMap, load_region_map, regions
from .engine import SweepResult, sweep
from .executors import EXECUTORS
from .spec import NAMED_ICS, SweepError, SweepSpec
from .store import load_sweep

__all__ = ["sweep", "SweepResult", "SweepSpec", "SweepError", "load_sweep", "EXECUTORS", "NAMED_ICS",
           "regions", "RegionMap", "load_region_map"]
