"""Special points of a branch: what crosses the unit circle between two points, and where.

A branch point is an orbit only if it has a stick phase or lies away from the steady-sliding
state (:func:`is_orbit`): a corrector that converges onto steady sliding (the equilibrium solves
the shooting equations for every period) ends the branch there, with no special point on it.

Multiplier tests use the non-trivial Floquet multipliers of the finite-difference monodromy (the
one closest to 1, the shift along the orbit of the autonomous flow, is left out) at two
consecutive points that have multipliers, and classify a change by what crossed the unit circle:

``fold``              the branch turns (τ_λ, the parameter component of the tangent, changes
                      sign) and a real multiplier crosses +1 (the sign of ∏(μ − 1) changes: a
                      complex pair contributes |μ − 1|² > 0, so only a real multiplier passing +1
                      changes it). A fold (saddle-node) of cycles, where two orbits meet and
                      disappear (the edge of bistability). Located on τ_λ.
``period-doubling``   a real multiplier crosses −1 (∏(μ + 1) changes sign).
``neimark-sacker``    a complex-conjugate pair crosses |μ| = 1: the number of complex multipliers
                      outside the unit circle changes while the number of complex multipliers
                      does not. A pair that meets on the real axis and splits into two real
                      multipliers changes the number of complex multipliers and crosses nothing:
                      it is no bifurcation (located by bisection).
``stick-phases``      the number of stick phases per period changes (a sliding bifurcation: a
                      stick phase appears or disappears; located by bisection).
``grazing``           the number of flight phases per period of the unilateral contacts (their
                      openings) changes: the orbit's gap touches zero with zero normal speed and
                      a flight phase appears or vanishes (located by bisection; the branch goes
                      on through it). Tested only where the model has a unilateral contact. A
                      flight shorter than the integrator's step is not recorded, so the count
                      changes a little past the zero of the largest gap (measured on hoffmann at
                      rtol 1e-10: flights up to ~9 ms, largest gap 1.3e-5, 4e-6 in belt speed).
                      A rigid contact's grazing ends the branch instead (its return map is
                      singular there): where the steps shrink below ``min_step`` and the flight
                      time τ_open of the last points extrapolates to zero (τ_open² linear in λ,
                      as for ``stick-vanishing``), the grazing is reported after the last point.
                      So does an impact that grazes (its landing speed v_i → 0 where the
                      free motion's extreme touches the stop): the return map has a square-root
                      singularity there (v_i ∝ √(λ* − λ), the period turns with the same root),
                      the steps shrink below ``min_step`` and the grazing is where v_i² of the
                      last points extrapolates linearly to zero (:func:`impact_grazing`); from
                      the side of the free orbits, where their smallest gap to the stop does
                      (:func:`approach_grazing`).
``hopf``              the branch turns where a pure-slip cycle has shrunk onto the equilibrium
                      (distance from it < :data:`HOPF_RATIO` of the start's): the Hopf point of
                      the linearisation (paper Eq. 15, Appendix); the branch ends.
``stick-vanishing``   the total stick time per period falls towards 0 and the branch ends: the
                      stick-slip orbit loses its stick phase (it meets the unstable pure-slip
                      cycle, a non-smooth fold). Located by extrapolating τ_stick² linearly in λ
                      to 0 over the last points (τ_stick ∝ √(λ* − λ) measured).

A change is located between the two points by the Illinois (modified regula falsi) method on the
arclength for continuous tests and by bisection for discrete ones, each evaluation a corrector
step from the left point (:func:`.arclength.step_from`). Each special point keeps the multipliers
of the two points it was found between.
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from ..errors import OrbitError, SimulationError
from . import branch_store as store
from .arclength import Point, Problem, point_at, step_from
from .layout import ORBIT_MIN_SIZE, distance_from_steady_sliding, is_steady_sliding
from .problem import nontrivial

__all__ = ["SpecialPoint", "SPECIAL_KINDS", "HOPF_RATIO", "MIN_STICK_FRACTION", "ORBIT_MIN_SIZE", "REAL_RTOL",
           "Detection", "circle_crossings", "is_orbit", "steady_stop", "detect_after_point", "detect_after_renewal"]

#: Kinds of special points, in the order they are reported.
SPECIAL_KINDS = ("fold", "period-doubling", "neimark-sacker", "stick-phases", "grazing", "stick-vanishing", "hopf")

#: A fold of a pure-slip branch whose orbit lies within this fraction of the start orbit's distance
#: from the equilibrium (in units of σ) is the Hopf point where the cycle shrinks onto the
#: equilibrium: it is reported as ``hopf`` and the branch ends (beyond it the shooting equations
#: follow the equilibrium with an arbitrary period). Measured: 0.007 (Model 1) and ~0.04 (Model 4)
#: of the start at the located turning point, against ≥ 0.3 on the rest of those branches.
HOPF_RATIO = 0.1


#: A multiplier is real when |Im μ| ≤ REAL_RTOL |μ|: LAPACK returns the real eigenvalues of a real
#: matrix with Im = 0 exactly and the others in conjugate pairs, so this only absorbs round-off.
REAL_RTOL = 1e-9

#: A branch stops when the stick time per period falls below this fraction of the period: the
#: stick phase is vanishing (measured at N = 50 N: τ_stick² falls linearly to 0 with Ω, so the
#: orbit ends where its stick phase shrinks to an instant; the finite-difference Jacobian is
#: meaningless once the perturbations reach the edge, ~1e-5 σ).
MIN_STICK_FRACTION = 1e-3

#: Points of the τ_stick² line fitted at the end of a branch, and the largest misfit accepted
#: relative to the largest τ_stick² (measured at N = 50 N: slopes of consecutive pairs agree to 3 %).
VANISH_FIT_POINTS, VANISH_FIT_RTOL = 4, 0.05
#: Farthest a vanishing phase's root is extrapolated ahead of the last point, in λ spans of the
#: fitted points. Measured on the rigid slider, whose steps shrink to ``min_step`` 2.3 spans short
#: of its flight's vanishing (the section in the flight lies ~1e-14 above the stop there): the
#: root agreed with a bisection on plain runs to 3.7e-8 in V (0.8 % of the distance extrapolated).
VANISH_REACH = 3.0

#: Location of a special point stops when the bracket in arclength is below this fraction of
#: the step it was found in, or after :data:`MAX_LOCATE` evaluations.
LOCATE_RTOL, MAX_LOCATE = 1e-3, 12

#: Stop reason of a branch that ends at a Hopf point.
HOPF_STOP = "hopf (the cycle shrinks onto the equilibrium)"
#: Stop reason of a branch that ends at a rigid contact's grazing (:func:`flight_vanishing`).
FLIGHT_VANISHING_STOP = "flight vanishing (grazing of a rigid contact)"
#: Stop reason of a branch that ends where an impact grazes (:func:`impact_grazing`).
IMPACT_GRAZING_STOP = "impact grazing (the landing speed of a rigid contact vanishes)"
#: Stop reason of a branch of free orbits that ends where they touch a rigid stop (:func:`approach_grazing`).
APPROACH_GRAZING_STOP = "impact grazing (the free orbit touches a rigid stop)"

#: Tests located by the Illinois method (sign changes of a continuous function).
_CONTINUOUS = ("fold", "period-doubling")

#: Tests between two points with multipliers, besides the turn.
_MULTIPLIER_KINDS = ("period-doubling", "neimark-sacker")

#: Tests that count phases per period (tested between consecutive points, located without Jacobians).
_PHASE_KINDS = ("stick-phases", "grazing")

#: Kinds whose label shows the test function on either side, e.g. ``grazing (0 → 1)``.
_COUNTED = ("stick-phases", "grazing", "neimark-sacker")


@dataclasses.dataclass(frozen=True)
class SpecialPoint:
    """A special point located on a branch.

    Parameters
    ----------
    kind : str
        One of :data:`SPECIAL_KINDS`.
    index : int
        The special point lies between branch points ``index`` and ``index + 1`` (after the last
        point for a ``hopf`` whose next point was the equilibrium).
    value : float
        Parameter value at the special point [unit of the parameter].
    period : float
        Period there [s].
    state : ndarray (2n,)
        State on the section there.
    multipliers : ndarray (2 n_free,) complex
        Floquet multipliers there (at the nearest evaluated point for discrete tests) [-].
    before, after : float
        Test function on either side (τ_λ; det(M + I); complex multipliers outside the unit
        circle; stick phases per period; flight phases per period; stick time [s]).
    bracket : float
        Width of the final bracket in λ [unit of the parameter] (0 if found exactly).
    located : bool
        False if the location stopped before the bracket tolerance was met.
    multipliers_before, multipliers_after : ndarray (2 n_free,) complex
        Floquet multipliers of the points it was found between (those that classify it; NaN
        where a point has none: a Broyden point, or the equilibrium after a Hopf point) [-].
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
    multipliers_before: np.ndarray
    multipliers_after: np.ndarray

    @property
    def label(self) -> str:
        """Short description, e.g. ``stick-phases (1 → 2)``, ``grazing (0 → 1)``."""
        extra = f" ({self.before:g} → {self.after:g})" if self.kind in _COUNTED else ""
        return f"{self.kind}{extra}"

    def to_record(self) -> dict:
        """JSON-ready dict (exact floats), for the journal of :func:`continue_orbit`."""
        return {"kind": self.kind, "index": int(self.index), "value": float(self.value), "period": float(self.period),
                "state": store.encode_array(self.state), "multipliers": store.encode_array(self.multipliers),
                "before": float(self.before), "after": float(self.after), "bracket": float(self.bracket),
                "located": bool(self.located), "multipliers_before": store.encode_array(self.multipliers_before),
                "multipliers_after": store.encode_array(self.multipliers_after)}

    @classmethod
    def from_record(cls, rec: dict) -> "SpecialPoint":
        """Inverse of :meth:`to_record`."""
        mult = store.decode_array(rec["multipliers"]).astype(complex)
        side = {k: store.decode_array(rec[k]).astype(complex) if k in rec else np.full(mult.shape, np.nan + 0j)
                for k in ("multipliers_before", "multipliers_after")}
        return cls(kind=rec["kind"], index=int(rec["index"]), value=float(rec["value"]), period=float(rec["period"]),
                   state=store.decode_array(rec["state"]), multipliers=mult, before=float(rec["before"]),
                   after=float(rec["after"]), bracket=float(rec["bracket"]), located=bool(rec["located"]), **side)


