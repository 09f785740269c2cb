"""Pseudo-arclength continuation of periodic stick-slip orbits in one parameter: the driver and
its result, :class:`Branch`.

:func:`continue_orbit` starts from a periodic orbit (or a run that settled on one), takes
predictor–corrector steps along the branch (:mod:`.arclength`), adapts the step to the
corrector's effort, detects and locates special points between consecutive points
(:mod:`.special_points`) and stops at the bounds, after ``max_points``, below ``min_step`` or
where the branch ends (a vanishing stick phase, a Hopf point). With ``out=PATH`` every accepted
point is journaled (:mod:`.branch_store`) and the same call again resumes from there.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from typing import Sequence

import numpy as np

from ..errors import (ContinuationError, ModelError, OrbitError, ParameterError, SimulationError,
                      SteadySlidingError)
from ..files import open_ours
from ..integrate.driver import simulate
from ..integrate.result import Trajectory
from ..model.parameters import Parameters
from ..model.system_model import FrictionModel
from . import branch_store as store
from .arclength import (DEFAULT_FD_STEP, DEFAULT_TOL, MIN_TANGENT_COS, Point, Problem, correct_onto_bound,
                        monodromy_method, numeric_parameter, point_at, problem_of, step_from)
from .models import ModelResult, plates_parameters, resolve, with_parameter
from .problem import METHODS, floquet_verdict, unstable_count
from .section import Section, resolve_section
from .shooting import PeriodicOrbit
from .special_points import (APPROACH_GRAZING_STOP, FLIGHT_VANISHING_STOP, IMPACT_GRAZING_STOP, MIN_STICK_FRACTION,
                             SPECIAL_KINDS, VANISH_FIT_POINTS, SpecialPoint, approach_grazing, detect_after_point,
                             detect_after_renewal, distance_from_equilibrium, flight_vanishing, impact_grazing,
                             is_orbit)
from .start import Start, start_orbit

__all__ = ["Branch", "continue_orbit", "load_branch"]

#: Corrector iterations at or below which the next step grows, and the growth/shrink factors.
EASY_ITERATIONS, GROW, SHRINK = 4, 1.5, 0.5

#: Corrector iterations above which the next step shrinks (between the two it is kept).
HARD_ITERATIONS = 6

#: Samples per period of the run that measures the amplitude of φ of each point.
AMPLITUDE_SAMPLES = 400

#: Samples per period of the run that finds a free orbit's smallest gap to a rigid stop (refined by
#: a parabola through the smallest and its neighbours: exact for a quadratic minimum, off by
#: ~h³ |g⃛| for a sample spacing h: ~3e-8 estimated for the belt with a stop, whose grazing it
#: locates to 2e-10 of the closed reference).
GAP_SAMPLES = 2000


@dataclasses.dataclass(frozen=True, eq=False)
class Branch(ModelResult, store.NetCDFResult):
    """A branch of periodic orbits computed by :func:`continue_orbit`.

    Parameters
    ----------
    param : str
        Name of the continuation parameter (a name of ``system.parameters``: the plates' ``N``,
        ``Omega``, ...; a model file's ``--set`` path).
    values : ndarray (n,)
        Parameter value of each orbit [unit of the parameter].
    periods : ndarray (n,)
        Periods [s].
    states : ndarray (n, 2n)
        States on the Poincaré section (the model's ``state_names``).
    multipliers : ndarray (n, 2 n_free) complex
        Floquet multipliers (eigenvalues of the monodromy, ``options["monodromy"]``), by decreasing
        modulus (NaN at points without a Jacobian of their own, see ``jacobian_every``, and where an
        impact lands too slowly for them to be resolved, :data:`.arclength.GRAZING_LANDING_RTOL`).
    stable : ndarray (n,) bool
        Every non-trivial multiplier inside the unit circle (by more than the multipliers' own
        error, :func:`~stickslip.orbits.problem.floquet_verdict`: :attr:`verdicts` tells a
        marginal orbit, on the circle within it, from an unstable one).
    n_unstable : ndarray (n,) int
        Non-trivial multipliers outside the unit circle (−1 where they are not known).
    stick_phases : ndarray (n,) int
        Slip → stick transitions per period (0: pure slip).
    stick_time : ndarray (n,)
        Total time in stick per period [s].
    amplitude : ndarray (n,)
        Peak-to-peak range of the model's observed dof (the plates' φ [rad]) over one period.
    arclength : ndarray (n,)
        Scaled pseudo-arclength from the first point [-].
    residuals : ndarray (n,)
        max |Φ(s0, T) − s0| / σ at each point [-].
    iterations : ndarray (n,) int
        Corrector iterations of each point (0 for the start).
    special : list of SpecialPoint
        The special points located on the branch (folds, period doublings, changes in the stick
        or flight phases, ...), in the order found.
    stop_reason : str
        Why the continuation ended (``bounds``, ``max_points``, ``min_step``, ``stop_on fold``,
        ``steady sliding at <param> = <value>`` where the corrector converged onto the equilibrium
        (that point is not in the branch), ``flight vanishing (grazing of a rigid contact)`` or
        ``impact grazing (...)`` (an impact's landing speed vanishes, or the free orbits touch a
        rigid stop) with a ``grazing`` point after the last, ...).
    system : FrictionModel
        The model at the start (the continuation parameter at its start value); ``params`` and
        ``model``: the plates' Parameters and variant, or None and the model's name.
    section : Section
        The Poincaré section of every point's state (:class:`stickslip.orbits.section.Section`).
    options : dict
        Numerical options (rtol, atol, tol, fd_step, step bounds, scales).
    timings : dict
        ``total_s``, ``simulations``, ``points`` (and ``points_resumed`` when written to ``out``).
    digest : str
        Digest of everything that determines the branch (start and settings); a run writing to
        the same ``out`` with another digest is refused.
    open_phases : ndarray (n,) int, or None
        Openings of the unilateral contacts per period (flight phases; 0: the contacts stay
        closed); None for a model without unilateral contacts.
    open_time : ndarray (n,), or None
        Time with some unilateral contact open per period [s]; None as ``open_phases``.
    """

    param: str
    values: np.ndarray
    periods: np.ndarray
    states: np.ndarray
    multipliers: np.ndarray
    stable: np.ndarray
    n_unstable: np.ndarray
    stick_phases: np.ndarray
    stick_time: np.ndarray
    amplitude: np.ndarray
    arclength: np.ndarray
    residuals: np.ndarray
    iterations: np.ndarray
    special: list
    stop_reason: str
    system: FrictionModel
    section: Section
    options: dict
    timings: dict
    digest: str = ""
    open_phases: np.ndarray | None = None
    open_time: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.values.size)

    @property
    def verdicts(self) -> list:
        """Floquet verdict of each orbit: ``stable``, ``marginal``, ``unstable`` or ``unknown``
        (no multipliers, ``jacobian_every``) (:func:`~stickslip.orbits.problem.floquet_verdict`)."""
        return [floquet_verdict(m) for m in self.multipliers]

    def folds(self) -> list:
        """The special points of kind ``fold``."""
        return [p for p in self.special if p.kind == "fold"]

    def orbit_system(self, i: int) -> FrictionModel:
        """The model of orbit ``i``."""
        return with_parameter(self.system, self.param, float(self.values[i]))

    def orbit_params(self, i: int) -> Parameters | None:
        """The plates' Parameters of orbit ``i`` (None for other models: :meth:`orbit_system`)."""
        return plates_parameters(self.orbit_system(i))

    def trajectory(self, i: int, periods: float = 1.0, sample_rate: float = 1000.0) -> Trajectory:
        """Simulate orbit ``i`` from its section state (for plots)."""
        o = self.options
        return simulate(self.orbit_system(i), periods * float(self.periods[i]), ic=self.states[i], rtol=o["rtol"],
                        atol=o["atol"], sample_rate=sample_rate)
    def to_xarray(self):
        """``xarray.Dataset`` with dims ``point``, ``state``, ``multiplier`` and ``special``."""
        return store.branch_dataset(self)

    @classmethod
    def from_xarray(cls, ds) -> "Branch":
        """The branch of a dataset written by :meth:`to_xarray` (files of this version: with
        ``section_spec`` and the special points' multipliers)."""
        fields = store.branch_fields(ds)
        return cls(**{**fields, "special": [SpecialPoint(**q) for q in fields["special"]]})


def load_branch(path):
    """Read a branch written by :meth:`Branch.to_netcdf` as an ``xarray.Dataset``.

    Parameters
    ----------
    path : str or Path
        The NetCDF file (``stickslip continue --out``, :meth:`Branch.to_netcdf`).

    Returns
    -------
    xarray.Dataset
        Dimensions ``point``, ``state``, ``multiplier`` and ``special`` (:meth:`Branch.to_xarray`);
        :meth:`Branch.from_xarray` rebuilds the :class:`Branch`.

    Raises
    ------
    stickslip.files.FileFormatError
        If the file is missing, truncated, not a stickslip branch or of a newer format (a ValueError).
    """
    return open_ours(path, "branch", what="a .nc file written by `stickslip continue` (Branch.to_netcdf)")


def _read_branch(path) -> tuple:
    """(attrs, Branch) of a branch file, for :func:`.branch_store.open_output` (files of earlier
    versions have no digest: they are refused by it, not read)."""
    ds = load_branch(path)
    return ds.attrs, (Branch.from_xarray(ds) if ds.attrs.get("digest") else None)


def _smallest_rigid_gap(problem: Problem, point) -> float:
    """The smallest gap of the rigid contacts over one period of ``point``'s orbit [m] (NaN if the run
    fails): the smallest sample of :data:`GAP_SAMPLES` per period, refined by the parabola through it
    and its neighbours."""
    s, T, lam = problem.unpack(point.v)
    system = problem.system_at(lam)
    sp = problem.shooting
    try:
        traj = simulate(system, T, ic=s, sample_rate=GAP_SAMPLES / T,
                        max_steps=int(sp.max_steps_per_second * max(T, 1.0)), rtol=sp.rtol, atol=sp.atol)
    except SimulationError:
        return float("nan")
    rigid = [c for c, contact in enumerate(system.contacts) if contact.unilateral and contact.normal.law == "rigid"]
    if traj.status != "success" or not rigid:
        return float("nan")
    g = np.min(traj.gap[:, rigid], axis=1)
    i = int(np.clip(np.argmin(g), 1, g.size - 2))
    curvature = g[i - 1] - 2.0 * g[i] + g[i + 1]
    return float(g[i] - (g[i + 1] - g[i - 1]) ** 2 / (8.0 * curvature) if curvature > 0.0 else g[i])


def _amplitude(problem: Problem, s: np.ndarray, T: float, lam: float) -> float:
    """Peak-to-peak range of the observed dof (the plates' φ [rad]) over one period from a sampled
    run (NaN if it fails)."""
    sp = problem.shooting
    system = problem.system_at(lam)
    try:
        traj = simulate(system, T, ic=s, sample_rate=AMPLITUDE_SAMPLES / T,
                        max_steps=int(sp.max_steps_per_second * max(T, 1.0)), rtol=sp.rtol, atol=sp.atol)
    except SimulationError:
        return float("nan")
    return float(np.ptp(traj.states[:, system.observed_index])) if traj.status == "success" else float("nan")


def continue_orbit(
    model=None,
    param: str = "Omega",
    start=None,
    *,
    direction: int = 1,
    step: float = 0.02,
    min_step: float = 1e-4,
    max_step: float = 0.2,
    max_points: int = 200,
    bounds: tuple[float, float] | None = None,
    stop_on: Sequence[str] = (),
    locate: bool = True,
    section="max",
    rtol: float = 1e-10,
    atol: float | None = None,
    tol: float = DEFAULT_TOL,
    fd_step: float = DEFAULT_FD_STEP,
    param_scale: float | None = None,
    slip_band: float | None = None,
    amplitude: bool = True,
    min_stick_fraction: float = MIN_STICK_FRACTION,
    jacobian_every: int = 1,
    monodromy: str = "auto",
    callback=None,
    out=None,
    resume: bool = True,
    on_resume=None,
) -> Branch:
    """Continue a periodic orbit in one parameter by pseudo-arclength continuation.

    Unknowns: the free states on the Poincaré section (except the section coordinate), the period T
    and the parameter λ; equations: the shooting equations Φ(s0, T; λ) − s0 = 0 on the free states
    (Φ the ``event`` method's flow) and the arclength condition τᵀ (v − v_k) = h in scaled
    unknowns v = (s0/σ, T/T_0, λ/λ_s). docs/continuation.md has the method, the stops and resuming.

    Parameters
    ----------
    model : FrictionModel, Parameters, str, optional
        The model at the start, as :func:`stickslip.simulate` takes it (default: that of ``start``
        if it is a PeriodicOrbit or a run, else the plates with Table 1).
    param : str
        The parameter to vary: any numeric parameter of the model (the plates' ``N`` [N],
        ``Omega`` [rad/s], ...; a model file's ``--set`` path, ``contact.0.drive``, ...).
    start : PeriodicOrbit, Trajectory, array-like (2n,), mapping or "equilibrium"
        The first orbit; or a run that settled on it (:func:`~stickslip.orbits.start.start_orbit_from_run`);
        or a state handed to :func:`~stickslip.orbits.periodic_orbit`.
    direction : {+1, −1}
        Start towards increasing (+1) or decreasing (−1) λ.
    step, min_step, max_step : float
        Initial, smallest and largest step in scaled arclength [-]: ×1.5 after an easy corrector,
        ×0.5 after a failure; the continuation stops below ``min_step``.
    max_points : int
        Branch points to compute (the start included).
    bounds : (lo, hi), optional
        Interval of λ; the continuation ends on its edge (the last point corrected at λ = edge).
    stop_on : sequence of str
        Special-point kinds (:data:`SPECIAL_KINDS`) after which to stop, e.g. ``("fold",)``; ``grazing``
        (a unilateral contact's flight phase appears or vanishes) only where the model has one.
    locate : bool
        Locate special points (Illinois/bisection); otherwise they are reported at the next point.
    section, rtol, atol, slip_band
        As :func:`~stickslip.orbits.periodic_orbit` (used when ``start`` is not an orbit).
    tol : float
        Corrector convergence: max |Φ(s0, T) − s0| / σ ≤ tol [-].
    fd_step : float
        Relative finite-difference step of the Jacobian columns [-].
    param_scale : float, optional
        λ_s, the unit of λ in the arclength (default |λ0|, or 1 if λ0 = 0).
    amplitude : bool
        Measure the peak-to-peak range of the observed dof of every orbit (one extra run per point).
    min_stick_fraction : float
        Stop where the stick time per period falls below this fraction of the period [-].
    jacobian_every : int
        Recompute the Jacobian at every ``jacobian_every``-th point only (in between the
        corrector's Broyden update gives the tangent; those points have NaN multipliers and
        ``n_unstable`` −1).
    monodromy : {"auto", "saltation", "finite-difference"}
        Each point's monodromy; ``auto``: saltation with a rigid contact (:func:`.arclength.monodromy_method`).
    callback : callable, optional
        ``callback(i, value, period, stable)`` after each accepted point (once journaled).
    out : path, optional
        NetCDF output (``.nc``), journaled point by point (``OUT.nc.journal``) as it is computed.
    resume : bool
        With ``out``: continue an interrupted run, or return the finished branch, written with the
        same start and settings; False: delete ``out`` and its journal and start over.
    on_resume : callable, optional
        ``on_resume(k)`` once, before any computation, when ``k`` points are read from ``out``.

    Returns
    -------
    Branch

    Raises
    ------
    ContinuationError
        If ``param`` is not numeric, the start orbit cannot be found, or the first Jacobian fails.
    SteadySlidingError
        If the start orbit is steady sliding, not a cycle (a ContinuationError).
    stickslip.orbits.branch_store.JournalMismatch
        If ``out`` or its journal was written with another start or other settings, or, for a
        model with unilateral contacts, by a version that did not count their open phases.
    """
    t_start = time.perf_counter()
    _check_request(direction, step, min_step, max_step, max_points, jacobian_every, stop_on, monodromy)
    system, (lo, hi) = _resolved(model, start, param, slip_band, bounds)
    atol, section = 1e-3 * rtol if atol is None else float(atol), resolve_section(section, system)
    numerics = dict(direction=direction, step=step, min_step=min_step, max_step=max_step, max_points=max_points,
                    bounds=None if bounds is None else [lo, hi], stop_on=list(stop_on), locate=bool(locate),
                    tol=tol, fd_step=fd_step, param_scale=param_scale, amplitude=bool(amplitude),
                    jacobian_every=int(jacobian_every), min_stick_fraction=min_stick_fraction,
                    monodromy=monodromy_method(system, monodromy))
    settings, digest = _settings(system, param, start, section, rtol, atol, numerics)
    journal, finished = _open_output(out, system, digest, settings, resume, on_resume)
    if finished is not None:  # nothing left to compute
        return finished
    run = _Continuation.begin(system, param, start, section, rtol, atol, numerics, journal, callback, on_resume, t_start)
    run.go_on()
    return run.finish(rtol, atol, digest, out)


def _resolved(model, start, param: str, slip_band, bounds) -> tuple:
    """The model of :func:`continue_orbit` (by default that of a ``start`` orbit or run) and (lo, hi)
    of its ``bounds`` (:func:`_bounds`)."""
    system = resolve(start.system if model is None and isinstance(start, (PeriodicOrbit, Trajectory)) else model,
                     slip_band)
    lam_start = numeric_parameter(start.system if isinstance(start, PeriodicOrbit) else system, param)
    return system, _bounds(bounds, param, lam_start)


def _bounds(bounds, param: str, lam_start: float) -> tuple:
    """(lo, hi) of ``bounds`` (None, None without), refused unless lo < hi contains the start."""
    if bounds is None:
        return None, None
    lo, hi = float(bounds[0]), float(bounds[1])
    if not (lo < hi) or not (lo <= lam_start <= hi):
        raise ContinuationError(f"bounds ({lo:g}, {hi:g}) must satisfy lo < hi and contain the start "
                                f"{param} = {lam_start:g}")
    return lo, hi


def _open_output(out, system: FrictionModel, digest: str, settings: dict, resume: bool, on_resume) -> tuple:
    """(journal, finished): the journal of ``out`` (None without ``out``), and the branch already
    finished there (None if there is work left; with its resumed count)."""
    if out is None:
        return None, None
    journal, finished = store.open_output(out, "branch", digest, settings, resume, _read_branch)
    if system.unilateral:
        _refuse_without_open_phases(out, journal, finished)
    if finished is None:
        return journal, None
    if on_resume is not None:
        on_resume(len(finished))
    return journal, dataclasses.replace(finished, timings={**finished.timings, "points_resumed": len(finished)})


#: What :meth:`_Continuation.advance` catches as a failed step (shrunk and tried again).
_STEP_FAILURES = (OrbitError, SimulationError, ParameterError, ModelError, np.linalg.LinAlgError)


@dataclasses.dataclass(eq=False)
class _Continuation:
    """A continuation under way (internal): the problem, the walk so far and the numerical options
    (:func:`continue_orbit`'s ``numerics``), with one method per part of a step."""

    problem: Problem
    begin_orbit: Start
    walk: "_Walk"
    numerics: dict
    journal: object
    callback: object
    measure: object
    size0: float | None
    resumed: int
    t_start: float

    @classmethod
    def begin(cls, system, param, start, section, rtol, atol, numerics, journal, callback, on_resume, t_start):
        """The start orbit (found, or read from the journal) and the walk at its first point, or
        at the last journaled one."""
        records = [] if journal is None else journal.records
        start_rec = next((r["start"] for r in records if "start" in r), None)
        if start_rec is None:
            begin = Start.of(start_orbit(system, param, start, section, rtol, atol))
            if journal is not None:
                journal.append({"start": store.start_record(begin)})
        else:
            begin = Start(**store.start_fields(start_rec))
        problem = problem_of(begin, param, numerics["fd_step"], numerics["param_scale"], numerics["monodromy"])
        lam0 = numeric_parameter(begin.system, param)
        if not is_orbit(problem, begin.state, lam0, begin.stick_phases):
            if journal is not None:
                journal.remove()  # it holds no work: nothing to resume
            raise SteadySlidingError(param, lam0)
        measure = (lambda p: _amplitude(problem, *problem.unpack(p.v))) if numerics["amplitude"] \
            else (lambda p: float("nan"))
        walk = _walk_from_records(records)
        resumed = 0 if walk is None else len(walk.points)
        if walk is None:
            walk = _first_walk(problem, begin, numerics["direction"], numerics["step"], measure)
            _journal_point(journal, walk, problem, [], 0.0, t_start)
        else:
            problem.counter["simulations"] = walk.simulations
            if on_resume is not None:
                on_resume(len(walk.points))
        size0 = distance_from_equilibrium(problem, begin.state, problem.unpack(walk.points[0].v)[2]) \
            if begin.stick_phases == 0 else None
        return cls(problem, begin, walk, numerics, journal, callback, measure, size0, resumed, t_start)

    def go_on(self) -> None:
        """Take steps until the walk stops or has ``max_points`` points."""
        walk = self.walk
        while walk.stop is None and len(walk.points) < self.numerics["max_points"]:
            self.advance()

    def advance(self) -> None:
        """One step along the branch from its last point: predictor and corrector (:func:`.arclength.step_from`,
        with a fresh finite-difference Jacobian every ``jacobian_every`` points), the edge of the
        bounds, then :meth:`accept`; a failed step :meth:`recovers <recover>`."""
        walk, numerics = self.walk, self.numerics
        last = walk.points[-1]
        fresh = (len(walk.points) - walk.fresh_index) >= numerics["jacobian_every"]
        try:
            new = step_from(self.problem, last, walk.h, numerics["tol"], with_jacobian=fresh)
            if float(new.tangent @ last.tangent) < MIN_TANGENT_COS:
                raise OrbitError("tangent turned too far")
        except _STEP_FAILURES:
            self.recover(last)
            return
        stop = None
        bounds = numerics["bounds"]
        lam_new = self.problem.unpack(new.v)[2]
        if bounds is not None and not (bounds[0] <= lam_new <= bounds[1]):
            try:
                new = correct_onto_bound(self.problem, last, new, bounds[1] if lam_new > bounds[1] else bounds[0],
                                         numerics["tol"])
            except _STEP_FAILURES:
                walk.stop = "bounds (last point before the edge)"
                return
            stop = "bounds"
        self.accept(last, new, stop)

    def recover(self, last: Point) -> None:
        """After a failed step: first renew the Broyden-updated Jacobian of the last point (and look
        for special points again with it), then shrink the step; below ``min_step`` the walk stops.
        Step changes are not journaled: a resumed run repeats these deterministic retries."""
        walk, numerics = self.walk, self.numerics
        if not last.fresh:
            try:
                walk.points[-1] = point_at(self.problem, last.v, last.iterations, last.tangent)
                found, walk.stop = detect_after_renewal(self.problem, walk, numerics["tol"], numerics["locate"],
                                                        self.size0, numerics["stop_on"])
                walk.fresh_index = len(walk.points) - 1
                walk.special.extend(found)
                _journal_point(self.journal, walk, self.problem, found, walk.elapsed, self.t_start)  # replaces it
                return
            except (OrbitError, SimulationError):
                pass
        walk.h *= SHRINK
        if walk.h < numerics["min_step"]:
            walk.stop = "min_step"

    def accept(self, last: Point, new: Point, stop: str | None) -> None:
        """Add the point ``new``: the special points between ``last`` and it (a point that is steady
        sliding is dropped and ends the branch), its arclength and amplitude, the next step's size
        from the corrector's effort, the journal and the callback."""
        walk, numerics, problem = self.walk, self.numerics, self.problem
        walk.points.append(new)
        found, stop, quiet, drop = detect_after_point(problem, walk, last, new, stop, numerics["tol"],
                                                      numerics["locate"], numerics["min_stick_fraction"], self.size0,
                                                      numerics["stop_on"])
        if drop:  # steady sliding, not an orbit: the branch ends at the point before
            walk.points.pop()
        else:
            new = walk.points[-1]  # its Jacobian may have been renewed to classify a turn
            walk.arclength.append(walk.arclength[-1] + float(np.linalg.norm(new.v - last.v)))
            walk.amplitudes.append(self.measure(new))
        walk.special.extend(found)
        walk.stop = stop
        if stop is None:
            if new.iterations <= EASY_ITERATIONS:
                walk.h = min(walk.h * GROW, numerics["max_step"])
            elif new.iterations >= HARD_ITERATIONS:
                walk.h = max(walk.h * SHRINK, numerics["min_step"])
        _journal_point(self.journal, walk, problem, found, walk.elapsed, self.t_start)
        if self.callback is not None and not quiet:
            _s, T_new, lam_cb = problem.unpack(new.v)
            self.callback(len(walk.points) - 1, lam_cb, T_new, floquet_verdict(new.multipliers) == "stable")

    def finish(self, rtol: float, atol: float, digest: str, out) -> Branch:
        """The :class:`Branch` of the finished walk (a grazing point where a rigid contact's flight
        vanished), written to ``out`` (the journal removed)."""
        walk, journal, numerics, problem = self.walk, self.journal, self.numerics, self.problem
        options = dict(rtol=rtol, atol=atol, **{key: numerics[key] for key in ("tol", "fd_step", "step", "min_step",
                                                                                "max_step", "max_points")},
                       slip_band=problem.shooting.system.slip_band, param_scale=problem.p_scale,
                       period_scale=problem.T_scale, bounds=numerics["bounds"], direction=numerics["direction"],
                       jacobian_every=numerics["jacobian_every"], monodromy=numerics["monodromy"])
        if walk.stop == "min_step" and self.problem.shooting.system.rigid and _flight_vanished(walk):
            walk.stop = FLIGHT_VANISHING_STOP
        elif walk.stop == "min_step" and self.problem.shooting.system.rigid:
            approach = functools.partial(approach_grazing, smallest_gap=lambda p: _smallest_rigid_gap(self.problem, p))
            for ends, reason in ((flight_vanishing, FLIGHT_VANISHING_STOP), (impact_grazing, IMPACT_GRAZING_STOP),
                                 (approach, APPROACH_GRAZING_STOP)):
                grazing = ends(self.problem, walk.points)
                if grazing is not None:
                    walk.special.append(grazing)
                    walk.stop = reason
                    break
        stop_reason = walk.stop or "max_points"
        if journal is not None and "stop" not in (journal.records[-1] if journal.records else {}):
            journal.append({"end": stop_reason})
        branch = _assemble_branch(self.problem, self.begin_orbit, walk, stop_reason, options,
                                  walk.elapsed + time.perf_counter() - self.t_start,
                                  self.resumed if out is not None else None, digest)
        if journal is not None:
            store.write_dataset(branch.to_xarray(), out)
            journal.remove()
        return branch


def _flight_vanished(walk: "_Walk") -> bool:
    """Whether the walk ends just past a located grazing where the flight phases ended (→ 0; within
    its last :data:`.special_points.VANISH_FIT_POINTS` points, none of which flies): a rigid
    contact's flight vanished there, and with it a section that lies in the flight."""
    last = walk.special[-1] if walk.special else None
    if last is None or last.kind != "grazing" or last.after != 0 or not last.located:
        return False
    after = walk.points[last.index + 1:]
    return len(after) <= VANISH_FIT_POINTS and all(p.open_phases == 0 for p in after)


def _settings(system, param, start, section, rtol, atol, numerics: dict) -> tuple[dict, str]:
    """(settings, digest) of a branch (:func:`.branch_store.branch_settings`); a branch by
    differences keeps the digest it had before the choice of monodromy existed (its journal resumes)."""
    recorded = {k: v for k, v in numerics.items() if k != "monodromy" or v != "finite-difference"}
    settings = store.branch_settings(system, param, start, section, rtol, atol, recorded)
    return settings, store.digest_of(settings)


def _check_request(direction, step, min_step, max_step, max_points, jacobian_every, stop_on, monodromy) -> None:
    """Refuse bad numerical options of :func:`continue_orbit` before computing (ContinuationError)."""
    if monodromy not in ("auto",) + METHODS:
        raise ContinuationError(f"unknown monodromy {monodromy!r}; choose auto, {', '.join(METHODS)}")
    if direction not in (1, -1):
        raise ContinuationError(f"direction must be +1 or -1, got {direction}")
    if not (0.0 < min_step <= step <= max_step):
        raise ContinuationError(f"need 0 < min_step <= step <= max_step, got {min_step}, {step}, {max_step}")
    if max_points < 1:
        raise ContinuationError(f"max_points must be >= 1, got {max_points}")
    if int(jacobian_every) < 1:
        raise ContinuationError(f"jacobian_every must be >= 1, got {jacobian_every}")
    unknown = sorted(set(stop_on) - set(SPECIAL_KINDS))
    if unknown:
        raise ContinuationError(f"unknown stop_on kind(s) {', '.join(unknown)}; choose from {', '.join(SPECIAL_KINDS)}")


def _refuse_without_open_phases(out, journal, finished) -> None:
    """Refuse the journal or finished output of an earlier version that did not count the open
    phases (:func:`.branch_store.refuse_without_open_phases`), releasing the output's lock."""
    try:
        store.refuse_without_open_phases(out, None if journal is None else journal.records, finished)
    except store.JournalMismatch:
        if journal is not None:
            journal.close()
        raise


def _first_walk(problem: Problem, begin: Start, direction: int, step: float, measure) -> "_Walk":
    """The walk at its first point: the start orbit with its Jacobian, tangent and amplitude."""
    v0 = problem.pack(begin.state, begin.period, numeric_parameter(begin.system, problem.param))
    try:
        p0 = point_at(problem, v0, 0, None, float(direction))
    except (OrbitError, SimulationError) as exc:
        raise ContinuationError(f"the Jacobian at the start orbit failed: {exc}") from exc
    return _Walk(points=[p0], arclength=[0.0], amplitudes=[measure(p0)], special=[], h=float(step))


@dataclasses.dataclass(eq=False)
class _Walk:
    """The state of a continuation between two points (internal): what the journal records."""

    points: list
    arclength: list
    amplitudes: list
    special: list
    h: float  # the next step
    fresh_index: int = 0  # the last point with a finite-difference Jacobian
    stop: str | None = None  # why it ends after the last point (None: it goes on)
    simulations: int = 0  # flow maps up to the last journaled point
    elapsed: float = 0.0  # wall time of earlier (interrupted) runs [s]


def _journal_point(journal, walk: _Walk, problem: Problem, found: list, elapsed: float, t_start: float) -> None:
    """Append the last point of ``walk``, the special points ``found`` with it and the state
    after it (nothing if not writing)."""
    if journal is None:
        return
    k = len(walk.points) - 1
    rec = {"point": k, **store.point_record(walk.points[k]), "amplitude": float(walk.amplitudes[k]),
           "arclength": float(walk.arclength[k]), "special": [q.to_record() for q in found], "h": float(walk.h),
           "fresh_index": int(walk.fresh_index), "simulations": int(problem.counter["simulations"]),
           "elapsed": float(elapsed + time.perf_counter() - t_start)}
    if walk.stop is not None:
        rec["stop"] = walk.stop
    journal.append(rec)


def _walk_from_records(records: list) -> _Walk | None:
    """The :class:`_Walk` after the last journaled point (None if no point was journaled).

    A later record of the same point (its Jacobian renewed) replaces the earlier one.
    """
    every = [r for r in records if "point" in r]
    if not every:
        return None
    last = every[-1]
    pts = list({int(r["point"]): r for r in every}.values())  # the last record of each point, in point order
    ends = [r["end"] for r in records if "end" in r]
    return _Walk(points=[Point(**store.point_fields(r)) for r in pts], arclength=[float(r["arclength"]) for r in pts],
                 amplitudes=[float(r["amplitude"]) for r in pts],
                 special=[SpecialPoint.from_record(q) for r in every for q in r["special"]], h=float(last["h"]),
                 fresh_index=int(last["fresh_index"]), stop=last.get("stop") or (ends[-1] if ends else None),
                 simulations=int(last["simulations"]), elapsed=float(last["elapsed"]))


def _assemble_branch(problem: Problem, begin: Start, walk: _Walk, stop_reason: str, options: dict,
                     total_s: float, resumed: int | None, digest: str) -> Branch:
    """The :class:`Branch` of a finished walk (``resumed``: points read from a journal, None if not writing)."""
    points = walk.points
    unpacked = [problem.unpack(p.v) for p in points]
    states = np.array([u[0] for u in unpacked])
    periods = np.array([u[1] for u in unpacked])
    values = np.array([u[2] for u in unpacked])
    mult = np.array([p.multipliers for p in points])
    n_unst = np.array([unstable_count(p.multipliers) if p.has_multipliers else -1 for p in points])
    timings = {"total_s": total_s, "points": len(points), "simulations": problem.counter["simulations"]}
    opened = {} if points[0].open_phases is None else {
        "open_phases": np.array([p.open_phases for p in points]), "open_time": np.array([p.open_time for p in points])}
    if resumed is not None:
        timings["points_resumed"] = resumed
    return Branch(param=problem.param, values=values, periods=periods, states=states, multipliers=mult,
                  stable=np.array([floquet_verdict(p.multipliers) == "stable" for p in points], dtype=bool),
                  n_unstable=n_unst, stick_phases=np.array([p.stick_phases for p in points]),
                  stick_time=np.array([p.stick_time for p in points]),
                  amplitude=np.array(walk.amplitudes, dtype=float), arclength=np.array(walk.arclength),
                  residuals=np.array([p.residual for p in points]),
                  iterations=np.array([p.iterations for p in points]), special=list(walk.special),
                  stop_reason=stop_reason, system=begin.system, section=begin.section,
                  options=options, timings=timings, digest=digest, **opened)


