"""What a run settles to, checked against independent routes: shooting the orbit, its
continuation (period doubling), the linear stability of steady sliding, much longer runs."""

import dataclasses
import math

import numpy as np
import pytest

import stickslip
from stickslip.attractors.confirm import QUASI_SPAN_S, lyapunov_sign
from stickslip.attractors import attractor, run_summary, simulate_until_settled
from stickslip.integrate.status import Status
from stickslip.model.library import two_plates
from stickslip.stability import stability

#: Detuned stiffnesses (docs/orbits.md, "A chaotic case") with Table 1 damping: the period-1
#: orbit at N = 100 N period-doubles as Ω falls through 1.0470 rad/s (continuation below).
DETUNED = dict(k_py=200.0, k_dx=2500.0, k_dy=3500.0, k_pphi=80.0, N=100.0)


def _shot(params, run, k=1):
    """Period [s] and orbit shot from a run (shooting: independent of the period rule)."""
    orbit = stickslip.periodic_orbit(params, run, period_multiplicity=k)
    return orbit.period, orbit


def test_converging_transient_is_unsettled_when_short_and_period_one_when_long():
    p = stickslip.Parameters(N=50.0, Omega=0.5)
    short = stickslip.simulate(p, 200.0, sample_rate=200.0)
    s = run_summary(short)
    # a 1e-3 return-map rule called this window period 2 at 0.769 Hz
    assert (s["attractor"], s["settled"], s["period_count"], s["fundamental_frequency_hz"]) == (
        "unsettled", False, None, None)
    assert s["settle_time_s"] is None
    period, _ = _shot(p, short)                        # T = 0.65015 s: a period-1 orbit
    assert s["dominant_frequency_hz"] == pytest.approx(1.0 / period, rel=1e-3)
    long = simulate_until_settled(p, sample_rate=200.0)
    a = long.summary()
    assert (a["attractor"], a["settled"], a["period_count"]) == ("periodic", True, 1)
    assert a["fundamental_frequency_hz"] == pytest.approx(1.0 / period, rel=1e-6)
    assert 200.0 < a["settle_time_s"] == long.trajectory.t[-1] <= 2000.0
    assert a["settle"]["settled"] and a["settle"]["cap_s"] == 2000.0


@pytest.mark.parametrize("N", [50.0, 70.0, 110.0])
def test_default_summary_never_calls_a_converging_transient_period_k(N):
    # the runs: 200 s at Ω = 0.5 rad/s were reported as period 2, 5 and 6
    s = run_summary(stickslip.simulate(stickslip.Parameters(N=N, Omega=0.5), 200.0, sample_rate=200.0))
    assert s["attractor"] == "unsettled" and s["period_count"] is None and s["fundamental_frequency_hz"] is None


def test_paper_defaults():
    p = stickslip.Parameters()                                    # N = 50 N, Ω = 5 rad/s
    s = run_summary(stickslip.simulate(p, 100.0))                # what `stickslip simulate` runs
    assert s["attractor"] == "unsettled" and s["fundamental_frequency_hz"] is None
    assert {"status", "model", "parameters"} <= set(s) and s["parameters"]["Omega"] == 5.0
    run = simulate_until_settled(p, sample_rate=500.0)
    a = run.attractor
    assert (a.attractor, a.period_count) == ("periodic", 1)
    period, orbit = _shot(p, run.trajectory)
    assert orbit.stable
    assert a.fundamental_frequency_hz == pytest.approx(1.0 / period, rel=1e-6)   # 2.7035 Hz


def test_stable_steady_sliding_is_an_equilibrium():
    from stickslip.sweep.spec import initial_condition

    p = stickslip.Parameters(N=50.0, Omega=12.0)                 # Fig. 7(e)
    ic, pert = initial_condition("near", two_plates(p, "full"))
    run = simulate_until_settled(p, ic=ic, perturbation=pert, sample_rate=200.0)
    a = run.summary()
    assert (a["attractor"], a["settled"], a["period_count"]) == ("equilibrium", True, None)
    # independent: a much longer, tighter run keeps shrinking in every coordinate (by ≥ 1e-2
    # over 1200 s; at rtol 1e-8 the translations stall at the integration noise, ~6e-9 m)
    long = stickslip.simulate(p, 1500.0, ic=ic, perturbation=pert, sample_rate=50.0, rtol=1e-11, atol=1e-14)
    early, late = (long.t >= 100.0) & (long.t < 300.0), long.t >= 1300.0
    for j in range(6):
        assert np.ptp(long.states[late, j]) < 1e-2 * np.ptp(long.states[early, j])


