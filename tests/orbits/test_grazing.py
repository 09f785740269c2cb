"""Grazing: a flight phase of a unilateral contact appears on a branch, located and passed.

The library model ``hoffmann`` (flutter, a compliant contact that lifts off) with μ_k = 1.3 and
damping 0.1 on both dofs settles, from x = 0.01, on a stick-slip cycle whose contact stays closed
at belt speed 0.1 and lifts off once a period at 0.12. Continued in the belt speed, the branch
passes a grazing point near 0.1102 (measured: 0.110165 going up, 0.110172 going down; the open
time then grows like √(λ − λ*), no fold, every orbit stable). The located λ* is checked without
the continuation: orbits shot at λ*(1 ∓ 10⁻³) have no flight and one flight per period, their
largest gap g has the signs to match, and at λ* it is zero to within the location's bracket; and
the closed cycle, which scales with the belt speed, predicts λ* from one orbit at 0.1. Models
without unilateral contacts keep their outputs: no open phases anywhere.
"""

import types

import numpy as np
import pytest

from stickslip.analysis.signal import CLOSE, OPEN, SLIP, STICK
from stickslip.model.library import load_model
from stickslip.orbits import branch_store as store
from stickslip.orbits import periodic_orbit
from stickslip.orbits.arclength import Point
from stickslip.orbits.continuation import Branch, continue_orbit, load_branch, start_run
from stickslip.orbits.layout import equilibrium_state
from stickslip.orbits.problem import open_count, open_time, stick_summary

DRIVE = "contact.0.drive"

#: Relative offset of the orbits shot on either side of the located grazing point (18× the
#: bracket the bisection leaves, 6e-6 measured).
SIDE = 1e-3

#: Largest gap of a flight the event integrator may step over without recording an opening: it
#: finds a flight inside a step where the step's cubic Hermite interpolant of the gap dips, so one
#: whose peak lies below that interpolant's error (~h⁴ max|d⁴g/dt⁴| / 384) may pass unseen.
#: Measured on orbits shot 1e-8 … 1e-6 past the scaling prediction of λ*: every flight recorded,
#: the smallest with largest gap 9.4e-8.
MISSED_GAP = 1e-7


def _hoffmann(drive: float):
    return load_model("hoffmann").replace(**{"contact.0.friction.mu_k": 1.3, "damping.0.0": 0.1,
                                             "damping.1.1": 0.1, DRIVE: drive})


def _branch(start: float, stop: float, **kw) -> Branch:
    system = _hoffmann(start)
    run = start_run(system, {"x": 0.01}, t_end=300.0)
    return continue_orbit(system, DRIVE, start=run, direction=1 if stop > start else -1,
                          bounds=(min(start, stop), max(start, stop)), amplitude=False, **kw)


@pytest.fixture(scope="module")
def up() -> Branch:
    """The branch from belt speed 0.1 (no flight) to 0.13 (~2 s once compiled)."""
    return _branch(0.1, 0.13)


def _grazing(branch):
    found = [q for q in branch.special if q.kind == "grazing"]
    assert len(found) == 1, branch.special
    return found[0]


def _largest_gap(drive: float, guess):
    """The largest gap g = g0 + W·q over one period of the orbit shot at ``drive`` from ``guess``,
    the gap's peak-to-peak range and the orbit's stick summary (with its open phases)."""
    system = _hoffmann(drive)
    orbit = periodic_orbit(system, guess)
    traj = orbit.trajectory(1.0, sample_rate=20000.0 / orbit.period)
    contact = system.contacts[0]
    gap = contact.gap + traj.states[:, :system.n] @ contact.gap_gradient
    return float(gap.max()), float(np.ptp(gap)), stick_summary(traj, orbit.period)


def test_the_branch_passes_a_located_grazing_point(up):
    g = _grazing(up)
    assert up.stop_reason == "bounds" and up.values[-1] == pytest.approx(0.13)  # continued through it
    assert (g.before, g.after) == (0, 1) and g.label == "grazing (0 → 1)" and g.located
    assert 0.1095 < g.value < 0.1105 and g.bracket < 1e-4
    # the points on either side: no flight before, one after; the stick phase stays
    assert up.open_phases[g.index] == 0 and up.open_phases[g.index + 1] == 1
    assert up.values[g.index] < g.value < up.values[g.index + 1]
    assert np.array_equal(up.open_phases, (up.values > g.value).astype(int)) and (up.stick_phases == 1).all()
    assert np.all(up.open_time[up.open_phases == 0] == 0.0) and np.all(up.open_time[up.open_phases == 1] > 0.0)
    assert up.stable.all() and not up.folds()


