"""The early-stopping classifier and the cycle features: each early decision agrees with long runs,
near the basin boundary too; matches are phase-independent and refuse what is not the cycle."""

import numpy as np
import pytest

import stickslip
from stickslip.basins import basin_stability, box
from stickslip.basins.context import make_context
from stickslip.basins.cycles import MATCH_PERIODS, Cycle, Section, cycles_equal, run_matches
from stickslip.basins.early import Options, Outcome, classify_state
from stickslip.model import model_from_spec
from stickslip.model.library import load_model

BELT = load_model("belt")


@pytest.fixture(scope="module")
def ctx():
    """The belt's context, built once per module on the worker that runs these tests."""
    return make_context(BELT)


def long_run(model, s0, t_end=1500.0):
    traj = stickslip.simulate(model, t_end, ic=s0, sample_rate=10)
    return "periodic" if np.ptp(traj.states[traj.t >= t_end - 100.0, 0]) > 1e-3 else "equilibrium"


def test_steady_sliding_itself_is_at_rest_at_once(ctx):
    o = classify_state(ctx, BELT, ctx.equilibrium.copy(), [], Options())
    assert (o.verdict, o.decided_by) == ("equilibrium", "at-rest")
    assert o.t_decided < 2 * ctx.chunk * ctx.dt  # after the first chunk (its last step may pass its end)


@pytest.mark.parametrize("amplitude", np.round(np.arange(1.30, 1.405, 0.01), 2))
def test_early_verdicts_across_the_basin_boundary_equal_long_runs(amplitude, ctx):
    """Along x = x_e + a, x' = 0 the equilibrium's basin ends between a = 1.3 and 1.4: there the
    run passes close to the grazing of v = 0 and the linear test must wait (or refuse)."""
    s0 = ctx.equilibrium + np.array([amplitude, 0.0])
    o = classify_state(ctx, BELT, s0, [], Options(t_end=1000.0))
    assert o.verdict == long_run(BELT, s0)


def test_the_linear_test_waits_longer_the_closer_the_boundary(ctx):
    times = [classify_state(ctx, BELT, ctx.equilibrium + np.array([a, 0.0]), [], Options()).t_decided
             for a in (0.2, 0.8, 1.3)]
    assert times[0] < times[1] < times[2]


def test_unstable_steady_sliding_is_never_claimed():
    slow = BELT.replace(**{"contact.0.drive": 1.0})  # below V = 1.151: steady sliding unstable
    ctx = make_context(slow)
    assert not ctx.stable and ctx.max_real_part > 0
    near = ctx.equilibrium + np.array([1e-3, 0.0])
    o = classify_state(ctx, slow, near, [], Options())
    assert o.verdict == "periodic"  # the oscillation grows onto the stick-slip cycle


def test_a_known_cycle_stops_runs_early_without_changing_verdicts(ctx):
    states = box(BELT, {"x": (-2, 2), "dx": (-2, 2)}, n=40, seed=11).states(BELT, ctx.equilibrium[:1])
    alone = [classify_state(ctx, BELT, s, [], Options()) for s in states]
    cycle = next(o.cycle for o in alone if o.verdict == "periodic")
    known = [classify_state(ctx, BELT, s, [cycle], Options()) for s in states]
    assert [o.verdict for o in alone] == [o.verdict for o in known]
    assert {o.decided_by for o in known if o.verdict == "periodic"} == {"recurred"}  # at their first breakaway
    assert sum(o.t_decided for o in known) < sum(o.t_decided for o in alone)


#: hoffmann with its contact spring as a prescribed load N = 1 + y (pressed: a run ends where N
#: reaches 0, "contact lost"), the form before contacts could open.
PRESSED_HOFFMANN = model_from_spec({
    "name": "hoffmann-pressed", "dofs": ["x", "y"], "mass": [[1.0, 0.0], [0.0, 1.0]],
    "damping": [[0.0, 0.0], [0.0, 0.0]], "stiffness": [[2.0, 1.0], [1.0, 2.0]], "force": [0.0, 0.0],
    "contact": [{"tangent": [[1.0, 0.0]], "drive": [1.0], "normal_force": 1.0, "normal_gradient": [0.0, 1.0],
                 "friction": {"law": "coulomb", "mu_k": 0.5, "delta_mu": 0.0}}]})


def test_an_open_contact_ends_at_once_as_contact_lost():
    """A pressed contact without load at the start (N = 1 + y: none for y < −1) ends the run."""
    model = PRESSED_HOFFMANN
    o = classify_state(make_context(model), model, np.array([0.0, -2.0, 0.0, 0.0]), [], Options())
    assert (o.verdict, o.decided_by, o.t_decided) == ("contact-lost", "stopped", 0.0)


