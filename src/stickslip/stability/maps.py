"""Stability maps of steady sliding over any two parameters of any model (paper Figs. 3 and 4).

For each grid point the equilibrium and the Jacobian are computed in one compiled call over the
whole grid (:func:`stickslip.stability.steady.jacobian_points`), the eigenvalues by NumPy's batched
LAPACK, and the boundary where max Re λ crosses 0 along the second axis by brentq. The grid holds
every contact closed; where that leaves a unilateral contact unpressed, or finds no steady sliding
of a model with unilateral contacts, the point is solved in Python with the open set that
``stickslip stability`` takes (as is every point of a model with rigid contacts).

A point's model is not rebuilt in Python: each axis is a table of data arrays (one row per value,
:class:`_Axis`), and a point takes the first axis' row with the second axis' entries put in. This is
exact when the two parameters set disjoint numbers of the model (checked; otherwise every point is
built). Computing only; figures are drawn by :mod:`stickslip.plot.stability`.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from .._version import __version__
from ..errors import EquilibriumError, ModelError, ParameterError
from ..files import format_name, open_ours, save_netcdf
from ..memory import check_memory, largest_count, map_point_bytes
from ..model.library import describe_system, system_from_description
from ..model.library.two_plates import plates_parameters
from ..model.parameters import PARAMETER_UNITS, Parameters, parameter_attrs
from ..model.variants import resolve_variant
from ..results import Plottable
from . import steady
from .analysis import linearization, model_stability
from .equilibrium import MAX_ITER, RESIDUAL_TOL, model_of, sliding_speeds, solve_steady_modes
from .verdict import MARGINAL_RTOL

__all__ = ["StabilityMap", "stability_map", "max_real_part", "boundary_omegas", "load_stability_map",
           "parse_family", "MapGrid"]

#: Absolute tolerance of the boundary along the second axis by brentq (for the plates' Ω
#: [rad/s]: far below any physical resolution and ~1e-11 relative for 0.1–20 rad/s); brentq's own
#: rtol (4 eps) governs where that is tighter.
BOUNDARY_XTOL = 1e-10

#: A bracketed sign change whose |max Re λ| at the located root exceeds this fraction of the
#: bracket values is a jump of max Re λ (equilibrium branch switching), not a smooth crossing.
JUMP_FRACTION = 1e-6

#: Points per compiled call (bounds the Jacobians held at once: 4096 × 12 × 12 × 8 B = 4.7 MB).
CHUNK_POINTS = 4096

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


def _numeric_parameters(system) -> list[str]:
    return [k for k, v in system.parameters.items() if not isinstance(v, (str, bool))]


def _check_axis_values(system, name: str, values: np.ndarray) -> None:
    """Refuse axis values that make the model invalid or leave a contact at rest without slip
    (no steady sliding: the friction direction is undefined), before any grid point is computed."""
    for v in np.unique(values):
        member = system.replace(**{name: float(v)})
        if min(sliding_speeds(member, np.zeros(member.n))) == 0.0:
            raise ValueError(f"{name} = {v:g} has no steady sliding (a contact does not slide at rest: the friction "
                             "direction is undefined); leave it out of the grid")


def _check_memory(system, na: int, nb: int, members: int, every_point: bool = False) -> None:
    """Refuse a map whose grid would not fit in memory, before it is built: per point and member
    :func:`stickslip.memory.map_point_bytes`, per axis value (every point when the axes are not
    separable) a row of the model's data, and the Jacobians of one compiled call with their
    eigenvalue copy."""
    row = 8.0 * _row(system).size
    k = 2 * system.n
    per = map_point_bytes(members) + (members * row if every_point else 0.0)
    fixed = members * (na + nb) * row + 2.0 * CHUNK_POINTS * 8 * k * k

    def fits(memory: float) -> str:
        side = math.isqrt(largest_count(per, memory, fixed))  # of a square grid that fits
        if side < 2:
            return f"free memory: its fixed arrays alone take {fixed / 1e6:.3g} MB"
        return f"give at most {side ** 2:.3g} points, e.g. {side} values per axis"

    check_memory(float(na) * nb * per + fixed,
                 f"a stability map of {na:.3g} × {nb:.3g} points and {members} member(s) of model {system.name!r}",
                 fits)


def _row(system) -> np.ndarray:
    """The model's data array and its kinematics fields, one row (L + nf,)."""
    kin = system.data.kin
    kv = steady.kinematics_values(kin) if _float_fields(kin) else np.empty(0)
    return np.concatenate([system.data.m, kv])


