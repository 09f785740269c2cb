"""One period detection: the classification and the steady-state summary (``Trajectory.steady``)
agree on whether a window is periodic, on the multiplicity and on the period."""

import math

import numpy as np
import pytest

import stickslip
from stickslip.analysis import classify, classify_response, detect_period, fundamental_frequency
from stickslip.analysis.period import MIN_REPEATS


def _agree(c, s):
    """Classification c and steady summary s make the same periodicity decision."""
    assert c.kind.startswith("periodic") == s.periodic
    assert c.multiplicity == s.period_multiplicity
    if s.periodic:
        assert s.fundamental_frequency_hz == 1.0 / c.period_s
    elif math.isfinite(s.fundamental_frequency_hz):
        assert s.fundamental_frequency_hz == c.fft_frequency_hz  # both the spectral peak


# ------------------------------------------------------------------ constructed signals
def _signal(kind):
    t = np.linspace(0.0, 40.0, 8001)
    w = 2 * np.pi * 0.5                                          # 0.5 Hz fundamental
    if kind == "sine":                                           # one peak per period
        return t, np.sin(w * t), w * np.cos(w * t)
    if kind == "two_humps":                                      # sin θ + 0.8 sin 2θ: θ' = 0 at
        return (t, np.sin(w * t) + 0.8 * np.sin(2 * w * t),      # cos θ = 0.568 and −0.880, i.e.
                w * np.cos(w * t) + 1.6 * w * np.cos(2 * w * t)) # two maxima per period
    if kind == "quasi":                                          # incommensurate: never repeats
        r = math.sqrt(2.0)
        return t, np.sin(w * t) + np.sin(r * w * t), w * np.cos(w * t) + r * w * np.cos(r * w * t)
    raise ValueError(kind)


@pytest.mark.parametrize("kind, periodic, k", [("sine", True, 1), ("two_humps", True, 2), ("quasi", False, 0)])
def test_constructed_signals_agree(kind, periodic, k):
    t, x, dx = _signal(kind)
    c = classify_response(t, x, dx)
    f, is_periodic, mult = fundamental_frequency(t, x, dx)
    per = detect_period(t, x, dx)
    assert (per.periodic, per.multiplicity) == (periodic, k)
    assert (is_periodic, mult) == (periodic, k)
    assert c.kind.startswith("periodic") == periodic and c.multiplicity == k
    if periodic:
        assert per.period_s == pytest.approx(2.0, rel=1e-6)      # 1 / 0.5 Hz
        assert f == 1.0 / c.period_s == pytest.approx(0.5, rel=1e-6)


def test_too_few_periods_is_not_periodic():
    t, x, dx = _signal("sine")
    keep = t <= (MIN_REPEATS - 1) * 2.0 + 0.7                   # fewer than MIN_REPEATS periods
    assert not detect_period(t[keep], x[keep], dx[keep]).periodic
    assert not fundamental_frequency(t[keep], x[keep], dx[keep])[1]


# ------------------------------------------------------------------ simulated known cases
def _traj(N, omega, ic, t_end):
    from stickslip.sweep.spec import initial_condition

    p = stickslip.Parameters(N=N, Omega=omega)
    s0, pert = initial_condition(ic, p, "full")
    traj = stickslip.simulate(p, t_end, ic=s0, perturbation=pert, sample_rate=200.0)
    assert traj.status == "success", traj.status
    return traj


@pytest.mark.parametrize("N, omega, ic, t_end, expect", [
    (50.0, 5.0, "far", 60.0, "stick-slip"),        # Fig. 7(a): stick-slip (not periodic to 1e-3 A here)
    (50.0, 12.0, "far", 60.0, "equilibrium"),      # Fig. 7(e): equilibrium
    (30.0, 0.5, "zero", 100.0, "periodic"),        # Fig. 10(a): periodic, nearly harmonic
    (52.0, 0.5, "zero", 200.0, "periodic"),        # Fig. 10(b) region: periodic, not harmonic; the
                                                   # former mid-level section (1e-4) called it not periodic
    (90.0, 0.5, "zero", 200.0, "non-periodic"),    # Fig. 12(a) sweep at 90 N: peaks never repeat
])
def test_classify_and_steady_summary_agree(N, omega, ic, t_end, expect):
    traj = _traj(N, omega, ic, t_end)
    t_from = 0.5 * t_end
    c = classify(traj, t_from)
    s = traj.steady_state(t_from)
    _agree(c, s)
    if expect == "stick-slip":
        assert c.is_stick_slip
    elif expect == "equilibrium":
        assert c.kind == "equilibrium" and not s.periodic
    elif expect == "periodic":
        assert c.kind == "periodic-stick-slip" and s.periodic
        if N == 30.0:                                  # Fig. 10(a): "almost only one amplitude peak"
            assert s.period_multiplicity == 1
    else:
        assert c.kind == "non-periodic" and not s.periodic
