"""Special points of a branch: detection between consecutive points and location on the arclength.

Test functions are evaluated at every branch point; a sign change (or a change of count)
between two consecutive points is a special point, located by the Illinois (modified regula
falsi) method on the arclength for continuous tests and by bisection for discrete ones, each
evaluation a corrector step from the left point (:func:`.arclength.step_from`):

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
                      to 0 over the last points (τ_stick ∝ √(λ* − λ) measured).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import OrbitError, SimulationError
from . import branch_store as store
from .arclength import Point, Problem, step_from
from .layout import equilibrium_state
from .problem import nontrivial

__all__ = ["SpecialPoint", "SPECIAL_KINDS", "HOPF_RATIO", "MIN_STICK_FRACTION", "detect_after_point",
           "detect_after_renewal"]

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


#: Location of a special point stops when the bracket in arclength is below this fraction of
#: the step it was found in, or after :data:`MAX_LOCATE` evaluations.
LOCATE_RTOL, MAX_LOCATE = 1e-3, 12

#: Stop reason of a branch that ends at a Hopf point.
HOPF_STOP = "hopf (the cycle shrinks onto the equilibrium)"


@dataclasses.dataclass(frozen=True)
class SpecialPoint:
    """A special point located on a branch.

    Attributes
    ----------
    kind : str
        One of :data:`SPECIAL_KINDS`.
    index : int
        The special point lies between branch points ``index`` and ``index + 1``.
    value : float
        Parameter value at the special point [unit of the parameter].
    period : float
        Period there [s].
    state : ndarray (2n,)
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


def _test_values(point: Point) -> dict:
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


def _locate(problem: Problem, left: Point, right_test, kind: str, h: float, tol: float, index: int) -> SpecialPoint:
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
            p = step_from(problem, left, s, tol, with_jacobian=need_jac)
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


def _detect(problem: Problem, last: Point, new: Point, tol: float, index: int, locate: bool, kinds) -> list:
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


def detect_after_point(problem: Problem, walk, last: Point, new: Point, stop: str | None, tol: float,
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
    reason = _stop_reason(found, stop_on)
    if reason == HOPF_STOP:
        return found, reason, True
    return found, reason if stop is None else stop, False


def detect_after_renewal(problem: Problem, walk, tol: float, locate: bool, size0, stop_on) -> tuple:
    """Special points hidden by a Broyden point, found once its Jacobian is renewed.

    Broyden's updates lie along the corrector steps, nearly orthogonal to the tangent, so a point
    without finite differences keeps its predecessor's tangent; τ_λ then changes sign only when
    the Jacobian of the last point is renewed (after a failed step), and the renewed point has
    multipliers. Test ``fold`` between the previous point and the renewed one, and the multiplier
    tests between the last point with multipliers (``walk.fresh_index``, not yet moved) and it.

    Returns
    -------
    (found, stop)
        Special points (along the branch, as in :func:`detect_after_point`; ``hopf`` for a fold of a slip branch on
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
    return found, _stop_reason(found, stop_on)


def _stop_reason(found: list, stop_on) -> str | None:
    """Why the branch ends at the special points ``found`` (None: it goes on)."""
    if any(q.kind == "hopf" for q in found):
        return HOPF_STOP
    if any(q.kind in stop_on for q in found):
        return "stop_on " + ",".join(sorted({q.kind for q in found if q.kind in stop_on}))
    return None


def distance_from_equilibrium(problem: Problem, state: np.ndarray, lam: float) -> float:
    """‖(s − s_eq)/σ‖ on the free states: the size of a slip cycle about the equilibrium of Eq. (14)."""
    sp = problem.shooting
    s_eq = equilibrium_state(problem.system_at(lam))
    return float(np.linalg.norm((state - s_eq)[sp.free] / sp.sigma))


def _as_hopf(problem: Problem, fold: SpecialPoint, size0: float) -> SpecialPoint:
    """A fold of a slip branch that sits on the equilibrium is its Hopf point (:data:`HOPF_RATIO`)."""
    if size0 > 0.0 and distance_from_equilibrium(problem, fold.state, fold.value) < HOPF_RATIO * size0:
        return dataclasses.replace(fold, kind="hopf")
    return fold


def _stick_vanishing(problem: Problem, points: list, index: int) -> SpecialPoint:
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

