"""AEOM (paper Sect. 3, method 1): RK4 order, converging transitions, Eq. (12) in stick,
agreement with `event`, model variants, step checks."""

import math

import numpy as np
import pytest

import stickslip
from stickslip import Parameters, SimulationError
from stickslip.attractors import run_summary
from stickslip.model.bundle import H_BAND
from stickslip.model.library import two_plates


def _vr_norm(traj):
    return np.hypot(*traj.relative_velocity.T)


def test_method_registered_and_summary_keys():
    a = stickslip.simulate(t_end=2.0, method="aeom", dt=1e-3)
    e = stickslip.simulate(t_end=2.0)
    assert a.method == "aeom" and a.status == "success"
    assert set(run_summary(a)) == set(run_summary(e))
    assert a.states.shape == (2001, 12)
    assert a.stats.accepted_steps >= 2000


def test_dt_required_and_too_large_rejected():
    with pytest.raises(SimulationError, match="fixed-step method: give the step dt"):
        stickslip.simulate(t_end=1.0, method="aeom")
    # Table 1: omega_max = sqrt(300/1) = 17.3 rad/s, limit 2/17.3 = 0.115 s
    with pytest.raises(SimulationError, match="too large for fixed-step RK4"):
        stickslip.simulate(t_end=1.0, method="aeom", dt=0.2)
    stickslip.simulate(t_end=1.0, method="aeom", dt=0.1)  # the paper's largest step is admitted


def test_rk4_fourth_order_in_smooth_slip():
    # 0-1 s from rest is pure slip (first stick at 1.52 s); reference: event at rtol 1e-13
    ref = stickslip.simulate(t_end=1.0, rtol=1e-13, atol=1e-15, sample_rate=100).final_state
    errors = []
    for dt in (2e-3, 1e-3, 5e-4):
        traj = stickslip.simulate(t_end=1.0, method="aeom", dt=dt, sample_rate=100)
        assert len(traj.transitions) == 0
        errors.append(np.abs(traj.final_state - ref).max())
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 4.0) < 0.2), orders


def test_transition_instants_converge():
    ref = stickslip.simulate(t_end=2.0, rtol=1e-12, atol=1e-14).transitions
    assert len(ref) == 4
    worst = []
    for dt in (2e-3, 2.5e-4):
        tr = stickslip.simulate(t_end=2.0, method="aeom", dt=dt).transitions
        assert np.array_equal(tr.kind, ref.kind)
        worst.append(np.abs(tr.time - ref.time).max())
    assert worst[1] < worst[0] / 10
    assert worst[1] < 1e-4  # s


@pytest.mark.parametrize("method", ["aeom", "naeom"])
def test_stick_entry_after_a_pass_by_the_origin(method):
    """The 7th transition (t ≈ 2.618 s, default case) is a stick entry whose v_r passes the origin
    inside the low-speed band, turning by 180° over a dozen steps of 1e-5 s. The slip → stick
    event refers to v_r's direction at the band's entry (fixed_step.event_direction): with the
    direction at each step start no step turned by 90° and stick began up to 4.9e-4 s late.
    Measured now: 1.6e-5 s (AEOM) and 2.3e-5 s (NAEOM) for that one (the approach in the band
    is the quasi-static direction here, the exact one in `event`), ≤ 6e-8 s for the others."""
    ref = stickslip.simulate(t_end=3.0, rtol=1e-12, atol=1e-14).transitions
    tr = stickslip.simulate(t_end=3.0, method=method, dt=1e-5).transitions
    assert np.array_equal(tr.kind, ref.kind) and len(ref) == 9
    err = np.abs(tr.time - ref.time)
    assert err[6] < 5e-5
    assert np.delete(err, 6).max() < 1e-6


def _eq12(prev, cur, dt, p):
    """x2, y2 at t_n from Eq. (12) as printed in the paper (ψ there read as dψ/dt)."""
    x1, y1, x2, y2, phi, psi, dx1, dy1, dx2, dy2, dphi, dpsi = prev
    r, Om = p.r, p.Omega
    w_prev = Om + dpsi
    w_cur = Om + cur[11]
    phi_n, dphi_n = cur[4], cur[10]
    lam = (x2 - x1) + dt / 2 * ((-r * dphi * math.sin(phi) + w_prev * (y1 - y2 + r * math.sin(phi)))
                                + (-r * dphi_n * math.sin(phi_n) + r * w_cur * math.sin(phi_n)))
    pi = (y2 - y1) + dt / 2 * ((r * dphi * math.cos(phi) - w_prev * (x1 - x2 + r * math.cos(phi)))
                               + (r * dphi_n * math.cos(phi_n) - r * w_cur * math.cos(phi_n)))
    den = 1 + dt**2 / 4 * w_cur**2
    u = (lam - dt / 2 * w_cur * pi) / den
    w = (dt / 2 * w_cur * lam + pi) / den
    return cur[0] + u, cur[1] + w


