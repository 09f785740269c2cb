"""The compiled batch (basins/batch.py) gives, state by state, the outcome rows of the Python
classifier (classify_state called on each state in turn with the cycles known then), and its
compiled tests decide only where the Python tests would decide the same."""

import math

import numpy as np
import pytest

import stickslip
from stickslip.analysis.period import SETTLE_RTOL, return_map
from stickslip.analysis.peaks import Peaks
from stickslip.basins import box, grid
from stickslip.basins.batch import classify_batch
from stickslip.basins.batch_rules import DOUBT, _at_most, maybe_settled, section
from stickslip.basins.context import make_context
from stickslip.basins.cycles import find_cycle, section_of
from stickslip.basins.early import DECIDED, Options, classify_state
from stickslip.model.library import load_model

BELT = load_model("belt")
WALL_TIME = 9  # the outcome row's wall time, the one column that may differ


@pytest.fixture(scope="module")
def ctx():
    return make_context(BELT)


def python_rows(ctx, model, states, cycles, opts):
    cycles, rows = list(cycles), []
    for s0 in states:
        o = classify_state(ctx, model, s0, cycles, opts)
        if o.verdict == "periodic" and find_cycle(cycles, o.cycle, opts.match_rtol) < 0:
            cycles.append(o.cycle)
        rows.append(o.to_row())
    return np.array(rows), cycles


def assert_same_rows(expected, got):
    a, b = np.delete(expected, WALL_TIME, axis=1), np.delete(got, WALL_TIME, axis=1)
    same = (a == b) | (np.isnan(a) & np.isnan(b))
    assert same.all(), [(int(i), np.flatnonzero(~same[i]).tolist()) for i in np.flatnonzero(~same.all(axis=1))[:5]]


def test_belt_rows_equal_the_python_classifier_state_by_state(ctx):
    states = box(BELT, {"x": (-2, 2), "dx": (0, 2)}, n=60, seed=3).states(BELT, ctx.equilibrium[:1])
    expected, cycles = python_rows(ctx, BELT, states, [], Options())
    got, found = classify_batch(ctx, BELT, states, [], Options())
    assert_same_rows(expected, got)
    assert len(found) == len(cycles) == 1
    decided = {DECIDED[int(d)] for d in got[:, 1]}
    # the first state on the cycle is left to the Python classifier (a new cycle), the others not:
    # they recur at their first breakaway on it
    assert decided == {"linear", "recurred", "period-rule"}


def test_runs_that_reach_t_end_and_cycles_known_before(ctx):
    """t_end = 40: states still undecided there get the window's verdict in Python."""
    states = box(BELT, {"x": (-2, 2), "dx": (0, 2)}, n=20, seed=5).states(BELT, ctx.equilibrium[:1])
    _, cycles = python_rows(ctx, BELT, states[:12], [], Options())
    opts = Options(t_end=40.0)
    expected, _ = python_rows(ctx, BELT, states, cycles, opts)
    got, _ = classify_batch(ctx, BELT, states, cycles, opts)
    assert_same_rows(expected, got)
    assert "end-verdict" in {DECIDED[int(d)] for d in got[:, 1]}


def test_plates_rows_equal_the_python_classifier():
    plates = load_model("two-plates").replace(N=50.0, Omega=8.5)
    c = make_context(plates)
    states = grid(plates, {"phi": (-0.2, 0.2), "dphi": (-5.0, 5.0)}, 2, base="zero",
                  fixed={"dy1": 1.7}).states(plates, c.equilibrium[:plates.n])
    opts = Options(t_end=600.0)
    expected, _ = python_rows(c, plates, states, [], opts)
    got, _ = classify_batch(c, plates, states, [], opts)
    assert_same_rows(expected, got)


def test_section_is_the_one_section_of_locates():
    traj = stickslip.simulate(BELT, 60.0, ic=np.array([1.5, 1.0]), sample_rate=10.0)
    t, x, dx = traj.t, traj.states[:, 0], traj.states[:, 1]
    expected = section_of(t[7:], x[7:], dx[7:])
    work = np.empty((5, t.size))
    m = section(t, x, dx, 7, t.size, work[3:5], work[0], work[1], work[2])
    assert m == len(expected) > 5
    np.testing.assert_array_equal(work[0, :m], expected.times)
    np.testing.assert_allclose(work[1, :m], expected.maxima, rtol=0, atol=1e-15)
    np.testing.assert_allclose(work[2, :m], expected.minima, rtol=0, atol=1e-15)


def test_a_test_near_its_threshold_is_in_doubt():
    assert _at_most(0.5, 1.0) == 1 and _at_most(2.0, 1.0) == 0 and _at_most(math.nan, 1.0) == 0
    assert _at_most(1.0 + 1e-12, 1.0) == DOUBT and _at_most(1.0 - 1e-12, 1.0) == DOUBT


@pytest.mark.parametrize("k", [1, 2, 3])
def test_the_period_rule_filter_never_misses_a_settled_sequence(k):
    """Crossings converging onto a k-cycle at rates that put the spread on both sides of the
    settle tolerance: wherever return_map settles, the compiled filter says it might."""
    rng = np.random.default_rng(k)
    branches = 1.0 + np.arange(k) * 0.3
    for scale in np.geomspace(1e-7, 1e-3, 60):
        n = 12 * k + 1
        i = np.arange(n)
        p = branches[i % k] + scale * 0.7 ** (i // k) * rng.uniform(0.5, 1.5)
        tau = i * (2.0 / k) + scale * 0.5 * rng.standard_normal(n)
        times = np.cumsum(np.abs(np.diff(tau, prepend=-1.0)))
        settled, _ = return_map(Peaks(times, p), 1.0)
        if settled is not None:
            assert maybe_settled(p, times, 1.0), (scale, settled)
    exact = np.tile(branches, 12)
    assert maybe_settled(exact, np.arange(exact.size) * (2.0 / k), 1.0)
    # a transient far above the settle tolerance is no candidate
    assert not maybe_settled(1.0 + 1e3 * SETTLE_RTOL * 0.7 ** np.arange(40), np.arange(40.0), 1.0)


def test_a_study_in_batches_of_either_path_gives_the_same_result(tmp_path, monkeypatch):
    """A whole study with batches large enough for the compiled batch gives the result of the same
    study whose batches all take the per-state path (the one classifier that decides small batches)."""
    from stickslip.basins import engine

    states = box(BELT, {"x": (-2, 2), "dx": (0, 2)}, n=80, seed=11)
    compiled = stickslip.basin_stability(BELT, states, t_end=200.0, executor="serial", batch_size=40,
                                         out=tmp_path / "compiled.nc")
    monkeypatch.setattr(engine, "MIN_COMPILED_BATCH", 10**9)
    per_state = stickslip.basin_stability(BELT, states, t_end=200.0, executor="serial", batch_size=40,
                                          out=tmp_path / "per_state.nc")
    a, b = compiled.to_xarray(), per_state.to_xarray()
    for name in ("label", "verdict", "decided_by", "t_decided", "steps", "fraction", "standard_error", "period"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
