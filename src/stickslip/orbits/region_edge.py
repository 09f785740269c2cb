"""The upper edge of Region II (paper Fig. 8): where the stick-slip orbit ends, over N.

For each N, :func:`fold_curve` continues the stick-slip orbit that the ``far`` initial condition
reaches at ``omega_start`` up in Ω (:func:`~stickslip.orbits.branch.continue_orbit`) until the
branch ends — at a fold of cycles or where its stick phase vanishes — in worker processes (one N
a task), journaling each N as it finishes. Between the linear-stability boundary Ω_c(N) and this
edge the stable stick-slip orbit coexists with the stable equilibrium. :func:`unstable_cycle`
finds the saddle cycle on the boundary between their basins by edge tracking.
"""

from __future__ import annotations

import dataclasses
import time
from concurrent.futures import as_completed
from typing import Sequence

import numpy as np

from ..errors import ContinuationError, OrbitError, SimulationError
from ..files import open_ours
from ..integrate.driver import simulate
from ..model.library import two_plates
from ..model.library.two_plates import is_plates, plates_parameters
from ..model.parameters import Parameters
from ..model.system_model import DEFAULT_SLIP_BAND
from ..parallel import check_workers, worker_pool
from . import branch_store as store
from .branch import Branch, continue_orbit
from .layout import equilibrium_state
from .models import resolve
from .shooting import PeriodicOrbit, periodic_orbit
from .start import START_RATE, start_orbit_from_run, start_run

__all__ = ["FoldCurve", "fold_curve", "load_fold_curve", "branch_edge", "unstable_cycle"]

#: If the ``far`` start at ``omega_start`` gives no stick-slip orbit (N = 10 N, Ω = 5 rad/s reaches a
#: slip-only oscillation), the start is retried at this fraction of ``omega_start`` (Region I).
START_FALLBACK = 0.6


#: Integration tolerance and corrector tolerance of :func:`fold_curve`: a flow map costs 1.4 ms
#: instead of 2.2 ms at rtol 1e-10 (Model 1, N = 50 N, measured), and the edge Ω, fixed by where
#: the stick time vanishes, moves by < 1e-3 rad/s (docs/continuation.md).
FOLD_RTOL, FOLD_TOL = 1e-9, 1e-7

#: Finite-difference Jacobian every this many points in :func:`fold_curve` (Broyden in between):
#: the edge needs the tangent and the stick time, not the multipliers of every point.
FOLD_JACOBIAN_EVERY = 4


@dataclasses.dataclass(frozen=True, eq=False)
class FoldCurve(store.NetCDFResult):
    """The upper edge of the stick-slip domain over N: where the stable stick-slip orbit ends.

    For each N the stick-slip orbit found from the ``far`` initial condition at ``omega_start``
    is continued in Ω (:func:`continue_orbit`) until it ends, at a fold of cycles (``fold``) or
    where its stick phase vanishes (``stick-vanishing``). Above the edge no stick-slip orbit of
    this branch exists; between the linear-stability boundary Ω_c(N) and the edge it coexists with
    the stable equilibrium (Region II of paper Fig. 8).

    Parameters
    ----------
    N : ndarray (n,)
        Normal loads [N].
    edge : ndarray (n,)
        Ω at the end of the branch [rad/s] (NaN if none was found).
    kind : tuple of str
        ``fold``, ``stick-vanishing``, ``bounds`` (the branch reached ``omega_max``) or ``failed``.
    located : ndarray (n,) bool
        The edge was located to tolerance.
    period : ndarray (n,)
        Period at the edge [s].
    omega_stable_max : ndarray (n,)
        Largest Ω of a stable orbit on the branch [rad/s].
    points : ndarray (n,) int
        Branch points computed.
    seconds : ndarray (n,)
        Wall time of each N [s].
    message : tuple of str
        Stop reason or error of each N.
    omega_start : float
        Ω of the start orbits [rad/s].
    params : Parameters
        The plates' base parameters (N is set to each of :attr:`N` in turn, Ω continued).
    model : str
        The plates' variant (``full``, ``x``, ``y``, ``rotation``).
    timings : dict
        ``total_s``, ``workers``, ``n`` (and ``n_resumed``, the N read back, when written to ``out``).
    digest : str
        Digest of the settings that determine each N's result (see :func:`fold_curve`).
    """

    N: np.ndarray
    edge: np.ndarray
    kind: tuple
    located: np.ndarray
    period: np.ndarray
    omega_stable_max: np.ndarray
    points: np.ndarray
    seconds: np.ndarray
    message: tuple
    omega_start: float
    params: Parameters
    model: str
    timings: dict
    digest: str = ""

    def to_xarray(self):
        """``xarray.Dataset`` over ``N``."""
        return store.fold_curve_dataset(self)

    def rows(self) -> dict:
        """``{N: row}`` with row = (edge, kind, located, period, omega_stable_max, points, seconds,
        message), the per-N result of :func:`fold_curve`, as plain Python values."""
        return {float(n): store.plain_row((self.edge[i], self.kind[i], self.located[i], self.period[i],
                                           self.omega_stable_max[i], self.points[i], self.seconds[i],
                                           self.message[i]))
                for i, n in enumerate(self.N)}


