"""Orbits whose rigid contact never opens: stick-slip on a rigid floor (tests/orbits/rigid_floor.toml).

The slider stays on the floor (y = 0, y' = 0) all along its cycle, so the section is crossed with
the rigid contact closed: shooting eliminates the floor's normal coordinate (its unknowns are x, z
and their rates) and the monodromy is the flow's linearisation on the constraint, 4 × 4.

Independent references: the stick-entry spacing of a long plain run (the period), and central
differences of the flow map, each run a plain simulation from a state perturbed along the floor.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import stickslip
from stickslip.integrate.contacts import TRANSITION_TO_STICK
from stickslip.orbits.continuation import continue_orbit

from .flow_differences import flow_map_differences

RIGID_FLOOR = Path(__file__).with_name("rigid_floor.toml")

#: The states shooting varies: the floor holds y and y' (indices 1 and 4) at 0.
ALONG_THE_FLOOR = [0, 2, 3, 5]


def differences_along_the_floor(model, s0, T):
    """∂Φ(s0, T)/∂s0 on x, z, x', z' by central differences of plain simulations (steps 1e-6)."""
    return flow_map_differences(model, s0, T, ALONG_THE_FLOOR, h=1e-6)


@pytest.fixture(scope="module")
def model():
    return stickslip.load_model(RIGID_FLOOR)


@pytest.fixture(scope="module")
def orbit(model):
    """Shot on the section x_max, crossed with the floor closed (refused before: 'crossed with rigid
    contact floor closed')."""
    return stickslip.periodic_orbit(model, {"x": 0.0, "y": 0.0}, search_time=100.0, section="x_max")


def test_the_orbit_on_the_floor_is_the_settled_cycle(model, orbit):
    run = stickslip.simulate(model, 300.0, ic={"x": 0.0, "y": 0.0}, rtol=1e-11, atol=1e-13, sample_rate=10.0)
    tr = run.transitions
    assert not np.isin(tr.kind, (2, 3, 4)).any()  # the floor never opens, no impact
    entries = np.diff(tr.time[tr.kind == TRANSITION_TO_STICK][-6:])
    assert np.ptp(entries) < 1e-8
    assert orbit.period == pytest.approx(entries.mean(), rel=1e-8)
    assert orbit.stick_phases == 1 and orbit.residual <= 1e-8
    assert orbit.free_states == ("x", "z", "dx", "dz") and orbit.state[1] == 0.0 and orbit.state[4] == 0.0


def test_multipliers_on_the_floor_equal_differences_of_the_flow_map(model, orbit):
    D = differences_along_the_floor(model, orbit.state, orbit.period)
    np.testing.assert_allclose(orbit.monodromy, D, rtol=0, atol=1e-6 * np.abs(D).max())
    np.testing.assert_allclose(np.sort_complex(orbit.multipliers), np.sort_complex(np.linalg.eigvals(D)), atol=1e-6)
    assert orbit.stable and np.abs(orbit.nontrivial_multipliers).max() > 0.5  # z's pair is not collapsed by stick


def test_continuation_on_the_floor(model, orbit):
    """The branch in the belt speed stays on the floor; its last orbit's multipliers are those of
    the flow map's differences there."""
    branch = continue_orbit(model, "V", start=orbit, max_points=5, amplitude=False)
    assert len(branch) == 5 and branch.options["monodromy"] == "saltation" and branch.values[-1] > 0.52
    assert (branch.states[:, [1, 4]] == 0.0).all()
    D = differences_along_the_floor(model.replace(V=float(branch.values[-1])), branch.states[-1],
                                    float(branch.periods[-1]))
    np.testing.assert_allclose(np.sort_complex(branch.multipliers[-1]), np.sort_complex(np.linalg.eigvals(D)),
                               atol=1e-6)