def test_at_rest_on_an_unstable_equilibrium_is_not_settled():
    # steady sliding at N = 50 N, Ω = 5.5 rad/s is unstable (below Ω_c = 6.18 rad/s, Fig. 3);
    # started exactly on it the run stays at rest for 20 s (growth at 0.016 1/s from
    # round-off), but that is no attractor
    p = stickslip.Parameters(N=50.0, Omega=5.5)
    assert not stability(p).stable
    run = stickslip.simulate(p, 20.0, ic="equilibrium", sample_rate=100.0)
    a = attractor(run)
    assert a.classification.signal == "at-rest"                   # the signal is at rest
    assert a.attractor == "unsettled" and "unstable" in a.evidence["reason"]


def test_period_two_past_a_period_doubling_is_confirmed():
    from stickslip.attractors.confirm import _sections_in_slip

    # the period-1 orbit at Ω = 1.08 rad/s, continued down in Ω: a real multiplier crosses −1
    p = stickslip.Parameters(Omega=1.08, **DETUNED)
    run1 = simulate_until_settled(p, ic="equilibrium", perturbation=1e-3, sample_rate=500.0)
    assert (run1.attractor.attractor, run1.attractor.period_count) == ("periodic", 1)
    section, mult = next(_sections_in_slip(run1.trajectory, "phi", run1.trajectory.steady_from,
                                           run1.attractor.period_s))
    orbit1 = stickslip.periodic_orbit(p, run1.trajectory, section=section, period_multiplicity=mult)
    branch = stickslip.continue_orbit(p, "Omega", start=orbit1, direction=-1, bounds=(1.0, 1.08), step=0.01,
                                      section=section)
    pd = [sp for sp in branch.special if sp.kind == "period-doubling"]
    assert len(pd) == 1 and 1.04 < pd[0].value < 1.05              # located at 1.0470 rad/s
    # past it, at Ω = 1.03 rad/s, the run settles on a period-2 orbit: 2 maxima of φ, 2 stick
    # phases, twice the period of the (now unstable) period-1 orbit
    q = p.replace(Omega=1.03)
    run2 = simulate_until_settled(q, ic="equilibrium", perturbation=1e-3, sample_rate=500.0)
    a = run2.attractor
    assert (a.attractor, a.period_count) == ("periodic", 2)
    assert a.evidence["shooting"]["confirmed"] and a.evidence["shooting"]["stick_phases"] == 2
    unstable1 = stickslip.periodic_orbit(q, orbit1.state, section=section, search_time=5.0)
    assert not unstable1.stable and np.min(unstable1.multipliers.real) < -1.0
    assert a.period_s == pytest.approx(2.0 * unstable1.period, rel=1e-2)


def test_two_maxima_per_period_are_confirmed_by_shooting():
    # N = 110 N, Ω = 0.5 rad/s: one stick phase per period, φ with two maxima (the peak section
    # is crossed in stick, so the orbit is shot on a level of φ crossed in slip)
    p = stickslip.Parameters(N=110.0, Omega=0.5)
    run = simulate_until_settled(p, sample_rate=200.0)
    a = run.attractor
    assert (a.attractor, a.period_count) == ("periodic", 2)
    shot = a.evidence["shooting"]
    assert shot["confirmed"] and shot["stick_phases"] == 1 and shot["section"] != "phi_max"
    # independent count: local maxima of φ sampled at 20 kHz over exactly one period of the orbit
    from stickslip.orbits.section import Section

    level = float(shot["section"].split("=")[1].split()[0])
    orbit = stickslip.periodic_orbit(p, run.trajectory, section=Section(4, level, -1 if "down" in shot["section"] else 1, "x"),
                                     period_multiplicity=1)
    dense = orbit.trajectory(periods=1.0, sample_rate=20000.0).states[:, 4]
    inner = (dense[1:-1] > dense[:-2]) & (dense[1:-1] >= dense[2:])
    assert int(inner.sum()) == 2
    assert a.period_s == pytest.approx(orbit.period, rel=1e-6)