def load_fold_curve(path) -> FoldCurve:
    """Read a :class:`FoldCurve` written by :meth:`FoldCurve.to_netcdf`.

    Raises
    ------
    stickslip.files.FileFormatError
        If the file is missing, truncated, not a stickslip fold curve or of a newer format (a ValueError).
    """
    ds = open_ours(path, "foldcurve", noun="fold-curve", what="a .nc file written by FoldCurve.to_netcdf")
    return FoldCurve(**store.fold_curve_fields(ds))


#: Edge tracking of :func:`unstable_cycle`: bisection steps on the segment equilibrium → orbit
#: (2⁻⁴⁰ ≈ 1e-12 of the segment, near the round-off of the states), the length of each probe run
#: [s] and the window at its end in which sticking means "reached the stick-slip orbit" [s].
EDGE_BISECTIONS, EDGE_PROBE, EDGE_WINDOW = 40, 60.0, 20.0

#: The two bracketing edge trajectories count as separated once their φ differ by this fraction of
#: the φ range of the stable orbit; the orbit guess is the part of the run before 0.9 × that time.
EDGE_SEPARATION = 0.05


def unstable_cycle(model, orbit_state: np.ndarray, *, rtol: float = 1e-10,
                   slip_band: float | None = None, section="max") -> PeriodicOrbit:
    """The saddle cycle on the boundary between the basins of a stable orbit and the equilibrium.

    Edge tracking: on the segment s(a) = s_eq + a (s_orbit − s_eq), a ∈ [0, 1], from the
    equilibrium of Eq. (14) to a state on the stable stick-slip orbit, bisection on a finds the
    basin boundary (runs from a below it stop sticking, from above they reach stick-slip). The run
    from the boundary lingers near the saddle cycle whose stable manifold the boundary is (in
    Region II, the unstable pure-slip cycle of the subcritical Hopf bifurcation at Ω_c); its part
    before the bracketing runs separate is the guess for :func:`~stickslip.orbits.periodic_orbit`.

    Parameters
    ----------
    model : FrictionModel, Parameters, str
        The model (as :func:`stickslip.simulate` takes it; e.g. ``Branch.orbit_system(i)``).
    orbit_state : ndarray (2n,)
        A state on the stable stick-slip orbit (e.g. ``Branch.states[i]``).
    rtol, slip_band, section
        As :func:`~stickslip.orbits.periodic_orbit`.

    Returns
    -------
    PeriodicOrbit

    Raises
    ------
    ContinuationError
        If the equilibrium end does not go to the equilibrium or the orbit end does not stick.
    """
    system = resolve(model, slip_band)
    s_eq = equilibrium_state(system)
    s_orb = np.asarray(orbit_state, dtype=float)
    atol = 1e-3 * rtol
    obs = system.observed_index

    def run(a, t_end=EDGE_PROBE, rate=100.0):
        return simulate(system, t_end, ic=s_eq + a * (s_orb - s_eq), sample_rate=rate, rtol=rtol, atol=atol)

    def sticks(a):
        tr = run(a)
        return bool(tr.mode[tr.t >= EDGE_PROBE - EDGE_WINDOW].any())

    lo, hi = 0.0, 1.0
    if not sticks(hi) or sticks(1e-3):
        raise ContinuationError("edge tracking needs a stable stick-slip orbit and a stable equilibrium "
                                "(Region II) at these parameters")
    for _ in range(EDGE_BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if sticks(mid) else (mid, hi)
    a_lo, a_hi = run(lo, rate=START_RATE), run(hi, rate=START_RATE)
    scale = max(float(np.ptp(a_hi.states[a_hi.t >= EDGE_PROBE - EDGE_WINDOW, obs])), 1e-12)
    apart = np.flatnonzero(np.abs(a_lo.states[:, obs] - a_hi.states[:, obs]) > EDGE_SEPARATION * scale)
    t_sep = a_lo.t[apart[0]] if apart.size else EDGE_PROBE
    m = int(np.searchsorted(a_lo.t, 0.9 * t_sep))
    guess = dataclasses.replace(a_lo, t=a_lo.t[:m], states=a_lo.states[:m], mode=a_lo.mode[:m])
    try:
        return periodic_orbit(None, guess, section=section, rtol=rtol, max_iter=40)
    except (OrbitError, SimulationError) as exc:
        raise ContinuationError(f"no saddle cycle from the edge run (it lingered {0.9 * t_sep:.1f} s): {exc}") from exc


def branch_edge(branch: Branch) -> tuple:
    """(Ω at the end, kind, located, period) of a branch continued until it ends."""
    for p in branch.special:
        if p.kind in ("fold", "stick-vanishing"):
            return p.value, p.kind, p.located, p.period
    if branch.stop_reason.startswith("bounds"):
        return float("nan"), "bounds", False, float("nan")
    return float("nan"), "failed", False, float("nan")


def _edge_at(N: float, params: Parameters, omega_start: float, omega_max: float, model: str, options: dict):
    """One N of :func:`fold_curve` (runs in a worker process)."""
    t0 = time.perf_counter()
    rtol = options.get("rtol", 1e-10)
    band = options.get("slip_band")
    errors = []
    for omega in (omega_start, START_FALLBACK * omega_start):
        p = params.replace(N=float(N), Omega=float(omega))
        try:
            plates = two_plates(p, model, DEFAULT_SLIP_BAND if band is None else band)
            run = start_run(plates, "far", rtol=rtol, slip_band=band)
            orbit = start_orbit_from_run(run, rtol=rtol, slip_band=band)
            if orbit.stick_phases == 0:
                raise ContinuationError(f"the start orbit at Omega = {omega:g} rad/s has no stick phase")
            break
        except (OrbitError, SimulationError) as exc:
            errors.append(str(exc).splitlines()[0][:200])
    else:
        return (float("nan"), "failed", False, float("nan"), float("nan"), 0, time.perf_counter() - t0,
                "; ".join(errors))
    try:
        branch = continue_orbit(start=orbit, param="Omega", bounds=(omega, omega_max), stop_on=("fold",),
                                amplitude=False, **options)
    except (OrbitError, SimulationError) as exc:
        return (float("nan"), "failed", False, float("nan"), float("nan"), 0, time.perf_counter() - t0,
                str(exc).splitlines()[0][:200])
    edge, kind, located, period = branch_edge(branch)
    stable = branch.values[branch.stable]
    return (edge, kind, located, period, float(stable.max()) if stable.size else float("nan"), len(branch),
            time.perf_counter() - t0, branch.stop_reason)


def _plates_of(model, options: dict) -> tuple[Parameters, str]:
    """The plates' Parameters and variant that ``model`` names (the fold curve's start runs are
    the plates' ``far``); a low-speed band of its own joins ``options``."""
    system = resolve(model)
    if not is_plates(system):
        raise ContinuationError(f"the fold curve is the plates' Region II edge; model {system.name!r} is not the two "
                                "plates: continue its orbits with continue_orbit")
    if system.slip_band != DEFAULT_SLIP_BAND:
        options.setdefault("slip_band", system.slip_band)
    return plates_parameters(system), system.label


def fold_curve(N: Sequence[float], model=None, *, omega_start: float = 5.0,
               omega_max: float = 40.0, workers: int = 1, step: float = 0.05,
               max_step: float = 1.0, max_points: int = 400, rtol: float = FOLD_RTOL, tol: float = FOLD_TOL,
               jacobian_every: int = FOLD_JACOBIAN_EVERY, out=None, resume: bool = True, **options) -> FoldCurve:
    """Ω where the stick-slip orbit ends, for each N: the upper edge of Region II (paper Fig. 8).

    Parameters
    ----------
    N : sequence of float
        Normal loads [N].
    model : Parameters, FrictionModel or str, optional
        The two plates, as :func:`stickslip.simulate` takes them: base parameters (Table 1,
        μk = 0.2, Δμ = 0.1, α = 5 by default, as in Fig. 8), in a variant with
        ``two_plates(params, "rotation")`` or a variant's name (``full``: Model 1, default).
    omega_start : float
        Ω of the start orbit [rad/s]: it must lie where the ``far`` initial condition reaches a
        period-1 stick-slip orbit (Region I or II of Fig. 8).
    omega_max : float
        Upper bound of the continuation [rad/s].
    workers : int
        Processes (one N per task; at most the CPUs this process may run on). They end with this
        process, also when it is killed (:func:`stickslip.parallel.worker_pool`).
    step, max_step, max_points, rtol, tol, **options
        Passed to :func:`continue_orbit` (``rtol``/``tol`` are looser than its defaults: the
        edge needs the branch, not 1e-8 orbits; see :data:`FOLD_RTOL`).
    jacobian_every : int
        Passed to :func:`continue_orbit`: a finite-difference Jacobian at every
        ``jacobian_every``-th point of each branch only, Broyden updates in between (default
        :data:`FOLD_JACOBIAN_EVERY`): the edge needs the tangent and the stick time, not the
        multipliers of every point.
    out : path, optional
        NetCDF output (:meth:`FoldCurve.to_netcdf`). Each N's result is appended to the journal
        ``OUT.nc.journal`` as soon as it finishes; a later call with the same settings (base
        parameters, ``omega_start``, ``omega_max``, model, options: the digest; the N list may
        differ) skips the N already in the journal or in a finished ``out``.
    resume : bool
        False: delete ``out`` and its journal and start over.

    Returns
    -------
    FoldCurve

    Raises
    ------
    stickslip.orbits.branch_store.JournalMismatch
        If ``out`` or its journal was written with other settings.
    stickslip.errors.WorkersError
        If ``workers`` is below 1 or above the CPUs available (before anything runs).
    """
    t0 = time.perf_counter()
    workers = check_workers(workers)
    params, model = _plates_of(model, options)
    Ns = [float(n) for n in N]
    options = dict(options, step=step, max_step=max_step, max_points=max_points, rtol=rtol, tol=tol,
                   jacobian_every=jacobian_every)
    settings = {"params": params.to_dict(), "omega_start": float(omega_start), "omega_max": float(omega_max),
                "model": model, "options": options}
    digest = store.digest_of(settings)
    done: dict = {}
    journal = None
    if out is not None:
        journal, finished = store.open_output(out, "fold-curve", digest, settings, resume,
                                              lambda path: _fold_curve_attrs_and_rows(path))
        if finished is not None:
            done = finished
            if not all(n in done for n in Ns):  # more N than the finished file: journal it, go on
                journal = store.Journal(out, "fold-curve", digest, settings)
                for n, row in done.items():
                    journal.append({"N": n, "row": row})
        else:
            done = {float(r["N"]): r["row"] for r in journal.records}
    todo = [n for n in dict.fromkeys(Ns) if n not in done]

    def record(n, row):
        done[n] = store.plain_row(row)
        if journal is not None:
            journal.append({"N": n, "row": done[n]})

    _edges(todo, params, omega_start, omega_max, model, options, workers, record)
    rows = [done[n] for n in Ns]
    cols = list(zip(*rows)) if rows else [()] * 8
    timings = {"total_s": time.perf_counter() - t0, "workers": int(workers), "n": len(Ns)}
    if out is not None:
        timings["n_resumed"] = len(set(Ns)) - len(todo)
    fc = FoldCurve(N=np.array(Ns), edge=np.array(cols[0], dtype=float), kind=tuple(cols[1]),
                   located=np.array(cols[2], dtype=bool), period=np.array(cols[3], dtype=float),
                   omega_stable_max=np.array(cols[4], dtype=float), points=np.array(cols[5], dtype=int),
                   seconds=np.array(cols[6], dtype=float), message=tuple(cols[7]), omega_start=float(omega_start),
                   params=params, model=model, timings=timings, digest=digest)
    if journal is not None:
        store.write_dataset(fc.to_xarray(), out)
        journal.remove()
    return fc


def _fold_curve_attrs_and_rows(path) -> tuple:
    """(attrs, {N: row}) of a finished fold-curve file, for :func:`.branch_store.open_output`."""
    fc = load_fold_curve(path)
    return {"digest": fc.digest}, fc.rows()


def _edges(Ns: list, params, omega_start, omega_max, model, options, workers: int, record) -> None:
    """:func:`_edge_at` for each N (in ``workers`` processes), ``record(N, row)`` as each finishes.

    With processes (:func:`stickslip.parallel.worker_pool`), an N whose task raises is
    re-raised after every other N is recorded.
    """
    if workers <= 1 or len(Ns) <= 1:
        for n in Ns:
            record(n, _edge_at(n, params, omega_start, omega_max, model, options))
        return
    with worker_pool(workers) as pool:
        futures = {pool.submit(_edge_at, n, params, omega_start, omega_max, model, options): n for n in Ns}
        error = None
        for fut in as_completed(futures):  # an N that raises does not lose the others: they are recorded first
            try:
                row = fut.result()
            except Exception as exc:
                error = error or exc
                continue
            record(futures[fut], row)
    if error is not None:
        raise error