class Detection(NamedTuple):
    """What :func:`detect_after_point` found after a new branch point."""

    found: list  # special points, along the branch
    stop: str | None  # why the branch ends here (None: it goes on)
    quiet: bool  # the new point is left out of the progress callback (the branch ended before it)
    drop: bool  # the new point is not an orbit (steady sliding): it is removed from the branch


# --------------------------------------------------------------------------- multiplier tests
def _multiplier_tests(multipliers: np.ndarray) -> dict:
    """The multiplier tests of one point (None for each when it has no multipliers).

    ``plus-one`` and ``period-doubling`` are ∏(μ − 1) and ∏(μ + 1) over the non-trivial
    multipliers (real: conjugate pairs give |μ ∓ 1|²); ``neimark-sacker`` counts the complex ones
    outside the unit circle, ``complex`` all complex ones.
    """
    if not np.all(np.isfinite(multipliers)):
        return dict.fromkeys(("plus-one", "period-doubling", "neimark-sacker", "complex"))
    mu = nontrivial(multipliers)
    cplx = np.abs(mu.imag) > REAL_RTOL * np.abs(mu)
    return {"plus-one": float(np.real(np.prod(mu - 1.0))), "period-doubling": float(np.real(np.prod(mu + 1.0))),
            "neimark-sacker": int(np.sum(cplx & (np.abs(mu) > 1.0))), "complex": int(np.sum(cplx))}


