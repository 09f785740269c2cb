"""Special points classified by what crosses the unit circle, and steady sliding that is no orbit.

Constructed problems whose multipliers are known (a real multiplier through +1 or −1, a complex
pair through |μ| = 1, a pair that collides on the real axis outside the circle, a turn without a
multiplier through +1), a branch that shrinks onto the equilibrium, and a two-mass belt model
whose continuation a user reported: its start run from rest ends on steady sliding, and from a
30 s run its branch has a collision of a complex pair outside the circle (no Neimark–Sacker point)
before a period doubling, both checked against multipliers of the saltation monodromy of orbits
shot independently at fixed drive.
"""

import math
from pathlib import Path

import numpy as np
import pytest

from stickslip import simulate
from stickslip.model.library import load_model
from stickslip.errors import SteadySlidingOrbitError
from stickslip.orbits import periodic_orbit
from stickslip.orbits import layout
from stickslip.orbits import special_points as S
from stickslip.orbits.continuation import (Branch, SteadySlidingError, circle_crossings, continue_orbit, load_branch,
                                           start_orbit_from_run, start_run)
from stickslip.orbits.models import with_parameter

from .constructed import SIGMA, SLIP, constructed_orbit, fold_multiplier, install

#: The user's model file: two masses on a belt, drives 0.2 m/s, exponential friction.
TWO_MASS = Path(__file__).with_name("two_mass_belt.toml")
DRIVE = "contact.0.drive"


# --------------------------------------------------------------------------- what crosses the circle
@pytest.mark.parametrize("before, after, crossed", [
    ([0.99, 1.0, 0.5], [1.01, 1.0, 0.5], {"+1"}),                              # a real multiplier through +1
    ([-0.99, 1.0, 0.5], [-1.01, 1.0, 0.5], {"-1"}),                            # ... through −1
    ([0.98 * np.exp(1j), 0.98 * np.exp(-1j), 1.0], [1.02 * np.exp(1j), 1.02 * np.exp(-1j), 1.0], {"pair"}),
    ([1.02 * np.exp(2j), 1.02 * np.exp(-2j), 1.0], [0.98 * np.exp(2j), 0.98 * np.exp(-2j), 1.0], {"pair"}),
    # the user's branch at drive 0.5557: the pair (|μ| 1.15) meets the negative real axis outside
    ([-1.1502 + 0.0322j, -1.1502 - 0.0322j, 1.0, 0.0], [-1.1481, -1.1417, 1.0, 0.0], set()),
    ([0.5 + 0.01j, 0.5 - 0.01j, 1.0], [0.52, 0.47, 1.0], set()),                # a collision inside
    ([0.98, 0.97, 1.0], [1.01, 0.97, 1.0], {"+1"}),
    ([-1.15 + 0.03j, -1.15 - 0.03j, 1.0], [-1.19, -0.997, 1.0], {"-1"}),       # collision, then one through −1
])
def test_circle_crossings(before, after, crossed):
    assert circle_crossings(np.array(before, complex), np.array(after, complex)) == crossed


# --------------------------------------------------------------------------- constructed multipliers
#: α where the constructed branch (v0 = √(2 − α/5) before the fold) has v0 = 1/2.
ALPHA_HALF = 5.0 * (2.0 - 0.25)


def _with_block(block):
    """1 ⊕ block(v) ⊕ (1 − v0/2): the trivial multiplier, a 2 × 2 block, the fold's multiplier."""
    def monodromy(v):
        M = np.zeros((4, 4))
        M[0, 0], M[3, 3] = 1.0, fold_multiplier(v)
        M[1:3, 1:3] = block(v)
        return M
    return monodromy


def _rotation(v):
    """r R(1 rad), r = 0.8 + 0.4 (1 − v0): the pair r e^{±i} leaves the unit circle at v0 = 1/2."""
    r = 0.8 + 0.4 * (1.0 - v[0])
    return r * np.array([[math.cos(1.0), -math.sin(1.0)], [math.sin(1.0), math.cos(1.0)]])


