"""The linearised flow map ∂Φ(s0, t)/∂s0 of any friction-contact model across its transitions.

The linearised flow of the non-smooth system is the product of the linearised flows of the smooth
segments between transitions (variational equations Φ̇ = J(s) Φ, :mod:`.var_kernels`) and of one
jump matrix per transition (:mod:`.saltation`). The nominal trajectory and its transitions come
from the ``event`` integrator (:func:`stickslip.simulate`); each smooth segment is re-integrated
together with its variational equations from the integrator's state at the segment start, its
events located on the dense output, and every event is matched with the integrator's recorded
transition (same contact, same kind, instant within :data:`MATCH_TIME_TOL`) and the state there
with the recorded one (scaled difference within :data:`MATCH_TOL`). Events the integrator does
not record — a 2-D contact leaving the low-speed band, a velocity reversal through v_c = 0 — get
their jumps without a match. A unilateral contact's opening and closing are events of their own
(:data:`.var_kernels.EV_GAP`), matched with the recorded ``open`` and ``close``.
"""

from __future__ import annotations

import dataclasses
import json
import time as _time
import types

import numpy as np

from .._version import __version__
from ..errors import OrbitError
from ..integrate import contacts as E
from ..model.compile_ahead import Split, compile_apart
from ..model import physics as P
from ..model.bundle import CST, H_N, H_NC, contact_state
from . import saltation as S
from . import var_kernels as V
from .layout import free_states
from .section import flow

__all__ = ["FlowJacobian", "flow_jacobian", "propagate", "initial_contacts", "ARRIVAL_SPEED"]

#: |v_c| [m/s] at which the integration of a 2-D contact's approach to stick stops and the arrival
#: jump is applied (the rest of the approach, τ = ρ_c/|dv_c/dt|, enters to first order in τ,
#: :func:`.saltation.arrival_jump`). With the first-order term the trivial multiplier of the
#: plates' orbits was 3e-8 off at ρ_c = 1e-7 and 1e-8 m/s alike; without it ≈ 10 ρ_c.
ARRIVAL_SPEED = 1e-7

#: Tolerances of the variational segments: rtol as the event integrator of the flow maps; atol on
#: the states and on the variations.
VAR_RTOL = 1e-10
VAR_ATOL_STATE = 1e-13
VAR_ATOL_PHI = 1e-10

#: Largest scaled difference between a re-integrated state and the event integrator's, and largest
#: difference of transition instants [s], before the result is refused (the two integrations then
#: followed different event sequences).
MATCH_TOL = 1e-6
MATCH_TIME_TOL = 1e-6

#: Step cap of one segment.
MAX_SEGMENT_STEPS = 1_000_000


def _variational_calls(md) -> dict:
    """The arguments with which the segment integrator and the saltation matrices call the kernels
    of :data:`VARIATIONAL`, for the model data ``md``."""
    n, nc = int(md.m[H_N]), int(md.m[H_NC])
    n2 = 2 * n
    y = np.zeros(n2 + n2 * n2)
    s = np.zeros(n2)
    z = np.zeros(n2, dtype=complex)
    cst = contact_state(md.m)
    F, N = np.zeros(2 * nc), np.zeros(nc)
    kind, level = np.zeros(nc, dtype=np.int64), np.zeros(nc)
    return {V.event_value: (V.EV_NONE, 0, s, 0.0, 0.0, cst, md),
            V.variational_rhs: (y, cst, md, n2, False, y, s, z, z, s),
            V.direction_residual: (z, cst, 0, md, 0.0, 0.0),
            V._first_event: (V.SegmentEvents(kind, level, level), y, y, np.zeros((y.size, 4)), 0.0, cst, md, n2, level,
                             y, s),
            V.contact_gradients: (s, cst, 0, md, n2, np.zeros((2, n2)), np.zeros((2, n2)), s, z,
                                  np.zeros(2 * nc, dtype=complex), np.zeros(nc, dtype=complex),
                                  np.zeros(2 * nc, dtype=complex)),
            E.initial_modes: (s, cst, md, 0.0, 0.0, F, N)}


