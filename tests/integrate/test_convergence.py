"""Verification layers 2 and 4: tolerance convergence and the smoothed-friction cross-check."""

import numpy as np
import pytest

from stickslip import Parameters, simulate
from stickslip.analysis import fundamental_frequency
from stickslip.integrate.smoothed import simulate_smoothed


@pytest.mark.parametrize("N", [30.0, 50.0, 70.0])
def test_frequency_converges_with_tolerance(N):
    P = Parameters(Omega=0.5, N=N)
    f = [simulate(P, 100.0, rtol=rtol, atol=rtol * 1e-2, sample_rate=500).steady.frequency_hz
         for rtol in (1e-6, 1e-8)]
    assert np.isfinite(f).all()
    assert abs(f[0] - f[1]) < 1e-3 * abs(f[1])


def test_smoothed_friction_approaches_event_solution():
    P = Parameters(Omega=0.5, N=30.0)
    t_end, t_from = 40.0, 20.0
    ref = simulate(P, t_end, rtol=1e-10, atol=1e-12).steady_state(t_from).frequency_hz
    errors = []
    for eps in (1e-2, 1e-3, 1e-4):
        t, y, info = simulate_smoothed(P, t_end, eps=eps)
        assert info["status"] == 0
        sel = t >= t_from
        f, _, _ = fundamental_frequency(t[sel], y[sel, 4], y[sel, 10])
        errors.append(abs(f - ref) / ref)
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.01


def test_event_times_converge():
    P = Parameters()
    runs = [simulate(P, 3.0, rtol=rtol, atol=rtol * 1e-2) for rtol in (1e-6, 1e-8, 1e-10)]
    assert all(len(r.transitions) >= 4 for r in runs)
    first = [r.transitions.time[:4] for r in runs]
    d1 = np.abs(first[0] - first[2]).max()
    d2 = np.abs(first[1] - first[2]).max()
    assert d2 < d1 and d2 < 1e-5


def test_tight_tolerances_finish_and_agree():
    """Regression: at rtol 1e-11 the approach to stick once underflowed the step size."""
    P = Parameters()
    runs = [simulate(P, 100.0, rtol=rtol, atol=rtol * 1e-2, sample_rate=200) for rtol in (1e-10, 1e-11)]
    assert all(r.status == "success" for r in runs)
    f = [r.steady.frequency_hz for r in runs]
    assert abs(f[0] - f[1]) < 1e-8 * f[1]
    assert len(runs[0].transitions) == len(runs[1].transitions)
