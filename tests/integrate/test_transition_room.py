"""Transition buffers: a run with more transitions than the first buffers hold is run again with
room for all, and gives exactly the run that had room from the start."""

import numpy as np
import pytest

import stickslip
from stickslip.integrate import runner


@pytest.mark.parametrize("method, dt", [("event", None), ("aeom", 1e-3), ("naeom", 1e-3)])
def test_overflowing_transition_buffers_rerun_identically(monkeypatch, method, dt):
    roomy = stickslip.simulate(t_end=10.0, method=method, dt=dt)
    assert roomy.transitions.time.size > 10  # stick-slip at the default case: ~5 per second
    monkeypatch.setattr(runner, "MIN_TRANSITION_ROOM", 3)  # the one buffer policy of every method
    monkeypatch.setattr(runner, "TRANSITIONS_PER_SECOND", 0)
    tight = stickslip.simulate(t_end=10.0, method=method, dt=dt)
    np.testing.assert_array_equal(tight.transitions.time, roomy.transitions.time)
    np.testing.assert_array_equal(tight.transitions.kind, roomy.transitions.kind)
    np.testing.assert_array_equal(tight.transitions.state, roomy.transitions.state)
    np.testing.assert_array_equal(tight.states, roomy.states)
