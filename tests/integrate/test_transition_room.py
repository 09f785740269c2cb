"""Transition buffers: a run with more transitions than the first buffers hold ends its chunks
early (the event method) or is run again with room for all (and, for the event method, where one
step outgrew the room left), and gives the run that had room from the start."""

import numpy as np
import pytest

import stickslip
from stickslip.integrate import runner


@pytest.mark.parametrize("method, dt", [("aeom", 1e-3), ("naeom", 1e-3)])
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


@pytest.mark.parametrize("room", [3, 0], ids=["chunks-end-early", "and-rerun"])
def test_event_chunks_end_before_their_transition_log_overflows(monkeypatch, room):
    """With room for 3 transitions every chunk of the event method ends at the first step outside
    an approach where fewer than two per contact are left (each a chunk of its own, rebased); with
    none, every step that records one outgrows it and is run again. Either way the same steps and
    transitions as the run with room: the instants to the round-off that rebasing the chunks'
    local time leaves (1e-12 relative; each root is found to the event tolerance from there), the
    states at them to that shift of the instant times the states' rates, the samples to 1e-12 of
    their range, the kinds exactly."""
    roomy = stickslip.simulate(t_end=10.0)
    assert roomy.transitions.time.size > 10
    monkeypatch.setattr(runner, "MIN_TRANSITION_ROOM", room)
    monkeypatch.setattr(runner, "TRANSITIONS_PER_SECOND", 0)
    tight = stickslip.simulate(t_end=10.0)
    assert tight.stats.accepted_steps == roomy.stats.accepted_steps
    assert tight.stats.rejected_steps == roomy.stats.rejected_steps
    np.testing.assert_array_equal(tight.transitions.kind, roomy.transitions.kind)
    np.testing.assert_allclose(tight.transitions.time, roomy.transitions.time, rtol=1e-12, atol=0)
    shift = np.abs(tight.transitions.time - roomy.transitions.time).max()
    scale = np.abs(roomy.states).max(axis=0)
    rate = (np.abs(np.diff(roomy.states, axis=0)) / np.diff(roomy.t)[:, None]).max(axis=0)  # per state
    worst = (np.abs(tight.transitions.state - roomy.transitions.state) / (1e-12 * scale + 10.0 * rate * shift)).max()
    assert worst <= 1.0, worst
    assert (np.abs(tight.states - roomy.states) / scale).max() <= 1e-12