def _colliding(v):
    """(−1.5, 1; c, −1.5), c = 0.4 (v0 − 1/2): multipliers −1.5 ± √c, two reals (−1.95, −1.05 at the
    start) that meet at −1.5 at v0 = 1/2 and leave the real axis as a pair of modulus √(2.25 − c) >
    1.5: outside the unit circle all the time."""
    return np.array([[-1.5, 1.0], [0.4 * (v[0] - 0.5), -1.5]])


def _continue(start, **kw):
    return continue_orbit(start=start, param="alpha", step=0.05, max_step=0.2, max_points=200, bounds=(4.0, 20.0),
                          amplitude=False, **kw)


def test_torus_birth_is_a_neimark_sacker_point(constructed_with):
    """A complex pair that crosses |μ| = 1 is found, where it crosses (r = 1)."""
    b = _continue(constructed_with(_with_block(_rotation)))
    assert [p.kind for p in b.special] == ["neimark-sacker", "fold"]
    ns = b.special[0]
    # bisection to 1e-3 of a step ≤ 0.2 in arclength, λ = 5 v4 with |dv4/ds| ≤ 1: 1e-3 in alpha
    assert ns.located and ns.bracket <= 1e-3 and ns.value == pytest.approx(ALPHA_HALF, abs=1e-3)
    pair_before = ns.multipliers_before[np.abs(ns.multipliers_before.imag) > 0.1]
    pair_after = ns.multipliers_after[np.abs(ns.multipliers_after.imag) > 0.1]
    assert pair_before.size == pair_after.size == 2
    assert np.all(np.abs(pair_before) < 1.0) and np.all(np.abs(pair_after) > 1.0)
    assert np.all(b.n_unstable[: ns.index + 1] == 0) and b.n_unstable[ns.index + 1] == 2


def test_collision_on_the_real_axis_outside_the_circle_is_no_bifurcation(constructed_with):
    """Two real multipliers outside the unit circle meet on the negative real axis and leave it as a
    complex pair: the number of complex multipliers outside the circle changes (0 → 2), but nothing
    crosses |μ| = 1: no Neimark–Sacker point, no period doubling; the fold is still found."""
    b = _continue(constructed_with(_with_block(_colliding)))
    outside = np.sum((np.abs(b.multipliers.imag) > 1e-9) & (np.abs(b.multipliers) > 1.0), axis=1)
    assert outside[0] == 0 and outside.max() == 2  # the collision happened on this branch
    assert [p.kind for p in b.special] == ["fold"] and b.special[0].value == pytest.approx(10.0, abs=1e-6)
    assert np.all(b.n_unstable[: b.special[0].index + 1] == 2)  # the pair stays outside until the fold


def test_turn_without_a_multiplier_through_plus_one_is_no_fold(constructed_with):
    """The branch turns at alpha = 10, but no multiplier crosses +1 there (diag(1, m, 0.5, 0.2)): it
    is no fold of cycles and not reported; the period doubling is."""
    b = _continue(constructed_with(lambda v: np.diag([1.0, -0.5 - 0.75 * (1.0 - v[0]), 0.5, 0.2])))
    assert 9.5 < np.max(b.values) <= 10.0 + 1e-9 and b.values[-1] < 5.0  # it turned at alpha = 10
    assert [p.kind for p in b.special] == ["period-doubling"]