def test_grazing_is_found_again_from_above_and_stops_when_asked(up):
    g = _grazing(up)
    down = _branch(0.12, 0.1)
    g_down = _grazing(down)
    assert (g_down.before, g_down.after) == (1, 0)
    slope = 6.3  # d g_max / d λ [gap per unit of belt speed], measured on either side of λ*
    # measured 7.5e-6 apart, brackets 5.8e-6 and 4.5e-6
    assert abs(g_down.value - g.value) <= g.bracket + g_down.bracket + MISSED_GAP / slope
    stopped = _branch(0.1, 0.13, stop_on=("grazing",))
    assert stopped.stop_reason == "stop_on grazing" and stopped.values[-1] < 0.12


def test_open_time_grows_like_the_square_root_of_the_distance_from_grazing(up):
    """τ_open² is linear in λ past grazing: the line through the first two points with a flight
    meets 0 at the located λ* (measured 2e-5 apart, against steps of 3e-3)."""
    g = _grazing(up)
    i = g.index + 1
    lam, tau2 = up.values[i:i + 2], up.open_time[i:i + 2] ** 2
    root = lam[0] - tau2[0] * (lam[1] - lam[0]) / (tau2[1] - tau2[0])
    assert root == pytest.approx(g.value, abs=2e-4)


def test_orbits_shot_on_either_side_of_grazing_differ_in_their_flight(up):
    """Independent of the continuation: Newton shooting at λ*(1 ∓ 10⁻³) from the grazing state.
    Below, the contact stays closed (g < 0 all period); above, it opens once (g > 0 at its
    peak); at λ* the largest gap is zero to within what the location allows: the bracket,
    |dg_max/dλ| · bracket, plus the flights too small to be seen inside a step (:data:`MISSED_GAP`)
    (measured: g_max = 1.4e-7 at λ*, ∓7.0e-4 at the sides, so 6.4 per unit of λ; bound 6.2e-5)."""
    g = _grazing(up)
    below, _, s_below = _largest_gap(g.value * (1.0 - SIDE), g.state)
    above, _, s_above = _largest_gap(g.value * (1.0 + SIDE), g.state)
    at, ptp, _ = _largest_gap(g.value, g.state)
    assert below < 0.0 < above
    assert (s_below["open_phases"], s_above["open_phases"]) == (0, 1)
    assert s_below["open_fraction"] == 0.0 and s_above["open_fraction"] > 0.0
    assert s_above["contacts"]["belt"]["open_phases"] == 1 and s_above["contacts"]["belt"]["stick_phases"] == 1
    slope = (above - below) / (2.0 * SIDE * g.value)
    assert abs(at) <= slope * g.bracket + MISSED_GAP and abs(at) < 1e-4 * ptp


def test_grazing_is_where_the_scaled_closed_cycle_reaches_zero_gap(up):
    """A second prediction without the continuation: while the contact stays closed, the model is
    linear in each of slip and stick and μ_s = μ_k, so the cycle's deviation from steady sliding
    scales with the belt speed d (the period does not change: 4.539271 s at 0.1 and 0.105). The
    largest gap is then g_max(d) = g_eq + d u, zero at d* = −g_eq d0 / (g_max(d0) − g_eq) from the
    one orbit at d0 = 0.1 (measured: 0.11016496, 2e-8 from the located λ*; bracket 6e-6; allowed
    the bracket and the λ of the smallest flight that may pass unseen, :data:`MISSED_GAP` / u)."""
    g = _grazing(up)
    largest, _, summary = _largest_gap(0.1, up.states[0])
    assert summary["open_phases"] == 0
    system = _hoffmann(0.1)
    contact = system.contacts[0]
    g_eq = contact.gap + equilibrium_state(system)[:system.n] @ contact.gap_gradient
    u = (largest - g_eq) / 0.1  # d g_max / d λ
    assert abs(-g_eq / u - g.value) <= g.bracket + MISSED_GAP / u


def test_open_phases_are_written_and_read_back(up, tmp_path):
    out = up.to_netcdf(tmp_path / "b.nc")
    ds = load_branch(out)
    assert ds["open_phases"].attrs["long_name"].startswith("openings") and ds["open_time"].attrs["units"] == "s"
    back = Branch.from_xarray(ds)
    assert np.array_equal(back.open_phases, up.open_phases) and np.array_equal(back.open_time, up.open_time)
    assert [q.label for q in back.special] == ["grazing (0 → 1)"]