#: A cold start's variational kernels in two processes (:mod:`stickslip.model.compile_ahead`):
#: the event functions, then the variational right-hand side (with the complex-step physics under
#: it) in the helper; the complex-step version of the band direction's residual, the first event's
#: search (which loads the helper's event functions), the contact gradients of the saltation
#: matrices and the starting modes here; the segment integrator then loads both.
VARIATIONAL = Split(
    helper=(V.event_value, V.variational_rhs),
    own=(V.direction_residual, V._first_event, V.contact_gradients, E.initial_modes),
    caller=V.integrate_segment,
    calls=_variational_calls)


#: Kind of the recorded transition each event kind ends in (+1 slip → stick, −1 stick → slip).
_RECORDED_KIND = {V.EV_MARGIN: E.TRANSITION_TO_SLIP, V.EV_ZERO: E.TRANSITION_TO_STICK,
                  V.EV_ARRIVE: E.TRANSITION_TO_STICK}


@dataclasses.dataclass(frozen=True, eq=False)
class FlowJacobian:
    """Linearised flow ∂Φ(s0, t)/∂s0 across stick↔slip transitions.

    Parameters
    ----------
    matrix : ndarray (2n, 2n)
        ∂s(t)/∂s0 in the model's units (rows and columns of locked states are zero).
    state0, state : ndarray (2n,)
        Initial and final state.
    duration : float
        t [s].
    events : tuple of (float, str, int)
        (instant [s], kind, contact) of every jump applied, kind one of ``"stick"``,
        ``"breakaway"``, ``"band"``, ``"reversal"``, ``"open"``, ``"close"`` (a unilateral contact's
        gap) and ``"impact"`` (a rigid contact's saltation matrix).
    mismatch : float
        Largest scaled difference between a re-integrated state and the event integrator's [-].
    wall_time : float
        Seconds taken.
    state_names : tuple of str
        Names of the states (rows and columns of :attr:`matrix`), the model's ``state_names``.
    """

    matrix: np.ndarray
    state0: np.ndarray
    state: np.ndarray
    duration: float
    events: tuple
    mismatch: float
    wall_time: float
    state_names: tuple = ()

    def to_xarray(self):
        """``xarray.Dataset``: the matrix, initial and final state, the jumps."""
        import xarray as xr

        data = {
            "flow_jacobian": (("state", "state_0"), self.matrix,
                              {"long_name": "linearised flow d s(t) / d s(0) (variational equations + saltation)"}),
            "state_initial": ("state", self.state0, {"long_name": "initial state"}),
            "state_final": ("state", self.state, {"long_name": "final state"}),
        }
        attrs = {"title": "stickslip linearised flow map", "stickslip_version": __version__,
                 "duration": self.duration, "duration_units": "s", "events": json.dumps(self.events),
                 "mismatch": self.mismatch, "wall_time_s": self.wall_time}
        names = list(self.state_names)
        return xr.Dataset(data, coords={"state": names, "state_0": names}, attrs=attrs)


def _sigma(system, scale) -> np.ndarray:
    """State scales (2n,) of the consistency checks: σ on the free states (default 1), 1 elsewhere."""
    sigma = np.ones(2 * system.n)
    if scale is not None:
        sigma[free_states(system)] = np.asarray(scale, dtype=float)
    return sigma


