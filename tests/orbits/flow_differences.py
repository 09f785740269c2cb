"""Central differences of the flow map by plain simulations: the independent reference of the
monodromy tests."""

from __future__ import annotations

import numpy as np

import stickslip


def plain_flow(model, s0, T: float) -> np.ndarray:
    """Φ(s0, T) by one ``simulate`` run (rtol 1e-12) whose last sample is exactly its end: the
    duration 1/(1/T), sampled at 1/T (a duration of T itself may end a rounding past the last sample)."""
    rate = 1.0 / T
    run = stickslip.simulate(model, 1.0 / rate, ic=s0, rtol=1e-12, atol=1e-14, sample_rate=rate)
    assert run.status == "success" and run.t[-1] == 1.0 / rate
    return run.final_state


def flow_map_differences(model, s0, T: float, states, h: float) -> np.ndarray:
    """∂Φ(s0, T)/∂s0 on ``states`` (rows and columns, state indices) by central differences of step h."""
    D = np.empty((len(states), len(states)))
    for k, j in enumerate(states):
        step = np.zeros(np.size(s0))
        step[j] = h
        D[:, k] = (plain_flow(model, s0 + step, T) - plain_flow(model, s0 - step, T))[list(states)] / (2.0 * h)
    return D