class _Interrupt(Exception):
    """Raised by the progress callback to stop a run as a kill would (after a journaled point)."""


def _stop_after(k):
    def callback(i, *_):
        if i == k:
            raise _Interrupt
    return callback


def test_an_interrupted_run_resumes_and_outputs_without_open_phases_are_refused(monkeypatch, tmp_path):
    """A journal resumes to the same branch; a journal or finished file of an earlier version (no
    open phases: emulated by leaving them out as it did) is refused in one line."""
    system = _hoffmann(0.1)
    run = start_run(system, {"x": 0.01}, t_end=300.0)
    opts = dict(model=system, param=DRIVE, start=run, bounds=(0.1, 0.12), amplitude=False)
    full = continue_orbit(**opts)
    out = tmp_path / "b.nc"
    with pytest.raises(_Interrupt):
        continue_orbit(out=out, callback=_stop_after(5), **opts)
    resumed = continue_orbit(out=out, **opts)
    assert np.array_equal(resumed.open_phases, full.open_phases) and np.array_equal(resumed.open_time, full.open_time)
    assert [(q.kind, q.value) for q in resumed.special] == [(q.kind, q.value) for q in full.special]

    point_record = store.point_record
    monkeypatch.setattr(store, "point_record", lambda p: {k: v for k, v in point_record(p).items()
                                                          if not k.startswith("open_")})
    old = tmp_path / "old.nc"
    with pytest.raises(_Interrupt):
        continue_orbit(out=old, callback=_stop_after(5), **opts)
    monkeypatch.undo()
    with pytest.raises(store.JournalMismatch, match=r"old\.nc\.journal was written by an earlier stickslip") as exc:
        continue_orbit(out=old, **opts)
    assert "\n" not in str(exc.value) and "--overwrite" in str(exc.value)
    assert continue_orbit(out=old, resume=False, **opts).open_phases is not None  # the lock was released

    monkeypatch.setattr(store, "_open_variables", lambda branch: {})
    finished = tmp_path / "finished.nc"
    continue_orbit(out=finished, **opts)
    monkeypatch.undo()
    with pytest.raises(store.JournalMismatch, match=r"finished\.nc was written by an earlier stickslip"):
        continue_orbit(out=finished, **opts)
    assert Branch.from_xarray(load_branch(finished)).open_phases is None  # still readable as it is


def test_models_without_unilateral_contacts_get_no_open_phases(constructed):
    b = continue_orbit(start=constructed, param="alpha", step=0.05, max_step=0.2, max_points=12, bounds=(4.0, 20.0),
                       amplitude=False)
    assert b.open_phases is None and b.open_time is None
    ds = b.to_xarray()
    assert not [name for name in ds.data_vars if "open" in name]
    assert Branch.from_xarray(ds).open_phases is None
    point = Point(v=np.zeros(2), J=np.zeros((1, 2)), M=np.eye(1), tangent=np.ones(2), multipliers=np.ones(1, complex),
                  stick_phases=1, stick_time=0.1, residual=0.0, iterations=0)
    assert set(store.point_record(point)) == {"v", "J", "M", "tangent", "multipliers", "stick_phases", "stick_time",
                                              "residual", "iterations"}
    assert "grazing" not in [q.kind for q in b.special]


@pytest.mark.parametrize("times, kinds, y, expected", [
    ([1.0, 2.0], [OPEN, CLOSE], 0.0, 1.0),              # one flight inside the period
    ([1.0, 3.0], [CLOSE, OPEN], 0.0, 3.0),              # open at the start: 0–1 and 3–5
    ([0.5, 1.0, 2.0, 3.0], [STICK, SLIP, OPEN, CLOSE], 0.0, 1.0),  # stick transitions do not count
    ([], [], -2.0, 5.0),                                # no event, gap g = −1 − y = 1 > 0: open all period
    ([], [], 0.0, 0.0),                                 # no event, closed (g = −1)
])
def test_open_time_of_one_period(times, kinds, y, expected):
    system = _hoffmann(0.1)
    tr = types.SimpleNamespace(time=np.array(times), kind=np.array(kinds, dtype=np.int8),
                               contact=np.zeros(len(times), dtype=np.int8))
    state = np.array([0.0, y, 0.0, 0.0])
    assert open_time(tr, 5.0, system, state) == pytest.approx(expected)
    assert open_count(tr) == kinds.count(OPEN)
