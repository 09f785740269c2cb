"""The orbit tools and basin stability on a model with a rigid contact (the rigid slider of
tests/contacts/rigid_slider.toml): its cycle of a plastic impact, slip, stick, slip and a flight.

Independent references: the settled cycle of a long run (its impact interval), central
differences of the flow map for the monodromy, the hand solution of steady sliding
(tests/contacts/test_rigid_steady.py) for the equilibrium a basin study finds.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import stickslip
from stickslip.basins.states import box
from stickslip.errors import BasinError
from stickslip.integrate.contacts import TRANSITION_OPEN
from stickslip.integrate.result import find_impacts
from stickslip.orbits.continuation import continue_orbit
from stickslip.orbits.linear_flow import flow_jacobian
from stickslip.orbits.problem import stick_summary

from orbits.flow_differences import flow_map_differences, plain_flow  # tests/orbits: plain runs of the flow map

RIGID_SLIDER = Path(__file__).with_name("rigid_slider.toml")


@pytest.fixture(scope="module")
def model():
    return stickslip.load_model(RIGID_SLIDER)


@pytest.fixture(scope="module")
def settled(model):
    """The impact interval of the settled cycle at V = 0.5 (a 150 s run at rtol 1e-11) [s]."""
    run = stickslip.simulate(model, 150.0, rtol=1e-11, atol=1e-13, sample_rate=10.0)
    intervals = np.diff(run.impacts.time[-6:])
    assert np.ptp(intervals) < 1e-8
    return float(intervals.mean())


@pytest.fixture(scope="module")
def orbit(model):
    """Shot from a state near the cycle (a flight, y = 0.05 above the belt), on the section of the
    highest point of the flight."""
    return stickslip.periodic_orbit(model, {"x": 1.0, "y": 0.05}, section="y_max", search_time=60.0)


def test_periodic_orbit_with_an_impact_is_the_settled_cycle(orbit, settled):
    assert orbit.residual <= 1e-9
    assert orbit.period == pytest.approx(settled, rel=1e-8)
    assert orbit.stick_phases == 1
    summary = stick_summary(orbit.trajectory(1.0, sample_rate=100.0), orbit.period)
    assert summary["open_phases"] == 1 and 0.3 < summary["open_fraction"] < 0.6
    assert orbit.state[1] > 0.0  # the section lies in the flight


def test_saltation_multipliers_across_the_impact_match_finite_differences(model, orbit):
    fd = stickslip.periodic_orbit(model, orbit.trajectory(3.0, sample_rate=200.0), section="y_max",
                                  monodromy="finite-difference")
    np.testing.assert_allclose(orbit.monodromy, fd.monodromy, rtol=0, atol=1e-6 * np.abs(fd.monodromy).max())
    # the trivial multiplier 1; the plastic impact and the stick phase collapse every other direction
    moduli = np.abs(orbit.multipliers)
    assert moduli[0] == pytest.approx(1.0, abs=1e-6) and (moduli[1:] < 1e-6).all()


def test_continuation_in_the_belt_speed_follows_the_cycle(model, orbit):
    branch = continue_orbit(model, "V", orbit, direction=-1, max_points=4, step=0.05, amplitude=False)
    assert branch.values.size == 4 and branch.values[-1] < 0.5
    assert (branch.open_phases == 1).all() and (branch.stick_phases == 1).all()
    # the last point against a periodic orbit shot at its speed from a fresh run
    last = model.replace(V=float(branch.values[-1]))
    direct = stickslip.periodic_orbit(last, {"x": 1.0, "y": 0.05}, section="y_max", search_time=60.0)
    assert branch.periods[-1] == pytest.approx(direct.period, rel=1e-8)


def test_basins_find_the_impacting_cycle_and_steady_sliding(model, orbit, tmp_path):
    states = box(model, {"x": (-4, 4), "dx": (-3, 3), "y": (0.001, 1.0), "dy": (-1, 1)}, n=12, seed=0)
    study = stickslip.basin_stability(model, states, t_end=400.0, workers=1, out=tmp_path / "b.nc",
                                      param="V", values=[0.5, 1.05])
    ds = study.dataset
    # V = 0.5: steady sliding is unstable and every state reaches the cycle with the impact
    cycle = int(np.flatnonzero(ds["fraction"].values[0] > 0)[0])
    assert ds["fraction"].values[0, cycle] == 1.0
    assert ds["period"].values[0, cycle] == pytest.approx(orbit.period, rel=1e-4)
    assert 0.3 < ds["open_fraction"].values[0, cycle] < 0.6
    # V = 1.05: steady sliding (the hand solution x_e = μ(V) P / (K11 − μ(V) K12)) attracts every state
    assert int(ds["steady_sliding_stable"].values[1]) == 1
    k11 = 1.0 + 3.0 * math.cos(math.radians(150.0)) ** 2
    k12 = 3.0 * math.cos(math.radians(150.0)) * math.sin(math.radians(150.0))
    mu = 0.3 + 0.6 * math.exp(-2.0 * 1.05)
    np.testing.assert_allclose(ds["steady_sliding"].values[1], [mu * 0.3 / (k11 - mu * k12), 0, 0, 0], atol=1e-10)
    assert ds["fraction"].values[1].max() == 1.0 and ds["attractor"].values[np.argmax(ds["fraction"].values[1])] \
        == "equilibrium"


def test_basins_refuse_states_inside_the_stop(model, tmp_path):
    states = box(model, {"x": (-1, 1), "y": (-0.5, 0.5)}, n=10, seed=0)
    with pytest.raises(BasinError, match=r"start inside a rigid contact's stop \(belt: gap < 0\)"):
        stickslip.basin_stability(model, states, t_end=100.0, workers=1, out=tmp_path / "b.nc")


def test_a_section_crossed_with_the_rigid_contact_closed_eliminates_its_normal_coordinate(model, orbit):
    """An up-crossing of x in a slip phase of the closed contact: shooting keeps y = 0, y' = 0 (the
    contact's normal coordinate is eliminated, its unknowns are x and x') and finds the cycle shot
    from the flight (period to 1e-10 relative); its monodromy on x, x' equals central differences of
    the flow map along the belt's surface (1e-6), multipliers {1, 0}: stick collapses the rest."""
    run = orbit.trajectory(3.0, sample_rate=1000.0)
    rising = ~run.open[:, 0] & ~run.stick[:, 0] & (run.states[:, 2] > 0.0)
    level = float(np.median(run.states[rising, 0]))
    closed = stickslip.periodic_orbit(model, run, section=("x", level))
    assert closed.free_states == ("x", "dx") and closed.state[1] == 0.0 and closed.state[3] == 0.0
    assert closed.period == pytest.approx(orbit.period, rel=1e-10)
    D = flow_map_differences(model, closed.state, closed.period, [0, 2], h=1e-6)
    np.testing.assert_allclose(closed.monodromy, D, rtol=0, atol=1e-6 * np.abs(D).max())
    np.testing.assert_allclose(np.sort(np.abs(closed.multipliers)), [0.0, 1.0], atol=1e-6)


