"""Bistability regions over (N, Ω) (paper Sect. 4.2.2, Fig. 8) and stick-slip domains (Fig. 9).

Each (model, N, Ω) is simulated from the two initial conditions of Sect. 4.2.2 (the paper does
not print them; ours are :data:`~stickslip.sweep.spec.NAMED_ICS`):

``far``   q = 0 with the upper plate carried along by the lower plate (v_r = 0 at t = 0):
          ẏ1 = Ω r when y1 is free, else φ̇ = Ω. Plates at rest (``zero``) is not far enough:
          at N = 50 N, Ω = 8.5 rad/s it decays to the equilibrium, while this one reaches the
          stick-slip oscillation that coexists with it (Fig. 7(c)).
``near``  the equilibrium of Eq. (14) with φ raised by 1e-3 rad.

Each run's outcome is decided (:func:`stickslip.attractors.attractor`); a response is
*stick-slip* when it moves to the end of its window and sticks in it
(:func:`stickslip.analysis.outcome.is_stick_slip`). Then

=========  ====================================================================
region 1   I: stick-slip from both initial conditions (stick-slip only)
region 2   II: stick-slip from one, equilibrium from the other (coexistence)
region 3   III: equilibrium from both (equilibrium only)
region 0   anything else (a run failed, or a slip-only oscillation)
=========  ====================================================================

The stick-slip domain of Fig. 9 is regions I ∪ II; its upper boundary Ω_ss(N) is reported as
the largest grid Ω at which stick-slip occurs.
"""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path
from typing import Sequence

import numpy as np

from ..analysis.outcome import is_stick_slip, outcome_code
from ..errors import SweepError
from ..files import atomic_write, lock
from ..model.library import resolve_model
from ..model.library.two_plates import is_plates
from ..parallel import check_workers
from ..results import Plottable
from .engine import SweepResult, sweep
from .spec import SweepSpec
from .store import load_sweep

__all__ = ["RegionMap", "regions", "load_region_map", "REGION_NAMES", "classify_regions"]

#: Keywords of :func:`~stickslip.sweep.sweep` that say how to run, not what to compute.
_RUN_OPTIONS = ("executor", "workers", "address", "batch_size", "progress", "overwrite", "snapshot_interval",
                "keep_journal")

REGION_NAMES = {0: "other", 1: "I: stick-slip only", 2: "II: coexistence", 3: "III: equilibrium only"}


def classify_regions(outcome: np.ndarray, stick_fraction: np.ndarray) -> np.ndarray:
    """Region codes (0–3) from outcome codes (:data:`~stickslip.analysis.outcome.OUTCOMES`) and
    stick fractions, with the two ICs on the last axis."""
    stick_slip = is_stick_slip(outcome, stick_fraction)
    equilibrium = outcome == outcome_code("equilibrium")
    a_ss, b_ss = stick_slip[..., 0], stick_slip[..., 1]
    a_eq, b_eq = equilibrium[..., 0], equilibrium[..., 1]
    region = np.zeros(a_ss.shape, dtype=np.int8)
    region[a_ss & b_ss] = 1
    region[(a_ss & b_eq) | (a_eq & b_ss)] = 2
    region[a_eq & b_eq] = 3
    return region


@dataclasses.dataclass(frozen=True, eq=False)
class RegionMap(Plottable):
    """Regions I/II/III over (model, N, Ω) and the stick-slip boundary.

    Parameters
    ----------
    dataset : xarray.Dataset
        The sweep (dims model, N, Omega, ic) plus ``region`` (model, N, Omega) and
        ``stick_slip_omega_max`` (model, N) [rad/s].
    path : Path or None
        The NetCDF file, or None when the map was computed without ``out``.
    timings : dict
        Wall times [s] and counts of the underlying sweep (:attr:`SweepResult.timings`).
    """

    FIGURE = "regions"

    dataset: object
    path: Path | None
    timings: dict

    @property
    def region(self) -> np.ndarray:
        return self.dataset["region"].values

    @property
    def models(self) -> list[str]:
        return [str(m) for m in self.dataset["model"].values]

    def to_xarray(self):
        return self.dataset



