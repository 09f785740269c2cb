"""The period rule: a settled orbit is periodic, a converging transient is not, and the
classification and the steady-state summary (``Trajectory.steady``) make the same decision."""

import math

import numpy as np
import pytest

import stickslip
from stickslip.analysis import classify, classify_response, detect_period, fundamental_frequency
from stickslip.analysis.classify import STATIONARY_MIN_PEAKS
from stickslip.analysis.period import MIN_PERIODS, SETTLE_RTOL
from stickslip.model.library import two_plates

W = 2 * np.pi * 0.5  # 0.5 Hz fundamental: period 2 s


def _agree(c, s):
    """Classification c and steady summary s make the same periodicity decision."""
    assert (c.outcome == "periodic") == s.periodic
    assert c.multiplicity == s.period_multiplicity
    if s.periodic:
        assert s.fundamental_frequency_hz == 1.0 / c.period_s
    else:
        assert math.isnan(s.fundamental_frequency_hz)  # no fundamental frequency without a period
    if math.isfinite(s.dominant_frequency_hz):
        assert s.dominant_frequency_hz == c.fft_frequency_hz  # both the spectral peak


# ------------------------------------------------------------------ constructed signals
def _signal(kind, t_end=100.0):
    t = np.linspace(0.0, t_end, int(t_end * 200) + 1)
    if kind == "sine":                                           # one peak per period
        return t, np.sin(W * t), W * np.cos(W * t)
    if kind == "two_humps":                                      # sin θ + 0.8 sin 2θ: θ' = 0 at
        return (t, np.sin(W * t) + 0.8 * np.sin(2 * W * t),      # cos θ = 0.568 and −0.880, i.e.
                W * np.cos(W * t) + 1.6 * W * np.cos(2 * W * t)) # two maxima per period
    if kind == "quasi":                                          # incommensurate: never repeats
        r = math.sqrt(2.0)
        return t, np.sin(W * t) + np.sin(r * W * t), W * np.cos(W * t) + r * W * np.cos(r * W * t)
    raise ValueError(kind)


def _modulated(t, c, gamma, theta):
    """(1 + a(t)) sin(W t) with a = c e^(−γ t) cos(θ t / T): the peak values converge like
    c r^n cos(n θ), a transient with Floquet-like multiplier r e^(iθ) per period T = 2 s."""
    a = c * np.exp(-gamma * t) * np.cos(theta * t / 2.0)
    da = c * np.exp(-gamma * t) * (-gamma * np.cos(theta * t / 2.0) - theta / 2.0 * np.sin(theta * t / 2.0))
    return (1 + a) * np.sin(W * t), da * np.sin(W * t) + (1 + a) * W * np.cos(W * t)


@pytest.mark.parametrize("kind, periodic, k", [("sine", True, 1), ("two_humps", True, 2), ("quasi", False, 0)])
def test_constructed_signals_agree(kind, periodic, k):
    # 300 s: the quasi-periodic signal's 212 peaks let every multiplicity up to 16 be tried
    t, x, dx = _signal(kind, t_end=300.0)
    c = classify_response(t, x, dx)
    f, is_periodic, mult = fundamental_frequency(t, x, dx)
    per = detect_period(t, x, dx)
    assert (per.periodic, per.multiplicity) == (periodic, k)
    assert (is_periodic, mult) == (periodic, k)
    assert (c.outcome == "periodic") == periodic and c.multiplicity == k
    if periodic:
        assert c.settled and c.signal == "periodic"
        assert per.period_s == pytest.approx(2.0, rel=1e-6)      # 1 / 0.5 Hz
        assert f == 1.0 / c.period_s == pytest.approx(0.5, rel=1e-6)
    else:
        assert not c.settled and c.signal == "stationary"        # stationary, not periodic
        assert c.evidence["peaks"] >= STATIONARY_MIN_PEAKS


def test_no_period_is_claimed_from_too_few_peaks():
    t, x, dx = _signal("quasi", t_end=100.0)                     # 70 peaks: k up to 16 cannot all be tried
    c = classify_response(t, x, dx)
    assert c.evidence["peaks"] < STATIONARY_MIN_PEAKS and c.signal == "drifting"


def test_too_few_periods_is_not_periodic():
    t, x, dx = _signal("sine")
    keep = t <= (MIN_PERIODS - 1) * 2.0 + 0.7                    # fewer than MIN_PERIODS periods
    assert not detect_period(t[keep], x[keep], dx[keep]).periodic
    assert not fundamental_frequency(t[keep], x[keep], dx[keep])[1]