def _float_fields(kin) -> bool:
    try:
        steady.kinematics_values(kin)
        return True
    except TypeError:
        return False


class _Axis:
    """One map axis: the rows (:func:`_row`) of the model with parameter ``name`` set to any value.

    Rows are built by ``replace`` at three probe values; entries that equal the value are set to
    it, entries affine in it (to 1e-13) are interpolated, and any other dependence (e.g. M⁻¹ of a
    mass) makes every row a ``replace``.
    """

    def __init__(self, base, name: str, values: np.ndarray):
        self.base, self.name = base, name
        lo, hi = float(values[0]), float(values[-1])
        probes = [lo, hi, 0.5 * (lo + hi)] if hi != lo else [lo]
        models = [self._model(v) for v in probes]
        if any(model.data.law != base.data.law for model in models):
            raise ValueError(f"{name} changes the parameters of the model's user friction law; it cannot be a "
                             "stability-map axis (run a sweep over it instead)")
        rows = np.array([_row(model) for model in models])
        self.base_row = rows[0]
        self.changed = np.any(rows != rows[0], axis=0)
        self.fast = False
        if len(probes) == 3:
            v = np.array(probes)
            slope = (rows[1] - rows[0]) / (v[1] - v[0])
            icpt = rows[0] - slope * v[0]
            pred = icpt + slope * v[2]
            scale = np.maximum(np.abs(rows).max(axis=0), 1e-300)
            self.identity = self.changed & np.all(rows == v[:, None], axis=0)
            self.slope, self.icpt = slope, icpt
            self.fast = bool(np.all(np.abs(pred - rows[2]) <= 1e-13 * scale))
        nf = self.base_row.size - base.data.m.size
        if nf and np.any(self.changed[-nf:]) and not _float_fields(base.data.kin):
            raise ValueError(f"{name} changes kinematics data that are not numbers; it cannot be a map axis")

    def _model(self, value: float):
        return self.base.replace(**{self.name: float(value)})

    def rows(self, values) -> np.ndarray:
        """Rows (len(values), L + nf) of the model at ``values``."""
        values = np.atleast_1d(np.asarray(values, dtype=float))
        if not self.fast:
            return np.array([_row(self._model(v)) for v in values])
        out = np.repeat(self.base_row[None, :], values.size, axis=0)
        c = self.changed
        out[:, c] = self.icpt[c] + self.slope[c] * values[:, None]
        out[:, self.identity] = values[:, None]
        return out


