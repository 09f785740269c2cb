"""Lyapunov spectra of a periodic impacting cycle against its Floquet multipliers and the closed form.

The impact oscillator (docs/models/impact-oscillator.md) with the normal spring's rest position on
the stop (d = 0), elastic impacts (e = 1), a tangential damper c and a fast stop (V = 2, so every
impact slides: |x' − V| > μ (1 + e) |ġ⁻|). Each flight is half a period of the normal spring,
π/ω = 0.5 s whatever its height, so the normal motion is a cycle of period T = 0.5 s whose two
multipliers are 1 (the shift along it, and its height, which does not change the period). The
impacts kick x' by μ (1 + e) m |ġ⁻|, which does not depend on x, x': the tangential variations
follow m x'' + c x' + kx x = 0 alone, so their multipliers are those of exp(A T), A the matrix of
that oscillator, and ln|μ|/T its eigenvalues: (−c ± √(c² − 4 m kx)) / (2 m) = (−3 ± √5)/2 for
c = 3, m = kx = 1. The spectrum is {0, 0, (−3 + √5)/2, (−3 − √5)/2}.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import stickslip
from stickslip.orbits.linear_flow import flow_jacobian

PERIOD = 0.5  # π/ω, ω = 2π rad/s
EXPONENTS = np.array([0.0, 0.0, (-3.0 + math.sqrt(5.0)) / 2.0, (-3.0 - math.sqrt(5.0)) / 2.0])


@pytest.fixture(scope="module")
def model():
    return stickslip.load_model("impact-oscillator").replace(
        **{"contact.0.normal.restitution": 1.0, "damping.0.0": 3.0, "V": 2.0, "d": 0.0})


@pytest.fixture(scope="module")
def on_cycle(model):
    """A state mid-flight on the settled cycle (20 s after a drop from y = 0.1)."""
    run = stickslip.simulate(model, 20.0, ic={"y": 0.1}, rtol=1e-11, atol=1e-13, sample_rate=10.0)
    assert (np.abs(np.diff(run.impacts.time[-4:]) - PERIOD) < 1e-9).all()
    assert (np.abs(run.impacts.speed_before[-4:] - 2.0) > 0.3 * 2.0 * np.abs(run.impacts.speed_before[-4:])).all()
    return run.final_state


def test_floquet_exponents_of_the_saltation_monodromy_are_the_closed_form(model, on_cycle):
    fj = flow_jacobian(model, on_cycle, PERIOD, rtol=1e-11)
    assert [kind for _, kind, _ in fj.events] == ["impact"]
    exponents = np.sort(np.log(np.abs(np.linalg.eigvals(fj.matrix))) / PERIOD)[::-1]
    np.testing.assert_allclose(exponents, EXPONENTS, rtol=0, atol=1e-7)


@pytest.mark.parametrize("method", ["variational", "finite-difference"])
def test_lyapunov_spectrum_across_impacts_equals_the_floquet_exponents(model, on_cycle, method):
    """Both methods to 1e-3 (the spectrum's error falls as 1/t: 2500 s of averaging). A frame of
    the coordinate directions held the tangential plane, which the flow leaves invariant, in one
    column until round-off let it out: an exponent 0 came out as −37/t (−0.19 over 200 s)."""
    spectrum = stickslip.lyapunov_spectrum(model, ic=on_cycle, t_transient=10.0, t_average=2500.0, rtol=1e-10,
                                           method=method)
    np.testing.assert_allclose(spectrum.exponents, EXPONENTS, rtol=0, atol=1e-3)
