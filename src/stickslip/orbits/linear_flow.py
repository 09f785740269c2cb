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
            V._first_event: (kind, level, level, y, y, np.zeros((y.size, 4)), 0.0, cst, md, n2, level, y, s),
            V.contact_gradients: (s, cst, 0, md, n2, np.zeros((2, n2)), np.zeros((2, n2)), s, z,
                                  np.zeros(2 * nc, dtype=complex), np.zeros(nc, dtype=complex),
                                  np.zeros(2 * nc, dtype=complex)),
            E.initial_modes: (s, cst, md, 0.0, 0.0, F, N)}


#: A cold start's variational kernels in two processes (:mod:`stickslip.model.compile_ahead`):
#: the event functions, then the variational right-hand side (with the complex-step physics under
#: it) in the helper; the complex-step version of the band direction's residual, the first event's
#: search, the contact gradients of the saltation matrices and the starting modes here; the
#: segment integrator then loads both. A model file's ``orbit`` after its ``stability``, from an
#: empty cache otherwise: the variational kernels in 14 s instead of 21 s; with the residual here
#: (the helper, the longer side before, then mostly finds it in the cache) the two sides 3.9–4.0 s
#: instead of 4.6 s; with the event functions in the helper (which the first event's search here
#: then loads) 2.9–3.0 s against 3.1–3.2 s.
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