def flow_jacobian(system, s0, duration: float, *, rtol: float = 1e-10, atol: float | None = None,
                  scale=None) -> FlowJacobian:
    """Linearised flow map ∂Φ(s0, t)/∂s0 from the variational equations with saltation matrices.

    Parameters
    ----------
    system : FrictionModel
    s0 : array-like (2n,)
        Initial state. Contacts that stick there start with their variations projected onto the
        stick manifold.
    duration : float
        t [s].
    rtol, atol : float
        Tolerances of the ``event`` run that gives the transitions (``atol`` default 1e-3 rtol).
    scale : array-like (2 n_free,), optional
        State scales σ of the free states (of the consistency checks; default 1).

    Raises
    ------
    OrbitError
        If a run fails, an event is grazing, or the re-integration departs from the event
        integrator's trajectory (different event sequence).
    """
    t_start = _time.perf_counter()
    atol = 1e-3 * rtol if atol is None else float(atol)
    free = free_states(system)
    s0 = np.asarray(s0, dtype=float).copy()
    end, tr = flow(system, s0, float(duration), rtol=rtol, atol=atol)
    n2 = 2 * system.n
    Phi = np.zeros((n2, n2))
    Phi[free, free] = 1.0
    Phi, events, mismatch = propagate(system, s0, float(duration), tr, end, Phi, scale=scale, rtol=rtol, atol=atol)
    M = np.zeros((n2, n2))
    M[np.ix_(free, free)] = Phi[np.ix_(free, free)]
    return FlowJacobian(matrix=M, state0=s0, state=np.asarray(end).copy(), duration=float(duration),
                        events=tuple(events), mismatch=mismatch, wall_time=_time.perf_counter() - t_start,
                        state_names=tuple(system.state_names))


def initial_contacts(system, s0, rtol: float, atol: float):
    """The contact states a run from ``s0`` starts in, as the re-integration follows them, and the
    state (projected where contacts stick): open and sticking contacts as they are, each 1-D
    slipping contact along its stored direction,
    each 2-D one with the exact direction, or the quasi-static one if it departs from v_c = 0."""
    md = system.data
    n2 = 2 * system.n
    nc = system.n_contacts
    y = np.ascontiguousarray(s0[:n2], dtype=float).copy()
    cst = contact_state(md.m)
    E.initial_modes(y, cst, md, rtol, atol, np.empty(2 * nc), np.empty(nc))
    for c in range(nc):
        mode = int(cst[CST * c])
        if mode == P.MODE_STICK or mode == P.MODE_OPEN:
            continue
        v0, v1 = P.slip_velocity(y, c, md)
        if system.contacts[c].dim == 1:
            e = float(np.sign(v0)) if v0 != 0.0 else float(np.sign(cst[CST * c + 1]) or 1.0)
            cst[:] = S.with_mode(cst, c, P.MODE_SLIP_QUASI_STATIC, (e, 0.0))
        elif mode == P.MODE_SLIP_EXACT:
            cst[CST * c + 3] = np.inf
    return y, cst


def _events_of(system, cst):
    """Per-contact event kinds, levels and stored 1-D directions of a segment in the modes of ``cst``
    (then, with unilateral contacts, each one's open/closed event at nc + c), and whether a 2-D
    contact slips inside the low-speed band (its direction turns with the state)."""
    nc = system.n_contacts
    size = 2 * nc if system.unilateral else nc
    kind = np.zeros(size, dtype=np.int64)
    level = np.zeros(size)
    e = np.zeros(size)
    band = False
    for c in range(nc):
        mode = int(cst[CST * c])
        if system.contacts[c].unilateral:
            kind[nc + c] = V.EV_GAP
        if mode == P.MODE_OPEN:
            continue
        if mode == P.MODE_STICK:
            kind[c] = V.EV_MARGIN
        elif system.contacts[c].dim == 1:
            kind[c] = V.EV_ZERO
            e[c] = cst[CST * c + 1]
        elif mode == P.MODE_SLIP_EXACT:
            kind[c], level[c] = V.EV_ARRIVE, ARRIVAL_SPEED
        else:
            kind[c], level[c] = V.EV_BAND, system.slip_band
            band = True
    return kind, level, e, band


