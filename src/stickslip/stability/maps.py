"""Stability maps over (N, Ω) for a family of a third parameter (paper Figs. 3 and 4).

Computing only; figures are drawn by :mod:`stickslip.plot.stability`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
from scipy import optimize

from ..files import atomic_write, format_name, open_ours
from ..model import kernels
from ..model.parameters import PARAMETER_UNITS, ParameterError, Parameters, parameter_attrs
from ..model.system import System, assemble
from ..model.variants import resolve_variant
from . import linearize
from .equilibrium import MAX_ITER, RESIDUAL_TOL

__all__ = ["StabilityMap", "stability_map", "max_real_part", "boundary_omegas", "load_stability_map",
           "parse_family"]

#: Absolute tolerance [rad/s] of the boundary Ω_c(N) by brentq: far below any physical
#: resolution of Ω and ~1e-11 relative for the Ω of the paper (0.1–20 rad/s); brentq's own
#: rtol (4 eps) governs where that is tighter.
BOUNDARY_XTOL = 1e-10

#: A bracketed sign change whose |max Re λ| at the located root exceeds this fraction of the
#: bracket values is a jump of max Re λ (equilibrium branch switching), not a smooth crossing.
JUMP_FRACTION = 1e-6


_SYMBOLS = {"delta_mu": "Δμ", "mu_k": "μk", "alpha": "α", "r": "r"}
_PAPER_MODEL = {"full": 1, "x": 2, "y": 3, "rotation": 4}


def _as_float_array(name: str, values) -> np.ndarray:
    arr = np.atleast_1d(np.asarray(values, dtype=float))
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D sequence of numbers")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} has non-finite values; give finite numbers")
    if arr.size > 1 and not np.all(np.diff(arr) > 0):
        raise ValueError(f"{name} must be strictly increasing")
    return arr


def parse_family(text: str | None) -> tuple[str, list] | None:
    """``"delta_mu=0.1,0.2,0.3"`` → ``("delta_mu", [0.1, 0.2, 0.3])``; ``"model=full,rotation"``
    → ``("model", ["full", "rotation"])``."""
    if text is None or text == "":
        return None
    name, sep, values = text.partition("=")
    name = name.strip()
    items = [v.strip() for v in values.split(",") if v.strip()]
    if not sep or not name or not items:
        raise ValueError(f"family {text!r}: give NAME=V1,V2,..., e.g. delta_mu=0.1,0.2,0.3 or model=full,rotation")
    if name == "model":
        return name, items
    try:
        return name, [float(v) for v in items]
    except ValueError:
        raise ValueError(f"family {text!r}: the values of {name} must be numbers") from None


def _family_systems(params: Parameters, model, family) -> tuple[str, list, list[System]]:
    if family is None:
        return "", [""], [assemble(params, model)]
    if isinstance(family, Mapping):
        if len(family) != 1:
            raise ValueError("family must name exactly one parameter, e.g. {'delta_mu': [0.1, 0.2]}")
        family = next(iter(family.items()))
    if isinstance(family, str):
        family = parse_family(family)
    name, values = family
    values = list(values)
    if not values:
        raise ValueError(f"family {name!r} has no values")
    if name == "model":
        return name, [resolve_variant(v).name for v in values], [assemble(params, v) for v in values]
    if name in ("N", "Omega"):
        raise ValueError(f"family parameter {name!r} is already an axis of the map; choose another parameter")
    if name not in Parameters.names():
        raise ParameterError(f"unknown family parameter {name!r}; use 'model' or one of {', '.join(Parameters.names())}")
    return name, values, [assemble(params.replace(**{name: v}), model) for v in values]


def max_real_part(system: System, N: float, Omega: float) -> float:
    """Largest real part of the eigenvalues at steady sliding for (N, Ω) [1/s]; NaN without equilibrium."""
    free = system.variant.free_indices.astype(np.int64)
    p = system.p.copy()
    p[kernels.P_N] = N
    p[kernels.P_OMEGA] = Omega
    k = free.size
    J = np.empty((2 * k, 2 * k))
    if not linearize.equilibrium_jacobian(free, system.minv, system.damp, system.stiff, p, MAX_ITER, RESIDUAL_TOL, J):
        return math.nan
    return float(np.max(np.linalg.eigvals(J).real))


def _grid_max_real_part(system: System, N: np.ndarray, Omega: np.ndarray, chunk_points: int = 4096) -> np.ndarray:
    """max Re λ over N × Ω (numba Jacobians, NumPy batched eigenvalues), chunked by rows of N."""
    free = system.variant.free_indices.astype(np.int64)
    k2 = 2 * free.size
    out = np.empty((N.size, Omega.size))
    rows = max(1, chunk_points // Omega.size)
    for a in range(0, N.size, rows):
        Nc = N[a:a + rows]
        J = np.empty((Nc.size, Omega.size, k2, k2))
        linearize.jacobian_grid(free, system.minv, system.damp, system.stiff, system.p, Nc, Omega,
                                MAX_ITER, RESIDUAL_TOL, J)
        ok = np.isfinite(J[:, :, 0, 0])
        res = np.full((Nc.size, Omega.size), np.nan)
        if np.any(ok):
            res[ok] = np.linalg.eigvals(J[ok]).real.max(axis=-1)
        out[a:a + rows] = res
    return out


def boundary_omegas(system: System, N: float, Omega: np.ndarray, values: np.ndarray | None = None):
    """Stability boundaries Ω_c along Ω at fixed N, by brentq on max Re λ(Ω) [rad/s].

    Every sign change of max Re λ between adjacent grid points with an equilibrium on both is
    refined to :data:`BOUNDARY_XTOL`.

    Returns
    -------
    roots : list of float
    directions : list of int
        +1 where the equilibrium becomes unstable as Ω increases, −1 where it becomes stable.
    jumps : list of bool
        True where max Re λ jumps across zero instead of crossing it smoothly.
    """
    if values is None:
        values = np.array([max_real_part(system, N, w) for w in Omega])
    roots, directions, jumps = [], [], []
    f = lambda w: max_real_part(system, N, w)  # noqa: E731
    for b in range(Omega.size - 1):
        fa, fb = values[b], values[b + 1]
        if not (np.isfinite(fa) and np.isfinite(fb)) or (fa < 0) == (fb < 0) or fa == 0.0:
            continue
        try:
            root = optimize.brentq(f, Omega[b], Omega[b + 1], xtol=BOUNDARY_XTOL)
        except ValueError:  # NaN (equilibrium lost) inside the bracket
            continue
        froot = f(root)
        roots.append(root)
        directions.append(1 if fb > fa else -1)
        jumps.append(bool(not np.isfinite(froot) or abs(froot) > JUMP_FRACTION * max(abs(fa), abs(fb))))
    return roots, directions, jumps


@dataclasses.dataclass(frozen=True, eq=False)
class StabilityMap:
    """Stability of steady sliding over an (N, Ω) grid for a family of a third parameter.

    Attributes
    ----------
    params : Parameters
        Base parameters (the family value replaces one of them per member).
    model : str
        Model of the base (per-member models in ``family_values`` when the family is ``model``).
    N : ndarray (nN,)
        Normal loads [N].
    Omega : ndarray (nΩ,)
        Angular velocities of the lower plate [rad/s].
    family_name : str
        Name of the varied parameter, ``"model"``, or ``""`` for a single map.
    family_values : list
    max_real_part : ndarray (nF, nN, nΩ)
        Largest real part of the eigenvalues [1/s]; NaN where no equilibrium was found.
    boundary : ndarray (nF, nN, nC)
        Ω_c where max Re λ crosses 0 along Ω at each N (brentq), NaN-padded [rad/s].
    boundary_direction : ndarray (nF, nN, nC) int8
        +1: unstable above Ω_c; −1: stable above Ω_c; 0: padding.
    boundary_jump : ndarray (nF, nN, nC) bool
        True where max Re λ jumps across zero (branch switch) rather than crossing it.
    timings : dict
        Wall times [s] of the grid and the boundary search.
    """

    params: Parameters
    model: str
    N: np.ndarray
    Omega: np.ndarray
    family_name: str
    family_values: list
    max_real_part: np.ndarray
    boundary: np.ndarray
    boundary_direction: np.ndarray
    boundary_jump: np.ndarray
    timings: dict

    @property
    def stable(self) -> np.ndarray:
        """Boolean (nF, nN, nΩ): max Re λ < 0 (False where no equilibrium exists)."""
        with np.errstate(invalid="ignore"):
            return self.max_real_part < 0.0

    @property
    def family_labels(self) -> list[str]:
        """Legend labels, e.g. ``Δμ = 0.1``."""
        if not self.family_name:
            return [f"model {self.model}"]
        if self.family_name == "model":
            return [f"model {v}" + (f" (Model {_PAPER_MODEL[v]})" if v in _PAPER_MODEL else "") for v in self.family_values]
        symbol = _SYMBOLS.get(self.family_name, self.family_name)
        return [f"{symbol} = {v:g}" for v in self.family_values]

    def to_xarray(self):
        """``xarray.Dataset`` (family, N, Omega) with units and the full parameter set in attrs."""
        import xarray as xr

        from .. import __version__

        fam = self.family_values if self.family_name else [self.model]
        fam_coord = np.asarray([str(v) for v in fam]) if (self.family_name in ("model", "")) else np.asarray(fam, float)
        fam_attrs = {"long_name": self.family_name or "model"}
        if self.family_name in PARAMETER_UNITS and PARAMETER_UNITS[self.family_name]:
            fam_attrs["units"] = PARAMETER_UNITS[self.family_name]
        data = {
            "max_real_part": (("family", "N", "Omega"), self.max_real_part,
                              {"units": "1/s", "long_name": "largest real part of the eigenvalues at steady sliding"}),
            "stable": (("family", "N", "Omega"), self.stable.astype(np.int8),
                       {"long_name": "steady sliding asymptotically stable", "flag_values": "0 1",
                        "flag_meanings": "unstable_or_no_equilibrium stable"}),
            "equilibrium_found": (("family", "N", "Omega"), np.isfinite(self.max_real_part).astype(np.int8),
                                  {"long_name": "steady-sliding equilibrium found (Eq. 14)"}),
            "boundary_omega": (("family", "N", "crossing"), self.boundary,
                               {"units": "rad/s", "long_name": "Omega where max Re(lambda) = 0 (brentq along Omega)"}),
            "boundary_direction": (("family", "N", "crossing"), self.boundary_direction.astype(np.int8),
                                   {"long_name": "+1 unstable above the crossing, -1 stable above, 0 none"}),
            "boundary_jump": (("family", "N", "crossing"), self.boundary_jump.astype(np.int8),
                              {"long_name": "1 where max Re(lambda) jumps across 0 instead of crossing it"}),
        }
        coords = {
            "family": ("family", fam_coord, fam_attrs),
            "N": ("N", self.N, {"units": "N", "long_name": "normal preload"}),
            "Omega": ("Omega", self.Omega, {"units": "rad/s", "long_name": "angular velocity of the lower plate"}),
            "crossing": ("crossing", np.arange(self.boundary.shape[2])),
        }
        attrs = {
            "title": "stickslip stability map of steady sliding (paper Sect. 4.1)",
            "format": format_name("stabilitymap", 1),
            "stickslip_version": __version__,
            "model": self.model,
            "family_name": self.family_name,
            "parameters": json.dumps(self.params.to_dict()),
            "timings": json.dumps(self.timings),
            "boundary_xtol": BOUNDARY_XTOL,
            "boundary_xtol_units": "rad/s",
        }
        attrs.update(parameter_attrs(self.params.to_dict()))
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def to_netcdf(self, path: str | Path) -> Path:
        """Write :meth:`to_xarray` to NetCDF-4 (h5netcdf engine)."""
        ds = self.to_xarray()
        return atomic_write(path, lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf"))

    def plot(self, **kwargs):
        """Figure of the map; see :func:`stickslip.plot.stability.plot_stability_map`."""
        from ..plot.stability import plot_stability_map

        return plot_stability_map(self, **kwargs)


def load_stability_map(path: str | Path) -> StabilityMap:
    """Read a map written by :meth:`StabilityMap.to_netcdf`."""
    ds = open_ours(path, "stabilitymap", noun="stability map", what="a .nc file written by `stickslip stability-map`")
    name = ds.attrs["family_name"]
    fam = [str(v) for v in ds["family"].values] if name in ("model", "") else [float(v) for v in ds["family"].values]
    return StabilityMap(
        params=Parameters.from_dict(json.loads(ds.attrs["parameters"])),
        model=ds.attrs["model"], N=ds["N"].values, Omega=ds["Omega"].values,
        family_name=name, family_values=fam if name else [],
        max_real_part=ds["max_real_part"].values, boundary=ds["boundary_omega"].values,
        boundary_direction=ds["boundary_direction"].values, boundary_jump=ds["boundary_jump"].values.astype(bool),
        timings=json.loads(ds.attrs["timings"]),
    )


def stability_map(
    params: Parameters | None = None,
    N: Sequence[float] = tuple(np.linspace(5.0, 200.0, 40)),
    Omega: Sequence[float] = tuple(np.linspace(0.25, 20.0, 80)),
    *,
    model="full",
    family: "tuple[str, Sequence] | Mapping[str, Sequence] | str | None" = None,
    boundary: bool = True,
) -> StabilityMap:
    """Max real part of the eigenvalues over an (N, Ω) grid, and the stability boundary Ω_c(N).

    Parameters
    ----------
    params : Parameters, optional
        Base parameters (default Table 1, μk = 0.2, Δμ = 0.1, α = 5).
    N : sequence of float
        Normal loads [N], strictly increasing, > 0.
    Omega : sequence of float
        Angular velocities [rad/s], strictly increasing, non-zero.
    model : str or iterable of DOF names
        ``full`` (Model 1) … ``rotation`` (Model 4).
    family : (name, values), {name: values}, "name=v1,v2" or None
        A third parameter varied over the map, any :class:`Parameters` field other than N, Ω,
        or ``"model"`` (e.g. ``("model", ["full", "rotation"])`` for paper Fig. 4).
    boundary : bool
        Locate Ω_c(N) for every N by brentq on max Re λ along Ω (bracketed by the grid).

    Returns
    -------
    StabilityMap

    Raises
    ------
    ValueError, ParameterError, VariantError
        For an empty or non-increasing grid, N ≤ 0, Ω = 0, or an unknown family parameter.
    """
    params = Parameters() if params is None else params
    if not isinstance(params, Parameters):
        raise TypeError(f"params must be a stickslip.Parameters, got {type(params).__name__}")
    N = _as_float_array("N", N)
    Omega = _as_float_array("Omega", Omega)
    if np.any(N <= 0):
        raise ValueError("N must be > 0 (the plates must be pressed together)")
    if np.any(Omega == 0):
        raise ValueError("Omega = 0 has no steady sliding (the friction direction is undefined); leave it out of the grid")
    name, values, systems = _family_systems(params, model, family)
    t0 = time.perf_counter()
    mrp = np.stack([_grid_max_real_part(sy, N, Omega) for sy in systems])
    t1 = time.perf_counter()
    per = [[([], [], []) for _ in N] for _ in systems]
    if boundary:
        for f, sy in enumerate(systems):
            for a, n in enumerate(N):
                per[f][a] = boundary_omegas(sy, float(n), Omega, mrp[f, a])
    t2 = time.perf_counter()
    nc = max([1] + [len(r[0]) for fam in per for r in fam])
    bnd = np.full((len(systems), N.size, nc), np.nan)
    bdir = np.zeros((len(systems), N.size, nc), dtype=np.int8)
    bjump = np.zeros((len(systems), N.size, nc), dtype=bool)
    for f in range(len(systems)):
        for a in range(N.size):
            roots, dirs, jumps = per[f][a]
            bnd[f, a, :len(roots)] = roots
            bdir[f, a, :len(dirs)] = dirs
            bjump[f, a, :len(jumps)] = jumps
    return StabilityMap(
        params=params, model=resolve_variant(model).name, N=N, Omega=Omega,
        family_name=name, family_values=values if name else [],
        max_real_part=mrp, boundary=bnd, boundary_direction=bdir, boundary_jump=bjump,
        timings={"grid_s": t1 - t0, "boundary_s": t2 - t1, "points": int(mrp.size)},
    )
