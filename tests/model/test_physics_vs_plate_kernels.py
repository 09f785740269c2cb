"""The generic physics, compiled for the plates' kinematics, against the plates' own hand-written
kernels (model/kernels.py, an independent implementation of paper Eqs. 1–10): the right-hand side
in every mode and the friction forces at random states agree to round-off."""

from __future__ import annotations

import numpy as np
import pytest

import stickslip
from stickslip.model import kernels as K
from stickslip.model import physics as P
from stickslip.model.bundle import contact_state
from stickslip.model.library import two_plates
from stickslip.model.system import assemble

MODES = {"slip": P.MODE_SLIP, "stick": P.MODE_STICK, "exact": P.MODE_SLIP_EXACT, "band": P.MODE_SLIP_QUASI_STATIC}


@pytest.mark.parametrize("variant", ["full", "x", "rotation"])
@pytest.mark.parametrize("mode", list(MODES))
def test_rhs_and_forces_match_the_plate_kernels(variant, mode):
    params = stickslip.Parameters(N=70.0, Omega=2.0)
    old = assemble(params, variant)
    model = two_plates(params, variant)
    rng = np.random.default_rng(7)
    cst = contact_state(model.data.m)
    cst[0] = MODES[mode]
    for _ in range(20):
        s = np.zeros(14)
        s[:12] = rng.normal(scale=0.05, size=12) * np.concatenate([model.free, model.free])
        if mode == "band":  # inside the low-speed band: a slip velocity below 5e-4 m/s
            P.project_velocities(s, cst, np.int64(0), model.data)
            s[6:12] += 1e-5 * rng.normal(size=6) * model.free
        ex, ey = 0.6, 0.8
        cst[1], cst[2] = ex, ey
        d_old = np.zeros(14)
        d_new = np.zeros(14)
        K.rhs(s, MODES[mode], ex, ey, old.minv, old.damp, old.stiff, old.p, d_old)
        P.rhs(s, cst, model.data, d_new)
        scale = np.max(np.abs(d_old[:12])) + 1.0
        np.testing.assert_allclose(d_new[:12], d_old[:12], rtol=0, atol=1e-12 * scale)
        F, N, v = np.zeros(2), np.zeros(1), np.zeros(2)
        P.contact_forces(s, cst, model.data, F, N, v)
        Fo = K.contact_force(s, MODES[mode], ex, ey, old.minv, old.damp, old.stiff, old.p)
        np.testing.assert_allclose(F, Fo, rtol=0, atol=1e-10 * (abs(Fo[0]) + abs(Fo[1]) + 1.0))