def _segment(system, y, Phi, t0, t1, cst, rtol, unwatched: int = -1):
    """Integrate [s, Φ] from t0 towards t1 in the modes of ``cst`` until the first event (the gap
    event of contact ``unwatched``, if one is given, not watched)."""
    n2 = 2 * system.n
    kind, level, e, band = _events_of(system, cst)
    if unwatched >= 0:
        kind[system.n_contacts + unwatched] = V.EV_NONE
    y0 = np.concatenate([y[:n2], Phi.ravel()])
    atol = np.full(y0.size, VAR_ATOL_PHI)
    atol[:n2] = VAR_ATOL_STATE
    status, t, y_end, c = V.integrate_segment(y0, float(t0), float(t1), cst, system.data, n2, band,
                                              float(rtol), atol, V.SegmentEvents(kind, level, e), MAX_SEGMENT_STEPS)
    if status > 1:
        raise OrbitError(f"variational integration failed at t = {t} s "
                         f"({'step underflow' if status == 2 else 'too many steps'})")
    return types.SimpleNamespace(event=status == 1, t=float(t), s=y_end[:n2].copy(),
                                 Phi=y_end[n2:].reshape(n2, n2), contact=int(c),
                                 kind=int(kind[c]) if c >= 0 else V.EV_NONE)


def propagate(system, s0, T: float, tr, end, Phi: np.ndarray, *, scale=None, after=None,
              max_interval: float = np.inf, rtol: float = VAR_RTOL, atol: float | None = None):
    """Carry the variations ``Phi`` (2n × k) along the event integrator's run from ``s0``.

    Parameters
    ----------
    system : FrictionModel
    s0 : ndarray (2n,)
    T : float
        Duration [s].
    tr : Transitions
        The run's transitions (instants, kinds, contacts, states).
    end : ndarray (2n,)
        The run's final state (checked against the re-integration).
    Phi : ndarray (2n, k)
        Initial variations (columns).
    scale : array-like (2 n_free,), optional
        State scales σ of the free states (consistency checks).
    after : callable (t, Phi) -> Phi, optional
        Called after every smooth piece and every jump (e.g. QR re-orthonormalisation).
    max_interval : float
        Longest smooth piece integrated in one call [s] (``after`` is called at least that often).
    rtol, atol : float
        Tolerances of the run (the initial modes are found as the run found them).

    Returns
    -------
    Phi : ndarray (2n, k)
    events : list of (float, str, int)
    mismatch : float
    """
    n2 = 2 * system.n
    atol = 1e-3 * rtol if atol is None else atol
    k_cols = Phi.shape[1]
    compile_apart(system.data, VARIATIONAL, f"{__name__}:VARIATIONAL")
    y, cst = initial_contacts(system, np.asarray(s0, dtype=float), rtol, atol)
    user_after = (lambda t, Q: Q) if after is None else after

    def carried(t, Q):  # the caller sees its k columns; the integration carries 2n
        out = np.zeros((n2, n2))
        out[:, :k_cols] = user_after(t, Q[:, :k_cols])
        return out

    full = np.zeros((n2, n2))
    full[:, :k_cols] = Phi
    if S.sticking(cst):
        full = S.stick_projection(system, y, cst) @ full
    carry = _Carry(system, tr, _sigma(system, scale), carried, y, cst, full)
    while carry.t < T:
        t_next = float(tr.time[carry.k]) if carry.k < len(tr) else T
        seg = carry.segment(T, t_next, max_interval, rtol)
        if not seg.event:
            carry.smooth(seg, t_next)
        elif seg.kind == V.EV_GAP and carry.lands(seg.contact - system.n_contacts):
            carry.impact(seg, t_next)
        elif seg.kind == V.EV_GAP:
            carry.gap(seg, t_next)
        elif seg.kind == V.EV_BAND:
            carry.band(seg)
        elif seg.kind == V.EV_MARGIN:
            carry.breakaway(seg, t_next)
        else:
            carry.arrival(seg, t_next)
    carry.check(carry.y, np.asarray(end)[:n2])
    return carry.Phi[:, :k_cols], carry.events, carry.mismatch


