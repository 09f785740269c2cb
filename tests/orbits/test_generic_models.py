"""Orbits, saltation monodromy and continuation of the model-file models, against independent solutions.

* ``belt`` (1 DOF, one 1-D contact): with the Coulomb law the stick-slip cycle is closed form
  (stick: x linear in t up to k x + c V = μs N; slip: a damped oscillator about μk N / k); with the
  exponential law the slip phase is a scipy DOP853 solution of the same equation written out here.
  A 1-DOF cycle with stick has the Floquet multipliers {1, 0}.
* ``popp-stelter`` (2 DOFs, two 1-D contacts that stick in turn): the saltation monodromy against
  central differences of the event integrator's flow map.
* A model file continued over a ``--set`` path against single-orbit solves at the same values.
"""

import math
import shutil

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from stickslip.model.library import HERE, load_model
from stickslip.orbits import OrbitError, monodromy, periodic_orbit
from stickslip.orbits.continuation import continue_orbit
from stickslip.orbits.layout import free_states
from stickslip.orbits.linear_flow import flow_jacobian
from stickslip.orbits.problem import central_differences
from stickslip.orbits.section import flow

#: bSTAB's friction case, written out independently of belt.toml: m, c, k, belt speed V, N, μk, Δμ, α.
BELT = dict(m=1.0, c=0.1, k=1.0, V=1.5, N=1.0, mu_k=0.5, delta_mu=0.5, alpha=2.0)


def mu(p, speed, law):
    return p["mu_k"] + (p["delta_mu"] * math.exp(-p["alpha"] * speed) if law == "exponential" else 0.0)


def slip_phase(p, law):
    """(duration, x at its end) of the slip phase from the breakaway (x_b, V) until x' = V again, the
    mass behind the belt (friction +μ(|x' − V|) N): closed form for Coulomb, DOP853 otherwise."""
    x_b = ((p["mu_k"] + p["delta_mu"]) * p["N"] - p["c"] * p["V"]) / p["k"]
    if law == "coulomb":
        w0 = math.sqrt(p["k"] / p["m"])
        z = p["c"] / (2.0 * p["m"] * w0)
        wd = w0 * math.sqrt(1.0 - z * z)
        xk = p["mu_k"] * p["N"] / p["k"]
        A, B = x_b - xk, (p["V"] + z * w0 * (x_b - xk)) / wd

        def state(t):
            e = math.exp(-z * w0 * t)
            c, s = math.cos(wd * t), math.sin(wd * t)
            return xk + e * (A * c + B * s), e * ((wd * B - z * w0 * A) * c - (z * w0 * B + wd * A) * s)

        tau = np.linspace(1e-6, 4.0 * math.pi / wd, 40001)
        gap = np.array([state(t)[1] for t in tau]) - p["V"]
        i = int(np.flatnonzero((gap[:-1] < 0.0) & (gap[1:] >= 0.0))[0])
        t_slip = brentq(lambda t: state(t)[1] - p["V"], tau[i], tau[i + 1], xtol=1e-15, rtol=1e-15)
        return t_slip, state(t_slip)[0]

    def f(t, y):
        return [y[1], (-p["c"] * y[1] - p["k"] * y[0] + mu(p, abs(y[1] - p["V"]), law) * p["N"]) / p["m"]]

    def back_on_belt(t, y):
        return y[1] - p["V"]
    back_on_belt.terminal, back_on_belt.direction = True, 1
    # start a hair after the breakaway (the slip velocity starts at 0 with zero acceleration)
    sol = solve_ivp(f, (0.0, 50.0), [x_b, p["V"]], method="DOP853", rtol=1e-13, atol=1e-14, events=back_on_belt,
                    first_step=1e-6)
    return float(sol.t_events[0][0]), float(sol.y_events[0][0][0])


def belt_model(law):
    """The library belt; for the Coulomb law undamped (with the default damping its slip phase never
    returns to the belt speed: no stick-slip cycle)."""
    model = load_model("belt")
    return model if law == "exponential" else model.replace(**{"contact.0.friction.law": "coulomb", "damping.x.x": 0.0})


@pytest.mark.parametrize("law", ["coulomb", "exponential"])
def test_belt_cycle_period_and_multipliers(law):
    """The stick-slip cycle of the belt is unique (it starts from the breakaway state whatever came
    before): period = slip phase + (x_b − x_s)/V. Its monodromy has rank 1 and multipliers {1, 0}."""
    p = BELT if law == "exponential" else dict(BELT, c=0.0)
    t_slip, x_s = slip_phase(p, law)
    x_b = ((p["mu_k"] + p["delta_mu"]) * p["N"] - p["c"] * p["V"]) / p["k"]
    period = t_slip + (x_b - x_s) / p["V"]
    orbit = periodic_orbit(belt_model(law), {"x": 0.0, "dx": p["V"]}, search_time=60.0)
    assert orbit.stick_phases == 1 and orbit.free_states == ("x", "dx")
    assert orbit.period == pytest.approx(period, rel=1e-9)        # measured 4e-12 (Coulomb), 3e-12 (exp.)
    assert orbit.options["monodromy"] == "saltation"
    mult = np.sort(np.abs(orbit.multipliers))
    assert abs(mult[1] - 1.0) < 1e-8 and mult[0] < 1e-10           # measured 1.1e-11, 1.5e-11 and 0
    fd = monodromy(orbit, "finite-difference")
    scale = np.abs(fd.matrix).max()
    assert np.max(np.abs(fd.matrix - orbit.monodromy)) < 1e-6 * scale   # measured 2.3e-9, 1.2e-9 relative
    assert [k for _, k, _ in monodromy(orbit).events] == ["stick", "breakaway"]


