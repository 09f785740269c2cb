"""Verification layer 1: the 1-DOF oscillator on a moving belt, through the same kernels.

Freeing only φ (model ``phi``) turns the two-plate model into J φ̈ + k φ = r F·e_n1 against
a surface moving at Ω r: with no damping and Coulomb friction (μk in slip, μs at stick) the
limit cycle has closed-form stick and slip durations.
"""

import math

import numpy as np
import pytest

from stickslip import Parameters, simulate
from stickslip.model.library import two_plates


def closed_form(P):
    k, J, r, N, Om = P.k_pphi, P.J_p, P.r, P.N, P.Omega
    omega = math.sqrt(k / J)
    phi_s = P.mu_s * N * r / k   # breakaway: k φ = μs N r
    phi_k = P.mu_k * N * r / k   # centre of the slip oscillation
    D = phi_s - phi_k
    beta = math.atan2(Om / omega, D)
    return 2 * D / Om, (math.pi + 2 * beta) / omega   # stick, slip durations [s]


@pytest.mark.parametrize("Omega, mu_k, delta_mu", [(0.5, 0.2, 0.1), (1.0, 0.3, 0.2), (0.2, 0.1, 0.05)])
def test_stick_and_slip_durations(Omega, mu_k, delta_mu):
    P = Parameters(c_pphi=0.0, Omega=Omega, mu_k=mu_k, delta_mu=delta_mu, friction_law="coulomb")
    t_stick, t_slip = closed_form(P)
    period = t_stick + t_slip
    ic = np.zeros(12)
    ic[10] = Omega  # start stuck to the belt at φ = 0
    traj = simulate(two_plates(P, "phi"), 12 * period, ic=ic, rtol=1e-11, atol=1e-13, sample_rate=200)
    assert traj.status == "success"
    tt, kind = traj.transitions.time, traj.transitions.kind
    assert len(tt) >= 10
    # the run starts in stick, so every stick after the first breakaway is on the limit cycle
    first = int(np.flatnonzero(kind == 1)[0])
    tt, kind = tt[first:], kind[first:]
    stick = tt[1::2][: len(tt[::2])] - tt[::2][: len(tt[1::2])]
    slip = tt[2::2] - tt[1::2][: len(tt[2::2])]
    assert np.all(kind[::2] == 1) and np.all(kind[1::2] == -1)
    assert np.allclose(stick, t_stick, rtol=1e-8)
    assert np.allclose(slip, t_slip, rtol=1e-8)


def test_stick_is_exact_on_the_belt():
    P = Parameters(c_pphi=0.0, Omega=0.5, friction_law="coulomb")
    ic = np.zeros(12)
    ic[10] = P.Omega
    traj = simulate(two_plates(P, "phi"), 5.0, ic=ic, sample_rate=2000)
    stick = traj.mode == 1
    assert stick.any()
    assert np.allclose(traj.states[stick, 10], P.Omega, rtol=0, atol=1e-10)
    # in stick the friction torque balances the spring: r F·e_n1 = k φ
    phi = traj.states[stick, 4]
    torque = P.r * (-np.sin(phi) * traj.friction[stick, 0] + np.cos(phi) * traj.friction[stick, 1])
    assert np.allclose(torque, P.k_pphi * phi, rtol=1e-9, atol=1e-12)


def test_run_that_starts_sliding_just_short_of_stick():
    """Regression: a run starting in slip with |v_r| < 1e-3 m/s once slid through v_r = 0 unseen
    and then chattered at the low-speed band for 5e7 steps."""
    P = Parameters(c_pphi=0.0, Omega=0.5, friction_law="coulomb")
    ic = np.zeros(12)
    ic[4], ic[10] = 0.00946034184785673, 0.49777818470226337  # v_r = r (φ̇ − Ω) ≈ −4.4e-4 m/s
    traj = simulate(two_plates(P, "phi"), 1.0, ic=ic, rtol=1e-10, atol=1e-13, max_steps=100_000)
    assert traj.status == "success"
    t_stick, t_slip = closed_form(P)
    tt = traj.transitions.time
    assert traj.transitions.kind[0] == 1 and len(tt) >= 4
    assert np.allclose(np.diff(tt)[0::2][:2], t_stick, rtol=1e-8)
    assert np.allclose(np.diff(tt)[1::2][:1], t_slip, rtol=1e-8)