@dataclasses.dataclass(eq=False)
class _Carry:
    """The variations :func:`propagate` carries along the event integrator's run (internal): the
    re-integration's state ``y``, time ``t`` [s], contact states ``cst`` and variations ``Phi``
    (2n × 2n), the next recorded transition ``k``, the jumps applied and the largest mismatch."""

    system: object
    tr: object
    sigma: np.ndarray
    after: object
    y: np.ndarray
    cst: np.ndarray
    Phi: np.ndarray
    t: float = 0.0
    k: int = 0
    events: list = dataclasses.field(default_factory=list)
    mismatch: float = 0.0

    def check(self, s_var, s_ref, which=None) -> None:
        """Refuse a re-integrated state ``s_var`` that left the run's ``s_ref`` (scaled difference on
        the free states, or on ``which``, beyond :data:`MATCH_TOL`)."""
        which = free_states(self.system) if which is None else which
        d = float(np.max(np.abs(s_var[which] - s_ref[which]) / self.sigma[which]))
        self.mismatch = max(self.mismatch, d)
        if d > MATCH_TOL:
            raise OrbitError(
                f"the variational re-integration left the event integrator's trajectory (scaled "
                f"difference {d:.1e} > {MATCH_TOL:.0e}): the event sequence differs (grazing, or a "
                "return to v ≈ 0 inside the low-speed band?)")

    def pending(self, kinds=None) -> bool:
        """Whether a recorded transition is ahead (of one of ``kinds``, if given)."""
        return self.k < len(self.tr) and (kinds is None or int(self.tr.kind[self.k]) in kinds)

    def segment(self, T: float, t_next: float, max_interval: float, rtol: float):
        """The next smooth piece (:func:`_segment`), up to its first event, at most ``max_interval``
        and a second past the next recorded transition (at ``t_next``). A flight (or touch) shorter
        than the re-integration's steps, which see the contact alike at both ends of one, was found
        by the run inside its step (on the gap's Hermite dip): the piece then ends at the recorded
        instant, with that transition's gap event. A piece towards a recorded impact ends at its
        instant (:meth:`towards_impact`)."""
        if self.pending((E.TRANSITION_IMPACT,)) and self.t + max_interval >= t_next:
            return self.towards_impact(t_next, rtol)
        t1 = min(self.t + max_interval, t_next + 1.0 if self.pending() else T)
        seg = _segment(self.system, self.y, self.Phi, self.t, t1, self.cst, rtol)
        if not seg.event and self.pending((E.TRANSITION_OPEN, E.TRANSITION_CLOSE)) \
                and seg.t >= t_next + MATCH_TIME_TOL:
            seg = _segment(self.system, self.y, self.Phi, self.t, t_next, self.cst, rtol)
            if not seg.event:
                seg.event, seg.contact, seg.kind = True, self.system.n_contacts + int(self.tr.contact[self.k]), V.EV_GAP
        return seg

    def towards_impact(self, t_next: float, rtol: float):
        """The piece up to the recorded impact of contact c at ``t_next``, its gap event unwatched, so
        that it ends there with c's gap event (unless another event comes first).

        The impact's jump (:func:`.saltation.impact_jump`) divides the variations' component across
        the gap by the landing speed ġ⁻; its error from evaluating the jump at the recorded state and
        the variations at another instant δt is ~ g̈ δt / ġ⁻ times the jump's large column. The
        re-integration's own landing lies up to :data:`MATCH_TIME_TOL` from the record, and near a
        grazing (a dip of the gap shorter than its steps, ~ ġ⁻/g̈) it can miss the landing
        altogether: the variations are therefore carried to the recorded instant itself."""
        c = int(self.tr.contact[self.k])
        seg = _segment(self.system, self.y, self.Phi, self.t, t_next, self.cst, rtol, unwatched=c)
        if not seg.event:
            seg.event, seg.contact, seg.kind = True, self.system.n_contacts + c, V.EV_GAP
        return seg

    def smooth(self, seg, t_next: float) -> None:
        """A piece without an event, which must not pass the next recorded transition."""
        if self.pending() and seg.t >= t_next + MATCH_TIME_TOL:
            raise OrbitError(f"the re-integration did not meet the integrator's transition at {t_next:.9f} s")
        self.y, self.t, self.Phi = seg.s, seg.t, self.after(seg.t, seg.Phi)

    def lands(self, c: int) -> bool:
        """Whether a gap event of contact ``c`` is a rigid contact's landing (an impact)."""
        contact = self.system.contacts[c]
        return contact.unilateral and contact.normal.law == "rigid" and int(self.cst[CST * c]) == P.MODE_OPEN

    def recorded_at(self, seg, c: int) -> list:
        """The recorded transitions of contact ``c`` at the piece's event instant, from ``k`` on."""
        tr = self.tr
        return [j for j in range(self.k, len(tr)) if abs(float(tr.time[j]) - seg.t) <= MATCH_TIME_TOL
                and int(tr.contact[j]) == c]

    def jump(self, matrix, seg_Phi, t: float, kind: str, c: int) -> None:
        """Apply the jump ``matrix`` at ``t`` to the piece's variations, and list it."""
        self.Phi = self.after(t, matrix @ seg_Phi)
        self.events.append((t, kind, c))

    def impact(self, seg, t_next: float) -> None:
        """A rigid contact lands: the impact's saltation matrix, at the recorded impact; the
        re-integration goes on from the recorded state after it (bounced off or closed)."""
        system, tr = self.system, self.tr
        c = seg.contact - system.n_contacts
        at = self.recorded_at(seg, c)
        kinds = [int(tr.kind[j]) for j in at]
        if E.TRANSITION_IMPACT not in kinds or kinds[-1] not in (E.TRANSITION_OPEN, E.TRANSITION_CLOSE):
            raise OrbitError(f"contact {c} lands in the re-integration at {seg.t:.9f} s, the integrator's next "
                             f"transition is at {t_next:.9f} s" + (" (it sticks there: no saltation matrix "
                                                                  "for stick at an impact; use the "
                                                                  "finite-difference monodromy)"
                                                                  if E.TRANSITION_TO_STICK in kinds else ""))
        i_impact = at[kinds.index(E.TRANSITION_IMPACT)]
        bounced = kinds[-1] == E.TRANSITION_OPEN
        if not bounced and system.contacts[c].normal.restitution > 0.0:
            raise OrbitError(f"contact {c}'s bounces accumulate at {seg.t:.9f} s (a Zeno sequence): no saltation "
                             "matrix; use the finite-difference monodromy")
        s_i = tr.state[i_impact][:2 * system.n]
        self.check(seg.s, s_i)
        jump, self.cst = S.impact_jump(system, s_i, self.cst, c, bounced)
        self.jump(jump, seg.Phi, float(tr.time[i_impact]), "impact", c)
        self.y, self.t, self.k = tr.state[at[-1]][:2 * system.n].copy(), float(tr.time[at[-1]]), at[-1] + 1

    def gap(self, seg, t_next: float) -> None:
        """A unilateral contact opens or closes (an opening from stick is recorded as stick → slip,
        then open, at one instant): the gap's saltation matrix at the recorded transition."""
        system, tr = self.system, self.tr
        c = seg.contact - system.n_contacts
        recorded = E.TRANSITION_CLOSE if int(self.cst[CST * c]) == P.MODE_OPEN else E.TRANSITION_OPEN
        at = self.recorded_at(seg, c)
        if not any(int(tr.kind[j]) == recorded for j in at):
            raise OrbitError(f"contact {c} {'closes' if recorded == E.TRANSITION_CLOSE else 'opens'} in the "
                             f"re-integration at {seg.t:.9f} s, the integrator's next transition is at "
                             f"{t_next:.9f} s")
        s_g = tr.state[at[-1]][:2 * system.n]
        self.check(seg.s, s_g)
        jump, self.cst = S.gap_jump(system, s_g, self.cst, c)
        self.jump(jump, seg.Phi, float(tr.time[at[-1]]), E.TRANSITION_KINDS[recorded], c)
        self.y, self.t, self.k = s_g.copy(), float(tr.time[at[-1]]), at[-1] + 1
        if int(tr.kind[at[-1]]) == E.TRANSITION_TO_STICK:
            raise OrbitError(f"contact {c} closes and sticks at {self.t:.9f} s: stick at closing has no saltation "
                             "matrix here; use the finite-difference monodromy")

    def band(self, seg) -> None:
        """A 2-D contact leaves the low-speed band (the run records nothing there)."""
        jump, self.cst = S.band_exit_jump(self.system, seg.s, self.cst, seg.contact)
        self.y, self.t = seg.s, seg.t
        self.jump(jump, seg.Phi, seg.t, "band", seg.contact)

    def matched(self, seg, t_next: float) -> bool:
        """Whether the event is the next recorded transition (same contact and kind, same instant)."""
        return (self.pending() and abs(seg.t - t_next) <= MATCH_TIME_TOL and int(self.tr.contact[self.k]) == seg.contact
                and int(self.tr.kind[self.k]) == _RECORDED_KIND[seg.kind])

    def breakaway(self, seg, t_next: float) -> None:
        """A sticking contact breaks away: the breakaway's saltation matrix at the recorded one."""
        c = seg.contact
        if not self.matched(seg, t_next):
            raise OrbitError(f"breakaway of contact {c} in the re-integration at {seg.t:.9f} s, "
                             f"the integrator's next transition is at {t_next:.9f} s")
        s_b = self.tr.state[self.k][:2 * self.system.n]
        self.check(seg.s, s_b)
        jump, self.cst = S.breakaway_jump(self.system, s_b, self.cst, c)
        self.jump(jump, seg.Phi, t_next, "breakaway", c)
        self.y, self.t, self.k = s_b.copy(), t_next, self.k + 1

    def arrival(self, seg, t_next: float) -> None:
        """A slipping contact reaches v = 0: stick at the recorded arrival (positions only,
        extrapolated over the rest of a 2-D approach to the integrator's instant: the velocities
        differ by that O(τ) rest and the integrator's projection), or, before the next recorded
        transition, a reversal."""
        c = seg.contact
        if not self.matched(seg, t_next):
            if self.pending() and seg.t > t_next + MATCH_TIME_TOL:
                raise OrbitError(f"arrival at stick of contact {c} in the re-integration at {seg.t:.9f} s, "
                                 f"the integrator's transition at {t_next:.9f} s")
            self.reversal(seg, t_next)
            return
        system = self.system
        s_s = self.tr.state[self.k][:2 * system.n]
        s_x = seg.s + (t_next - seg.t) * S.field(system, seg.s, self.cst)
        free = free_states(system)
        self.check(s_x, s_s, free[: free.size // 2])
        jump, self.cst = S.arrival_jump(system, seg.s, self.cst, c, s_s)
        self.jump(jump, seg.Phi, t_next, "stick", c)
        self.y, self.t, self.k = s_s.copy(), t_next, self.k + 1

    def reversal(self, seg, t_next: float) -> None:
        """v_c reaches 0 before the integrator's next transition: stick must be inadmissible there
        (a velocity reversal, which the integrator does not record); slip departs along the
        breakaway direction of the stick force."""
        system, c = self.system, seg.contact
        s_r = seg.s.copy()
        P.project_velocities(s_r, self.cst, np.int64(c), system.data)
        F = np.empty(2 * system.n_contacts)
        N = np.empty(system.n_contacts)
        P.stick_forces(s_r, self.cst, np.int64(c), system.data, F, N)
        limit = S.static_coefficient(system.contacts[c].friction.row()) * N[c]
        if np.hypot(F[2 * c], F[2 * c + 1]) <= limit:
            raise OrbitError(f"the re-integration reaches an admissible stick of contact {c} at {seg.t:.9f} s, "
                             f"the event integrator does not (next transition {t_next:.9f} s): the event "
                             "sequences differ (e.g. a return to v ≈ 0 inside the low-speed band)")
        e_b = E.breakaway_direction(F[2 * c], F[2 * c + 1], system.contacts[c].dim)
        jump, self.cst = S.arrival_jump(system, seg.s, self.cst, c, s_r, departure=e_b)
        self.jump(jump, seg.Phi, seg.t, "reversal", c)
        self.y, self.t = s_r, seg.t
