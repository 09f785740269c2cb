"""Pseudo-arclength continuation of periodic stick-slip orbits in one parameter.

The orbit is the zero of the shooting map of :mod:`stickslip.orbits.shooting`, now with the
parameter λ (any field of :class:`~stickslip.Parameters`: ``N``, ``Omega``, ``delta_mu``, ...)
as an extra unknown. In scaled unknowns v = (z, T/T_s, λ/λ_s) — z the free states on the
Poincaré section except the coordinate the section fixes, in units of their scales σ — the
2 n_free equations are

    F(v) = (Φ(s(z), T; λ) − s(z))[free] / σ = 0,

Φ the exact flow map of the ``event`` integrator over T seconds (paper Eqs. 1–10, 13). One
more equation closes the system: the pseudo-arclength condition τ_kᵀ (v − v_k) = h, τ_k the unit
tangent of the branch at the last point (the null vector of ∂F/∂v there) and h the step.

Each point costs one finite-difference Jacobian ∂F/∂v (2 n_free + 1 columns, each two
simulations; the column of the section coordinate is added so that the same differences give the
full monodromy matrix and the Floquet multipliers) plus a few corrector simulations: the corrector
is Newton's method started with the Jacobian of the previous point and kept current by Broyden
rank-one updates, so it needs no new differences. The same Jacobian gives the tangent.

Special points between two consecutive points are detected from sign changes of test functions
and located by the Illinois (modified regula falsi) method on the arclength:

``fold``              τ_λ (the parameter component of the tangent) changes sign: a fold (saddle-node)
                      of cycles, where two orbits meet and disappear (the edge of bistability).
``period-doubling``   det(M + I) changes sign: a real multiplier crosses −1.
``neimark-sacker``    the number of complex multipliers outside the unit circle changes
                      (located by bisection).
``stick-phases``      the number of stick phases per period changes (grazing/sliding: a stick
                      phase appears or disappears; located by bisection).
``hopf``              a fold of a pure-slip branch where the cycle has shrunk onto the equilibrium
                      (distance from it < :data:`HOPF_RATIO` of the start's): the Hopf point of
                      the linearisation (paper Eq. 15, Appendix); the branch ends.
``stick-vanishing``   the total stick time per period falls towards 0 and the branch ends: the
                      stick-slip orbit loses its stick phase (it meets the unstable pure-slip
                      cycle, a non-smooth fold). Located by extrapolating τ_stick² linearly in λ
                      to 0 over the last three points (τ_stick ∝ √(λ* − λ) measured).

Long runs write as they go: with ``out=PATH`` :func:`continue_orbit` journals every accepted point
(with its Jacobian, tangent and the next step) and :func:`fold_curve` every finished N to
``PATH.journal`` (:mod:`.branch_store`), and the same call again resumes from there.
"""

from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path
from typing import Sequence

import numpy as np

from .. import __version__
from ..files import open_ours
from ..integrate.driver import SimulationError, simulate
from ..integrate.result import Trajectory
from ..model.kernels import DEFAULT_SLIP_BAND
from ..model.parameters import ParameterError, Parameters, parameter_attrs
from ..model.system import assemble
from ..model.variants import STATE_NAMES
from . import branch_store as store
from .section import OrbitError, Section, resolve_section, vector_field
from .shooting import PeriodicOrbit, periodic_orbit

__all__ = ["Branch", "SpecialPoint", "FoldCurve", "continue_orbit", "fold_curve", "branch_edge", "start_run", "crossings_per_stick",
           "start_orbit_from_run", "unstable_cycle", "load_branch", "load_fold_curve",
           "ContinuationError", "SPECIAL_KINDS"]

#: Kinds of special points, in the order they are reported.
SPECIAL_KINDS = ("fold", "period-doubling", "neimark-sacker", "stick-phases", "stick-vanishing", "hopf")

#: A fold of a pure-slip branch whose orbit lies within this fraction of the start orbit's distance
#: from the equilibrium (in units of σ) is the Hopf point where the cycle shrinks onto the
#: equilibrium: it is reported as ``hopf`` and the branch ends (beyond it the shooting equations
#: follow the equilibrium with an arbitrary period). Measured: 0.007 (Model 1) and ~0.04 (Model 4)
#: of the start at the located turning point, against ≥ 0.3 on the rest of those branches.
HOPF_RATIO = 0.1

#: A branch stops when the stick time per period falls below this fraction of the period: the
#: stick phase is vanishing (measured at N = 50 N: τ_stick² falls linearly to 0 with Ω, so the
#: orbit ends where its stick phase shrinks to an instant; the finite-difference Jacobian is
#: meaningless once the perturbations reach the edge, ~1e-5 σ).
MIN_STICK_FRACTION = 1e-3

#: Points of the τ_stick² line fitted at the end of a branch, and the largest misfit accepted
#: relative to the largest τ_stick² (measured at N = 50 N: slopes of consecutive pairs agree to 3 %).
VANISH_FIT_POINTS, VANISH_FIT_RTOL = 4, 0.05

#: Corrector convergence: max |F| (residual in units of σ), as :data:`.shooting.DEFAULT_TOL`.
DEFAULT_TOL = 1e-8

#: Relative finite-difference step (of σ for states, of λ_s for the parameter). Central
#: differences: truncation ~ step², integration noise ~ rtol/step = 1e-5 at rtol 1e-10.
DEFAULT_FD_STEP = 1e-5

#: Corrector iterations before a step counts as failed (then halved). Broyden from the previous
#: point's Jacobian reduces the residual ~5× per iteration (measured on Model 1, N = 50 N: the
#: 0.997 multipliers make M − I nearly singular, so the FD Jacobian's noise limits the rate) and
#: converges in 4–6 iterations from a predictor error of ~5e-4 σ.
MAX_CORRECTOR = 8

#: Corrector iterations at or below which the next step grows, and the growth/shrink factors.
EASY_ITERATIONS, GROW, SHRINK = 4, 1.5, 0.5

#: Corrector iterations above which the next step shrinks (between the two it is kept).
HARD_ITERATIONS = 6

#: Smallest cosine between consecutive tangents accepted: a larger turn means the step jumped
#: over a sharp feature (or onto another branch); the step is halved instead.
MIN_TANGENT_COS = 0.9

#: Steps of a flow map allowed per simulated second: a period of Model 1 takes ~1e3 steps at
#: rtol 1e-10; a stalled integration (approach to stick, docs/orbits.md) fails fast instead of
#: running 5e7 steps.
MAX_STEPS_PER_SECOND = 2e5

#: Location of a special point stops when the bracket in arclength is below this fraction of
#: the step it was found in, or after :data:`MAX_LOCATE` evaluations.
LOCATE_RTOL, MAX_LOCATE = 1e-3, 12

#: Samples per period of the run that measures the amplitude of φ of each point.
AMPLITUDE_SAMPLES = 400


class ContinuationError(OrbitError):
    """Continuation could not start or go on (the message says why)."""


# --------------------------------------------------------------------------- the problem
@dataclasses.dataclass(frozen=True, eq=False)
class _Problem:
    """Everything fixed along a branch: base parameters, parameter name, section, scales."""

    base: Parameters
    param: str
    model: str
    section: Section
    free: np.ndarray  # state indices of the free states (2 n_free,)
    cols: np.ndarray  # positions in ``free`` of the unknown section states (2 n_free − 1,)
    sigma: np.ndarray  # scales of the free states [SI]
    T_scale: float  # [s]
    p_scale: float  # [unit of the parameter]
    rtol: float
    atol: float
    slip_band: float
    fd_step: float
    counter: dict = dataclasses.field(default_factory=lambda: {"simulations": 0})

    def params_at(self, lam: float) -> Parameters:
        """Parameters with the continuation parameter set to ``lam``."""
        return self.base.replace(**{self.param: float(lam)})

    def unpack(self, v: np.ndarray):
        """Scaled unknowns (2 n_free + 1,) → (state on the section (12,), T [s], λ)."""
        s = np.zeros(12)
        s[self.free[self.cols]] = v[:-2] * self.sigma[self.cols]
        s[self.section.index] = self.section.value
        return s, float(v[-2] * self.T_scale), float(v[-1] * self.p_scale)

    def pack(self, s: np.ndarray, T: float, lam: float) -> np.ndarray:
        """Inverse of :meth:`unpack`."""
        return np.concatenate([s[self.free[self.cols]] / self.sigma[self.cols], [T / self.T_scale, lam / self.p_scale]])


def _flow(problem: _Problem, params: Parameters, s0: np.ndarray, T: float):
    """Φ(s0, T) (12,) and the transitions of the run (as :func:`.section.flow`, with a step cap)."""
    if not np.isfinite(T) or T <= 0.0:
        raise OrbitError(f"return time T = {T} s is not positive")
    problem.counter["simulations"] += 1
    rate = 1.0 / T
    T_exact = 1.0 / rate  # the last sample time the driver computes, so the run ends on it
    traj = simulate(params, T_exact, model=problem.model, ic=s0, rtol=problem.rtol, atol=problem.atol,
                    sample_rate=rate, slip_band=problem.slip_band,
                    max_steps=int(MAX_STEPS_PER_SECOND * max(T, 1.0)))
    if traj.status != "success" or traj.t[-1] != T_exact:
        raise OrbitError(f"the flow map over T = {T} s failed: {traj.status}")
    return traj.final_state, traj.transitions