def test_continuation_ends_at_the_grazing_of_the_rigid_contact(model, orbit):
    """Towards lower belt speeds the cycle's flight shortens (τ_open² linear in V) until it
    vanishes at a grazing; the branch ends there with a located ``grazing`` point, which must
    agree with a bisection on independent runs: whether the settled motion still opens the contact."""
    branch = continue_orbit(model, "V", orbit, direction=-1, max_points=60, step=0.1, max_step=1.0, amplitude=False)
    assert branch.stop_reason == "flight vanishing (grazing of a rigid contact)"
    grazing = branch.special[-1]
    assert grazing.kind == "grazing" and grazing.located and grazing.before == 1.0 and grazing.after == 0.0

    def flies(speed):
        run = stickslip.simulate(model.replace(V=speed), 300.0, rtol=1e-12, atol=1e-14, sample_rate=1.0)
        return bool(np.any((run.transitions.kind == TRANSITION_OPEN) & (run.transitions.time > 250.0)))

    lo, hi = 0.3655, 0.3665
    assert flies(hi) and not flies(lo)
    while hi - lo > 1e-7:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if flies(mid) else (mid, hi)
    assert grazing.value == pytest.approx(0.5 * (lo + hi), abs=1e-5)


@pytest.mark.parametrize(("speed", "landing"), [(0.37054988, 1.1e-3), (0.36615648, 1.2e-5), (0.36594959, 8.7e-8)])
def test_saltation_monodromy_towards_the_flight_vanishing_equals_one_sided_differences(model, speed, landing):
    """Belt speeds where the cycle's flight is short and its plastic impact lands at about ``landing``
    (relative to the velocity scale ≈ 1), down to 8.7e-8, where the impact map's central differences
    of step 1e-7 straddled the reversal of the landing speed (a multiplier −98 before).

    Reference: forward differences of plain runs of step 1e-10 (the flight at the section is 1.2e-10
    high at the slowest landing: the y column there converges like the square-root singularity,
    8e-2, 1.6e-2, 9e-4 at steps 1e-6, 1e-8, 1e-10); multipliers {1, 0, 0, 0}."""
    system = model.replace(V=speed)
    orbit = stickslip.periodic_orbit(system, {"x": 1.0, "y": 0.05}, section="y_max", search_time=60.0,
                                     monodromy="saltation")
    slowest = float(np.min(-find_impacts(system, orbit.trajectory(1.0, sample_rate=10.0).transitions).speed_before))
    assert 0.5 * landing < slowest < 1.5 * landing
    np.testing.assert_allclose(np.sort(np.abs(orbit.multipliers)), [0.0, 0.0, 0.0, 1.0], atol=1e-6)
    M = flow_jacobian(system, orbit.state, orbit.period, rtol=1e-10).matrix
    h = 1e-10
    end = plain_flow(system, orbit.state, orbit.period)
    D = np.column_stack([(plain_flow(system, orbit.state + h * np.eye(4)[j], orbit.period) - end) / h
                         for j in range(4)])
    column_tol = np.array([1e-4, 2e-3 if landing < 1e-6 else 1e-4, 1e-4, 1e-4])
    assert (np.abs(M - D).max(axis=0) < column_tol).all(), np.abs(M - D).max(axis=0)