def test_slip_branch_that_shrinks_onto_the_equilibrium_ends_there(monkeypatch, tmp_path):
    """A pure-slip constructed branch whose 'equilibrium' is phi = 0 (its size |v0| falls to 0 at the
    fold): with the size threshold raised to 0.1 (the mechanism, at the constructed problem's scale),
    the first point closer than that is steady sliding: it is dropped, the branch ends there with
    that stop reason and no special point after its last orbit (the period doubling at v0 = 1/3 is
    kept); written and resumed, the file holds the same branch."""
    install(monkeypatch, transitions=SLIP)
    monkeypatch.setattr(layout, "ORBIT_MIN_SIZE", 0.1)

    def equilibrium(system):
        s = np.zeros(12)
        # psi as on the branch (v1 = 0.1 v4), phi = 0: |s − s_eq| / σ = |v0|
        s[5] = SIGMA[1] * 0.1 * system.parameters["alpha"] / 5.0
        return s

    monkeypatch.setattr(layout, "equilibrium_state", equilibrium)
    opts = dict(start=constructed_orbit(stick_phases=0), param="alpha", step=0.05, max_step=0.2, max_points=200,
                bounds=(4.0, 20.0), amplitude=False)
    b = continue_orbit(**opts)
    v0 = b.states[:, 4] / SIGMA[0]
    assert np.all(v0 >= 0.1) and v0[-1] < 0.4  # every point an orbit; it stopped within a step of the edge
    assert b.stop_reason.startswith("steady sliding at alpha = ")
    lam_end = float(b.stop_reason.rsplit("= ", 1)[1])  # the dropped point: v0 = √(2 − alpha/5) < 0.1 there
    assert b.values[-1] < lam_end <= 10.0 and math.sqrt(max(2.0 - lam_end / 5.0, 0.0)) < 0.1 + 1e-5
    assert [p.kind for p in b.special] == ["period-doubling"] and b.special[0].index < len(b) - 1
    out = tmp_path / "b.nc"

    class Stop(Exception):
        pass

    def stop_at(i, *_):
        if i == len(b) - 2:
            raise Stop

    with pytest.raises(Stop):
        continue_orbit(out=out, callback=stop_at, **opts)
    resumed = continue_orbit(out=out, **opts)
    for r in (resumed, Branch.from_xarray(load_branch(out))):
        assert np.array_equal(r.values, b.values) and np.array_equal(r.states, b.states)
        assert r.stop_reason == b.stop_reason and [p.value for p in r.special] == [p.value for p in b.special]


# --------------------------------------------------------------------------- the user's two-mass belt
def test_start_on_steady_sliding_is_refused_as_such(tmp_path):
    """From rest the 60 s run's crossings shoot onto steady sliding (amplitude 0, any period): the
    continuation refuses it as steady sliding at drive 0.2, and writes nothing."""
    belt = load_model(TWO_MASS)
    run = start_run(belt, "zero", t_end=60.0)
    with pytest.raises(SteadySlidingOrbitError, match="shooting converged onto steady sliding"):
        start_orbit_from_run(run)
    orbit = start_orbit_from_run(run, steady_sliding="keep")
    # independent of the shooting: a run from its state barely moves (a cycle's x1 spans ~0.05 m); it
    # is the unstable equilibrium (multipliers ~3.3 a period), so its 1e-12 m offset grows to ~3e-8 m in 5 s
    traj = simulate(belt, 5.0, ic=orbit.state, sample_rate=200.0)
    assert orbit.stick_phases == 0 and np.ptp(traj.states[:, :2], axis=0).max() < 1e-6
    out = tmp_path / "b.nc"
    with pytest.raises(SteadySlidingError, match=r"converged to steady sliding at contact\.0\.drive = 0\.2:"):
        continue_orbit(belt, DRIVE, start=run, max_points=30, bounds=(0.2, 1.2), out=out)
    assert not out.exists() and not Path(str(out) + ".journal").exists()


def _saltation_multipliers(belt, branch, drive):
    """Floquet multipliers at ``drive`` from the saltation monodromy of the orbit shot there from the
    nearest branch state (a 2 s search run: the orbit is unstable, a longer one would leave it)."""
    i = int(np.argmin(np.abs(branch.values - drive)))
    orbit = periodic_orbit(with_parameter(belt, DRIVE, drive), branch.states[i], search_time=2.0)
    assert orbit.options["monodromy"] == "saltation" and orbit.period == pytest.approx(branch.periods[i], rel=1e-2)
    mu = orbit.nontrivial_multipliers
    return mu[np.abs(mu) > 1e-3]  # the stick phase's multiplier 0 left out