def _residual(problem: _Problem, v: np.ndarray):
    """F(v) (2 n_free,) in units of σ, the end state and the transitions of the run."""
    s, T, lam = problem.unpack(v)
    end, tr = _flow(problem, problem.params_at(lam), s, T)
    return (end[problem.free] - s[problem.free]) / problem.sigma, end, tr


def _jacobian(problem: _Problem, v: np.ndarray, end: np.ndarray):
    """Finite-difference Jacobian ∂F/∂v (2 n_free × 2 n_free + 1) and the monodromy matrix.

    Central differences in every free state (the section coordinate too: its column is not part
    of ∂F/∂v but completes the monodromy ∂Φ/∂s0, whose eigenvalues are the Floquet multipliers)
    and in λ; the T column is exact, f(Φ) from the vector field. 2 (2 n_free + 1) simulations.

    Returns
    -------
    J : ndarray (2 n_free, 2 n_free + 1)
        In scaled units (rows / σ, columns × σ, T_s, λ_s).
    M : ndarray (2 n_free, 2 n_free)
        ∂Φ(s0, T)/∂s0 on the free states [SI].
    """
    s, T, lam = problem.unpack(v)
    params = problem.params_at(lam)
    free, sigma = problem.free, problem.sigma
    n = free.size
    M = np.empty((n, n))
    for k, j in enumerate(free):
        h = problem.fd_step * sigma[k]
        sp, sm = s.copy(), s.copy()
        sp[j] += h
        sm[j] -= h
        M[:, k] = (_flow(problem, params, sp, T)[0][free] - _flow(problem, params, sm, T)[0][free]) / (2.0 * h)
    J = np.empty((n, n + 1))
    J[:, :-2] = (M[:, problem.cols] - np.eye(n)[:, problem.cols]) * sigma[problem.cols][None, :] / sigma[:, None]
    system = assemble(params, problem.model, problem.slip_band)
    J[:, -2] = vector_field(system, end)[free] / sigma * problem.T_scale
    dl = problem.fd_step * problem.p_scale
    ep = _flow(problem, problem.params_at(lam + dl), s, T)[0][free]
    em = _flow(problem, problem.params_at(lam - dl), s, T)[0][free]
    J[:, -1] = (ep - em) / (2.0 * dl) / sigma * problem.p_scale
    return J, M


def _tangent(J: np.ndarray, previous: np.ndarray | None = None, direction: float = 1.0) -> np.ndarray:
    """Unit null vector of J (n × n + 1), oriented along ``previous`` (or with sign(τ_λ) = direction)."""
    t = np.linalg.svd(J)[2][-1]
    ref = float(t @ previous) if previous is not None else direction * t[-1]
    return -t if ref < 0.0 else t


def _correct(problem: _Problem, v: np.ndarray, J: np.ndarray, row: np.ndarray, target: float, tol: float):
    """Newton–Broyden corrector on F(v) = 0, rowᵀ v = target.

    Starts from ``J`` (a Jacobian near ``v``) and keeps it current by Broyden's rank-one updates,
    so each iteration costs one simulation.

    Returns
    -------
    (v, R, end, transitions, iterations, J)
        At convergence; ``J`` the updated Jacobian.

    Raises
    ------
    OrbitError, SimulationError
        No convergence in :data:`MAX_CORRECTOR` iterations, growing residual, or a failed run.
    """
    R, end, tr = _residual(problem, v)
    J = J.copy()
    history = [float(np.max(np.abs(R)))]
    for it in range(MAX_CORRECTOR + 1):
        c = float(row @ v - target)
        if history[-1] <= tol and abs(c) <= tol:
            return v, R, end, tr, it, J
        if it == MAX_CORRECTOR:
            break
        A = np.vstack([J, row])
        dv = np.linalg.solve(A, -np.concatenate([R, [c]]))
        v_new = v + dv
        R_new, end, tr = _residual(problem, v_new)
        J += np.outer(R_new - R - J @ dv, dv) / float(dv @ dv)  # Broyden's good update
        v, R = v_new, R_new
        history.append(float(np.max(np.abs(R))))
        if it >= 1 and history[-1] > 0.5 * history[-2] and history[-1] > 10 * tol:
            break  # not contracting: give the step back
    raise OrbitError(f"corrector did not converge (residuals {', '.join(f'{r:.1e}' for r in history)})")


# --------------------------------------------------------------------------- points
@dataclasses.dataclass(frozen=True, eq=False)
class _Point:
    """One converged orbit of a branch (internal)."""

    v: np.ndarray
    J: np.ndarray
    M: np.ndarray
    tangent: np.ndarray
    multipliers: np.ndarray
    stick_phases: int
    stick_time: float
    residual: float
    iterations: int

    @property
    def fresh(self) -> bool:
        """True if J is a finite-difference Jacobian at this point (multipliers known)."""
        return bool(np.all(np.isfinite(self.multipliers)))


def _stick_time(tr) -> float:
    """Total time in stick over one period [s] from the run's transitions (it starts in slip)."""
    t_in = tr.time[tr.kind == 1]
    t_out = tr.time[tr.kind == -1]
    n = min(t_in.size, t_out.size)
    return float(np.sum(t_out[:n] - t_in[:n]))


def _sorted_multipliers(M: np.ndarray) -> np.ndarray:
    mu = np.linalg.eigvals(M)
    return mu[np.argsort(-np.abs(mu), kind="stable")]


def nontrivial(multipliers: np.ndarray) -> np.ndarray:
    """Multipliers without the one closest to 1 (the shift along the orbit)."""
    k = int(np.argmin(np.abs(np.asarray(multipliers) - 1.0)))
    return np.delete(np.asarray(multipliers), k)


def unstable_count(multipliers: np.ndarray) -> int:
    """Number of non-trivial multipliers outside the unit circle."""
    return int(np.sum(np.abs(nontrivial(multipliers)) > 1.0))


def _test_values(point: _Point) -> dict:
    """Test functions of the special points at one point (continuous ones are floats; None where
    the point has no multipliers, see ``jacobian_every``)."""
    fresh = point.fresh
    mu = nontrivial(point.multipliers) if fresh else None
    return {
        "fold": float(point.tangent[-1]),
        "period-doubling": float(np.real(np.prod(mu + 1.0))) if fresh else None,
        "neimark-sacker": int(np.sum((np.abs(mu) > 1.0) & (np.abs(mu.imag) > 1e-9 * np.abs(mu)))) if fresh else None,
        "stick-phases": int(point.stick_phases),
    }


def _make_point(problem: _Problem, v, R, end, tr, iterations, previous_tangent, direction) -> _Point:
    J, M = _jacobian(problem, v, end)
    t = _tangent(J, previous_tangent, direction)
    return _Point(v=v, J=J, M=M, tangent=t, multipliers=_sorted_multipliers(M),
                  stick_phases=int(np.sum(tr.kind == 1)), stick_time=_stick_time(tr), residual=float(np.max(np.abs(R))), iterations=iterations)


def _step_from(problem: _Problem, point: _Point, h: float, tol: float, with_jacobian: bool = True) -> _Point:
    """The branch point at arclength ``h`` from ``point`` (predictor along its tangent + corrector)."""
    v_pred = point.v + h * point.tangent
    v, R, end, tr, it, J = _correct(problem, v_pred, point.J, point.tangent, float(point.tangent @ v_pred), tol)
    if not with_jacobian:  # Broyden-updated Jacobian: tangent, but no multipliers
        n = point.M.shape[0]
        return _Point(v=v, J=J, M=np.full((n, n), np.nan), tangent=_tangent(J, point.tangent),
                      multipliers=np.full(n, np.nan + 0j), stick_phases=int(np.sum(tr.kind == 1)), stick_time=_stick_time(tr), residual=float(np.max(np.abs(R))), iterations=it)
    return _make_point(problem, v, R, end, tr, it, point.tangent, 1.0)


def _point_record(point: _Point) -> dict:
    """A branch point as a JSON-ready dict (exact floats: a resumed run restarts bit for bit)."""
    enc = store.encode_array
    return {"v": enc(point.v), "J": enc(point.J), "M": enc(point.M), "tangent": enc(point.tangent),
            "multipliers": enc(point.multipliers), "stick_phases": int(point.stick_phases),
            "stick_time": float(point.stick_time), "residual": float(point.residual), "iterations": int(point.iterations)}


def _point_from_record(rec: dict) -> _Point:
    """Inverse of :func:`_point_record`."""
    dec = store.decode_array
    return _Point(v=dec(rec["v"]), J=dec(rec["J"]), M=dec(rec["M"]), tangent=dec(rec["tangent"]),
                  multipliers=dec(rec["multipliers"]).astype(complex), stick_phases=int(rec["stick_phases"]),
                  stick_time=float(rec["stick_time"]), residual=float(rec["residual"]),
                  iterations=int(rec["iterations"]))


