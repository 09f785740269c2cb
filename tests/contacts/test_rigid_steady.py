"""Steady sliding with a closed rigid contact, and the constrained eigenproblem, against the hand
solution of the rigid slider (tests/contacts/rigid_slider.toml).

With the contact closed, y ≡ 0 and the normal force is what the y equation needs,
λ = P + K12 x (K12 = k3 cos θ sin θ); the slider slides against the belt (v = −V), F = μ(V − ẋ) λ:

    x_e = μ(V) P / (K11 − μ(V) K12),      ẍ = −(K11 − μ K12) x − (cx + μ'(V) λ_e) ẋ   (linearised),

μ(s) = μk + Δμ e^(−α s), μ' = −α Δμ e^(−α s): two eigenvalues, of the motion that keeps y = 0.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import stickslip
from stickslip.errors import EquilibriumError
from stickslip.stability.analysis import model_stability

RIGID_SLIDER = Path(__file__).with_name("rigid_slider.toml")
KX, K3, THETA, CX, MU_K, DELTA_MU, ALPHA = 1.0, 3.0, math.radians(150.0), 0.05, 0.3, 0.6, 2.0
K11 = KX + K3 * math.cos(THETA) ** 2
K12 = K3 * math.cos(THETA) * math.sin(THETA)


def hand(P, V):
    mu = MU_K + DELTA_MU * math.exp(-ALPHA * V)
    dmu = -ALPHA * DELTA_MU * math.exp(-ALPHA * V)
    x = mu * P / (K11 - mu * K12)
    lam = P + K12 * x
    A = np.array([[0.0, 1.0], [-(K11 - mu * K12), -(CX + dmu * lam)]])
    eig = np.linalg.eigvals(A)
    return x, lam, eig[np.lexsort((-eig.imag, -eig.real))]


@pytest.mark.parametrize(("P", "V"), [(0.3, 0.5), (0.3, 2.0), (1.0, 0.2)])
def test_steady_sliding_and_constrained_eigenvalues_match_the_hand_solution(P, V):
    model = stickslip.load_model(RIGID_SLIDER).replace(P=P, V=V)
    result = model_stability(model)
    x, lam, eig = hand(P, V)
    np.testing.assert_allclose(result.equilibrium, [x, 0.0], atol=1e-12)
    assert result.eigenvalues.size == 2  # y and ẏ are held by the closed contact
    np.testing.assert_allclose(result.eigenvalues, eig, atol=1e-9)
    s = np.zeros(4)
    s[0] = x
    tr = stickslip.simulate(model, 0.01, ic=s, sample_rate=1000.0)
    np.testing.assert_allclose(tr.normal_force[0, 0], lam, rtol=1e-10)


def test_a_rigid_contact_that_nothing_presses_is_no_steady_sliding():
    model = stickslip.load_model(RIGID_SLIDER).replace(P=-0.3)
    with pytest.raises(EquilibriumError, match="would be open"):
        model_stability(model)


def test_stability_map_of_the_constrained_eigenproblem_matches_the_hand_solution():
    """The map over (P, V) and its boundary in V: the linearised x equation loses its damping where
    cx + μ'(V) λ_e(P, V) = 0 (the hand solution's root, by brentq on the closed form)."""
    from scipy import optimize

    P = np.array([0.2, 0.3, 0.5])
    V = np.linspace(0.3, 2.0, 8)
    smap = stickslip.stability_map(stickslip.load_model(RIGID_SLIDER), N=P, Omega=V, axes=("P", "V"))
    expected = np.array([[hand(p, v)[2].real.max() for v in V] for p in P])
    np.testing.assert_allclose(smap.max_real_part[0], expected, atol=1e-9)
    for i, p in enumerate(P):
        root = optimize.brentq(lambda v: hand(p, v)[2].real.max(), V[0], V[-1], xtol=1e-13)
        found = smap.boundary[0, i][np.isfinite(smap.boundary[0, i])]
        np.testing.assert_allclose(found, [root], atol=1e-8)
        assert smap.boundary_direction[0, i, 0] == -1  # stable above the boundary: μ' → 0 as V grows


def painleve(mu, kx=1.0, tangent=(1.0, 1.0)):
    """W = [0, 1] and G = [1, 1] (M = I), sliding forward (e = +1): the normal force's equation has
    the pivot D = W·(W − μ G e) = 1 − μ, which is ≤ 0 for μ ≥ 1 (Painlevé)."""
    from stickslip.model.model_file import model_from_spec

    return model_from_spec({
        "name": "painleve", "dofs": ["x", "y"], "mass": [[1.0, 0.0], [0.0, 1.0]],
        "damping": [[0.0, 0.0], [0.0, 0.0]], "stiffness": [[kx, 0.0], [0.0, 1.0]], "force": [0.0, -1.0],
        "contact": [{"tangent": [list(tangent)], "drive": [-1.0], "gap": 0.0, "gap_gradient": [0.0, 1.0],
                     "normal": {"law": "rigid", "restitution": 0.0},
                     "friction": {"law": "coulomb", "mu_k": mu, "delta_mu": 0.0}}]})


@pytest.mark.parametrize("mu", [1.0, 1.5])
@pytest.mark.parametrize("kx", [0.0, 1.0])
def test_a_painleve_contact_is_named_as_the_paradox_not_a_fold(mu, kx):
    with pytest.raises(EquilibriumError) as caught:
        model_stability(painleve(mu, kx))
    text = str(caught.value)
    assert "Painlevé paradox" in text and "no consistent value, or two" in text
    assert "fold" not in text and "Newton" not in text and "\n" not in text
    assert "≤ 0" in text


def test_a_rigid_slider_without_stiffness_along_the_contact_is_not_a_fold():
    """D = 1 − 0.5 > 0 (no Painlevé), but x has no spring: nothing balances the friction along x."""
    with pytest.raises(EquilibriumError) as caught:
        model_stability(painleve(0.5, kx=0.0))
    text = str(caught.value)
    assert "no position with the rigid contacts closed balances the forces" in text
    assert "fold" not in text and "Newton" not in text and "Painlevé" not in text