def test_lyapunov_exponents_from_perturbed_trajectories_across_impacts(model, orbit):
    """Perturbed states stay where the rigid contact lets a motion start (on the surface of the
    closed contact, above the stop in a flight); on the impacting cycle the largest exponent is 0
    (a periodic attractor), and the finite-difference spectrum's largest equals the variational
    one's (the same averaging)."""
    largest = stickslip.lyapunov_exponent(model, ic=orbit, t_transient=10.0, t_average=100.0, chunk=1.0)
    assert abs(largest.exponent) < 1e-2
    kw = dict(ic=orbit, t_transient=10.0, t_average=60.0)
    fd = np.sort(stickslip.lyapunov_spectrum(model, method="finite-difference", **kw).exponents)[::-1]
    variational = np.sort(stickslip.lyapunov_spectrum(model, **kw).exponents)[::-1]
    assert abs(fd[0]) < 1e-2 and (fd[1:] < -10.0).all()
    assert fd[0] == pytest.approx(variational[0], abs=1e-6)


def test_variational_spectrum_on_a_closed_rigid_contact_collapses_the_directions_it_forbids(model):
    """At V = 1.05 the run lands (plastic) and settles on steady sliding with the contact closed.
    The off-surface directions (y, y') are no motion: they collapse at the start (large negative
    exponents) instead of staying frozen at 0; the other two tend to Re λ of the constrained
    eigenproblem (the hand solution: −(cx + μ'(V) λ_e)/2)."""
    fast = model.replace(V=1.05)
    exponents = np.sort(stickslip.lyapunov_spectrum(fast, ic={"x": 1.0, "y": 0.05}, t_transient=100.0,
                                                    t_average=200.0).exponents)[::-1]
    k12 = 3.0 * math.cos(math.radians(150.0)) * math.sin(math.radians(150.0))
    k11 = 1.0 + 3.0 * math.cos(math.radians(150.0)) ** 2
    mu, dmu = 0.3 + 0.6 * math.exp(-2.1), -1.2 * math.exp(-2.1)
    lam = 0.3 + k12 * mu * 0.3 / (k11 - mu * k12)
    re = -(0.05 + dmu * lam) / 2.0
    assert (exponents[2:] < -1.0).all()
    np.testing.assert_allclose(exponents[:2], re, atol=2e-3)


def test_orbit_command_with_a_rigid_contact(tmp_path):
    """The command line shoots the impacting cycle from a flight state, and refuses a section
    crossed with the contact closed in one line."""
    import json

    from typer.testing import CliRunner

    from stickslip.cli import app

    runner = CliRunner()
    common = ["orbit", "--model", str(RIGID_SLIDER), "--ic", "x=1,y=0.05", "--search-time", "60", "--no-plot"]
    result = runner.invoke(app, [*common, "--section", "y_max", "--json", "--out", str(tmp_path / "o.nc")])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output.strip().splitlines()[-1])
    assert summary["period_s"] == pytest.approx(3.1792661354, rel=1e-8) and summary["open_phases"] == 1
    refused = runner.invoke(app, [*common, "--section", "x=0.0", "--out", str(tmp_path / "p.nc")])
    lines = [line for line in refused.output.splitlines() if line.strip()]
    assert refused.exit_code == 2 and len(lines) == 1, refused.output