# --------------------------------------------------------------------------- results
@dataclasses.dataclass(frozen=True)
class SpecialPoint:
    """A special point located on a branch.

    Attributes
    ----------
    kind : str
        ``fold``, ``period-doubling``, ``neimark-sacker`` or ``stick-phases`` (:data:`SPECIAL_KINDS`).
    index : int
        The special point lies between branch points ``index`` and ``index + 1``.
    value : float
        Parameter value at the special point [unit of the parameter].
    period : float
        Period there [s].
    state : ndarray (12,)
        State on the section there.
    multipliers : ndarray complex
        Floquet multipliers there (at the nearest evaluated point for discrete tests) [-].
    before, after : float
        Test function on either side (τ_λ; det(M + I); complex multipliers outside the unit
        circle; stick phases per period).
    bracket : float
        Width of the final bracket in λ [unit of the parameter] (0 if found exactly).
    located : bool
        False if the location stopped before the bracket tolerance was met.
    """

    kind: str
    index: int
    value: float
    period: float
    state: np.ndarray
    multipliers: np.ndarray
    before: float
    after: float
    bracket: float
    located: bool

    @property
    def label(self) -> str:
        """Short description, e.g. ``fold at Omega = 8.73``."""
        extra = f" ({self.before:g} → {self.after:g})" if self.kind in ("stick-phases", "neimark-sacker") else ""
        return f"{self.kind}{extra}"

    def to_record(self) -> dict:
        """JSON-ready dict (exact floats), for the journal of :func:`continue_orbit`."""
        return {"kind": self.kind, "index": int(self.index), "value": float(self.value), "period": float(self.period),
                "state": store.encode_array(self.state), "multipliers": store.encode_array(self.multipliers),
                "before": float(self.before), "after": float(self.after), "bracket": float(self.bracket),
                "located": bool(self.located)}

    @classmethod
    def from_record(cls, rec: dict) -> "SpecialPoint":
        """Inverse of :meth:`to_record`."""
        return cls(kind=rec["kind"], index=int(rec["index"]), value=float(rec["value"]), period=float(rec["period"]),
                   state=store.decode_array(rec["state"]), multipliers=store.decode_array(rec["multipliers"]).astype(complex),
                   before=float(rec["before"]), after=float(rec["after"]), bracket=float(rec["bracket"]),
                   located=bool(rec["located"]))