@dataclasses.dataclass
class MapGrid:
    """A model over a grid of two parameters, as the compiled kernel takes it.

    ``rows_a`` (nA, L + nf) and ``rows_b`` (nB, L + nf) are the model's rows along each axis;
    point (i, j) is ``rows_a[i]`` with the entries ``mask_b`` from ``rows_b[j]``. Where the two
    parameters are not separable (they set the same numbers), ``rows_a`` holds every point
    (nA·nB rows, A-major) and ``mask_b`` is all False.
    """

    system: object
    names: tuple
    a: np.ndarray
    b: np.ndarray
    axis_a: _Axis
    axis_b: _Axis
    rows_a: np.ndarray
    rows_b: np.ndarray
    mask_b: np.ndarray
    separable: bool

    @classmethod
    def build(cls, system, names: tuple[str, str], a: np.ndarray, b: np.ndarray) -> "MapGrid":
        if names[0] == names[1]:
            raise ValueError(f"the two axes of a map must be different parameters, got {names[0]!r} twice")
        axis_a, axis_b = _Axis(system, names[0], a), _Axis(system, names[1], b)
        rows_a, rows_b = axis_a.rows(a), axis_b.rows(b)
        mask_b = axis_b.changed
        separable = not np.any(axis_a.changed & mask_b)
        if separable:  # check the far corner against a full build
            corner = rows_a[-1].copy()
            corner[mask_b] = rows_b[-1][mask_b]
            full = _row(system.replace(**{names[0]: float(a[-1]), names[1]: float(b[-1])}))
            separable = np.array_equal(np.abs(corner - full) <= 1e-13 * np.maximum(np.abs(full), 1e-300),
                                       np.ones_like(full, dtype=bool))
        if not separable:
            _check_memory(system, a.size, b.size, 1, every_point=True)
            rows_a = np.array([_row(system.replace(**{names[0]: float(x), names[1]: float(y)}))
                               for x in a for y in b])
            mask_b = np.zeros_like(mask_b)
        return cls(system, tuple(names), a, b, axis_a, axis_b, rows_a, rows_b, mask_b, bool(separable))

    def jacobians(self, ia: np.ndarray, ib: np.ndarray, rows_b: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
        """Jacobians (P, 2k, 2k) at the points (ia[p], ib[p]) with every contact closed (NaN where
        no such steady sliding exists), and each point's outcome (P,) int8: ``steady.STEADY_*``
        (whether every unilateral contact is pressed there)."""
        system = self.system
        L = system.data.m.size
        rb = self.rows_b if rows_b is None else rows_b
        free = np.flatnonzero(system.free).astype(np.int64)
        out = np.empty((ia.size, 2 * free.size, 2 * free.size))
        found = np.empty(ia.size, dtype=np.int8)
        ra = self.rows_a
        if not self.separable:
            ra, ia = ra[ia * self.b.size + ib], np.arange(ia.size, dtype=np.int64)
        tables = steady.AxisTables(ra[:, :L], rb[:, :L], self.mask_b[:L], ra[:, L:], rb[:, L:], self.mask_b[L:],
                                   ia.astype(np.int64), ib.astype(np.int64))
        steady.jacobian_points(tables, system.data.kin, system.data.law, free, MAX_ITER, RESIDUAL_TOL, out, found)
        return out, found

    def max_real_part(self) -> tuple[np.ndarray, np.ndarray]:
        """max Re λ over the grid (nA, nB) [1/s], NaN where no steady sliding exists, and the
        tolerance within which it counts as 0 (:data:`.verdict.MARGINAL_RTOL` × ‖J‖₂) [1/s].

        Every point is solved by the compiled grid with every contact closed. A model with
        unilateral contacts takes, at the points where that leaves one unpressed or finds no steady
        sliding, the open set that ``stickslip stability`` takes (:meth:`point_stability`, one solve
        in Python each); a model with rigid contacts takes it at every point (the constrained
        eigenproblem)."""
        nA, nB = self.a.size, self.b.size
        if self.system.rigid:
            rows = [[self.point_stability(i, y) for y in self.b] for i in range(nA)]
            return tuple(np.array([[p[k] for p in row] for row in rows]).reshape(nA, nB) for k in (0, 1))
        ia_all = np.repeat(np.arange(nA, dtype=np.int64), nB)
        ib_all = np.tile(np.arange(nB, dtype=np.int64), nA)
        out = np.full(nA * nB, np.nan)
        tol = np.full(nA * nB, np.nan)
        for p0 in range(0, nA * nB, CHUNK_POINTS):
            sl = slice(p0, p0 + CHUNK_POINTS)
            J, found = self.jacobians(ia_all[sl], ib_all[sl])
            ok = np.isfinite(J[:, 0, 0]) & (found != steady.STEADY_UNPRESSED)
            if np.any(ok):
                out[sl][ok] = np.linalg.eigvals(J[ok]).real.max(axis=-1)
                tol[sl][ok] = MARGINAL_RTOL * np.linalg.norm(J[ok], 2, axis=(1, 2))
            if self.system.unilateral:
                for p in p0 + np.flatnonzero(~ok):
                    out[p], tol[p] = self.point_stability(ia_all[p], self.b[ib_all[p]])
        return out.reshape(nA, nB), tol.reshape(nA, nB)

    def point_stability(self, i: int, y: float) -> tuple[float, float]:
        """(max Re λ, its tolerance) [1/s] of a model with unilateral contacts at ``a[i]`` and the
        second parameter = ``y`` (:func:`_unilateral_max_real_part`)."""
        return _unilateral_max_real_part(self.system.replace(**{self.names[0]: float(self.a[i]),
                                                                self.names[1]: float(y)}))

    def value_at(self, i: int, y: float) -> float:
        """max Re λ at the first axis' value ``a[i]`` and the second parameter = ``y`` [1/s]."""
        if self.system.unilateral:
            return self.point_stability(i, y)[0]
        if self.separable:
            J = self.jacobians(np.array([i]), np.array([0]), self.axis_b.rows([y]))[0]
        else:
            J = _jacobian_of(self.system.replace(**{self.names[0]: float(self.a[i]), self.names[1]: float(y)}))
        return float(np.max(np.linalg.eigvals(J[0]).real)) if np.isfinite(J[0, 0, 0]) else math.nan


def _unilateral_max_real_part(system) -> tuple[float, float]:
    """max Re λ at steady sliding of a model with unilateral contacts and its tolerance [1/s], NaN
    without steady sliding (−inf where closed rigid contacts fix every free dof: no motion is left).

    Steady sliding may leave such contacts open, and which ones depends on the point, while the
    compiled grid kernel holds every contact closed. So such a point takes the open set that
    ``stickslip stability`` takes (:func:`~stickslip.stability.equilibrium.solve_steady_modes`):
    one steady-sliding solve in Python (milliseconds). Closed rigid contacts make the eigenproblem
    a constrained one (the motion that keeps them closed), solved as
    :func:`~stickslip.stability.analysis.model_stability` solves it; without them the eigenvalues
    are those of the Jacobian, as the compiled grid takes them (the same numbers bit for bit where
    every contact is closed).
    """
    try:
        if system.rigid:
            result = model_stability(system)
            return result.max_real_part, float(result.tolerance)
        q, _, _, opened = solve_steady_modes(system)
    except EquilibriumError:
        return math.nan, math.nan
    J = linearization(system, q, opened)[0]
    if not np.all(np.isfinite(J)):
        return math.nan, math.nan
    return float(np.max(np.linalg.eigvals(J).real)), float(MARGINAL_RTOL * np.linalg.norm(J, 2))


def _jacobian_of(system) -> np.ndarray:
    """The steady-sliding Jacobian (1, 2k, 2k) of one model (NaN without steady sliding)."""
    free = np.flatnonzero(system.free).astype(np.int64)
    out = np.empty((1, 2 * free.size, 2 * free.size))
    steady.steady_jacobian(system.data, free, MAX_ITER, RESIDUAL_TOL, out[0])
    return out


def max_real_part(system, N: float, Omega: float, names: tuple[str, str] = ("N", "Omega")) -> float:
    """Largest real part of the eigenvalues at steady sliding with the parameters ``names`` set to
    (N, Ω) [1/s]; NaN without steady sliding."""
    point = system.replace(**{names[0]: float(N), names[1]: float(Omega)})
    if point.unilateral:
        return _unilateral_max_real_part(point)[0]
    J = _jacobian_of(point)
    return float(np.max(np.linalg.eigvals(J[0]).real)) if np.isfinite(J[0, 0, 0]) else math.nan


def boundary_omegas(grid: MapGrid, i: int, values: np.ndarray):
    """Stability boundaries along the second axis at the first axis' value ``grid.a[i]``, by brentq.

    Every sign change of max Re λ between adjacent grid points with an equilibrium on both is
    refined to :data:`BOUNDARY_XTOL`.

    Returns
    -------
    roots : list of float
    directions : list of int
        +1 where the equilibrium becomes unstable as the parameter increases, −1 where it becomes stable.
    jumps : list of bool
        True where max Re λ jumps across zero instead of crossing it smoothly.
    """
    from scipy import optimize  # imported on use: scipy takes ~0.3 s of every command's start

    roots, directions, jumps = [], [], []
    f = lambda w: grid.value_at(i, w)  # noqa: E731
    Y = grid.b
    for b in range(Y.size - 1):
        fa, fb = values[b], values[b + 1]
        if not (np.isfinite(fa) and np.isfinite(fb)) or (fa < 0) == (fb < 0) or fa == 0.0:
            continue
        try:
            root = optimize.brentq(f, Y[b], Y[b + 1], xtol=BOUNDARY_XTOL)
        except ValueError:  # NaN (equilibrium lost) inside the bracket
            continue
        froot = f(root)
        roots.append(root)
        directions.append(1 if fb > fa else -1)
        jumps.append(bool(not np.isfinite(froot) or abs(froot) > JUMP_FRACTION * max(abs(fa), abs(fb))))
    return roots, directions, jumps


@dataclasses.dataclass(frozen=True, eq=False)
class StabilityMap(Plottable):
    """Stability of steady sliding over a grid of two parameters, for a family of a third.

    Parameters
    ----------
    params : Parameters or None
        The plates' base parameters (None for other models: see ``system``).
    model : str
        The plates' variant of the base (per-member variants in ``family_values`` when the family
        is ``model``), or the model's name.
    N : ndarray (nA,)
        Values of the first axis (``axes[0]``; for the plates' maps the normal load N [N]).
    Omega : ndarray (nB,)
        Values of the second axis (``axes[1]``; for the plates' maps Ω [rad/s]).
    family_name : str
        Name of the varied parameter, ``"model"``, or ``""`` for a single map.
    family_values : list
        The values of the family's parameter (variant names for ``model``); ``[]`` for a single map.
    max_real_part : ndarray (nF, nA, nB)
        Largest real part of the eigenvalues [1/s]; NaN where no equilibrium was found.
    boundary : ndarray (nF, nA, nC)
        Values of the second parameter where max Re λ crosses 0 at each value of the first
        (brentq), NaN-padded.
    boundary_direction : ndarray (nF, nA, nC) int8
        +1: unstable above the crossing; −1: stable above it; 0: padding.
    boundary_jump : ndarray (nF, nA, nC) bool
        True where max Re λ jumps across zero (branch switch) rather than crossing it.
    timings : dict
        Wall times [s] of the grid and the boundary search.
    axes : (str, str)
        The parameters of the two axes (plates names such as ``N``, or model paths such as
        ``contact.0.friction.mu_k``).
    system : FrictionModel or None
        The base model.
    marginal_tolerance : ndarray (nF, nA, nB), optional
        Tolerance within which max Re λ counts as 0 at each point, :data:`.verdict.MARGINAL_RTOL`
        × ‖J‖₂ [1/s]: a point within it is ``marginal`` (a centre or a zero eigenvalue), neither
        stable nor unstable (:attr:`verdicts`).
    """

    FIGURE = "stability_map"

    params: Parameters | None
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
    axes: tuple = ("N", "Omega")
    system: object = None
    marginal_tolerance: np.ndarray | None = None

    @property
    def tolerance(self) -> np.ndarray:
        """(nF, nA, nB): the tolerance within which max Re λ counts as 0 (:data:`.verdict.MARGINAL_RTOL`
        × ‖J‖₂ of each point; 0 for a map read from a file written without it) [1/s]."""
        if self.marginal_tolerance is None:
            return np.zeros_like(self.max_real_part)
        return self.marginal_tolerance

    @property
    def stable(self) -> np.ndarray:
        """Boolean (nF, nA, nB): max Re λ < −tolerance (False where no equilibrium exists)."""
        with np.errstate(invalid="ignore"):
            return self.max_real_part < -self.tolerance

    @property
    def marginal(self) -> np.ndarray:
        """Boolean (nF, nA, nB): |max Re λ| ≤ tolerance, a centre or a zero eigenvalue that the
        linearisation leaves undecided (:func:`.verdict.stability_verdict`)."""
        with np.errstate(invalid="ignore"):
            return np.abs(self.max_real_part) <= self.tolerance

    @property
    def verdicts(self) -> np.ndarray:
        """(nF, nA, nB) of str: ``stable``, ``marginal``, ``unstable`` or ``none`` (no equilibrium)."""
        out = np.full(self.max_real_part.shape, "unstable", dtype=object)
        out[self.stable] = "stable"
        out[self.marginal] = "marginal"
        out[~np.isfinite(self.max_real_part)] = "none"
        return out

    @property
    def family_labels(self) -> list[str]:
        """Legend labels, e.g. ``Δμ = 0.1``."""
        if not self.family_name:
            return [f"model {self.model}"]
        if self.family_name == "model":
            return [f"model {v}" + (f" (Model {_PAPER_MODEL[v]})" if v in _PAPER_MODEL else "") for v in self.family_values]
        symbol = _SYMBOLS.get(self.family_name, self.family_name)
        return [f"{symbol} = {v:g}" for v in self.family_values]

    def _parameters(self) -> dict:
        return self.params.to_dict() if self.params is not None else dict(self.system.parameters)

    def to_xarray(self):
        """``xarray.Dataset`` (family, axis 1, axis 2) with units and the full parameter set in attrs."""
        import xarray as xr


        a, b = self.axes
        fam = self.family_values if self.family_name else [self.model]
        fam_coord = np.asarray([str(v) for v in fam]) if (self.family_name in ("model", "")) else np.asarray(fam, float)
        fam_attrs = {"long_name": self.family_name or "model"}
        if self.family_name in PARAMETER_UNITS and PARAMETER_UNITS[self.family_name]:
            fam_attrs["units"] = PARAMETER_UNITS[self.family_name]
        grid = ("family", a, b)
        bname = "boundary_omega" if b == "Omega" else "boundary"
        battrs = {"long_name": f"{b} where max Re(lambda) = 0 (brentq along {b})"}
        if PARAMETER_UNITS.get(b):
            battrs["units"] = PARAMETER_UNITS[b]
        data = {
            "max_real_part": (grid, self.max_real_part,
                              {"units": "1/s", "long_name": "largest real part of the eigenvalues at steady sliding"}),
            "stable": (grid, self.stable.astype(np.int8),
                       {"long_name": "steady sliding asymptotically stable", "flag_values": "0 1",
                        "flag_meanings": "unstable_marginal_or_no_equilibrium stable"}),
            "marginal": (grid, self.marginal.astype(np.int8),
                         {"long_name": "max Re(lambda) = 0 within the eigenvalue solver's accuracy",
                          "flag_values": "0 1", "flag_meanings": "decided marginal"}),
            "marginal_tolerance": (grid, self.tolerance,
                                   {"units": "1/s", "long_name": "tolerance within which max Re(lambda) counts as 0"}),
            "equilibrium_found": (grid, np.isfinite(self.max_real_part).astype(np.int8),
                                  {"long_name": "steady-sliding equilibrium found"}),
            bname: (("family", a, "crossing"), self.boundary, battrs),
            "boundary_direction": (("family", a, "crossing"), self.boundary_direction.astype(np.int8),
                                   {"long_name": "+1 unstable above the crossing, -1 stable above, 0 none"}),
            "boundary_jump": (("family", a, "crossing"), self.boundary_jump.astype(np.int8),
                              {"long_name": "1 where max Re(lambda) jumps across 0 instead of crossing it"}),
        }
        long_names = {"N": "normal preload", "Omega": "angular velocity of the lower plate"}
        coords = {"family": ("family", fam_coord, fam_attrs), "crossing": ("crossing", np.arange(self.boundary.shape[2]))}
        for name, values in ((a, self.N), (b, self.Omega)):
            attrs = {"long_name": long_names.get(name, name)}
            if PARAMETER_UNITS.get(name):
                attrs["units"] = PARAMETER_UNITS[name]
            coords[name] = (name, values, attrs)
        attrs = {
            "title": "stickslip stability map of steady sliding",
            "format": format_name("stabilitymap", 1),
            "stickslip_version": __version__,
            "model": self.model,
            "family_name": self.family_name,
            "axes": json.dumps(list(self.axes)),
            "parameters": json.dumps(self._parameters()),
            "timings": json.dumps(self.timings),
            "boundary_xtol": BOUNDARY_XTOL,
        }
        if self.system is not None:
            attrs["system"] = json.dumps(describe_system(self.system))
        if self.params is not None:
            attrs["boundary_xtol_units"] = "rad/s"
            attrs.update(parameter_attrs(self.params.to_dict()))
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def to_netcdf(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Write :meth:`to_xarray` to NetCDF-4 (h5netcdf engine), atomically.

        An existing ``path`` is replaced only with ``overwrite=True``
        (:class:`stickslip.errors.OutputError` otherwise).
        """
        return save_netcdf(self.to_xarray(), path, overwrite=overwrite)



def load_stability_map(path: str | Path) -> StabilityMap:
    """Read a map written by :meth:`StabilityMap.to_netcdf`.

    Parameters
    ----------
    path : str or Path
        The NetCDF file (``stickslip stability-map --out``).

    Returns
    -------
    StabilityMap

    Raises
    ------
    FileFormatError
        When the file is not a stability map written by stickslip.
    """
    ds = open_ours(path, "stabilitymap", noun="stability map", what="a .nc file written by `stickslip stability-map`")
    name = ds.attrs["family_name"]
    fam = [str(v) for v in ds["family"].values] if name in ("model", "") else [float(v) for v in ds["family"].values]
    a, b = json.loads(ds.attrs["axes"]) if "axes" in ds.attrs else ("N", "Omega")
    system = system_from_description(json.loads(ds.attrs["system"])) if "system" in ds.attrs else None
    params = Parameters.from_dict(json.loads(ds.attrs["parameters"])) if "param_N" in ds.attrs else None
    return StabilityMap(
        params=params, model=ds.attrs["model"], N=ds[a].values, Omega=ds[b].values,
        family_name=name, family_values=fam if name else [],
        max_real_part=ds["max_real_part"].values,
        boundary=ds["boundary_omega" if "boundary_omega" in ds else "boundary"].values,
        boundary_direction=ds["boundary_direction"].values, boundary_jump=ds["boundary_jump"].values.astype(bool),
        timings=json.loads(ds.attrs["timings"]), axes=(a, b), system=system,
        marginal_tolerance=ds["marginal_tolerance"].values if "marginal_tolerance" in ds else None,
    )


def _members(system, family) -> tuple[str, list, list]:
    """(family name, values, member models) of a family over the base model ``system``."""
    if family is None:
        return "", [""], [system]
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
    if name == "model":  # the variants (sets of free DOFs) of a model that has them: the plates' Models 1-4
        if "variant" not in system.parameters:
            raise ValueError(f"a family of models needs a model with variants (the plates: full, x, y, rotation); "
                             f"model {system.name!r} has none: vary one of its parameters instead")
        names = [resolve_variant(v).name for v in values]
        return name, names, [system.replace(variant=v) for v in names]
    known = _numeric_parameters(system)
    try:
        key = system.resolver(name) if system.resolver is not None else name
    except ModelError:
        key = None
    if key not in known:
        shown = ", ".join(known) if len(known) <= 30 else ", ".join(known[:30]) + ", ..."
        raise ParameterError(f"unknown family parameter {name!r} of model {system.name!r}; use "
                             + ("'model' or " if "variant" in system.parameters else "") + f"one of {shown}")
    return name, values, [system.replace(**{name: float(v)}) for v in values]


def stability_map(
    model=None,
    N: Sequence[float] = tuple(np.linspace(5.0, 200.0, 40)),
    Omega: Sequence[float] = tuple(np.linspace(0.25, 20.0, 80)),
    *,
    family: "tuple[str, Sequence] | Mapping[str, Sequence] | str | None" = None,
    boundary: bool = True,
    axes: tuple[str, str] = ("N", "Omega"),
) -> StabilityMap:
    """Max real part of the eigenvalues over a grid of two parameters, and the stability boundary.

    Parameters
    ----------
    model : FrictionModel, Parameters or str, optional
        The model, as :func:`stickslip.simulate` takes it: the plates' base parameters (default
        Table 1, μk = 0.2, Δμ = 0.1, α = 5; in a variant: ``two_plates(params, "rotation")``), or
        any model (a FrictionModel, a library name or a model file path).
    N, Omega : sequence of float
        Values of the first and second parameter (``axes``), strictly increasing; for the plates'
        default axes the normal loads [N] (> 0) and angular velocities [rad/s] (non-zero).
    family : (name, values), {name: values}, "name=v1,v2" or None
        A third parameter varied over the map (any parameter of the model other than the axes), or
        for the plates ``"model"`` (e.g. ``("model", ["full", "rotation"])`` for paper Fig. 4).
    boundary : bool
        Locate the crossings of max Re λ = 0 along the second axis for every value of the first
        by brentq (bracketed by the grid).
    axes : (str, str)
        The two parameters: plates names (``N``, ``Omega``, ``delta_mu``, ...) or a model's
        parameter paths (``contact.0.normal_force``, ``contact.0.friction.mu_k``, ``stiffness.x.y``).

    Returns
    -------
    StabilityMap

    Raises
    ------
    ValueError, ParameterError, ModelError, VariantError
        For an empty or non-increasing grid, N ≤ 0, Ω = 0 (plates), an unknown parameter, or a
        value that makes the model invalid.
    """
    system = model_of(model)
    axes = tuple(axes)
    N = _as_float_array(axes[0], N)
    Omega = _as_float_array(axes[1], Omega)
    for name, values in zip(axes, (N, Omega)):
        _check_axis_values(system, name, values)
    fam = family if not isinstance(family, str) else parse_family(family)
    fam_name = (next(iter(fam)) if isinstance(fam, Mapping) else fam[0]) if fam is not None else ""
    if fam_name in axes:
        raise ValueError(f"family parameter {fam_name!r} is already an axis of the map; choose another parameter")
    name, values, systems = _members(system, fam)
    _check_memory(system, N.size, Omega.size, len(systems))
    t0 = time.perf_counter()
    grids = [MapGrid.build(sy, axes, N, Omega) for sy in systems]
    mrp, tol = (np.stack(part) for part in zip(*(g.max_real_part() for g in grids)))
    t1 = time.perf_counter()
    per = [[([], [], []) for _ in N] for _ in systems]
    if boundary:
        for f, g in enumerate(grids):
            for a in range(N.size):
                per[f][a] = boundary_omegas(g, a, mrp[f, a])
    t2 = time.perf_counter()
    nc = max([1] + [len(r[0]) for fam_rows in per for r in fam_rows])
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
        params=plates_parameters(system), model=system.label or system.name, N=N, Omega=Omega,
        family_name=name, family_values=values if name else [],
        max_real_part=mrp, boundary=bnd, boundary_direction=bdir, boundary_jump=bjump,
        timings={"grid_s": t1 - t0, "boundary_s": t2 - t1, "points": int(mrp.size)}, axes=axes, system=system,
        marginal_tolerance=tol,
    )