def _with_regions(ds):
    import xarray as xr

    outcome = ds["attractor"].transpose("model", "N", "Omega", "ic").values
    sf = ds["stick_fraction"].transpose("model", "N", "Omega", "ic").values
    region = classify_regions(outcome, np.nan_to_num(sf))
    omega = ds["Omega"].values
    ss = (region == 1) | (region == 2)
    omax = np.where(ss.any(axis=-1), np.max(np.where(ss, omega, -np.inf), axis=-1), np.nan)
    return ds.assign(
        region=(("model", "N", "Omega"), region, {
            "long_name": "steady-state region (Fig. 8)", "flag_values": "0 1 2 3",
            "flag_meanings": "other I_stick_slip_only II_coexistence III_equilibrium_only"}),
        stick_slip_omega_max=(("model", "N"), omax, {
            "units": "rad/s", "long_name": "largest grid Omega with stick-slip (upper edge of the Fig. 9 domain)"}),
    ) if isinstance(ds, xr.Dataset) else ds


def regions(N: Sequence[float], Omega: Sequence[float], model=None, *,
            variants: Sequence[str] | None = None, out=None, t_end: float = 200.0, t_from: float | None = None,
            **sweep_options) -> RegionMap:
    """Classify (N, Ω) into regions I, II, III (Fig. 8) for each model (Fig. 9 with all four).

    Parameters
    ----------
    N, Omega : sequences
        Grid of normal loads [N] and lower-plate speeds [rad/s] (increasing).
    model : Parameters, FrictionModel or str, optional
        The two plates, as :func:`stickslip.simulate` takes them: base parameters (μk = 0.2,
        Δμ = 0.1, α = 5 by default, as in Figs. 8–9), or the plates in a variant.
    variants : sequence of str, optional
        The plates' variants mapped: ``full``, ``x``, ``y``, ``rotation`` (Models 1–4); default
        the variant of ``model`` (``full`` for Parameters).
    out : path, optional
        NetCDF output; resumable like :func:`~stickslip.sweep.sweep`.
    t_end, t_from : float
        Run length and start of the steady window [s].
    **sweep_options
        Passed to :func:`~stickslip.sweep.sweep` (executor, workers, progress, sample_rate, ...).

    Raises
    ------
    stickslip.files.LockError
        If another process is writing ``out``.
    """
    if "ic" in sweep_options:
        raise SweepError("regions() uses the two initial conditions 'far' and 'near'; do not pass ic")
    system = resolve_model(model)
    if not is_plates(system):
        raise SweepError(f"regions are those of the two plates (Figs. 8, 9); model {system.name!r} is not the plates: "
                         "sweep its parameters with sweep()")
    variants = [system.label] if variants is None else list(variants)
    grid = {"model": variants, "N": list(N), "Omega": list(Omega), "ic": ["far", "near"]}
    run = {k: sweep_options.pop(k) for k in _RUN_OPTIONS if k in sweep_options}
    spec = SweepSpec.build(grid, system, t_end=t_end, t_from=t_from, **sweep_options)  # bad input: before the lock
    check_workers(run.get("workers"), address=run.get("address"))
    if out is None:
        res: SweepResult = sweep(spec, **run)
        return RegionMap(_with_regions(res.dataset), None, res.timings)
    path = Path(out)
    with lock(path):  # held across the sweep (which takes it again) and the region variables
        res = sweep(spec, out=path, **run)
        if "region" in res.dataset:
            return RegionMap(res.dataset, path, res.timings)
        extra = _with_regions(res.dataset)[["region", "stick_slip_omega_max"]].load()
        res.dataset.close()  # a large sweep is open lazily from this very file

        def add_regions(tmp):  # a copy of the sweep plus two variables: bounded memory, replaced atomically
            shutil.copyfile(path, tmp)
            extra.to_netcdf(tmp, engine="h5netcdf", mode="a")

        atomic_write(path, add_regions)
    return RegionMap(load_sweep(path, load="auto"), path, res.timings)


def load_region_map(path) -> RegionMap:
    """Read a region map written by :func:`regions` (``out=``).

    Parameters
    ----------
    path : str or Path
        The NetCDF file.

    Returns
    -------
    RegionMap

    Raises
    ------
    SweepError
        When the file is a sweep but not a region map.
    """
    ds = load_sweep(path, load="auto")
    if not {"model", "N", "Omega", "ic"} <= set(ds.dims):
        raise SweepError(f"{path} is a stickslip sweep but not a region map (dims {tuple(ds.dims)}); "
                         "give a file written by `stickslip regions`")
    if "region" not in ds:
        ds = _with_regions(ds)
    return RegionMap(ds, Path(path), {})