@dataclasses.dataclass(frozen=True, eq=False)
class Branch:
    """A branch of periodic orbits computed by :func:`continue_orbit`.

    Attributes
    ----------
    param : str
        Name of the continuation parameter (a :class:`~stickslip.Parameters` field).
    values : ndarray (n,)
        Parameter value of each orbit [unit of the parameter].
    periods : ndarray (n,)
        Periods [s].
    states : ndarray (n, 12)
        States on the Poincaré section [m, rad, m/s, rad/s].
    multipliers : ndarray (n, 2 n_free) complex
        Floquet multipliers (eigenvalues of the finite-difference monodromy), by decreasing modulus
        (NaN at points without a finite-difference Jacobian, see ``jacobian_every``).
    stable : ndarray (n,) bool
        Every non-trivial multiplier inside the unit circle.
    n_unstable : ndarray (n,) int
        Non-trivial multipliers outside the unit circle (−1 where not computed, ``jacobian_every``).
    stick_phases : ndarray (n,) int
        Slip → stick transitions per period (0: pure slip).
    stick_time : ndarray (n,)
        Total time in stick per period [s].
    amplitude : ndarray (n,)
        Peak-to-peak range of φ over one period [rad].
    arclength : ndarray (n,)
        Scaled pseudo-arclength from the first point [-].
    residuals : ndarray (n,)
        max |Φ(s0, T) − s0| / σ at each point [-].
    iterations : ndarray (n,) int
        Corrector iterations of each point (0 for the start).
    special : list of SpecialPoint
    stop_reason : str
        Why the continuation ended (``bounds``, ``max_points``, ``min_step``, ``stop_on fold``, ...).
    params : Parameters
        Base parameters (the continuation parameter at its start value).
    model : str
    section : Section
    options : dict
        Numerical options (rtol, atol, tol, fd_step, step bounds, scales).
    timings : dict
        ``total_s``, ``simulations``, ``points`` (and ``points_resumed`` when written to ``out``).
    digest : str
        Digest of everything that determines the branch (start and settings); a run writing to
        the same ``out`` with another digest is refused.
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
    params: Parameters
    model: str
    section: Section
    options: dict
    timings: dict
    digest: str = ""

    def __len__(self) -> int:
        return int(self.values.size)

    def folds(self) -> list:
        """The special points of kind ``fold``."""
        return [p for p in self.special if p.kind == "fold"]

    def orbit_params(self, i: int) -> Parameters:
        """Parameters of orbit ``i``."""
        return self.params.replace(**{self.param: float(self.values[i])})

    def trajectory(self, i: int, periods: float = 1.0, sample_rate: float = 1000.0) -> Trajectory:
        """Simulate orbit ``i`` from its section state (for plots)."""
        o = self.options
        return simulate(self.orbit_params(i), periods * float(self.periods[i]), model=self.model, ic=self.states[i],
                        rtol=o["rtol"], atol=o["atol"], sample_rate=sample_rate, slip_band=o["slip_band"])

    def to_xarray(self):
        """``xarray.Dataset`` with dims ``point``, ``state``, ``multiplier`` and ``special``."""
        import xarray as xr

        from ..model.parameters import PARAMETER_UNITS

        unit = PARAMETER_UNITS.get(self.param, "")
        sp = self.special
        data = {
            "value": ("point", self.values, {"long_name": f"continuation parameter {self.param}", "units": unit}),
            "period": ("point", self.periods, {"long_name": "period", "units": "s"}),
            "state_on_section": (("point", "state"), self.states, {"long_name": "state on the Poincaré section",
                                                                   "units": "m m m m rad rad m/s m/s m/s m/s rad/s rad/s"}),
            "multiplier_real": (("point", "multiplier"), self.multipliers.real, {"long_name": "Floquet multiplier, real part", "units": "1"}),
            "multiplier_imag": (("point", "multiplier"), self.multipliers.imag, {"long_name": "Floquet multiplier, imaginary part", "units": "1"}),
            "stable": ("point", self.stable.astype(np.int8), {"long_name": "1 if every non-trivial multiplier is inside the unit circle"}),
            "n_unstable": ("point", self.n_unstable.astype(np.int16), {"long_name": "non-trivial multipliers outside the unit circle"}),
            "stick_phases": ("point", self.stick_phases.astype(np.int16), {"long_name": "stick phases per period"}),
            "stick_time": ("point", self.stick_time, {"long_name": "time in stick per period", "units": "s"}),
            "amplitude": ("point", self.amplitude, {"long_name": "peak-to-peak range of phi over one period", "units": "rad"}),
            "arclength": ("point", self.arclength, {"long_name": "scaled pseudo-arclength", "units": "1"}),
            "residual": ("point", self.residuals, {"long_name": "scaled shooting residual", "units": "1"}),
            "iterations": ("point", self.iterations.astype(np.int16), {"long_name": "corrector iterations"}),
            "special_kind": ("special", np.array([p.kind for p in sp], dtype=str), {"long_name": "kind of special point"}),
            "special_index": ("special", np.array([p.index for p in sp], dtype=np.int32),
                              {"long_name": "lies between branch points index and index + 1"}),
            "special_value": ("special", np.array([p.value for p in sp], dtype=float), {"long_name": f"{self.param} at the special point", "units": unit}),
            "special_period": ("special", np.array([p.period for p in sp], dtype=float), {"long_name": "period at the special point", "units": "s"}),
            "special_before": ("special", np.array([p.before for p in sp], dtype=float), {"long_name": "test function before"}),
            "special_after": ("special", np.array([p.after for p in sp], dtype=float), {"long_name": "test function after"}),
            "special_bracket": ("special", np.array([p.bracket for p in sp], dtype=float), {"long_name": "final bracket width", "units": unit}),
            "special_located": ("special", np.array([p.located for p in sp], dtype=np.int8), {"long_name": "1 if located to tolerance"}),
            "special_state": (("special", "state"), np.array([p.state for p in sp], dtype=float).reshape(len(sp), 12),
                              {"long_name": "state on the section at the special point"}),
            "special_multiplier_real": (("special", "multiplier"), np.array([np.real(p.multipliers) for p in sp], dtype=float)
                                        .reshape(len(sp), self.multipliers.shape[1]),
                                        {"long_name": "Floquet multiplier at the special point, real part", "units": "1"}),
            "special_multiplier_imag": (("special", "multiplier"), np.array([np.imag(p.multipliers) for p in sp], dtype=float)
                                        .reshape(len(sp), self.multipliers.shape[1]),
                                        {"long_name": "Floquet multiplier at the special point, imaginary part", "units": "1"}),
        }
        coords = {"point": np.arange(len(self)), "state": list(STATE_NAMES),
                  "multiplier": np.arange(self.multipliers.shape[1]), "special": np.arange(len(sp))}
        attrs = {
            "title": f"stickslip branch of periodic orbits in {self.param} (pseudo-arclength continuation)",
            "format": "stickslip-branch-1",
            "stickslip_version": __version__,
            "param": self.param, "param_units": unit,
            "model": self.model, "section": self.section.name,
            "section_spec": json.dumps([self.section.index, self.section.value, self.section.direction, self.section.name]),
            "digest": self.digest,
            "stop_reason": self.stop_reason,
            "options": json.dumps(self.options),
            "timings": json.dumps(self.timings),
            "parameters": json.dumps(self.params.to_dict()),
        }
        attrs.update(parameter_attrs(self.params.to_dict()))
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def to_netcdf(self, path) -> Path:
        """Write :meth:`to_xarray` to ``path`` (NetCDF4 via h5netcdf; atomically: temporary file + rename)."""
        ds = self.to_xarray()
        return store.write_atomically(Path(path), lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf"))

    @classmethod
    def from_xarray(cls, ds) -> "Branch":
        """The branch of a dataset written by :meth:`to_xarray` (files of this version: with
        ``section_spec`` and the special points' multipliers)."""
        index, value, direction, name = json.loads(ds.attrs["section_spec"])
        mult = ds["multiplier_real"].values + 1j * ds["multiplier_imag"].values
        smult = ds["special_multiplier_real"].values + 1j * ds["special_multiplier_imag"].values
        special = [SpecialPoint(kind=str(ds["special_kind"].values[k]), index=int(ds["special_index"].values[k]),
                                value=float(ds["special_value"].values[k]), period=float(ds["special_period"].values[k]),
                                state=ds["special_state"].values[k], multipliers=smult[k],
                                before=float(ds["special_before"].values[k]), after=float(ds["special_after"].values[k]),
                                bracket=float(ds["special_bracket"].values[k]),
                                located=bool(ds["special_located"].values[k]))
                   for k in range(ds.sizes.get("special", 0))]
        return cls(param=ds.attrs["param"], values=ds["value"].values, periods=ds["period"].values,
                   states=ds["state_on_section"].values, multipliers=mult, stable=ds["stable"].values.astype(bool),
                   n_unstable=ds["n_unstable"].values.astype(int), stick_phases=ds["stick_phases"].values.astype(int),
                   stick_time=ds["stick_time"].values, amplitude=ds["amplitude"].values,
                   arclength=ds["arclength"].values, residuals=ds["residual"].values,
                   iterations=ds["iterations"].values.astype(int), special=special, stop_reason=ds.attrs["stop_reason"],
                   params=Parameters.from_dict(json.loads(ds.attrs["parameters"])), model=ds.attrs["model"],
                   section=Section(index=int(index), value=float(value), direction=int(direction), name=name),
                   options=json.loads(ds.attrs["options"]), timings=json.loads(ds.attrs["timings"]),
                   digest=str(ds.attrs.get("digest", "")))


def load_branch(path):
    """Read a branch written by :meth:`Branch.to_netcdf` as an ``xarray.Dataset``.

    Raises
    ------
    stickslip.files.FileFormatError
        If the file is missing, truncated, not a stickslip branch or of a newer format (a ValueError).
    """
    return open_ours(path, "branch", what="a .nc file written by `stickslip continue` (Branch.to_netcdf)")


# --------------------------------------------------------------------------- location
def _locate(problem: _Problem, left: _Point, right_test, kind: str, h: float, tol: float, index: int) -> SpecialPoint:
    """Locate a sign change (or count change) of test ``kind`` between ``left`` and arclength ``h``.

    Continuous tests (fold, period-doubling): Illinois regula falsi on the arclength s ∈ (0, h).
    Discrete tests (neimark-sacker, stick-phases): bisection. Every evaluation is a corrector
    from ``left`` along its tangent (and a Jacobian when the test needs multipliers).
    """
    continuous = kind in ("fold", "period-doubling")
    need_jac = kind != "stick-phases"
    f_left = _test_values(left)[kind]
    f_right = right_test
    a, b, fa, fb = 0.0, h, f_left, f_right
    side = 0
    best = left
    evaluations = 0
    while abs(b - a) > LOCATE_RTOL * abs(h) and evaluations < MAX_LOCATE:
        if continuous and fa != fb:
            s = (a * fb - b * fa) / (fb - fa)
            if not (min(a, b) < s < max(a, b)):
                s = 0.5 * (a + b)
        else:
            s = 0.5 * (a + b)
        try:
            p = _step_from(problem, left, s, tol, with_jacobian=need_jac)
        except (OrbitError, SimulationError):
            break
        evaluations += 1
        fs = _test_values(p)[kind]
        best = p
        same_as_left = (np.sign(fs) == np.sign(fa)) if continuous else (fs == f_left)
        if same_as_left:
            a, fa = s, fs
            if continuous and side == -1:
                fb *= 0.5  # Illinois: halve the retained end's value
            side = -1
        else:
            b, fb = s, fs
            if continuous and side == 1:
                fa *= 0.5
            side = 1
        if continuous and fs == 0.0:
            a = b = s
            break
    s_best, T_best, lam_best = problem.unpack(best.v)
    la = problem.unpack(left.v + a * left.tangent)[2]
    lb = problem.unpack(left.v + b * left.tangent)[2]
    return SpecialPoint(kind=kind, index=index, value=lam_best, period=T_best, state=s_best,
                        multipliers=best.multipliers, before=float(f_left), after=float(f_right),
                        bracket=float(abs(lb - la)), located=bool(abs(b - a) <= LOCATE_RTOL * abs(h)))


# --------------------------------------------------------------------------- driver
def _start_orbit(params, param, start, model, section, rtol, atol, slip_band) -> PeriodicOrbit:
    if isinstance(start, PeriodicOrbit):
        return start
    try:
        if isinstance(start, Trajectory):  # one stick onset per period (several φ maxima at low N)
            run = start if start.params == params else dataclasses.replace(start, params=params)
            return start_orbit_from_run(run, section=section, rtol=rtol, atol=atol, slip_band=slip_band)
        return periodic_orbit(params, start, model=model, section=section, rtol=rtol, atol=atol, slip_band=slip_band)
    except (OrbitError, SimulationError) as exc:
        raise ContinuationError(f"no periodic orbit to start from at {param} = {getattr(params, param):g}: {exc}") from exc


@dataclasses.dataclass(frozen=True, eq=False)
class _Start:
    """What a branch needs of its start orbit (internal; journaled so a resumed run needs no shooting)."""

    state: np.ndarray  # (12,) on the section
    period: float  # [s]
    stick_phases: int
    scale: np.ndarray  # σ of the free states
    params: Parameters
    model: str
    section: Section
    options: dict  # rtol, atol, slip_band


def _start_of(orbit: PeriodicOrbit) -> _Start:
    """The :class:`_Start` of a periodic orbit."""
    o = orbit.options
    return _Start(state=np.asarray(orbit.state, dtype=float), period=float(orbit.period),
                  stick_phases=int(orbit.stick_phases), scale=np.asarray(orbit.scale, dtype=float),
                  params=orbit.params, model=orbit.model, section=orbit.section,
                  options={"rtol": o["rtol"], "atol": o["atol"], "slip_band": o["slip_band"]})


def _start_record(start: _Start) -> dict:
    """:class:`_Start` as a JSON-ready dict (exact floats)."""
    sec = start.section
    return {"state": start.state.tolist(), "period": start.period, "stick_phases": start.stick_phases,
            "scale": start.scale.tolist(), "params": start.params.to_dict(), "model": start.model,
            "section": [sec.index, sec.value, sec.direction, sec.name], "options": start.options}


def _start_from_record(rec: dict) -> _Start:
    """Inverse of :func:`_start_record`."""
    index, value, direction, name = rec["section"]
    return _Start(state=np.array(rec["state"], dtype=float), period=float(rec["period"]),
                  stick_phases=int(rec["stick_phases"]), scale=np.array(rec["scale"], dtype=float),
                  params=Parameters.from_dict(rec["params"]), model=rec["model"],
                  section=Section(index=int(index), value=float(value), direction=int(direction), name=name),
                  options=dict(rec["options"]))


def _problem(orbit: _Start, param: str, fd_step: float, param_scale: float | None) -> _Problem:
    if param not in Parameters.names() or param == "friction_law":
        raise ContinuationError(f"cannot continue in {param!r}; choose a numeric parameter: "
                                + ", ".join(n for n in Parameters.names() if n != "friction_law"))
    lam0 = float(getattr(orbit.params, param))
    scale = abs(lam0) if param_scale is None else float(param_scale)
    if not (np.isfinite(scale) and scale > 0.0):
        scale = 1.0  # λ0 = 0: work in the parameter's own unit
    system = assemble(orbit.params, orbit.model, orbit.options["slip_band"])
    free_dofs = system.variant.free_indices
    free = np.concatenate([free_dofs, free_dofs + 6])
    cols = np.array([k for k, j in enumerate(free) if j != orbit.section.index])
    return _Problem(base=orbit.params, param=param, model=orbit.model, section=orbit.section, free=free, cols=cols,
                    sigma=np.asarray(orbit.scale, dtype=float), T_scale=float(orbit.period), p_scale=scale,
                    rtol=orbit.options["rtol"], atol=orbit.options["atol"], slip_band=orbit.options["slip_band"],
                    fd_step=fd_step)


def _amplitude(problem: _Problem, s: np.ndarray, T: float, lam: float) -> float:
    """Peak-to-peak φ over one period [rad] from a sampled run (NaN if it fails)."""
    try:
        traj = simulate(problem.params_at(lam), T, model=problem.model, ic=s, rtol=problem.rtol, atol=problem.atol,
                        sample_rate=AMPLITUDE_SAMPLES / T, slip_band=problem.slip_band,
                        max_steps=int(MAX_STEPS_PER_SECOND * max(T, 1.0)))
    except SimulationError:
        return float("nan")
    return float(np.ptp(traj.states[:, 4])) if traj.status == "success" else float("nan")


def continue_orbit(
    params: Parameters | None = None,
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
    model: str = "full",
    section="phi_max",
    rtol: float = 1e-10,
    atol: float | None = None,
    tol: float = DEFAULT_TOL,
    fd_step: float = DEFAULT_FD_STEP,
    param_scale: float | None = None,
    slip_band: float = DEFAULT_SLIP_BAND,
    amplitude: bool = True,
    min_stick_fraction: float = MIN_STICK_FRACTION,
    jacobian_every: int = 1,
    callback=None,
    out=None,
    resume: bool = True,
    on_resume=None,
) -> Branch:
    """Continue a periodic orbit in one parameter by pseudo-arclength continuation.

    Unknowns: the free states on the Poincaré section (except the section coordinate), the period T
    and the parameter λ; equations: the shooting equations Φ(s0, T; λ) − s0 = 0 on the free states
    (Φ the exact stick-slip flow of paper Eqs. 1–13, integrated by the ``event`` method) and the
    arclength condition τᵀ (v − v_k) = h in scaled unknowns v = (s0/σ, T/T_0, λ/λ_s).

    Parameters
    ----------
    params : Parameters, optional
        Parameters of the start orbit (default: those of ``start`` if it is a PeriodicOrbit).
    param : str
        The parameter to vary: any numeric :class:`~stickslip.Parameters` field (``N`` [N],
        ``Omega`` [rad/s], ``delta_mu``, ``alpha`` [s/m], ``k_px`` [N/m], ...).
    start : PeriodicOrbit, Trajectory, array-like (12,) or "equilibrium"
        The first orbit; or a run that settled on it (shot by :func:`start_orbit_from_run`, one
        stick onset per period); or a state handed to :func:`~stickslip.orbits.periodic_orbit`.
    direction : {+1, −1}
        Start towards increasing (+1) or decreasing (−1) λ.
    step, min_step, max_step : float
        Initial, smallest and largest step in scaled arclength (≈ relative change of λ where the
        branch is steep in λ) [-]. The step grows by 1.5 after a corrector converges in ≤ 3
        iterations and halves after a failure; below ``min_step`` the continuation stops.
    max_points : int
        Branch points to compute (the start included).
    bounds : (lo, hi), optional
        Interval of λ; the continuation ends on its edge (the last point is corrected at λ = edge).
    stop_on : sequence of str
        Special-point kinds (:data:`SPECIAL_KINDS`) after which to stop, e.g. ``("fold",)``.
    locate : bool
        Locate special points (Illinois/bisection); otherwise they are reported at the next point.
    model, section, rtol, atol, slip_band
        As :func:`~stickslip.orbits.periodic_orbit` (used when ``start`` is not an orbit).
    tol : float
        Corrector convergence: max |Φ(s0, T) − s0| / σ ≤ tol [-].
    fd_step : float
        Relative finite-difference step of the Jacobian columns [-].
    param_scale : float, optional
        λ_s, the unit of λ in the arclength (default |λ0|, or 1 if λ0 = 0).
    amplitude : bool
        Measure the peak-to-peak φ of every orbit (one extra run per point).
    min_stick_fraction : float
        Stop when the stick time per period of a stick-slip orbit falls below this fraction of
        the period (the stick phase vanishes; a ``stick-vanishing`` point is reported) [-].
    jacobian_every : int
        Recompute the finite-difference Jacobian (2 (2 n_free + 1) simulations) at every
        ``jacobian_every``-th point only; in between, the corrector's Broyden-updated Jacobian gives
        the tangent, and the points have no multipliers (NaN; ``n_unstable`` −1). Period doubling
        and Neimark–Sacker are then detected between points with multipliers. 1 (default): every
        point has multipliers.
    callback : callable, optional
        ``callback(i, value, period, stable)`` after each accepted point (progress), once the
        point is journaled when writing to ``out``.
    out : path, optional
        NetCDF output (``.nc``) written as the branch is computed: the start orbit and every
        accepted point (with its special points and the step after it) are appended to the journal
        ``OUT.nc.journal`` as they are found (:mod:`.branch_store`); at the end the branch is
        written to ``out`` (:meth:`Branch.to_netcdf`) and the journal removed.
    resume : bool
        With ``out``: continue an interrupted run from its journal (the last journaled point, its
        Jacobian, tangent and step: the resumed branch is the uninterrupted one), or return the
        branch of a finished ``out``, when they were written with the same start and settings
        (the same digest). False: delete ``out`` and its journal and start over.
    on_resume : callable, optional
        ``on_resume(k)`` once, before any computation, when ``k`` points are read from ``out`` or
        its journal.

    Returns
    -------
    Branch

    Raises
    ------
    ContinuationError
        If ``param`` is not numeric, the start orbit cannot be found, or the first Jacobian fails.
    stickslip.orbits.branch_store.JournalMismatch
        If ``out`` or its journal was written with another start or other settings (an
        :class:`~stickslip.orbits.OrbitError`, like ContinuationError).
    """
    t_start = time.perf_counter()
    _check_request(direction, step, min_step, max_step, max_points, jacobian_every, stop_on)
    jacobian_every = int(jacobian_every)
    if isinstance(start, (PeriodicOrbit, Trajectory)) and params is None:
        params = start.params
    params = Parameters() if params is None else params
    if param not in Parameters.names() or param == "friction_law":
        raise ContinuationError(f"cannot continue in {param!r}; choose a numeric parameter: "
                                + ", ".join(n for n in Parameters.names() if n != "friction_law"))
    lo = hi = None
    if bounds is not None:
        lo, hi = float(bounds[0]), float(bounds[1])
        lam_start = float(getattr(params if not isinstance(start, PeriodicOrbit) else start.params, param))
        if not (lo < hi) or not (lo <= lam_start <= hi):
            raise ContinuationError(f"bounds ({lo:g}, {hi:g}) must satisfy lo < hi and contain the start "
                                    f"{param} = {lam_start:g}")
    atol = 1e-3 * rtol if atol is None else float(atol)
    section = resolve_section(section)
    numerics = dict(direction=direction, step=step, min_step=min_step, max_step=max_step, max_points=max_points,
                    bounds=None if bounds is None else [lo, hi], stop_on=list(stop_on), locate=bool(locate),
                    tol=tol, fd_step=fd_step, param_scale=param_scale, amplitude=bool(amplitude),
                    min_stick_fraction=min_stick_fraction, jacobian_every=jacobian_every)
    settings = _branch_settings(params, param, start, model, section, rtol, atol, slip_band, numerics)
    digest = store.digest_of(settings)
    journal = None
    if out is not None:
        journal, finished = store.open_output(out, "branch", digest, settings, resume, _read_branch)
        if finished is not None:  # nothing left to compute
            if on_resume is not None:
                on_resume(len(finished))
            return dataclasses.replace(finished, timings={**finished.timings, "points_resumed": len(finished)})
    records = [] if journal is None else journal.records
    start_rec = next((r["start"] for r in records if "start" in r), None)
    if start_rec is None:
        begin = _start_of(_start_orbit(params, param, start, model, section, rtol, atol, slip_band))
        if journal is not None:
            journal.append({"start": _start_record(begin)})
    else:
        begin = _start_from_record(start_rec)
    problem = _problem(begin, param, fd_step, param_scale)
    measure = (lambda p: _amplitude(problem, *problem.unpack(p.v))) if amplitude else (lambda p: float("nan"))
    walk = _walk_from_records(records)
    resumed = 0 if walk is None else len(walk.points)
    if walk is None:
        walk = _first_walk(problem, begin, direction, step, measure)
        _journal_point(journal, walk, problem, [], 0.0, t_start)
    else:
        problem.counter["simulations"] = walk.simulations
        if on_resume is not None:
            on_resume(len(walk.points))
    size0 = _distance_from_equilibrium(problem, begin.state, problem.unpack(walk.points[0].v)[2]) \
        if begin.stick_phases == 0 else None
    while walk.stop is None and len(walk.points) < max_points:
        last = walk.points[-1]
        fresh = (len(walk.points) - walk.fresh_index) >= jacobian_every
        try:
            new = _step_from(problem, last, walk.h, tol, with_jacobian=fresh)
            if float(new.tangent @ last.tangent) < MIN_TANGENT_COS:
                raise OrbitError("tangent turned too far")
        except (OrbitError, SimulationError, ParameterError, np.linalg.LinAlgError):
            # step changes are not journaled: a resumed run repeats these deterministic retries
            if not last.fresh:  # first renew the Broyden-updated Jacobian, then shrink
                try:
                    R, end, tr = _residual(problem, last.v)
                    walk.points[-1] = _make_point(problem, last.v, R, end, tr, last.iterations, last.tangent, 1.0)
                    found, walk.stop = _after_renewal(problem, walk, tol, locate, size0, stop_on)
                    walk.fresh_index = len(walk.points) - 1
                    walk.special.extend(found)
                    _journal_point(journal, walk, problem, found, walk.elapsed, t_start)  # replaces the record
                    continue
                except (OrbitError, SimulationError):
                    pass
            walk.h *= SHRINK
            if walk.h < min_step:
                walk.stop = "min_step"
            continue
        stop = None
        lam_new = problem.unpack(new.v)[2]
        if bounds is not None and not (lo <= lam_new <= hi):
            try:
                new = _correct_onto_bound(problem, last, new, hi if lam_new > hi else lo, tol)
            except (OrbitError, SimulationError, ParameterError, np.linalg.LinAlgError):
                walk.stop = "bounds (last point before the edge)"
                break
            stop = "bounds"
        walk.points.append(new)
        walk.arclength.append(walk.arclength[-1] + float(np.linalg.norm(new.v - last.v)))
        walk.amplitudes.append(measure(new))
        found, stop, quiet = _after_point(problem, walk, last, new, stop, tol, locate, jacobian_every,
                                          min_stick_fraction, size0, stop_on)
        walk.special.extend(found)
        walk.stop = stop
        if stop is None:
            if new.iterations <= EASY_ITERATIONS:
                walk.h = min(walk.h * GROW, max_step)
            elif new.iterations >= HARD_ITERATIONS:
                walk.h = max(walk.h * SHRINK, min_step)
        _journal_point(journal, walk, problem, found, walk.elapsed, t_start)
        if callback is not None and not quiet:
            _s, T_new, lam_cb = problem.unpack(new.v)
            callback(len(walk.points) - 1, lam_cb, T_new, new.fresh and unstable_count(new.multipliers) == 0)
    stop_reason = walk.stop or "max_points"
    if journal is not None and "stop" not in (journal.records[-1] if journal.records else {}):
        journal.append({"end": stop_reason})
    branch = _assemble_branch(problem, begin, walk, stop_reason,
                              dict(rtol=rtol, atol=atol, tol=tol, fd_step=fd_step, step=step, min_step=min_step,
                                   max_step=max_step, max_points=max_points, slip_band=problem.slip_band,
                                   param_scale=problem.p_scale, period_scale=problem.T_scale,
                                   bounds=None if bounds is None else [lo, hi], direction=direction,
                                   jacobian_every=jacobian_every),
                              walk.elapsed + time.perf_counter() - t_start, resumed if out is not None else None, digest)
    if journal is not None:
        branch.to_netcdf(out)
        journal.remove()
    return branch


def _check_request(direction, step, min_step, max_step, max_points, jacobian_every, stop_on) -> None:
    """Refuse bad numerical options of :func:`continue_orbit` before computing (ContinuationError)."""
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


def _first_walk(problem: _Problem, begin: _Start, direction: int, step: float, measure) -> "_Walk":
    """The walk at its first point: the start orbit with its Jacobian, tangent and amplitude."""
    v0 = problem.pack(begin.state, begin.period, float(getattr(begin.params, problem.param)))
    try:
        R, end, tr = _residual(problem, v0)
        p0 = _make_point(problem, v0, R, end, tr, 0, None, float(direction))
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


def _journal_point(journal, walk: _Walk, problem: _Problem, found: list, elapsed: float, t_start: float) -> None:
    """Append the last point of ``walk``, the special points ``found`` with it and the state
    after it (nothing if not writing)."""
    if journal is None:
        return
    k = len(walk.points) - 1
    rec = {"point": k, **_point_record(walk.points[k]), "amplitude": float(walk.amplitudes[k]),
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
    return _Walk(points=[_point_from_record(r) for r in pts], arclength=[float(r["arclength"]) for r in pts],
                 amplitudes=[float(r["amplitude"]) for r in pts],
                 special=[SpecialPoint.from_record(q) for r in every for q in r["special"]], h=float(last["h"]),
                 fresh_index=int(last["fresh_index"]), stop=last.get("stop") or (ends[-1] if ends else None),
                 simulations=int(last["simulations"]), elapsed=float(last["elapsed"]))


def _correct_onto_bound(problem: _Problem, last: _Point, new: _Point, edge: float, tol: float) -> _Point:
    """The branch point at λ = ``edge`` (a bound the step ``last`` → ``new`` crossed)."""
    e = np.zeros_like(new.v)
    e[-1] = 1.0
    guess = last.v + (edge / problem.p_scale - last.v[-1]) / last.tangent[-1] * last.tangent \
        if abs(last.tangent[-1]) > 1e-12 else new.v
    v, R, end, tr, it, _ = _correct(problem, guess, last.J, e, edge / problem.p_scale, tol)
    return _make_point(problem, v, R, end, tr, it, last.tangent, 1.0)


def _after_point(problem: _Problem, walk: _Walk, last: _Point, new: _Point, stop: str | None, tol: float,
                 locate: bool, jacobian_every: int, min_stick_fraction: float, size0, stop_on) -> tuple:
    """Special points between ``last`` and the new last point of ``walk``, and whether to stop.

    Returns
    -------
    (found, stop, quiet)
        The special points (along the branch; at one index in :data:`SPECIAL_KINDS` order), the stop reason (None: go on; the
        ``stop`` passed in is kept unless the branch ends here for another reason), and whether
        the point is left out of the progress callback (the branch ended before it: stick phase
        vanishing, Hopf point). Updates ``walk.fresh_index``.
    """
    points = walk.points
    if last.stick_time > 0.0 and new.stick_time < min_stick_fraction * problem.unpack(new.v)[1]:
        # its multipliers are not trusted: the differences cross the edge of the stick phase
        return [_stick_vanishing(problem, points, len(points) - 2)], "stick phase vanishing", True
    found = _detect(problem, last, new, tol, len(points) - 2, locate, ("fold", "stick-phases"))
    if new.fresh and jacobian_every > 1:
        found += _detect(problem, points[walk.fresh_index], new, tol, walk.fresh_index, locate,
                         ("period-doubling", "neimark-sacker"))
    elif new.fresh:
        found += _detect(problem, last, new, tol, len(points) - 2, locate, ("period-doubling", "neimark-sacker"))
    if new.fresh:
        walk.fresh_index = len(points) - 1
    found = [_as_hopf(problem, q, size0) if q.kind == "fold" and size0 is not None
             and new.stick_phases == 0 else q for q in found]
    found = sorted(found, key=lambda q: (q.index, SPECIAL_KINDS.index(q.kind)))
    if any(q.kind == "hopf" for q in found):
        return found, "hopf (the cycle shrinks onto the equilibrium)", True
    if stop is None and any(q.kind in stop_on for q in found):
        stop = "stop_on " + ",".join(sorted({q.kind for q in found if q.kind in stop_on}))
    return found, stop, False


def _after_renewal(problem: _Problem, walk: _Walk, tol: float, locate: bool, size0, stop_on) -> tuple:
    """Special points hidden by a Broyden point, found once its Jacobian is renewed.

    Broyden's updates lie along the corrector steps, nearly orthogonal to the tangent, so a point
    without finite differences keeps its predecessor's tangent; τ_λ then changes sign only when
    the Jacobian of the last point is renewed (after a failed step), and the renewed point has
    multipliers. Test ``fold`` between the previous point and the renewed one, and the multiplier
    tests between the last point with multipliers (``walk.fresh_index``, not yet moved) and it.

    Returns
    -------
    (found, stop)
        Special points (along the branch, as in :func:`_after_point`; ``hopf`` for a fold of a slip branch on
        the equilibrium) and the stop reason (or None).
    """
    if len(walk.points) < 2:
        return [], None
    k = len(walk.points) - 1
    found = _detect(problem, walk.points[k - 1], walk.points[k], tol, k - 1, locate, ("fold",))
    found += _detect(problem, walk.points[walk.fresh_index], walk.points[k], tol, walk.fresh_index, locate,
                     ("period-doubling", "neimark-sacker"))
    found = sorted(found, key=lambda q: (q.index, SPECIAL_KINDS.index(q.kind)))
    found = [_as_hopf(problem, q, size0) if size0 is not None and walk.points[-1].stick_phases == 0 else q
             for q in found]
    if any(q.kind == "hopf" for q in found):
        return found, "hopf (the cycle shrinks onto the equilibrium)"
    if any(q.kind in stop_on for q in found):
        return found, "stop_on " + ",".join(sorted({q.kind for q in found if q.kind in stop_on}))
    return found, None


def _start_digest(start, params: Parameters, model: str) -> str:
    """Digest of the ``start`` argument of :func:`continue_orbit` (an orbit, a run or a state)."""
    if isinstance(start, PeriodicOrbit):
        sec = start.section
        return store.digest_of({"orbit": store.array_digest(start.state, np.array([start.period]), start.scale),
                                "params": start.params.to_dict(), "model": start.model,
                                "section": [sec.index, sec.value, sec.direction, sec.name],
                                "options": {k: start.options.get(k) for k in ("rtol", "atol", "slip_band")}})
    if isinstance(start, Trajectory):
        return store.digest_of({"run": store.array_digest(start.t, start.states, start.mode),
                                "params": start.params.to_dict(), "model": start.model})
    if start is None or isinstance(start, str):
        return store.digest_of({"start": repr(start), "params": params.to_dict(), "model": model})
    return store.digest_of({"state": store.array_digest(np.asarray(start, dtype=float)), "params": params.to_dict(),
                            "model": model})


def _branch_settings(params, param, start, model, section, rtol, atol, slip_band, numerics: dict) -> dict:
    """Everything that determines a branch (its digest; the journal header)."""
    return {"start": _start_digest(start, params, model), "params": params.to_dict(), "param": param,
            "model": model, "section": [section.index, section.value, section.direction, section.name],
            "rtol": rtol, "atol": atol, "slip_band": slip_band, **numerics}


def _read_branch(path) -> tuple:
    """(attrs, Branch) of a branch file, for :func:`.branch_store.open_output` (files of earlier
    versions have no digest: they are refused by it, not read)."""
    ds = load_branch(path)
    return ds.attrs, (Branch.from_xarray(ds) if ds.attrs.get("digest") else None)


def _distance_from_equilibrium(problem: _Problem, state: np.ndarray, lam: float) -> float:
    """‖(s − s_eq)/σ‖ on the free states: the size of a slip cycle about the equilibrium of Eq. (14)."""
    from ..stability import equilibrium

    s_eq = np.zeros(12)
    s_eq[:6] = equilibrium(problem.params_at(lam), problem.model)
    return float(np.linalg.norm((state - s_eq)[problem.free] / problem.sigma))


def _as_hopf(problem: _Problem, fold: SpecialPoint, size0: float) -> SpecialPoint:
    """A fold of a slip branch that sits on the equilibrium is its Hopf point (:data:`HOPF_RATIO`)."""
    if size0 > 0.0 and _distance_from_equilibrium(problem, fold.state, fold.value) < HOPF_RATIO * size0:
        return dataclasses.replace(fold, kind="hopf")
    return fold


def _stick_vanishing(problem: _Problem, points: list, index: int) -> SpecialPoint:
    """Where the stick time of the last points extrapolates to zero (τ_stick² linear in λ).

    A least-squares line through τ_stick² of the last :data:`VANISH_FIT_POINTS` stick-slip
    points; the root counts as located if the line fits them to :data:`VANISH_FIT_RTOL` and the
    root lies ahead of the last point by at most twice the λ span of the fit.
    """
    use = [p for p in points[-VANISH_FIT_POINTS:] if p.stick_time > 0.0]
    lam = np.array([problem.unpack(p.v)[2] for p in use])
    tau2 = np.array([p.stick_time ** 2 for p in use])
    last = points[-1]
    s, T, lam_last = problem.unpack(last.v)
    value, located = lam_last, False
    if lam.size >= 3 and np.ptp(lam) > 0.0:
        slope, intercept = np.polyfit(lam, tau2, 1)
        fit_ok = np.max(np.abs(slope * lam + intercept - tau2)) <= VANISH_FIT_RTOL * np.max(tau2)
        if slope != 0.0:
            root = -intercept / slope
            ahead = (root - lam_last) * np.sign(lam[-1] - lam[0])
            if fit_ok and 0.0 <= ahead <= 2.0 * np.ptp(lam):
                value, located = float(root), True
    return SpecialPoint(kind="stick-vanishing", index=index, value=value, period=T, state=s,
                        multipliers=last.multipliers, before=float(points[-2].stick_time),
                        after=float(last.stick_time), bracket=float(abs(value - lam_last)), located=located)


def _detect(problem: _Problem, last: _Point, new: _Point, tol: float, index: int, locate: bool, kinds) -> list:
    """Special points of ``kinds`` between two branch points (located when ``locate``)."""
    a, b = _test_values(last), _test_values(new)
    found = []
    h_actual = float(last.tangent @ (new.v - last.v))  # arclength of ``new`` along the last tangent
    for kind in kinds:
        if a[kind] is None or b[kind] is None:
            continue
        changed = (np.sign(a[kind]) != np.sign(b[kind])) if kind in ("fold", "period-doubling") else a[kind] != b[kind]
        if not changed:
            continue
        if locate:
            found.append(_locate(problem, last, b[kind], kind, h_actual, tol, index))
        else:
            s, T, lam = problem.unpack(new.v)
            found.append(SpecialPoint(kind, index, lam, T, s, new.multipliers, float(a[kind]), float(b[kind]),
                                      float(abs(lam - problem.unpack(last.v)[2])), False))
    return found


def _assemble_branch(problem: _Problem, begin: _Start, walk: _Walk, stop_reason: str, options: dict,
                     total_s: float, resumed: int | None, digest: str) -> Branch:
    """The :class:`Branch` of a finished walk (``resumed``: points read from a journal, None if not writing)."""
    points = walk.points
    unpacked = [problem.unpack(p.v) for p in points]
    states = np.array([u[0] for u in unpacked])
    periods = np.array([u[1] for u in unpacked])
    values = np.array([u[2] for u in unpacked])
    mult = np.array([p.multipliers for p in points])
    n_unst = np.array([unstable_count(p.multipliers) if p.fresh else -1 for p in points])
    timings = {"total_s": total_s, "points": len(points), "simulations": problem.counter["simulations"]}
    if resumed is not None:
        timings["points_resumed"] = resumed
    return Branch(param=problem.param, values=values, periods=periods, states=states, multipliers=mult,
                  stable=n_unst == 0, n_unstable=n_unst, stick_phases=np.array([p.stick_phases for p in points]),
                  stick_time=np.array([p.stick_time for p in points]),
                  amplitude=np.array(walk.amplitudes, dtype=float), arclength=np.array(walk.arclength),
                  residuals=np.array([p.residual for p in points]),
                  iterations=np.array([p.iterations for p in points]), special=list(walk.special),
                  stop_reason=stop_reason, params=begin.params, model=problem.model, section=problem.section,
                  options=options, timings=timings, digest=digest)


# --------------------------------------------------------------------------- Region II edge
@dataclasses.dataclass(frozen=True, eq=False)
class FoldCurve:
    """The upper edge of the stick-slip domain over N: where the stable stick-slip orbit ends.

    For each N the stick-slip orbit found from the ``far`` initial condition at ``omega_start``
    is continued in Ω (:func:`continue_orbit`) until it ends, at a fold of cycles (``fold``) or
    where its stick phase vanishes (``stick-vanishing``). Above the edge no stick-slip orbit of
    this branch exists; between the linear-stability boundary Ω_c(N) and the edge it coexists with
    the stable equilibrium (Region II of paper Fig. 8).

    Attributes
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
    model : str
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
        import xarray as xr

        data = {
            "edge": ("N", self.edge, {"long_name": "Omega where the stick-slip branch ends", "units": "rad/s"}),
            "kind": ("N", np.array(self.kind, dtype=str), {"long_name": "fold | stick-vanishing | bounds | failed"}),
            "located": ("N", self.located.astype(np.int8), {"long_name": "1 if located to tolerance"}),
            "period": ("N", self.period, {"long_name": "period at the edge", "units": "s"}),
            "omega_stable_max": ("N", self.omega_stable_max, {"long_name": "largest Omega of a stable orbit", "units": "rad/s"}),
            "points": ("N", self.points.astype(np.int32), {"long_name": "branch points"}),
            "seconds": ("N", self.seconds, {"long_name": "wall time", "units": "s"}),
            "message": ("N", np.array(self.message, dtype=str), {"long_name": "stop reason or error"}),
        }
        attrs = {"title": "stickslip: end of the stick-slip branch over N (upper edge of Region II, Fig. 8)",
                 "format": "stickslip-foldcurve-1", "stickslip_version": __version__, "model": self.model,
                 "omega_start": self.omega_start, "timings": json.dumps(self.timings),
                 "parameters": json.dumps(self.params.to_dict()), "digest": self.digest}
        attrs.update(parameter_attrs(self.params.to_dict()))
        return xr.Dataset(data, coords={"N": ("N", self.N, {"units": "N", "long_name": "normal load"})}, attrs=attrs)

    def to_netcdf(self, path) -> Path:
        """Write :meth:`to_xarray` to ``path`` (NetCDF4 via h5netcdf; atomically: temporary file + rename)."""
        ds = self.to_xarray()
        return store.write_atomically(Path(path), lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf"))

    def rows(self) -> dict:
        """``{N: row}`` with row = (edge, kind, located, period, omega_stable_max, points, seconds,
        message), the per-N result of :func:`fold_curve`, as plain Python values."""
        return {float(n): _plain_row((self.edge[i], self.kind[i], self.located[i], self.period[i],
                                      self.omega_stable_max[i], self.points[i], self.seconds[i], self.message[i]))
                for i, n in enumerate(self.N)}


def _plain_row(row) -> list:
    """A row of :func:`fold_curve` (see :meth:`FoldCurve.rows`) as JSON-ready Python values."""
    edge, kind, located, period, stable_max, points, seconds, message = row
    return [float(edge), str(kind), bool(located), float(period), float(stable_max), int(points), float(seconds),
            str(message)]


def load_fold_curve(path) -> FoldCurve:
    """Read a :class:`FoldCurve` written by :meth:`FoldCurve.to_netcdf`.

    Raises
    ------
    stickslip.files.FileFormatError
        If the file is missing, truncated, not a stickslip fold curve or of a newer format (a ValueError).
    """
    ds = open_ours(path, "foldcurve", noun="fold-curve", what="a .nc file written by FoldCurve.to_netcdf")
    return FoldCurve(N=ds["N"].values, edge=ds["edge"].values, kind=tuple(str(k) for k in ds["kind"].values),
                     located=ds["located"].values.astype(bool), period=ds["period"].values,
                     omega_stable_max=ds["omega_stable_max"].values, points=ds["points"].values.astype(int),
                     seconds=ds["seconds"].values, message=tuple(str(m) for m in ds["message"].values),
                     omega_start=float(ds.attrs["omega_start"]),
                     params=Parameters.from_dict(json.loads(ds.attrs["parameters"])), model=ds.attrs["model"],
                     timings=json.loads(ds.attrs["timings"]), digest=str(ds.attrs.get("digest", "")))


#: Length [s] and sample rate [Hz] of the run from the ``far`` initial condition that gives the
#: start orbit of each N (the stick-slip oscillation settles within ~20 s at Ω = 5 rad/s).
START_RUN, START_RATE = 60.0, 2000.0

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


def start_run(params: Parameters, ic: str = "far", *, model: str = "full", t_end: float = START_RUN,
              rtol: float = 1e-10, slip_band: float = DEFAULT_SLIP_BAND) -> Trajectory:
    """A run from a named initial condition, to hand to :func:`continue_orbit` as ``start``.

    Parameters
    ----------
    params : Parameters
    ic : str
        ``far``, ``near``, ``zero`` or ``equilibrium`` (:data:`stickslip.sweep.NAMED_ICS`).
    model : str
    t_end : float
        Run length [s]; the orbit guess is taken from its last section crossings.
    rtol : float
        Integration tolerance (``atol`` = 1e-3 rtol).
    slip_band : float
        Low-speed band of the slip direction [m/s] (see :func:`stickslip.simulate`).
    """
    from ..sweep.spec import initial_condition

    state, pert = initial_condition(ic, params, model)
    run = simulate(params, t_end, model=model, ic=state, perturbation=pert, sample_rate=START_RATE,
                   rtol=rtol, atol=1e-3 * rtol, slip_band=slip_band)
    if run.status != "success":
        raise ContinuationError(f"the start run from ic {ic!r} failed: {run.status}")
    return run


def crossings_per_stick(run: Trajectory, section="phi_max") -> int:
    """Section crossings between the last two stick onsets of a run (≥ 1): the period
    multiplicity to shoot with when the orbit has one stick phase per period (at low N the
    stick-slip orbit of Model 1 has several maxima of φ per period)."""
    from .section import section_crossings

    sec = resolve_section(section)
    onsets = run.transitions.time[run.transitions.kind == 1]
    if onsets.size < 2:
        return 1
    system = assemble(run.params, run.model)
    times, _ = section_crossings(system, sec, run.t, run.states, run.mode)
    return max(int(np.sum((times > onsets[-2]) & (times <= onsets[-1]))), 1)


def start_orbit_from_run(run: Trajectory, *, section="phi_max", rtol: float = 1e-10, atol: float | None = None,
                         slip_band: float = DEFAULT_SLIP_BAND) -> PeriodicOrbit:
    """Shoot the stick-slip orbit a run has settled on, with one stick onset per period.

    The period multiplicity is :func:`crossings_per_stick`. Where some section crossings lie in
    stick, the run is cut back one sample period at a time (up to one orbit period) until the
    first crossing used by :func:`~stickslip.orbits.periodic_orbit` lies in slip.

    Raises
    ------
    OrbitError
        If no cut gives a converged orbit.
    """
    k = crossings_per_stick(run, section)
    onsets = run.transitions.time[run.transitions.kind == 1]
    span = float(onsets[-1] - onsets[-2]) if onsets.size >= 2 else 1.0
    cut_step = max(int(round(span / (run.t[1] - run.t[0]) / (4 * k))), 1)  # a quarter of a crossing interval
    error = None
    for cut in range(0, 4 * k + 1):
        m = run.t.size - cut * cut_step
        part = dataclasses.replace(run, t=run.t[:m], states=run.states[:m], mode=run.mode[:m])
        try:
            return periodic_orbit(run.params, part, section=section, rtol=rtol, atol=atol, period_multiplicity=k,
                                  slip_band=slip_band)
        except OrbitError as exc:
            error = exc
            if "crossed in stick" not in str(exc):
                break
    raise OrbitError(f"no stick-slip orbit from the run ({error})")


#: Edge tracking of :func:`unstable_cycle`: bisection steps on the segment equilibrium → orbit
#: (2⁻⁴⁰ ≈ 1e-12 of the segment, near the round-off of the states), the length of each probe run
#: [s] and the window at its end in which sticking means "reached the stick-slip orbit" [s].
EDGE_BISECTIONS, EDGE_PROBE, EDGE_WINDOW = 40, 60.0, 20.0

#: The two bracketing edge trajectories count as separated once their φ differ by this fraction of
#: the φ range of the stable orbit; the orbit guess is the part of the run before 0.9 × that time.
EDGE_SEPARATION = 0.05


def unstable_cycle(params: Parameters, orbit_state: np.ndarray, *, model: str = "full", rtol: float = 1e-10,
                   slip_band: float = DEFAULT_SLIP_BAND, section="phi_max") -> PeriodicOrbit:
    """The saddle cycle on the boundary between the basins of a stable orbit and the equilibrium.

    Edge tracking: on the segment s(a) = s_eq + a (s_orbit − s_eq), a ∈ [0, 1], from the
    equilibrium of Eq. (14) to a state on the stable stick-slip orbit, bisection on a finds the
    basin boundary (runs from a below it stop sticking, from above they reach stick-slip). The run
    from the boundary lingers near the saddle cycle whose stable manifold the boundary is (in
    Region II, the unstable pure-slip cycle of the subcritical Hopf bifurcation at Ω_c); its part
    before the bracketing runs separate is the guess for :func:`~stickslip.orbits.periodic_orbit`.

    Parameters
    ----------
    params : Parameters
    orbit_state : ndarray (12,)
        A state on the stable stick-slip orbit (e.g. ``Branch.states[i]``).
    model, rtol, slip_band, section
        As :func:`~stickslip.orbits.periodic_orbit`.

    Returns
    -------
    PeriodicOrbit

    Raises
    ------
    ContinuationError
        If the equilibrium end does not go to the equilibrium or the orbit end does not stick.
    """
    from ..stability import equilibrium

    s_eq = np.zeros(12)
    s_eq[:6] = equilibrium(params, model)
    s_orb = np.asarray(orbit_state, dtype=float)
    atol = 1e-3 * rtol

    def run(a, t_end=EDGE_PROBE, rate=100.0):
        return simulate(params, t_end, model=model, ic=s_eq + a * (s_orb - s_eq), sample_rate=rate, rtol=rtol,
                        atol=atol, slip_band=slip_band)

    def sticks(a):
        tr = run(a)
        return bool(tr.mode[tr.t >= EDGE_PROBE - EDGE_WINDOW].any())

    lo, hi = 0.0, 1.0
    if not sticks(hi) or sticks(1e-3):
        raise ContinuationError("edge tracking needs a stable stick-slip orbit and a stable equilibrium "
                                f"(Region II) at {params.N:g} N, {params.Omega:g} rad/s")
    for _ in range(EDGE_BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if sticks(mid) else (mid, hi)
    a_lo, a_hi = run(lo, rate=START_RATE), run(hi, rate=START_RATE)
    scale = max(float(np.ptp(a_hi.states[a_hi.t >= EDGE_PROBE - EDGE_WINDOW, 4])), 1e-12)
    apart = np.flatnonzero(np.abs(a_lo.states[:, 4] - a_hi.states[:, 4]) > EDGE_SEPARATION * scale)
    t_sep = a_lo.t[apart[0]] if apart.size else EDGE_PROBE
    m = int(np.searchsorted(a_lo.t, 0.9 * t_sep))
    guess = dataclasses.replace(a_lo, t=a_lo.t[:m], states=a_lo.states[:m], mode=a_lo.mode[:m])
    try:
        return periodic_orbit(params, guess, section=section, rtol=rtol, slip_band=slip_band, max_iter=40)
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
    band = options.get("slip_band", DEFAULT_SLIP_BAND)
    errors = []
    for omega in (omega_start, START_FALLBACK * omega_start):
        p = params.replace(N=float(N), Omega=float(omega))
        try:
            run = start_run(p, "far", model=model, rtol=rtol, slip_band=band)
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


def fold_curve(N: Sequence[float], params: Parameters | None = None, *, omega_start: float = 5.0,
               omega_max: float = 40.0, model: str = "full", workers: int = 1, step: float = 0.05,
               max_step: float = 1.0, max_points: int = 400, rtol: float = FOLD_RTOL, tol: float = FOLD_TOL,
               jacobian_every: int = FOLD_JACOBIAN_EVERY, out=None, resume: bool = True, **options) -> FoldCurve:
    """Ω where the stick-slip orbit ends, for each N: the upper edge of Region II (paper Fig. 8).

    Parameters
    ----------
    N : sequence of float
        Normal loads [N].
    params : Parameters, optional
        Base parameters (Table 1, μk = 0.2, Δμ = 0.1, α = 5 by default, as in Fig. 8).
    omega_start : float
        Ω of the start orbit [rad/s]: it must lie where the ``far`` initial condition reaches a
        period-1 stick-slip orbit (Region I or II of Fig. 8).
    omega_max : float
        Upper bound of the continuation [rad/s].
    model : str
    workers : int
        Processes (one N per task).
    step, max_step, max_points, rtol, tol, **options
        Passed to :func:`continue_orbit` (``rtol``/``tol`` are looser than its defaults: the
        edge needs the branch, not 1e-8 orbits; see :data:`FOLD_RTOL`).
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
    """
    t0 = time.perf_counter()
    params = Parameters() if params is None else params
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
        done[n] = _plain_row(row)
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
        fc.to_netcdf(out)
        journal.remove()
    return fc


def _fold_curve_attrs_and_rows(path) -> tuple:
    """(attrs, {N: row}) of a finished fold-curve file, for :func:`.branch_store.open_output`."""
    fc = load_fold_curve(path)
    return {"digest": fc.digest}, fc.rows()


def _edges(Ns: list, params, omega_start, omega_max, model, options, workers: int, record) -> None:
    """:func:`_edge_at` for each N (in ``workers`` processes), ``record(N, row)`` as each finishes.

    With processes, an N whose task raises is re-raised after every other N is recorded.
    """
    from concurrent.futures import ProcessPoolExecutor, as_completed
    import multiprocessing

    if workers <= 1 or len(Ns) <= 1:
        for n in Ns:
            record(n, _edge_at(n, params, omega_start, omega_max, model, options))
        return
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
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