def _test_values(point: Point) -> dict:
    """Test functions of the special points at one point (multiplier tests None where the point
    has no multipliers, see ``jacobian_every``; ``grazing`` None where the model has no unilateral
    contact)."""
    return {"fold": float(point.tangent[-1]), "stick-phases": int(point.stick_phases),
            "grazing": None if point.open_phases is None else int(point.open_phases),
            **_multiplier_tests(point.multipliers)}


def _changed(kind: str, a: dict, b: dict) -> bool:
    """Whether test ``kind`` changes between the test values ``a`` and ``b``."""
    if a[kind] is None or b[kind] is None:
        return False
    if kind in _CONTINUOUS or kind == "plus-one":
        return bool(np.sign(a[kind]) != np.sign(b[kind]))
    if kind == "neimark-sacker":  # a pair crossed |μ| = 1, not one that met on (or left) the real axis
        return a[kind] != b[kind] and a["complex"] == b["complex"]
    return a[kind] != b[kind]


def circle_crossings(before: np.ndarray, after: np.ndarray) -> set:
    """What crossed the unit circle between two sets of Floquet multipliers (trivial one included).

    Returns
    -------
    set of str
        ``"+1"`` (a real multiplier crossed +1), ``"-1"`` (a real multiplier crossed −1),
        ``"pair"`` (a complex-conjugate pair crossed |μ| = 1); empty if nothing crossed, e.g. a
        complex pair that met on the real axis and split into two real multipliers.
    """
    a, b = _multiplier_tests(np.asarray(before)), _multiplier_tests(np.asarray(after))
    names = {"plus-one": "+1", "period-doubling": "-1", "neimark-sacker": "pair"}
    return {name for kind, name in names.items() if _changed(kind, a, b)}


