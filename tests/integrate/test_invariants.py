"""Verification layer 3: energy balance, the stick constraint, continuity at breakaway."""

import numpy as np
import pytest

from stickslip import Parameters, simulate
from stickslip.model import physics as P
from stickslip.model.bundle import contact_state
from stickslip.model.library import two_plates


def state14(s):
    """The 12 states with the two work accumulators the physics kernels carry along."""
    out = np.zeros(14)
    out[:12] = s[:12]
    return out


@pytest.fixture(scope="module")
def stick_slip_run():
    # Ω = 5 rad/s, N = 50 N: stick-slip from t ≈ 1.5 s (paper Sect. 4.2.1 case)
    return simulate(Parameters(), 6.0, rtol=1e-10, atol=1e-12, sample_rate=20000)


def test_run_has_stick_and_slip(stick_slip_run):
    tr = stick_slip_run
    assert tr.status == "success"
    assert tr.stats.slip_to_stick >= 3 and tr.stats.stick_to_slip >= 3
    assert 0.0 < tr.mode.mean() < 1.0


def test_energy_balance(stick_slip_run):
    tr = stick_slip_run
    dE = tr.mechanical_energy - tr.mechanical_energy[0]
    work = tr.work[:, 0] + tr.work[:, 1]
    scale = np.abs(tr.work).max()
    assert scale > 1.0  # the check is not vacuous: joules of work are exchanged
    assert np.abs(dE - work).max() < 1e-7 * scale


def test_stick_constraint_and_friction_cone(stick_slip_run):
    tr = stick_slip_run
    stick = tr.mode == 1
    speed = np.hypot(*tr.relative_velocity[stick].T)
    assert speed.max() <= 1e-9
    assert tr.friction_magnitude[stick].max() <= tr.params.mu_s * tr.params.N * (1 + 1e-12)


def test_friction_continuous_at_breakaway(stick_slip_run):
    tr = stick_slip_run
    md = two_plates(tr.params, tr.model).data
    cst = contact_state(md.m)
    cst[0] = P.MODE_STICK
    muN = tr.params.mu_s * tr.params.N
    for t_b, s in zip(tr.transitions.time[tr.transitions.kind == -1], tr.transitions.state[tr.transitions.kind == -1]):
        Fs, N = np.zeros(2), np.zeros(1)
        P.stick_forces(state14(s), cst, np.int64(-1), md, Fs, N)
        assert abs(np.hypot(*Fs) - muN) < 1e-8 * muN  # breakaway is located on |F| = μs N (Eq. 10)
        # samples straddling the breakaway: F moves by O(sample spacing), no jump
        i = np.searchsorted(tr.t, t_b)
        jump = np.hypot(*(tr.friction[i] - tr.friction[i - 1]))
        typical = np.median(np.hypot(*np.diff(tr.friction, axis=0).T))
        assert jump < 50 * typical + 1e-3 * muN


def test_slip_to_stick_lands_on_zero_velocity(stick_slip_run):
    tr = stick_slip_run
    md = two_plates(tr.params).data
    for s in tr.transitions.state[tr.transitions.kind == 1]:
        assert np.hypot(*P.slip_velocity(state14(s), np.int64(0), md)) < 1e-12


def test_rotation_model_rank_one_stick_has_no_nan():
    tr = simulate(two_plates(Parameters(Omega=0.5), "rotation"), 20.0)
    assert tr.status == "success"
    assert np.isfinite(tr.states).all() and np.isfinite(tr.friction).all()
    assert tr.stats.slip_to_stick > 0
    assert np.all(tr.states[:, [0, 1, 2, 3, 6, 7, 8, 9]] == 0.0)
