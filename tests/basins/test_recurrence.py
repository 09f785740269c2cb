"""The recurrence test at breakaways (basins/recurrence.py): the belt's cycle is recognised at the
breakaway state that closed-form mechanics gives, runs are decided there with the labels of long
plain runs, a period that recurs must still match the cycle, and the compiled test says DOUBT at
its threshold."""

import numpy as np
import pytest

import stickslip
from stickslip.basins import box, early
from stickslip.basins.batch_rules import DOUBT, recurs as compiled_recurs
from stickslip.basins.context import make_context
from stickslip.basins.cycles import Cycle, period_matches
from stickslip.basins.early import Options, classify_state
from stickslip.basins.recurrence import RECURRENCE_FACTOR, cycle_point, recurrence_tolerance, recurs
from stickslip.model.library import load_model

BELT = load_model("belt")


@pytest.fixture(scope="module")
def ctx():
    return make_context(BELT)


@pytest.fixture(scope="module")
def cycle(ctx):
    o = classify_state(ctx, BELT, np.array([2.0, 2.0]), [], Options())  # bSTAB's LC template
    assert o.verdict == "periodic" and o.decided_by == "period-rule"
    return o.cycle


def long_run(s0, t_end=1500.0):
    traj = stickslip.simulate(BELT, t_end, ic=s0, sample_rate=10)
    return "periodic" if np.ptp(traj.states[traj.t >= t_end - 100.0, 0]) > 1e-3 else "equilibrium"


def first_breakaways(s0, t_end=80.0):
    tr = stickslip.simulate(BELT, t_end, ic=s0, sample_rate=10).transitions
    return tr.time[tr.kind == -1]


def test_the_belts_cycle_point_is_the_breakaway_of_closed_form_mechanics(ctx, cycle):
    """Stuck on the belt, x' = v_d and the spring and damper load the contact until
    k x + c v_d = μs N: the breakaway state is x = (μs N − c v_d) / k = (1.0 − 0.1 · 1.5) / 1."""
    p = cycle_point(ctx, BELT, cycle, Options())
    assert p is not None and p.contact == 0
    np.testing.assert_allclose(p.state, [0.85, 1.5], rtol=0, atol=1e-9)


def test_runs_onto_the_cycle_are_decided_at_their_first_breakaway_with_the_labels_of_long_runs(ctx, cycle):
    states = box(BELT, {"x": (-2, 2), "dx": (0, 2)}, n=24, seed=21).states(BELT, ctx.equilibrium[:1])
    outcomes = [classify_state(ctx, BELT, s, [cycle], Options()) for s in states]
    assert [o.verdict for o in outcomes] == [long_run(s) for s in states]
    onto = [(s, o) for s, o in zip(states, outcomes) if o.verdict == "periodic"]
    assert len(onto) >= 8 and {o.decided_by for _, o in onto} == {"recurred"}
    for s, o in onto:  # the first piece of one T_c that ends after the first breakaway (the
        t_b = first_breakaways(s)[0]  # pieces' times summed may round below the plain run's)
        assert t_b - 1e-9 <= o.t_decided <= t_b + 2 * ctx.period


def test_without_the_cycles_point_a_run_recurs_on_itself_one_period_later(ctx, cycle, monkeypatch):
    monkeypatch.setattr(early, "cycle_point", lambda *args: None)
    states = box(BELT, {"x": (-2, 2), "dx": (0, 2)}, n=24, seed=21).states(BELT, ctx.equilibrium[:1])
    for s in states:
        o = classify_state(ctx, BELT, s, [cycle], Options())
        if o.verdict == "periodic":
            assert o.decided_by == "recurred"
            b = first_breakaways(s)
            assert b[1] - 1e-9 <= o.t_decided <= b[1] + 2 * ctx.period  # the second breakaway repeats the first


def test_a_period_that_recurs_must_match_the_cycle(cycle):
    k, T, A = cycle.multiplicity, cycle.period, cycle.amplitude
    low = np.array([cycle.peaks.max() - A])
    assert period_matches(cycle, T, cycle.peaks, low, 1e-3)
    assert not period_matches(cycle, T * (1 + 2e-3), cycle.peaks, low, 1e-3)  # another period
    assert not period_matches(cycle, T, cycle.peaks + 2e-3 * A, low + 2e-3 * A, 1e-3)  # other maxima
    assert not period_matches(cycle, T, cycle.peaks, low - 2e-3 * A, 1e-3)  # another amplitude
    assert not period_matches(cycle, T, np.tile(cycle.peaks, 2), low, 1e-3)  # two periods' maxima
    assert not period_matches(cycle, T, cycle.peaks, np.empty(0), 1e-3)  # no minimum located
    other = Cycle(k + 1, T, A, np.resize(cycle.peaks, k + 1), 0.0, cycle.state)
    assert not period_matches(other, T, cycle.peaks, low, 1e-3)


def test_states_recur_within_the_tolerance_and_the_compiled_test_doubts_at_it():
    s1 = np.array([0.85, 1.5])
    tol = recurrence_tolerance(s1, s1, 1e-10, 1e-8)
    np.testing.assert_allclose(tol, RECURRENCE_FACTOR * (1e-10 + 1e-8 * np.abs(s1)))
    assert recurs(s1, s1 + 0.5 * tol, 1e-10, 1e-8) and not recurs(s1, s1 + 2.0 * tol, 1e-10, 1e-8)
    assert compiled_recurs(s1, s1 + 0.5 * tol, RECURRENCE_FACTOR, 1e-10, 1e-8) == 1
    assert compiled_recurs(s1, s1 + np.array([0.5, 2.0]) * tol, RECURRENCE_FACTOR, 1e-10, 1e-8) == 0
    s2 = s1.copy()  # below s1: the tolerance is s1's; the difference is it within round-off
    s2[0] = s1[0] - tol[0] * (1 - 1e-13)
    assert compiled_recurs(s1, s2, RECURRENCE_FACTOR, 1e-10, 1e-8) == DOUBT