def test_stick_follows_eq12_and_holds_vr_zero():
    dt = 1e-3
    traj = stickslip.simulate(t_end=3.0, method="aeom", dt=dt, sample_rate=1 / dt)
    p = traj.params
    # consecutive samples (= step ends) both in stick with no transition between them
    both = (traj.mode[1:] == 1) & (traj.mode[:-1] == 1)
    tr = traj.transitions.time
    pairs = [i for i in np.flatnonzero(both) if not np.any((tr > traj.t[i] - 1e-12) & (tr < traj.t[i + 1] + 1e-12))]
    assert len(pairs) > 50
    for i in pairs:
        x2, y2 = _eq12(traj.states[i], traj.states[i + 1], dt, p)
        assert abs(traj.states[i + 1, 2] - x2) < 1e-13 and abs(traj.states[i + 1, 3] - y2) < 1e-13
    # v_r = 0 by construction (ẋ2, ẏ2 from Eq. 11): round-off only
    assert _vr_norm(traj)[traj.mode == 1].max() < 1e-12
    # |F| in stick within the static limit (Eq. 10)
    assert traj.friction_magnitude[traj.mode == 1].max() <= (p.mu_k + p.delta_mu) * p.N * (1 + 1e-9)


@pytest.mark.parametrize("model", ["x", "y", "rotation"])
def test_variants_no_nan_and_vr_zero_in_stick(model):
    # start in stick: lower plate not turning (dψ/dt = −Ω), so v_r = 0 at rest; at Ω = 0.5 rad/s
    # Models 2 and 4 also re-enter stick later (Model 3 does not in this case)
    params = Parameters(Omega=0.5)
    ic = np.zeros(12)
    ic[11] = -params.Omega
    traj = stickslip.simulate(two_plates(params, model), 6.0, method="aeom", dt=1e-4, sample_rate=1e4, ic=ic)
    assert traj.status == "success"
    assert np.all(np.isfinite(traj.states))
    assert traj.mode[0] == 1 and traj.stats.stick_to_slip > 0
    if model != "y":
        assert traj.stats.slip_to_stick > 0
    # step ends coincide with samples (sample_rate = 1/dt)
    vr = traj.relative_velocity[traj.mode == 1]
    if model == "y":
        # Model 3 near φ = 0: the x-row of G is ≈ 0 (A = G M⁻¹ Gᵀ of rank 1), no friction force
        # can act on v_r·e_x, so only the controllable component is held
        vr = vr[:, 1:]
    assert np.abs(vr).max() < 1e-12
    locked = ~two_plates(params, model).free
    assert np.all(traj.states[:, :6][:, locked] == 0.0)


def test_agrees_with_event_short_run():
    """30 s, steady window 15-30 s: frequency and amplitude of φ within 0.5 % at Δt = 1e-4 s."""
    e = stickslip.simulate(t_end=30.0, steady_from=15.0, rtol=1e-10, atol=1e-12).steady
    a = stickslip.simulate(t_end=30.0, steady_from=15.0, method="aeom", dt=1e-4).steady
    assert abs(a.frequency_hz / e.frequency_hz - 1) < 5e-3
    assert abs((a.maximum - a.minimum) / (e.maximum - e.minimum) - 1) < 5e-3


@pytest.mark.slow
def test_agrees_with_event_100s():
    e = stickslip.simulate(t_end=100.0, rtol=1e-10, atol=1e-12).steady
    for method in ("aeom", "naeom"):
        a = stickslip.simulate(t_end=100.0, method=method, dt=1e-4).steady
        assert abs(a.frequency_hz / e.frequency_hz - 1) < 5e-3
        assert abs((a.maximum - a.minimum) / (e.maximum - e.minimum) - 1) < 5e-3


def test_step_band_formula():
    from stickslip.integrate.fixed_step import step_band, step_data

    model = two_plates(Parameters(), "full")
    # Δt μs N tr(G M⁻¹ Gᵀ) at R = r: 1e-4 * 15 * (1 + 1 + 0.1 + 0.1 + 0.04/0.5 + 0.04/5)
    assert step_band(model, 1e-4) == pytest.approx(1e-4 * 15 * 2.288)
    assert step_data(model, 1e-4).m[H_BAND] == pytest.approx(1e-4 * 15 * 2.288)
    assert step_data(model, 1e-6).m[H_BAND] == model.slip_band  # the model's band where that is wider
    assert step_data(model, 1e-6).kin == model.data.kin


@pytest.mark.parametrize("method", ["aeom", "naeom"])
def test_samples_on_the_step_grid_are_the_step_ends(method):
    # with the sample period a multiple of Δt every sample is a step end, written directly
    # (fixed_step.end_sample_only) rather than interpolated: it must be the integrator's state
    # there, which is the final state of a run that stops at that instant
    dt = 1e-3
    long = stickslip.simulate(t_end=2.0, method=method, dt=dt)
    assert long.mode.min() == 0 and long.mode.max() == 1  # the window holds stick and slip
    for k in (137, 700, 1401, 1999):
        short = stickslip.simulate(t_end=k * dt, method=method, dt=dt)
        np.testing.assert_array_equal(long.states[k], short.final_state)