def _segment(system, y, Phi, t0, t1, cst, rtol):
    """Integrate [s, Φ] from t0 towards t1 in the modes of ``cst`` until the first event."""
    n2 = 2 * system.n
    kind, level, e, band = _events_of(system, cst)
    y0 = np.concatenate([y[:n2], Phi.ravel()])
    atol = np.full(y0.size, VAR_ATOL_PHI)
    atol[:n2] = VAR_ATOL_STATE
    status, t, y_end, c = V.integrate_segment(y0, float(t0), float(t1), cst, system.data, n2, band,
                                              float(rtol), atol, kind, level, e, MAX_SEGMENT_STEPS)
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
    free = free_states(system)
    free_q = free[: free.size // 2]
    sigma = _sigma(system, scale)
    atol = 1e-3 * rtol if atol is None else atol
    events = []
    mismatch = 0.0
    k_cols = Phi.shape[1]

    def check(s_var, s_ref, which=free):
        nonlocal mismatch
        d = float(np.max(np.abs(s_var[which] - s_ref[which]) / sigma[which]))
        mismatch = max(mismatch, d)
        if d > MATCH_TOL:
            raise OrbitError(
                f"the variational re-integration left the event integrator's trajectory (scaled "
                f"difference {d:.1e} > {MATCH_TOL:.0e}): the event sequence differs (grazing, or a "
                "return to v ≈ 0 inside the low-speed band?)")

    compile_apart(system.data, VARIATIONAL, f"{__name__}:VARIATIONAL")
    y, cst = initial_contacts(system, np.asarray(s0, dtype=float), rtol, atol)
    user_after = (lambda t, Q: Q) if after is None else after

    def after(t, Q):  # the caller sees its k columns; the integration carries 2n
        out = np.zeros((n2, n2))
        out[:, :k_cols] = user_after(t, Q[:, :k_cols])
        return out

    full = np.zeros((n2, n2))
    full[:, :k_cols] = Phi
    Phi = full
    if S.sticking(cst):
        Phi = S.stick_projection(system, y, cst) @ Phi
    t = 0.0
    k = 0
    n_tr = len(tr)
    while t < T:
        t_next = float(tr.time[k]) if k < n_tr else T
        t1 = min(t + max_interval, t_next + 1.0 if k < n_tr else T)
        seg = _segment(system, y, Phi, t, t1, cst, rtol)
        if not seg.event and k < n_tr and seg.t >= t_next + MATCH_TIME_TOL and \
                int(tr.kind[k]) in (E.TRANSITION_OPEN, E.TRANSITION_CLOSE):
            # a flight (or touch) shorter than the re-integration's steps, which see the contact
            # alike at both ends of one: the run found it inside its step (on the gap's Hermite
            # dip), so carry the variations to its recorded instant and take its jump there
            seg = _segment(system, y, Phi, t, t_next, cst, rtol)
            if not seg.event:
                seg.event, seg.contact, seg.kind = True, system.n_contacts + int(tr.contact[k]), V.EV_GAP
        if not seg.event:
            if k < n_tr and seg.t >= t_next + MATCH_TIME_TOL:
                raise OrbitError(f"the re-integration did not meet the integrator's transition at {t_next:.9f} s")
            y, t, Phi = seg.s, seg.t, after(seg.t, seg.Phi)
            continue
        c, kind = seg.contact, seg.kind
        if kind == V.EV_GAP and system.contacts[c - system.n_contacts].unilateral \
                and system.contacts[c - system.n_contacts].normal.law == "rigid" \
                and int(cst[CST * (c - system.n_contacts)]) == P.MODE_OPEN:
            c -= system.n_contacts
            at = [j for j in range(k, n_tr) if abs(float(tr.time[j]) - seg.t) <= MATCH_TIME_TOL
                  and int(tr.contact[j]) == c]
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
            s_i = tr.state[i_impact][:n2]
            check(seg.s, s_i)
            jump, cst = S.impact_jump(system, s_i, cst, c, bounced)
            Phi = after(float(tr.time[i_impact]), jump @ seg.Phi)
            events.append((float(tr.time[i_impact]), "impact", c))
            y, t, k = tr.state[at[-1]][:n2].copy(), float(tr.time[at[-1]]), at[-1] + 1
            continue
        if kind == V.EV_GAP:
            c -= system.n_contacts
            recorded = E.TRANSITION_CLOSE if int(cst[CST * c]) == P.MODE_OPEN else E.TRANSITION_OPEN
            # an opening from stick is recorded as stick → slip, then open, at one instant
            at = [j for j in range(k, n_tr) if abs(float(tr.time[j]) - seg.t) <= MATCH_TIME_TOL
                  and int(tr.contact[j]) == c]
            if not any(int(tr.kind[j]) == recorded for j in at):
                raise OrbitError(f"contact {c} {'closes' if recorded == E.TRANSITION_CLOSE else 'opens'} in the "
                                 f"re-integration at {seg.t:.9f} s, the integrator's next transition is at "
                                 f"{t_next:.9f} s")
            s_g = tr.state[at[-1]][:n2]
            check(seg.s, s_g)
            jump, cst = S.gap_jump(system, s_g, cst, c)
            Phi = after(float(tr.time[at[-1]]), jump @ seg.Phi)
            events.append((float(tr.time[at[-1]]), E.TRANSITION_KINDS[recorded], c))
            y, t, k = s_g.copy(), float(tr.time[at[-1]]), at[-1] + 1
            if int(tr.kind[at[-1]]) == E.TRANSITION_TO_STICK:
                raise OrbitError(f"contact {c} closes and sticks at {t:.9f} s: stick at closing has no saltation "
                                 "matrix here; use the finite-difference monodromy")
            continue
        if kind == V.EV_BAND:
            jump, cst = S.band_exit_jump(system, seg.s, cst, c)
            y, t, Phi = seg.s, seg.t, after(seg.t, jump @ seg.Phi)
            events.append((t, "band", c))
            continue
        matched = (k < n_tr and abs(seg.t - t_next) <= MATCH_TIME_TOL and int(tr.contact[k]) == c
                   and int(tr.kind[k]) == _RECORDED_KIND[kind])
        if kind == V.EV_MARGIN:
            if not matched:
                raise OrbitError(f"breakaway of contact {c} in the re-integration at {seg.t:.9f} s, "
                                 f"the integrator's next transition is at {t_next:.9f} s")
            s_b = tr.state[k][:n2]
            check(seg.s, s_b)
            jump, cst = S.breakaway_jump(system, s_b, cst, c)
            Phi = after(t_next, jump @ seg.Phi)
            events.append((t_next, "breakaway", c))
            y, t, k = s_b.copy(), t_next, k + 1
            continue
        if matched:
            s_s = tr.state[k][:n2]
            # positions only, extrapolated over the rest of a 2-D approach to the integrator's
            # instant: the velocities differ by that O(τ) rest and the integrator's projection
            s_x = seg.s + (t_next - seg.t) * S.field(system, seg.s, cst)
            check(s_x, s_s, free_q)
            jump, cst = S.arrival_jump(system, seg.s, cst, c, s_s)
            Phi = after(t_next, jump @ seg.Phi)
            events.append((t_next, "stick", c))
            y, t, k = s_s.copy(), t_next, k + 1
            continue
        if k < n_tr and seg.t > t_next + MATCH_TIME_TOL:
            raise OrbitError(f"arrival at stick of contact {c} in the re-integration at {seg.t:.9f} s, "
                             f"the integrator's transition at {t_next:.9f} s")
        # v_c reaches 0 before the integrator's next transition: stick must be inadmissible there
        # (a velocity reversal, which the integrator does not record)
        s_r = seg.s.copy()
        P.project_velocities(s_r, cst, np.int64(c), system.data)
        F = np.empty(2 * system.n_contacts)
        N = np.empty(system.n_contacts)
        P.stick_forces(s_r, cst, np.int64(c), system.data, F, N)
        dim = system.contacts[c].dim
        limit = S.static_coefficient(system.contacts[c].friction.row()) * N[c]
        if np.hypot(F[2 * c], F[2 * c + 1]) <= limit:
            raise OrbitError(f"the re-integration reaches an admissible stick of contact {c} at {seg.t:.9f} s, "
                             f"the event integrator does not (next transition {t_next:.9f} s): the event "
                             "sequences differ (e.g. a return to v ≈ 0 inside the low-speed band)")
        e_b = E.breakaway_direction(F[2 * c], F[2 * c + 1], dim)
        jump, cst = S.arrival_jump(system, seg.s, cst, c, s_r, departure=e_b)
        Phi = after(seg.t, jump @ seg.Phi)
        events.append((seg.t, "reversal", c))
        y, t = s_r, seg.t
    check(y, np.asarray(end)[:n2])
    return Phi[:, :k_cols], events, mismatch