def test_two_mass_belt_collision_is_no_neimark_sacker_and_the_period_doubling_is_found():
    """`continue --search-time 30`: the complex pair (|μ| ≈ 1.15) meets the negative real axis near
    drive 0.5557 and splits into two real multipliers outside the circle (saltation multipliers at
    0.5457 and 0.5657): no Neimark–Sacker point; one of them crosses −1 between 0.5858 and 0.5958
    (saltation), where the period doubling is found."""
    belt = load_model(TWO_MASS)
    b = continue_orbit(belt, DRIVE, start=start_run(belt, "zero", t_end=30.0), max_points=30, bounds=(0.2, 1.2))
    assert "neimark-sacker" not in [p.kind for p in b.special]
    pair, reals = _saltation_multipliers(belt, b, 0.5457), _saltation_multipliers(belt, b, 0.5657)
    assert np.all(np.abs(pair.imag) > 0) and np.all(np.abs(pair) > 1.0)
    assert np.all(reals.imag == 0) and np.all(reals.real < -1.0)
    assert np.all(b.n_unstable[b.values < 0.58] == 2)
    pd = [p for p in b.special if p.kind == "period-doubling"][0]
    lo, hi = _saltation_multipliers(belt, b, 0.5858), _saltation_multipliers(belt, b, 0.5958)
    assert np.sum(lo.real < -1.0) == 2 and np.sum(hi.real < -1.0) == 1 and np.all(hi.imag == 0)
    assert pd.located and 0.5858 < pd.value < 0.5958
    # the multipliers on either side: the pair before (the collision lies in the same step), −1 passed after
    assert np.sum(np.abs(pd.multipliers_before.imag) > 0) == 2
    after = pd.multipliers_after[np.abs(pd.multipliers_after) > 1e-3].real
    assert np.sum(after < -1.0) == 1 and np.sum((after > -1.0) & (after < -0.9)) == 1


def test_model1_slip_cycle_torus_birth_is_found_where_a_complex_pair_leaves_the_circle():
    """Model 1, N = 50 N: the unstable pure-slip cycle between the basins (edge tracking at
    Ω ≈ 10 rad/s), continued up in Ω, has a complex pair (arg ≈ 66°) that leaves the unit circle
    near 13.45 rad/s: a Neimark–Sacker point, found there; the saltation multipliers (variational
    equations) of the cycles shot at 13.40 and 13.50 rad/s have the pair inside, then outside."""
    from stickslip import Parameters
    from stickslip.orbits.continuation import unstable_cycle

    p = Parameters(N=50.0, Omega=8.0)
    b = continue_orbit(start=periodic_orbit(p, start_run(p, "far", t_end=60.0)), param="Omega", step=0.05,
                       max_step=1.0, max_points=400, bounds=(8.0, 30.0), amplitude=False)
    i = int(np.argmin(np.abs(b.values - 10.0)))
    up = continue_orbit(start=unstable_cycle(b.orbit_params(i), b.states[i]), param="Omega", step=0.05,
                        max_step=1.0, max_points=60, bounds=(b.values[i], 13.6), amplitude=False)
    assert [q.kind for q in up.special] == ["neimark-sacker"]
    ns = up.special[0]

    def pair(mu):
        return mu[(mu.imag > 0.5)][0]  # the pair near e^{±1.15i}

    assert abs(pair(ns.multipliers_before)) < 1.0 < abs(pair(ns.multipliers_after))
    radius = {}
    for omega in (13.40, 13.50):
        j = int(np.argmin(np.abs(up.values - omega)))
        cycle = periodic_orbit(Parameters(N=50.0, Omega=omega), up.states[j], search_time=1.0)
        assert cycle.stick_phases == 0 and cycle.options["monodromy"] == "saltation"
        radius[omega] = abs(pair(cycle.multipliers))
    assert radius[13.40] < 1.0 < radius[13.50] and 13.40 < ns.value < 13.50