def test_a_unilateral_contact_open_at_the_start_is_no_loss():
    """hoffmann's contact spring lifts off instead: the same state is a flight, and the run goes on."""
    hoffmann = load_model("hoffmann")
    o = classify_state(make_context(hoffmann), hoffmann, np.array([0.0, -2.0, 0.0, 0.0]), [], Options())
    assert o.verdict != "contact-lost" and o.t_decided > 0.0


def _cycle(peaks, period=2.0, amplitude=3.0):
    return Cycle(len(peaks), period, amplitude, np.asarray(peaks, float), 0.1, np.zeros(2))


def _section(peaks, period, periods, low=-1.0, jitter=0.0):
    k = len(peaks)
    m = k * periods + 1
    times = np.arange(m) * period / k + 0.3
    maxima = np.array([peaks[(i + 1) % k] for i in range(m)]) + jitter
    return Section(times, maxima, np.r_[np.nan, np.full(m - 1, low)])


def test_cycles_are_equal_up_to_a_shift_and_differ_beyond_the_tolerance():
    a = _cycle([2.0, 1.0, 1.5])
    assert cycles_equal(a, _cycle([1.0, 1.5, 2.0]), 1e-3)  # the same cycle from another phase
    assert not cycles_equal(a, _cycle([1.5, 1.0, 2.0]), 1e-3)  # reversed order is another cycle
    assert not cycles_equal(a, _cycle([2.0, 1.0]), 1e-3)
    assert not cycles_equal(a, _cycle([2.0, 1.0, 1.5], period=2.01), 1e-3)
    assert cycles_equal(a, _cycle([2.0, 1.0, 1.5], period=2.001), 1e-3)
    assert not cycles_equal(a, _cycle([2.0, 1.0, 1.5], amplitude=3.01), 1e-3)


def test_a_run_matches_only_after_enough_recurring_crossings():
    c = _cycle([2.0], period=2.0, amplitude=3.0)
    assert run_matches(c, _section([2.0], 2.0, MATCH_PERIODS), 1e-2)
    assert not run_matches(c, _section([2.0], 2.0, MATCH_PERIODS - 1), 1e-2)  # too few periods
    assert not run_matches(c, _section([2.0], 2.0, MATCH_PERIODS, jitter=0.05), 1e-2)  # values off by 1.7 %
    assert not run_matches(c, _section([2.0], 2.05, MATCH_PERIODS), 1e-2)  # period off by 2.5 %
    assert not run_matches(c, _section([2.0], 2.0, MATCH_PERIODS, low=-1.2), 1e-2)  # amplitude 3.2
    assert run_matches(c, _section([2.0], 2.0, MATCH_PERIODS, jitter=0.02), 1e-2)


def test_outcome_rows_round_trip(ctx):
    o = classify_state(ctx, BELT, np.array([2.0, 2.0]), [], Options())
    back = Outcome.from_row(o.to_row(), 1)
    assert (back.verdict, back.decided_by, back.t_decided, back.steps) == (o.verdict, o.decided_by, o.t_decided,
                                                                            o.steps)
    assert cycles_equal(back.cycle, o.cycle, 1e-15) and np.array_equal(back.state, o.state)


def test_every_library_model_runs():
    """Each library model gives a complete study with labels from the known set."""
    cases = {"belt": {"x": (-2, 2)}, "popp-stelter": {"x1": (-0.5, 0.5)}, "hoffmann": {"y": (-1.5, 0.5)},
             "two-plates": {"phi": (-0.2, 0.2)}}
    for name, ranges in cases.items():
        model = load_model(name)
        res = basin_stability(model, box(model, ranges, n=6, base="zero"), t_end=100.0, executor="serial")
        assert res.complete and res.n == 6, name
        assert set(res.names) <= {"equilibrium", "periodic", "periodic-2", "unsettled", "contact-lost"}, res.names
    res = basin_stability(PRESSED_HOFFMANN, box(PRESSED_HOFFMANN, {"y": (-3.0, -1.5)}, n=5, base="zero"), t_end=10.0,
                          executor="serial")
    assert res.names == ["contact-lost"]


@pytest.mark.parametrize("n", [1, 2, 9, 10])
def test_studies_of_a_few_states(n):
    """The first states run in this process (compile, then timing); a study may have fewer."""
    res = basin_stability(BELT, box(BELT, {"x": (-0.1, 0.1)}, n=n), executor="processes", workers=1)
    assert res.complete and res.n == n and res.names == ["equilibrium"]