def test_noise_far_below_the_tolerance_is_settled():
    t, x, dx = _signal("sine")
    rng = np.random.default_rng(1)
    per = detect_period(t, x + 1e-9 * rng.standard_normal(t.size), dx)
    assert per.periodic and per.multiplicity == 1


def test_transient_with_multipliers_near_minus_one_is_not_period_two():
    # multiplier r e^(iθ) per period, θ = π − 0.2, r = e^(−0.06): every second peak repeats 5×
    # better than every peak; at c = 2e-3 the k = 2 returns are < 1e-3 A over the window
    # (a 1e-3 return-map rule called it period 2), the k = 1 returns are not
    t = np.linspace(0.0, 100.0, 20001)
    x, dx = _modulated(t, 2e-3, 0.03, np.pi - 0.2)
    per = detect_period(t, x, dx)
    p = per.peaks.value
    amp = float(np.ptp(x))
    assert np.max(np.abs(p[2:] - p[:-2])) < 1e-3 * amp < np.max(np.abs(p[1:] - p[:-1]))  # the old trap
    assert not per.periodic and per.multiplicity == 0
    c = classify_response(t, x, dx, stick_fraction=0.5)
    assert c.outcome == "unsettled" and not c.settled and c.signal == "drifting"


def test_slow_monotone_drift_below_the_tolerance_is_not_settled():
    # p_n = 1 + c e^(−γ t_n): every return differs by c γ T = 2e-8 A ≪ SETTLE_RTOL, but the
    # peaks move by ~1e-6 A across the window and will still move by c e^(−γ t) ≈ 9e-5 A
    t = np.linspace(0.0, 100.0, 20001)
    c, gamma = 1e-4, 1e-3
    x = (1 + c * np.exp(-gamma * t)) * np.sin(W * t)
    dx = -gamma * c * np.exp(-gamma * t) * np.sin(W * t) + (1 + c * np.exp(-gamma * t)) * W * np.cos(W * t)
    per = detect_period(t, x, dx)
    assert per.evidence.multiplicity == 1 and per.evidence.spread < SETTLE_RTOL
    assert per.evidence.drift > per.evidence.spread
    assert not per.periodic


# ------------------------------------------------------------------ simulated known cases
def _traj(N, omega, ic, t_end, model="full"):
    from stickslip.sweep.spec import initial_condition

    p = stickslip.Parameters(N=N, Omega=omega)
    s0, pert = initial_condition(ic, two_plates(p, model))
    traj = stickslip.simulate(two_plates(p, model), t_end, ic=s0, perturbation=pert, sample_rate=200.0)
    assert traj.status == "success", traj.status
    return traj


def test_transient_matching_many_peaks_later_is_not_periodic():
    # N = 50 N, Ω = 0.5 rad/s from rest, window 400–500 s: the returns after 11 peaks are within
    # 5e-6 A with no drift (the slow multipliers rotate by ~2π/11 per crossing) while those after
    # one peak are 1.6e-5 A; the orbit is period 1 (shooting, test_settle), so no k = 11 claim
    traj = _traj(50.0, 0.5, "zero", 500.0)
    sel = traj.t >= 400.0
    per = detect_period(traj.t[sel], traj.states[sel, 4], traj.states[sel, 10])
    assert not per.periodic


@pytest.mark.parametrize("N, omega, ic, t_end, expect", [
    (50.0, 5.0, "far", 60.0, "stick-slip"),        # Fig. 7(a): stick-slip, still settling
    (50.0, 12.0, "far", 60.0, "decaying"),         # Fig. 7(e): decaying onto the equilibrium
    (50.0, 0.5, "zero", 200.0, "unsettled"),       # converging transient (period 1 by 600 s)
    (70.0, 0.5, "zero", 200.0, "unsettled"),       # converging transient (period 1 by 600 s)
])
def test_classify_and_steady_summary_agree(N, omega, ic, t_end, expect):
    traj = _traj(N, omega, ic, t_end)
    t_from = 0.5 * t_end
    c = classify(traj, t_from)
    s = traj.steady_state(t_from)
    _agree(c, s)
    assert not s.periodic and not c.settled
    if expect == "stick-slip":
        assert c.is_stick_slip
    elif expect == "decaying":
        assert c.outcome == "equilibrium" and c.signal == "decaying"
    else:
        assert c.outcome == "unsettled" and c.signal == "drifting"


def test_settled_window_is_periodic_in_both():
    # the same N = 50 N, Ω = 0.5 rad/s run, window 600–700 s: settled period 1
    traj = _traj(50.0, 0.5, "zero", 700.0)
    c = classify(traj, 600.0)
    s = traj.steady_state(600.0)
    _agree(c, s)
    assert c.outcome == "periodic" and c.is_stick_slip and c.multiplicity == 1 and c.settled