def test_no_period_k_claim_without_confirmation():
    p = stickslip.Parameters(N=110.0, Omega=0.5)
    run = simulate_until_settled(p, sample_rate=200.0)
    a = attractor(run.trajectory, confirm=False)
    assert a.classification.signal == "periodic" and a.classification.multiplicity == 2
    assert a.attractor == "unsettled" and a.period_count is None and "confirm" in a.evidence["reason"]


def test_a_run_that_blew_up_is_unbounded():
    run = stickslip.simulate(stickslip.Parameters(), 1.0, sample_rate=100.0)
    broken = dataclasses.replace(run, status="state became non-finite at t = 0.5 s", status_code=Status.NOT_FINITE)
    a = attractor(broken)
    assert (a.attractor, a.settled, a.period_count) == ("unbounded", True, None)


def test_a_run_that_stopped_is_named_by_how_it_stopped():
    # a step cap the run cannot finish within: the outcome is ``failed``, not a transient
    run = stickslip.simulate(stickslip.Parameters(), 1.0, sample_rate=100.0, max_steps=50)
    assert run.status_code == Status.MAX_STEPS
    a = attractor(run)
    assert (a.attractor, a.settled, a.code) == ("failed", False, stickslip.OUTCOMES.index("failed"))
    assert "max_steps" in a.evidence["reason"]
    lost = dataclasses.replace(run, status="contact lost at t = 0.5 s", status_code=Status.CONTACT_LOST)
    assert attractor(lost).attractor == "contact-lost"
    cut = dataclasses.replace(run, status="interrupted at t = 0.5 s (partial run)", status_code=Status.INTERRUPTED)
    assert attractor(cut).attractor == "unsettled"  # only cut short: nothing is known of where it goes


def test_lyapunov_sign_needs_both_separations_to_agree(monkeypatch):
    import stickslip.attractors.confirm as confirm

    run = stickslip.simulate(stickslip.Parameters(), 1.0, sample_rate=100.0)

    def fake(by_d0):
        return lambda *a, d0, **k: type("R", (), {"exponent": by_d0[d0][0], "standard_error": by_d0[d0][1]})()

    for by_d0, expect in [({1e-7: (0.2, 0.015), 1e-6: (0.19, 0.015)}, "positive"),
                          ({1e-7: (0.345, 0.029), 1e-6: (-0.001, 0.022)}, None),   # Model 3, Ω = 0.677 rad/s
                          ({1e-7: (0.006, 0.02), 1e-6: (0.006, 0.02)}, "zero"),
                          ({1e-7: (-0.3, 0.01), 1e-6: (-0.3, 0.01)}, None)]:
        monkeypatch.setattr(confirm, "lyapunov_exponent", fake(by_d0))
        out = lyapunov_sign(run)
        assert out["sign"] == expect, by_d0
        assert out["exponents"] == [by_d0[1e-7][0], by_d0[1e-6][0]] and (expect is not None or "reason" in out)


def test_slow_approach_with_zero_exponent_is_not_a_torus():
    # N = 50 N, Ω = 0.5 rad/s, Δμ = 0.0661: no decay visible within 330 s and λ ≈ 0, but the
    # spreads fall ×2.7 per 500 s (0.52 at 0–500 s → 4.6e-4 at 3500–4000 s in a plain run)
    p = stickslip.Parameters(N=50.0, Omega=0.5, delta_mu=0.0661)
    run = simulate_until_settled(p, sample_rate=200.0)
    a = run.attractor
    assert a.attractor == "unsettled" and a.evidence["lyapunov"]["sign"] == "zero"
    assert a.evidence["span"]["rate"] > 10 * 1e-4
    plain = stickslip.simulate(p, 4000.0, sample_rate=50.0)
    early, late = plain.t < 500.0, plain.t >= 3500.0
    assert np.ptp(plain.states[late, 4]) < np.ptp(plain.states[early, 4])


