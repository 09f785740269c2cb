"""Largest Lyapunov exponent (Benettin) of a periodic orbit → 0."""

import numpy as np
import pytest

from stickslip import Parameters
from stickslip.orbits import LyapunovResult, OrbitError, lyapunov_exponent, periodic_orbit
from stickslip.plot.orbits import plot_lyapunov_convergence


@pytest.fixture(scope="module")
def orbit():
    return periodic_orbit(Parameters(N=50.0, Omega=0.5), "equilibrium", model="full", search_time=30.0)


def test_periodic_orbit_exponent_vanishes(orbit):
    L = lyapunov_exponent(ic=orbit, t_transient=1.0, t_average=100.0, chunk=1.0)
    assert isinstance(L, LyapunovResult) and L.time.size == 100
    # on a periodic orbit the separation ends along the flow: the summed log growth stays
    # bounded (measured |Σ| < 2), so λ ~ 1/t; 0.02 1/s is 1.3 % of the orbit's 1.54 Hz
    assert abs(L.exponent) < 0.02
    assert np.max(np.abs(np.cumsum(L.log_growth))) < 5.0
    ds = L.to_xarray()
    assert ds["estimate"].attrs["units"] == "1/s" and ds.attrs["exponent"] == L.exponent
    fig = plot_lyapunov_convergence(L)
    assert len(fig.axes[0].lines) == 2   # the curve and the zero line


def test_bad_options():
    with pytest.raises(OrbitError, match="t_transient"):
        lyapunov_exponent(Parameters(), t_transient=0.0)
    with pytest.raises(OrbitError, match="chunk"):
        lyapunov_exponent(Parameters(), t_transient=1.0, t_average=0.1, chunk=1.0)


def test_belt_orbit_exponent_vanishes():
    """1-DOF belt oscillator (stick collapses every other direction): λ → 0 like 1/t.
    (Once slow, ~65 s: chunks starting just before stick cost 10⁵+ steps before a fix of the
    event integrator's initial mode; now ~1 s.)"""
    P = Parameters(Omega=0.5)
    ic = np.zeros(12)
    ic[10] = 0.5
    o = periodic_orbit(P, ic, model="phi", search_time=10.0)
    L = lyapunov_exponent(ic=o, t_transient=1.0, t_average=100.0, chunk=1.0)
    assert abs(L.exponent) < 0.01           # measured −0.0029 1/s
    assert np.max(np.abs(np.cumsum(L.log_growth))) < 1.0   # measured 0.35


# ---------------------------------------------------------------------------------------------
# Full spectrum (variational equations + saltation matrices + QR)
# ---------------------------------------------------------------------------------------------

from stickslip.orbits import LyapunovSpectrum, lyapunov_spectrum  # noqa: E402
from stickslip.plot.orbits import plot_lyapunov_spectrum  # noqa: E402


def test_belt_spectrum_periodic_orbit():
    """Belt oscillator on its stick-slip orbit: exponents {0, −∞} (the flow direction, and the
    direction that stick collapses; −∞ comes out as ln(round-off) per period, ≪ −100 1/s)."""
    P = Parameters(Omega=0.5)
    ic = np.zeros(12)
    ic[10] = 0.5
    o = periodic_orbit(P, ic, model="phi", search_time=10.0)
    L = lyapunov_spectrum(ic=o, t_transient=1.0, t_average=50.0)
    assert isinstance(L, LyapunovSpectrum) and L.exponents.size == 2
    assert abs(L.largest) < 0.01                # measured 2.8e-3 after 50 s (~1/t)
    assert L.exponents[1] < -100.0              # measured −1384 1/s
    assert L.stick_phases == pytest.approx(50.0 / o.period, abs=1)
    ds = L.to_xarray()
    assert ds["exponent"].attrs["units"] == "1/s" and ds["estimate"].shape == (L.time.size, 2)
    fig = plot_lyapunov_spectrum(L)
    assert len(fig.axes[0].lines) == 2          # λ1 and the zero line (λ2 < −10 is left out)


@pytest.mark.slow
def test_model1_spectrum_equals_floquet_exponents(orbit):
    """Model 1, N = 50 N, Ω = 0.5 rad/s: the spectrum of a periodic orbit is ln|μ_i|/T, μ_i
    the Floquet multipliers (here from the finite-difference monodromy, independent of the
    variational code). 400 s (~40 s of computation): the estimates converge like 1/t."""
    from stickslip.orbits.variational import monodromy

    ref = np.sort(np.log(np.abs(monodromy(orbit, "finite-difference").multipliers[:10])) / orbit.period)[::-1]
    L = lyapunov_spectrum(ic=orbit, t_transient=1.0, t_average=400.0)
    lam = np.sort(L.exponents)[::-1]
    assert abs(lam[0]) < 0.005
    assert np.all(lam[1:] < 0.0)
    assert np.max(np.abs(lam[:10] - ref)) < 0.01
    assert np.all(lam[10:] < -20.0)             # the two directions stick collapses
