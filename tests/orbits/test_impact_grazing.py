"""An impact that grazes on a branch: the belt oscillator with a rigid stop at a clearance.

The belt (1 DOF, exponential friction) settles on a stick-slip cycle whose largest displacement
is x* ≈ 2.2065; a stop at x = clearance below x* is hit once a period (restitution 0.5), and the
landing speed falls to 0 as the clearance rises to x*. Continued in the clearance, the branch
must call every orbit stable (each period holds a stick phase, which collapses every direction
but the flow's: the multipliers are {1, 0}) and end at a located grazing point at x*; continued
down from above x*, the free orbits' branch must end there too.

Independent references: x* from the free cycle (slip from the breakaway state (0.85, 1.5) to its
turning point) integrated in the test with scipy's ``solve_ivp``; the multipliers from central
differences of the flow map, each run a plain simulation from a perturbed state.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import stickslip
from stickslip.orbits.continuation import continue_orbit, start_run

from stickslip.integrate.result import find_impacts

from .flow_differences import flow_map_differences, plain_flow

BELT_STOP = Path(__file__).with_name("belt_stop.toml")


def free_cycle_maximum() -> float:
    """x* of the belt's stick-slip cycle without the stop.

    The cycle sticks (x' = 1.5) until the stick force x + 0.1·1.5 reaches μs = 1, i.e. at
    x = 0.85; from there it slips backwards (v = x' − 1.5 < 0), x'' = −0.1 x' − x + μ(|v|) with
    μ(|v|) = 0.5 + 0.5 exp(−2|v|), and turns (x' = 0) at x* before it returns to stick.
    """
    def rhs(t, y):
        return [y[1], -0.1 * y[1] - y[0] + 0.5 + 0.5 * np.exp(-2.0 * abs(y[1] - 1.5))]

    def turning(t, y):
        return y[1]

    turning.terminal, turning.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 10.0), [0.85, 1.5], method="DOP853", rtol=1e-13, atol=1e-14, events=turning)
    return float(sol.y_events[0][0][0])


@pytest.fixture(scope="module")
def model():
    return stickslip.load_model(BELT_STOP).replace(clearance=2.1)


@pytest.fixture(scope="module")
def branch(model):
    """The branch in the clearance from 2.1 upwards (the default monodromy; ~2 s once compiled)."""
    run = start_run(model, {"x": 0.0, "dx": 1.5}, t_end=60.0)
    return continue_orbit(model, "clearance", start=run, section=("x", 1.0), bounds=(2.1, 2.3), amplitude=False)


def test_the_impacting_cycle_is_stable_up_to_the_grazing(branch):
    assert branch.options["monodromy"] == "saltation"
    assert len(branch) >= 10 and (branch.open_phases == 1).all() and (branch.stick_phases == 1).all()
    assert branch.stable.all(), branch.multipliers  # differences called the last orbits unstable (|μ| up to 12)
    assert [q.kind for q in branch.special] == ["grazing"]  # no Neimark-Sacker point before it
    np.testing.assert_allclose(np.abs(branch.multipliers), [[1.0, 0.0]] * len(branch), atol=1e-5)


def test_the_grazing_is_located_where_the_free_cycle_touches_the_stop(branch):
    x_star = free_cycle_maximum()
    assert branch.stop_reason.startswith("impact grazing")
    (grazing,) = branch.special
    assert grazing.located and grazing.value == pytest.approx(x_star, abs=1e-4)
    assert branch.values[-1] < x_star and grazing.index == len(branch) - 1


def test_the_grazing_is_located_from_the_free_side_too(model):
    """From a clearance above x* the orbits do not touch the stop (the free cycle, the same for every
    clearance); continued down, the branch ends where their smallest gap to the stop vanishes."""
    system = model.replace(clearance=2.3)
    run = start_run(system, {"x": 0.0, "dx": 1.5}, t_end=60.0)
    free = continue_orbit(system, "clearance", start=run, section=("x", 1.0), direction=-1, bounds=(2.1, 2.3),
                          amplitude=False)
    assert free.stop_reason == "impact grazing (the free orbit touches a rigid stop)"
    assert (free.open_phases == 0).all() and free.stable.all()
    (grazing,) = free.special
    assert grazing.kind == "grazing" and grazing.located
    assert grazing.value == pytest.approx(free_cycle_maximum(), abs=1e-4)
    np.testing.assert_allclose(free.periods, free.periods[0], rtol=1e-9)  # the free cycle throughout


@pytest.mark.parametrize("i", [0, 2, 4])
def test_multipliers_equal_differences_of_the_flow_map(model, branch, i):
    system = model.replace(clearance=float(branch.values[i]))
    D = flow_map_differences(system, branch.states[i], float(branch.periods[i]), [0, 1], h=1e-5)
    fd = np.sort_complex(np.linalg.eigvals(D))
    np.testing.assert_allclose(np.sort_complex(branch.multipliers[i]), fd, rtol=0, atol=1e-6)


@pytest.mark.parametrize("landing", [1e-3, 1e-4, 1e-5])
def test_saltation_monodromy_at_slow_impacts_equals_one_sided_differences(model, landing):
    """Clearances just below x*, where the cycle lands at about ``landing`` (v_i² ≈ 2 |x''(x*)| (x* − clearance),
    x''(x*) = −x* + μ(1.5) ≈ −1.68). The monodromy grows like 1/v_i (the flow map's square-root singularity
    at the grazing), and must be the saltation one (no fallback to differences, which straddle the grazing).

    Reference: forward differences of plain runs with steps h = 1e-3 v_i², well inside the impacting side
    (the perturbed orbits reach the stop up to ~0.3 v_i² further). Their truncation error is ~ h/v_i² of the
    entries (1.2e-3 and 3.3e-3 measured at 1e-3 and 1e-4); at 1e-5 the steps (1e-13) are below the plain runs'
    noise, and only the multipliers are compared: {1, 0}, the stick phase collapsing all but the flow."""
    x_star = free_cycle_maximum()
    system = model.replace(clearance=x_star - landing ** 2 / (2.0 * 1.6816))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a fallback to differences warns
        orbit = stickslip.periodic_orbit(system, {"x": 0.0, "dx": 1.5}, section=("x", 1.0), search_time=60.0,
                                         monodromy="saltation")
    speed = -find_impacts(system, orbit.trajectory(1.0, sample_rate=10.0).transitions).speed_before
    assert speed.size == 1 and 0.5 * landing < speed[0] < 1.5 * landing
    M = orbit.monodromy
    assert np.abs(M).max() > 0.5 / landing  # the singular growth is resolved, not damped
    np.testing.assert_allclose(np.sort(np.abs(orbit.multipliers)), [0.0, 1.0], atol=1e-3)
    if landing < 1e-4:
        return
    h = 1e-3 * landing ** 2
    end = plain_flow(system, orbit.state, orbit.period)
    D = np.column_stack([(plain_flow(system, orbit.state + h * np.eye(2)[j], orbit.period) - end) / h
                         for j in range(2)])
    np.testing.assert_allclose(M, D, rtol=0, atol=1e-2 * np.abs(D).max())