def test_quasiperiodic_slip_oscillation_of_model_3():
    # Model 3 (y), N = 35 N, Ω = 0.5 rad/s: a slip-only oscillation at 2.246 Hz modulated at 0.139 Hz
    p = stickslip.Parameters(N=35.0, Omega=0.5)
    run = simulate_until_settled(two_plates(p, "y"), sample_rate=200.0)
    a = run.attractor
    assert a.attractor == "quasiperiodic" and a.period_count is None and a.fundamental_frequency_hz is None
    assert a.evidence["span"]["span_s"] == QUASI_SPAN_S
    # independent: over a 4000 s run the maxima of φ never repeat (thousands of distinct values)
    # while their set does not move (same extremes in the second and fourth 1000 s)
    plain = stickslip.simulate(two_plates(p, "y"), 4000.0, sample_rate=200.0)
    pk = stickslip.find_peaks(plain.t, plain.states[:, 4], plain.states[:, 10])
    late = pk.value[pk.time > 1000.0]
    amp = float(np.ptp(plain.states[plain.t > 1000.0, 4]))
    assert np.unique(np.round(late / amp, 6)).size > 0.9 * late.size > 5000
    second, fourth = late[pk.time[pk.time > 1000.0] < 2000.0], late[pk.time[pk.time > 1000.0] > 3000.0]
    assert abs(second.max() - fourth.max()) < 1e-4 * amp and abs(second.min() - fourth.min()) < 1e-4 * amp


def test_chaotic_case_is_chaotic():
    # docs/orbits.md, "A chaotic case": λ_max ≈ 0.2 1/s (Benettin over 2000 s, four seeds/d0)
    damping = {k: 0.01 for k in ("c_px", "c_py", "c_dx", "c_dy", "c_pphi", "c_dpsi")}
    p = stickslip.Parameters(Omega=1.0, **DETUNED, **damping)
    run = simulate_until_settled(p, ic="equilibrium", perturbation=1e-3, t_min=300.0, sample_rate=200.0)
    a = run.attractor
    assert a.attractor == "chaotic" and a.period_count is None and a.fundamental_frequency_hz is None
    assert min(a.evidence["lyapunov"]["exponents"]) > 0.05


def test_extended_run_is_one_uniform_record():
    p = stickslip.Parameters(N=50.0, Omega=0.5)
    settled = simulate_until_settled(p, sample_rate=100.0, cap=400.0, t_min=200.0)
    run = settled.trajectory
    assert run.t[0] == 0.0 and run.t[-1] == 400.0 and not settled.attractor.settled
    assert np.allclose(np.diff(run.t), 0.01) and run.states.shape == (40001, 12)
    assert np.all(np.diff(run.transitions.time) > 0)
    assert np.all(np.diff(run.work[:, 1]) <= 1e-12)               # damper work keeps falling across joins
    assert run.options["settle"]["extensions"] == 2 and run.steady_from == 300.0


def test_window_mode_keeps_the_last_span_and_reaches_the_same_verdict():
    # Model 3, N = 41 N, Ω = 0.5 rad/s still drifts at 1300 s
    p = stickslip.Parameters(N=41.0, Omega=0.5)
    full = simulate_until_settled(two_plates(p, "y"), sample_rate=100.0, cap=1300.0)
    window = simulate_until_settled(two_plates(p, "y"), sample_rate=100.0, cap=1300.0, keep="window")
    assert full.trajectory.t[0] == 0.0 and window.trajectory.t[0] == pytest.approx(1300.0 - QUASI_SPAN_S, abs=0.01)
    assert window.trajectory.t[-1] == full.trajectory.t[-1] == 1300.0 and not full.attractor.settled
    assert window.attractor.evidence == full.attractor.evidence


def test_bad_settle_options_say_what_to_do():
    with pytest.raises(stickslip.SimulationError, match="t_min"):
        simulate_until_settled(None, window=300.0, t_min=200.0)
    with pytest.raises(stickslip.SimulationError, match="cap"):
        simulate_until_settled(None, cap=math.nan)
    with pytest.raises(stickslip.SimulationError, match="t_end"):
        simulate_until_settled(None, t_end=100.0)


def test_samples_that_alias_the_motion_carry_no_verdict():
    # The plates' defaults settle on a period-1 stick-slip cycle of 2.7035 Hz. Sampled at 1 Hz
    # (below twice the fastest linear mode, 2.757 Hz) its section crossings are aliases: such a
    # window was called a settled torus. The same run sampled at 200 Hz is the periodic cycle.
    sparse = stickslip.simulate(t_end=1500.0, sample_rate=1.0)
    v = attractor(sparse, 1000.0)
    assert (v.attractor, v.settled, v.period_count) == ("unsettled", False, None)
    assert "alias" in v.evidence["reason"] and "at least 6" in v.evidence["reason"]
    dense = attractor(stickslip.simulate(t_end=1500.0, sample_rate=200.0), 1400.0)
    assert (dense.attractor, dense.period_count) == ("periodic", 1)
    assert dense.fundamental_frequency_hz == pytest.approx(2.7035, abs=1e-4)
