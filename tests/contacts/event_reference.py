"""An event-driven reference for a model with one compliant unilateral contact and 1-D friction,
written with scipy alone (it shares nothing with the package's kernels).

Modes: ``open`` (no contact force), ``stick`` (v = 0, the stick force within its limit) and slip
with sign(v) = ±1. Each mode is integrated with DOP853 at rtol 1e-12 up to its first located
event, and restarted from there in the next mode:

| mode | event | then |
| --- | --- | --- |
| slip σ | the contact indicator φ falls to 0 | open |
| slip σ | v passes 0 | stick if the stick force is within its limit, else slip the other way |
| stick | φ falls to 0 | slip, then open |
| stick | the stick force reaches its limit | slip opposite to the stick force (breakaway) |
| open | φ rises through 0 | slip along sign(v) (close) |

A test states its own model through the functions it passes: ``field(mode)`` the right-hand side
in a mode, ``phi(s)`` the indicator (the contact is closed while φ > 0), ``slip_speed(s)`` v,
``stick_force(s)`` the force that holds v = 0, ``limit(s)`` its bound μs λ.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from stickslip.analysis.signal import CLOSE, OPEN, SLIP, STICK

OPEN_MODE, STICK_MODE = "open", "stick"


def event_driven(field, phi, slip_speed, stick_force, limit, t_eval, y0):
    """The states at ``t_eval`` (from ``t_eval[0] = 0``) and the instants of each transition kind
    (OPEN, CLOSE, STICK, SLIP) of the run from ``y0``, which starts closed and slipping."""
    def contact(t, s):
        return phi(s)

    def slip(t, s):
        return slip_speed(s)

    def margin(t, s):
        return limit(s) - abs(stick_force(s))

    for event in (contact, slip, margin):
        event.terminal = True
    t0, s = 0.0, np.array(y0, dtype=float)
    mode = -1 if slip_speed(s) < 0.0 else 1
    out = np.empty((len(t_eval), s.size))
    switches = {OPEN: [], CLOSE: [], STICK: [], SLIP: []}
    while t0 < t_eval[-1]:
        if mode == OPEN_MODE:
            contact.direction, events = 1.0, [contact]
        elif mode == STICK_MODE:
            contact.direction, margin.direction, events = -1.0, -1.0, [contact, margin]
        else:
            contact.direction, slip.direction, events = -1.0, -float(mode), [contact, slip]
        # the samples ahead, interpolated by scipy in the steps that hold them (a segment between
        # two close events may hold none); the segment ends at its event, or at the last sample
        ahead = np.flatnonzero(t_eval >= t0)
        sol = solve_ivp(field(mode), (t0, t_eval[-1]), s, method="DOP853", rtol=1e-12, atol=1e-14,
                        events=events, t_eval=t_eval[ahead])
        if len(sol.t):  # scipy leaves them lists when no sample fell in the segment
            out[ahead[:len(sol.t)]] = sol.y.T
        if sol.status != 1:
            break
        k = next(k for k, te in enumerate(sol.t_events) if te.size)
        t0, s = sol.t_events[k][0], sol.y_events[k][0]
        fired, t1 = events[k], t0
        if fired is contact and mode != OPEN_MODE:
            if mode == STICK_MODE:
                switches[SLIP].append(t1)
            switches[OPEN].append(t1)
            mode = OPEN_MODE
        elif fired is contact:
            switches[CLOSE].append(t1)
            mode = -1 if slip_speed(s) < 0.0 else 1
        elif fired is slip:
            F = stick_force(s)
            if abs(F) <= limit(s):
                mode = STICK_MODE
                switches[STICK].append(t1)
            else:
                mode = -1 if F > 0 else 1
        else:  # breakaway: slip leaves opposite to the excess stick force
            switches[SLIP].append(t1)
            mode = 1 if stick_force(s) < 0 else -1
    return out, {k: np.array(v) for k, v in switches.items()}


def assert_matches(traj, ref, switches, atol, least=1):
    """The run ``traj`` against the reference: it ended successfully, has at least ``least``
    transitions of each kind (OPEN, CLOSE, STICK, SLIP), each at the reference's instant, and every
    sample's state equal to ``ref``, all to ``atol``."""
    assert traj.status == "success"
    tr = traj.transitions
    for kind in (OPEN, CLOSE, STICK, SLIP):
        assert np.sum(tr.kind == kind) >= least, kind
        np.testing.assert_allclose(tr.time[tr.kind == kind], switches[kind], rtol=0, atol=atol)
    np.testing.assert_allclose(traj.states, ref, rtol=0, atol=atol)
