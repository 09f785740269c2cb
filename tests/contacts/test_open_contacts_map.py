"""Stability maps and basin studies of models whose steady sliding leaves a contact open.

* The belt oscillator of ``clearance-oscillator`` (x'' + 0.1 x' + x = μ(|v|) N, v = x' − v_d,
  μ(|v|) = 0.5 + 0.5 exp(−2 |v|)) with a frictionless *compliant* stop of stiffness KS at x = xs
  (λ = max(0, KS (x − xs))). Steady sliding is x_e = μ(v_d) with the stop open where xs > μ(v_d),
  else x_e = (μ(v_d) + KS xs) / (1 + KS) with it pressed. Linearised by hand (μ'(|v|) = −exp(−2|v|),
  d|v|/dẋ = −1): J = [[0, 1], [−D, T]], T = −0.1 + exp(−2 v_d), D = 1 open or 1 + KS closed, so
  max Re λ = T / 2 where T² < 4 D. A map over xs and v_d crosses from the stop pressed to open.
* ``slider-belt`` with a negative preload: its one contact, the one with friction, is open at the
  equilibrium: no steady sliding (NaN in the map).
* ``clearance-oscillator`` itself (the stop rigid): pressed, the stop fixes the one dof and no
  motion is left (max Re λ −inf); open, the free oscillator's T / 2.
* ``hoffmann`` (K(μ) = [[2, 1 − μ], [1, 2]], damping c on both dofs) across N0 = 0, where its
  contact spring lifts off (its one contact with friction open: no steady sliding), and across its
  flutter onset: pressed, max Re λ is the largest real root of the characteristic polynomial
  λ⁴ + 2c λ³ + (4 + c²) λ² + 4c λ + 3 + μ, which the preload does not enter.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import stickslip
from stickslip.errors import EquilibriumError
from stickslip.model import model_from_spec
from stickslip.stability import stability
from stickslip.stability.maps import stability_map

KS = 4.0
XS = np.array([0.2, 0.4, 0.55, 0.8])
DRIVES = np.array([1.0, 1.5, 2.0])


def compliant_stop_model():
    """The belt oscillator with a frictionless compliant stop at x = xs (module docstring)."""
    return model_from_spec({
        "name": "compliant-clearance", "dofs": ["x"], "mass": [[1.0]], "damping": [[0.1]],
        "stiffness": [[1.0]], "force": [0.0], "parameters": {"xs": 1.2},
        "contact": [
            {"name": "belt", "tangent": [[1.0]], "drive": [1.5], "normal_force": 1.0,
             "friction": {"law": "exponential", "mu_k": 0.5, "delta_mu": 0.5, "alpha": 2.0}},
            {"name": "stop", "gap": "xs", "gap_gradient": [-1.0],
             "normal": {"law": "compliant", "stiffness": KS, "damping": 0.0}}]})


def by_hand(xs: float, drive: float) -> float:
    """max Re λ of the linearisation written out in the module docstring."""
    mu = 0.5 + 0.5 * math.exp(-2.0 * drive)
    trace = -0.1 + math.exp(-2.0 * drive)
    det = 1.0 if xs > mu else 1.0 + KS
    assert trace * trace < 4.0 * det
    return trace / 2.0


def check_map_against_stability(model, axes=("xs", "contact.0.drive.0"), a=XS, b=DRIVES, expected=None) -> set:
    """Every point of the map over ``axes`` equals ``stability()`` there (1e-9 relative; NaN where
    it finds no steady sliding) and ``expected(a, b)`` where given; returns the open sets met
    (None for a point without steady sliding)."""
    smap = stability_map(model, a, b, axes=axes, boundary=False)
    seen = set()
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            got = smap.max_real_part[0, i, j]
            try:
                res = stability(model.replace(**{axes[0]: float(x), axes[1]: float(y)}))
            except EquilibriumError:
                assert np.isnan(got), (x, y)
                seen.add(None)
                continue
            seen.add(res.open_contacts)
            assert got == pytest.approx(res.max_real_part, rel=1e-9, abs=0.0), (x, y)
            if expected is not None:
                assert got == pytest.approx(expected(x, y), rel=1e-9, abs=0.0), (x, y)
    return seen


def test_a_map_over_a_compliant_stop_opens_it_where_stability_does():
    seen = check_map_against_stability(compliant_stop_model(), expected=by_hand)
    assert seen == {(), ("stop",)}  # the map crosses from the stop pressed to open


def test_a_map_over_a_rigid_stop_leaves_no_motion_where_it_is_pressed():
    def expected(xs, drive):
        return by_hand(xs, drive) if xs > 0.5 + 0.5 * math.exp(-2.0 * drive) else -math.inf

    seen = check_map_against_stability(stickslip.load_model("clearance-oscillator"), expected=expected)
    assert seen == {(), ("stop",)}
    pressed = stability(stickslip.load_model("clearance-oscillator").replace(xs=0.3))
    assert pressed.verdict == "stable"
    assert pressed.summary()["max_real_part_reason"].startswith("no eigenvalues")


def test_a_map_has_no_steady_sliding_where_the_only_contact_with_friction_opens():
    """``slider-belt`` lifted off its belt (preload P < 0): its one contact is open at the
    equilibrium, so nothing slides there (``stability`` refuses), and the map has no value."""
    seen = check_map_against_stability(stickslip.load_model("slider-belt"), ("P", "V"), [-0.3, -0.1, 0.3, 0.6],
                                       [0.3, 0.5])
    assert seen == {None, ()}


def test_a_hoffmann_map_across_lift_off_and_flutter_is_stability_at_each_point():
    """The compiled grid holds the contact closed; where that leaves it unpressed (N0 ≤ 0) the map
    takes the point's open set as ``stability`` does (no steady sliding: NaN)."""
    c = 0.1
    model = stickslip.load_model("hoffmann").replace(**{"damping.x.x": c, "damping.y.y": c})

    def by_hand(n0, mu):
        return float(np.max(np.roots([1.0, 2.0 * c, 4.0 + c * c, 4.0 * c, 3.0 + mu]).real))

    seen = check_map_against_stability(model, ("N0", "contact.0.friction.mu_k"), np.array([-0.4, 0.0, 0.5, 1.5]),
                                       np.linspace(0.3, 2.5, 12), expected=by_hand)
    assert seen == {None, ()}  # lifted off and pressed; the grid crosses the flutter onset μ = 1 + 2c²:
    assert by_hand(1.0, 0.9) < 0.0 < by_hand(1.0, 1.1)


@pytest.mark.parametrize("xs, open_fraction", [(1.2, 1.0), (0.3, 0.0)])
def test_the_equilibrium_attractor_is_open_where_steady_sliding_leaves_the_stop_open(xs, open_fraction):
    """A basin study of ``clearance-oscillator`` from starts near steady sliding: its equilibrium
    keeps the stop open the whole time at xs = 1.2 (open fraction 1) and pressed at xs = 0.3 (0)."""
    from stickslip.basins import basin_stability, box

    model = stickslip.load_model("clearance-oscillator").replace(xs=xs)
    x = (0.4, 0.6) if xs > 0.6 else (0.28, 0.3)
    res = basin_stability(model, box(model, {"x": x, "dx": (0.0, 0.05)}, n=2, seed=1), t_end=400.0,
                          executor="serial")
    eq = [a for a in res.to_json()["attractors"] if a["name"] == "equilibrium"]
    assert eq and eq[0]["open_fraction"] == open_fraction