# --------------------------------------------------------------------------- orbit or steady sliding
def distance_from_equilibrium(problem: Problem, state: np.ndarray, lam: float) -> float:
    """‖(s − s_eq)/σ‖ on the free states: the size of a slip cycle about the equilibrium of Eq. (14)."""
    sp = problem.shooting
    return distance_from_steady_sliding(problem.system_at(lam), state, sp.free, sp.sigma)


def is_orbit(problem: Problem, state: np.ndarray, lam: float, stick_phases: int) -> bool:
    """Whether a solution of the shooting equations at ``lam`` is an orbit, not steady sliding
    (:func:`.layout.is_steady_sliding`)."""
    sp = problem.shooting
    return not is_steady_sliding(problem.system_at(lam), state, sp.free, sp.sigma, stick_phases)


def steady_stop(param: str, value: float) -> str:
    """Stop reason of a branch whose corrector converged onto steady sliding at ``param`` = ``value``."""
    return f"steady sliding at {param} = {value:.6g}"


# --------------------------------------------------------------------------- location
def _nan_like(point: Point) -> np.ndarray:
    return np.full(point.multipliers.shape, np.nan + 0j)


def _locate(problem: Problem, left: Point, right: Point, kind: str, h: float, tol: float, index: int) -> SpecialPoint:
    """Locate a sign change (or count change) of test ``kind`` between ``left`` and arclength ``h``
    (``right`` the point there).

    Continuous tests (fold, period-doubling): Illinois regula falsi on the arclength s ∈ (0, h).
    Discrete tests (neimark-sacker, stick-phases, grazing): bisection. Every evaluation is a
    corrector from ``left`` along its tangent (and a Jacobian when the test needs multipliers).
    """
    continuous = kind in _CONTINUOUS
    need_jac = kind not in _PHASE_KINDS
    f_left = _test_values(left)[kind]
    f_right = _test_values(right)[kind]
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
            p = step_from(problem, left, s, tol, with_jacobian=need_jac)
        except (OrbitError, SimulationError):
            break
        evaluations += 1
        fs = _test_values(p)[kind]
        if fs is None:  # no multipliers there (an impact grazes): not located further
            break
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
                        bracket=float(abs(lb - la)), located=bool(abs(b - a) <= LOCATE_RTOL * abs(h)),
                        multipliers_before=left.multipliers, multipliers_after=right.multipliers)


