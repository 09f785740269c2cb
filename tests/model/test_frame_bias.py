"""The velocity bias h = Ġ q̇ − ẇ of the stick multiplier: the plates' closed form (registered with
their kinematics) against the generic complex step of their frame, and against a central
difference of v along the flow at q̈ = 0; slip_velocity_and_rate's rate against a finite
difference of v along a state derivative."""

from __future__ import annotations

import numpy as np
from numba import njit

import stickslip
from stickslip.model import frames
from stickslip.model import physics as P
from stickslip.model.library import two_plates


@njit
def _closed_form(s, md):
    G, w, h = np.zeros((2, 6), dtype=s.dtype), np.zeros(2, dtype=s.dtype), np.zeros(2, dtype=s.dtype)
    normal = frames.frame_with_bias(s, 0, md, G, w, h)
    return G, w, h, normal


@njit
def _complex_step(s, md):
    G, w, h = np.zeros((2, 6)), np.zeros(2), np.zeros(2)
    normal = frames._frame_bias_complex_step(s, 0, md, G, w, h)
    return G, w, h, normal


@njit
def _central(s, md):
    G, w, h = np.zeros((2, 6), dtype=s.dtype), np.zeros(2, dtype=s.dtype), np.zeros(2, dtype=s.dtype)
    frames._frame_bias_central(s, 0, md, G, w, h)
    return h


def _states(count, seed=3):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        s = np.zeros(14)
        s[:12] = rng.normal(scale=[0.01] * 4 + [1.5, 0.3] + [0.05] * 4 + [2.0, 0.5])
        yield s


def test_plates_closed_form_bias_equals_the_complex_step_of_their_frame():
    model = two_plates(stickslip.Parameters(N=50.0, Omega=5.0, r=0.05))
    for s in _states(50):
        G1, w1, h1, n1 = _closed_form(s, model.data)
        G2, w2, h2, n2 = _complex_step(s, model.data)
        np.testing.assert_array_equal(G1, G2)
        np.testing.assert_array_equal(w1, w2)
        assert n1 == n2 == 50.0
        np.testing.assert_allclose(h1, h2, rtol=1e-13, atol=1e-13 * np.max(np.abs(h2)))
        # and against the flow itself: v(q + ε q̇, q̇) − v(q − ε q̇, q̇) over 2ε
        eps = 1e-6
        v = [P.slip_velocity(np.concatenate([s[:6] + side * eps * s[6:12], s[6:]]), 0, model.data)
             for side in (1.0, -1.0)]
        np.testing.assert_allclose(h1, (np.array(v[0]) - np.array(v[1])) / (2 * eps), rtol=1e-7,
                                   atol=1e-7 * np.max(np.abs(h1)))


def test_plates_closed_form_bias_is_complex_safe():
    """Inside a complex-step Jacobian the closed form runs on complex states: its real part is the
    float bias and it agrees with the generic central difference there."""
    model = two_plates(stickslip.Parameters(N=50.0, Omega=5.0))
    for s in _states(20, seed=4):
        z = s.astype(complex)
        z[4] += 1e-150j
        _, _, hz, _ = _closed_form(z, model.data)
        _, _, hf, _ = _closed_form(s, model.data)
        np.testing.assert_array_equal(hz.real, hf)
        np.testing.assert_allclose(hz.real, _central(z, model.data).real, rtol=1e-8, atol=1e-8 * np.max(np.abs(hf)))


def test_slip_rate_is_the_derivative_of_the_slip_velocity_along_ds():
    model = two_plates(stickslip.Parameters(N=50.0, Omega=5.0))
    rng = np.random.default_rng(5)
    for s in _states(20, seed=6):
        ds = np.zeros(14)
        ds[:6] = s[6:12]
        ds[6:12] = rng.normal(size=6)
        v0, v1, a0, a1 = P.slip_velocity_and_rate(s, ds, 0, model.data)
        assert (v0, v1) == P.slip_velocity(s, 0, model.data)
        eps = 1e-6
        vp = np.array(P.slip_velocity(s + eps * ds, 0, model.data))
        vm = np.array(P.slip_velocity(s - eps * ds, 0, model.data))
        np.testing.assert_allclose([a0, a1], (vp - vm) / (2 * eps), rtol=1e-7, atol=1e-7 * (abs(a0) + abs(a1)))