def test_popp_stelter_saltation_monodromy_against_the_flow_map():
    """Two 1-D contacts sticking in turn (the x2 maximum is crossed with both slipping): the
    variational equations with one saltation matrix per transition of the contact that changed,
    against central differences of the event integrator's flow map over one period."""
    system = load_model("popp-stelter")
    orbit = periodic_orbit(system, {"x1": 0.5, "x2": -0.5}, search_time=200.0, section="x2_max")
    assert orbit.stick_phases == 2
    fj = flow_jacobian(system, orbit.state, orbit.period, scale=orbit.scale)
    assert [(k, c) for _, k, c in fj.events] == [("stick", 0), ("breakaway", 0), ("stick", 1), ("breakaway", 1)]
    free = free_states(system)
    M = fj.matrix[np.ix_(free, free)]
    Mfd = central_differences(lambda s: flow(system, s, orbit.period, rtol=1e-10, atol=1e-13)[0], orbit.state,
                              free, 1e-5 * orbit.scale)
    assert np.max(np.abs(M - Mfd)) < 1e-6 * np.max(np.abs(Mfd))    # measured 6e-9 on entries up to 1.5
    mult = np.abs(orbit.multipliers)
    assert abs(mult[0] - 1.0) < 1e-8 and mult[-1] < 1e-10 and orbit.stable


def test_model_file_continued_over_a_set_path_matches_single_orbits(tmp_path):
    """The belt as a model file on disk, its stick-slip cycle continued in the belt speed
    ``contact.0.drive``; orbits of the branch against periodic_orbit at the same speeds."""
    path = tmp_path / "belt.toml"
    shutil.copy(HERE / "belt.toml", path)
    system = load_model(path)
    start = periodic_orbit(system, {"x": 0.0, "dx": 1.5}, search_time=60.0)
    branch = continue_orbit(system, "contact.0.drive", start=start, bounds=(1.5, 1.8), step=0.02, max_step=0.05,
                            max_points=12, amplitude=False)
    assert branch.values[0] == 1.5 and branch.values.max() > 1.6
    assert branch.stop_reason.startswith("bounds") or len(branch) == 12
    assert branch.model == "belt" and branch.params is None
    for i in (len(branch) // 2, len(branch) - 1):
        V = float(branch.values[i])
        single = periodic_orbit(system.replace(**{"contact.0.drive": V}), {"x": 0.0, "dx": V}, search_time=60.0)
        assert branch.periods[i] == pytest.approx(single.period, rel=1e-8)
        assert np.abs(branch.multipliers[i]).max() == pytest.approx(1.0, abs=1e-4)   # {1, 0} (FD Jacobian)
        ds = branch.to_xarray()
        assert ds.attrs["model"] == "belt" and list(ds["state"].values) == ["x", "dx"]


def test_bad_continuation_parameter_and_section():
    from stickslip.orbits.arclength import ContinuationError

    start = periodic_orbit("belt", {"x": 0.0, "dx": 1.5}, search_time=60.0)
    with pytest.raises(ContinuationError, match="contact.0.drive"):
        continue_orbit(param="Omega", start=start, max_points=2)       # the plates' name on the belt
    with pytest.raises(ContinuationError, match="not a finite number"):
        continue_orbit(param="contact.0.friction.law", start=start, max_points=2)
    with pytest.raises(OrbitError, match="dof of x"):
        periodic_orbit("belt", {"x": 0.0, "dx": 1.5}, section="phi_max")


def test_popp_stelter_spectrum_equals_powers_of_the_fd_monodromy():
    """Lyapunov spectrum of a model file: over exactly 20 periods of the popp-stelter orbit from
    its section state, the variational spectrum equals the finite-time exponents of (M_FD)^20, M_FD
    the finite-difference monodromy (independent of the variational code); the direction that
    stick collapses is round-off on both sides and not compared."""
    from tests.orbits.test_lyapunov import finite_time_exponents

    from stickslip.orbits import lyapunov_spectrum

    orbit = periodic_orbit("popp-stelter", {"x1": 0.5, "x2": -0.5}, search_time=200.0, section="x2_max")
    n = 20
    L = lyapunov_spectrum(ic=orbit, t_transient=orbit.period, t_average=n * orbit.period, t_frame=0.0)
    assert L.model == "popp-stelter" and L.exponents.size == 4
    ref = finite_time_exponents(monodromy(orbit, "finite-difference").matrix, L.scale, n, orbit.period)
    # the collapsed direction: ln(round-off) per stick phase, and ln(1e-10)/T from the FD matrix's noise
    assert L.exponents[3] < -20.0 and ref[3] < -5.0
    assert np.max(np.abs(L.exponents[:3] - ref[:3])) < 1e-5       # measured 1.6e-9 1/s