def _detect(problem: Problem, left: Point, right: Point, tol: float, index: int, locate: bool, kinds) -> list:
    """Special points of ``kinds`` between two branch points (located when ``locate``)."""
    a, b = _test_values(left), _test_values(right)
    found = []
    h_actual = float(left.tangent @ (right.v - left.v))  # arclength of ``right`` along the left tangent
    for kind in kinds:
        if not _changed(kind, a, b):
            continue
        if locate:
            found.append(_locate(problem, left, right, kind, h_actual, tol, index))
        else:
            s, T, lam = problem.unpack(right.v)
            found.append(SpecialPoint(kind=kind, index=index, value=lam, period=T, state=s,
                                      multipliers=right.multipliers, before=float(a[kind]), after=float(b[kind]),
                                      bracket=float(abs(lam - problem.unpack(left.v)[2])), located=False,
                                      multipliers_before=left.multipliers, multipliers_after=right.multipliers))
    return found


def _turns(problem: Problem, left: Point, right: Point, before: Point, tol: float, index: int, locate: bool,
           size0) -> list:
    """The turn of the branch between ``left`` and ``right`` (τ_λ changes sign) as a special point:
    ``hopf`` where a slip cycle has shrunk onto the equilibrium (``size0``: the start's distance
    from it, None for a stick-slip branch), ``fold`` where a real multiplier crossed +1 between
    ``before`` (the last point with multipliers up to ``left``) and ``right``; otherwise none (a
    turn without a multiplier crossing +1 is no fold of cycles)."""
    found = _detect(problem, left, right, tol, index, locate, ("fold",))
    if not found:
        return []
    turn = found[0]
    if size0 is not None and right.stick_phases == 0 and size0 > 0.0 \
            and distance_from_equilibrium(problem, turn.state, turn.value) < HOPF_RATIO * size0:
        return [dataclasses.replace(turn, kind="hopf", multipliers_before=before.multipliers)]
    if "+1" in circle_crossings(before.multipliers, right.multipliers):
        return [dataclasses.replace(turn, multipliers_before=before.multipliers)]
    return []


def _sorted(found: list) -> list:
    return sorted(found, key=lambda q: (q.index, SPECIAL_KINDS.index(q.kind)))


# --------------------------------------------------------------------------- after each point
def detect_after_point(problem: Problem, walk, last: Point, new: Point, stop: str | None, tol: float,
                       locate: bool, min_stick_fraction: float, size0, stop_on) -> Detection:
    """Special points between ``last`` and the new last point of ``walk``, and whether to stop.

    A new point that is not an orbit (:func:`is_orbit`) ends the branch: at a ``hopf`` point if
    the slip cycle shrank onto the equilibrium there, else as steady sliding (:func:`steady_stop`)
    with no special point; it is dropped. A turn seen by a point without multipliers (a Broyden
    point) renews that point's Jacobian first, so that the turn is classified. Updates
    ``walk.fresh_index`` (and ``walk.points[-1]`` when renewed).

    Returns
    -------
    Detection
        The special points (along the branch; at one index in :data:`SPECIAL_KINDS` order), the
        stop reason (the ``stop`` passed in is kept unless the branch ends here for another
        reason), whether the point is left out of the progress callback (stick phase vanishing,
        Hopf point) and whether it is dropped.
    """
    points = walk.points
    k = len(points) - 1
    s_new, T_new, lam_new = problem.unpack(new.v)
    before = points[walk.fresh_index]
    if not is_orbit(problem, s_new, lam_new, new.stick_phases):
        found = _turns(problem, last, new, before, tol, k - 1, locate, size0) if last.stick_phases == 0 else []
        hopf = [dataclasses.replace(q, multipliers_after=_nan_like(new)) for q in found if q.kind == "hopf"]
        return Detection(hopf, HOPF_STOP if hopf else steady_stop(problem.param, lam_new), True, True)
    if last.stick_time > 0.0 and new.stick_time < min_stick_fraction * T_new:
        # its multipliers are not trusted: the differences cross the edge of the stick phase
        return Detection([_stick_vanishing(problem, points, k - 1)], "stick phase vanishing", True, False)
    if not new.fresh and _changed("fold", _test_values(last), _test_values(new)):
        try:
            new = points[-1] = point_at(problem, new.v, new.iterations, last.tangent)
        except (OrbitError, SimulationError):
            pass  # the turn stays unclassified (no multipliers): it is not reported
    found = _detect(problem, last, new, tol, k - 1, locate, _PHASE_KINDS)
    if new.fresh:
        found += _turns(problem, last, new, before, tol, k - 1, locate, size0)
        found += _detect(problem, before, new, tol, walk.fresh_index, locate, _MULTIPLIER_KINDS)
        walk.fresh_index = k
    found = _sorted(found)
    reason = _stop_reason(found, stop_on)
    if reason == HOPF_STOP:
        return Detection(found, reason, True, False)
    return Detection(found, reason if stop is None else stop, False, False)


def detect_after_renewal(problem: Problem, walk, tol: float, locate: bool, size0, stop_on) -> tuple:
    """Special points hidden by a Broyden point, found once its Jacobian is renewed.

    Broyden's updates lie along the corrector steps, nearly orthogonal to the tangent, so a point
    without finite differences keeps its predecessor's tangent; τ_λ then changes sign only when
    the Jacobian of the last point is renewed (after a failed step), and the renewed point has
    multipliers. Test the turn between the previous point and the renewed one, and the multiplier
    tests between the last point with multipliers (``walk.fresh_index``, not yet moved) and it.

    Returns
    -------
    (found, stop)
        Special points (along the branch, as in :func:`detect_after_point`) and the stop reason
        (or None).
    """
    if len(walk.points) < 2:
        return [], None
    k = len(walk.points) - 1
    before, renewed = walk.points[walk.fresh_index], walk.points[k]
    found = _turns(problem, walk.points[k - 1], renewed, before, tol, k - 1, locate, size0)
    found += _detect(problem, before, renewed, tol, walk.fresh_index, locate, _MULTIPLIER_KINDS)
    found = _sorted(found)
    return found, _stop_reason(found, stop_on)


def _stop_reason(found: list, stop_on) -> str | None:
    """Why the branch ends at the special points ``found`` (None: it goes on)."""
    if any(q.kind == "hopf" for q in found):
        return HOPF_STOP
    if any(q.kind in stop_on for q in found):
        return "stop_on " + ",".join(sorted({q.kind for q in found if q.kind in stop_on}))
    return None


def _extrapolated_zero(problem: Problem, points: list, duration) -> tuple[float, bool]:
    """Where ``duration(point)`` (a phase's time per period [s]) of the last points extrapolates to
    zero, its square linear in λ: (λ*, located).

    A least-squares line through duration² of the last :data:`VANISH_FIT_POINTS` points that have
    the phase; the root counts as located if the line fits them to :data:`VANISH_FIT_RTOL` and the
    root lies ahead of the last point by at most :data:`VANISH_REACH` λ spans of the fit (else λ* is
    the last point's λ).
    """
    use = [p for p in points[-VANISH_FIT_POINTS:] if duration(p) > 0.0]
    lam = np.array([problem.unpack(p.v)[2] for p in use])
    tau2 = np.array([duration(p) ** 2 for p in use])
    lam_last = problem.unpack(points[-1].v)[2]
    if lam.size >= 3 and np.ptp(lam) > 0.0:
        slope, intercept = np.polyfit(lam, tau2, 1)
        fit_ok = np.max(np.abs(slope * lam + intercept - tau2)) <= VANISH_FIT_RTOL * np.max(tau2)
        if slope != 0.0:
            root = -intercept / slope
            ahead = (root - lam_last) * np.sign(lam[-1] - lam[0])
            if fit_ok and 0.0 <= ahead <= VANISH_REACH * np.ptp(lam):
                return float(root), True
    return float(lam_last), False


def _stick_vanishing(problem: Problem, points: list, index: int) -> SpecialPoint:
    """Where the stick time of the last points extrapolates to zero (:func:`_extrapolated_zero`;
    τ_stick ∝ √(λ* − λ))."""
    last = points[-1]
    s, T, lam_last = problem.unpack(last.v)
    value, located = _extrapolated_zero(problem, points, lambda p: p.stick_time)
    return SpecialPoint(kind="stick-vanishing", index=index, value=value, period=T, state=s,
                        multipliers=last.multipliers, before=float(points[-2].stick_time),
                        after=float(last.stick_time), bracket=float(abs(value - lam_last)), located=located,
                        multipliers_before=points[-2].multipliers, multipliers_after=last.multipliers)


def _grazing_after(problem: Problem, points: list, duration, before: float, after: float = 0.0) -> SpecialPoint | None:
    """A ``grazing`` point after the last of ``points`` where ``duration`` (a positive size of the
    last points that vanishes as √(λ* − λ)) extrapolates to zero, or None where it is not located."""
    last = points[-1]
    value, located = _extrapolated_zero(problem, points, duration)
    if not located:
        return None
    s, T, lam_last = problem.unpack(last.v)
    return SpecialPoint(kind="grazing", index=len(points) - 1, value=value, period=T, state=s,
                        multipliers=last.multipliers, before=before, after=after,
                        bracket=float(abs(value - lam_last)), located=True, multipliers_before=last.multipliers,
                        multipliers_after=_nan_like(last))


def impact_grazing(problem: Problem, points: list) -> SpecialPoint | None:
    """The grazing of an impact where a branch ends, or None.

    Towards the parameter λ* where the free motion's extreme just touches a rigid stop, the
    smallest landing speed of the orbit's impacts vanishes as v_i ∝ √(λ* − λ) (the penetration the
    free motion would make, v_i²/(2 |g̈|), is linear in λ); the return map has a square-root
    singularity there and the corrector's steps shrink to ``min_step`` before it. When the branch
    ends so, the grazing is where v_i² of the last points extrapolates linearly to zero
    (:func:`_extrapolated_zero`): a ``grazing`` point after the last (``before`` its flight phases
    per period, ``after`` 0), reported only where the extrapolation locates it.
    """
    last = points[-1]
    if last.impact_speed is None:
        return None
    return _grazing_after(problem, points, lambda p: p.impact_speed or 0.0, float(last.open_phases or 0))


def approach_grazing(problem: Problem, points: list, smallest_gap) -> SpecialPoint | None:
    """The grazing of a rigid stop that a branch of free orbits ends at, or None.

    Towards it the smallest gap g_min of the free motion to a rigid contact (``smallest_gap(point)``,
    ≥ 0 [m]) falls linearly in λ to 0; past it the orbit lands on the stop, whose return map has a
    square-root singularity there, so the corrector's steps shrink to ``min_step`` before it. The
    grazing is where g_min of the last points extrapolates linearly to zero
    (:func:`_extrapolated_zero` of √g_min): a ``grazing`` point after the last (``before`` its
    flight phases per period, ``after`` one more: an impact appears), reported only where the
    extrapolation locates it.
    """
    last = points[-1]
    if last.impact_speed is not None:
        return None
    gaps = {id(p): smallest_gap(p) for p in points[-VANISH_FIT_POINTS:]}
    if not all(np.isfinite(g) and g >= 0.0 for g in gaps.values()):
        return None
    before = float(last.open_phases or 0)
    return _grazing_after(problem, points, lambda p: np.sqrt(gaps.get(id(p), 0.0)), before, before + 1.0)


def flight_vanishing(problem: Problem, points: list) -> SpecialPoint | None:
    """The grazing of a rigid contact where a branch ends, or None.

    Towards a rigid contact's grazing the flight of the orbit shortens as τ_open ∝ √(λ* − λ)
    (measured on the rigid slider: τ_open² linear in the belt speed to 1 % over its last points)
    and its landing speed vanishes; the return map is singular there, so the corrector's steps
    shrink to ``min_step`` before it. When the branch ends so, the grazing is where τ_open of the
    last points extrapolates to zero (:func:`_extrapolated_zero`): a ``grazing`` point after the
    last (``before`` its flight phases per period, ``after`` 0), reported only where the
    extrapolation locates it.
    """
    last = points[-1]
    if not last.open_phases:
        return None
    return _grazing_after(problem, points, lambda p: p.open_time or 0.0, float(last.open_phases))
