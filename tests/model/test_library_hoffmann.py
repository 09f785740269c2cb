"""The ``hoffmann`` library model: stability of steady sliding against the analytic linearisation.

Written out by hand here, independently of the package: with M = I, C = diag(c1, c2), friction
μ N along x and N = N0 + k3 y, steady sliding (v = −V < 0, friction +μ N) satisfies

    K(μ) q = (μ N0, 0),   K(μ) = [[k11, k12 − μ k3], [k21, k22]],

and small motions about it obey M q'' + C q' + K(μ) q = 0, whose characteristic polynomial is

    det(λ² M + λ C + K) = λ⁴ + (c1 + c2) λ³ + (k11 + k22 + c1 c2) λ² + (c1 k22 + c2 k11) λ
                          + k11 k22 − (k12 − μ k3) k21.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq, linear_sum_assignment

from stickslip.model.library import load_model
from stickslip.stability.analysis import stability

K11, K12, K21, K22, K3, N0 = 2.0, 1.0, 1.0, 2.0, 1.0, 1.0


def model(mu, c1=0.0, c2=0.0):
    return load_model("hoffmann").replace(**{"contact.0.friction.mu_k": mu, "damping.x.x": c1, "damping.y.y": c2})


def stiffness(mu):
    return np.array([[K11, K12 - mu * K3], [K21, K22]])


def analytic_eigenvalues(mu, c1=0.0, c2=0.0):
    """Eigenvalues of the first-order form of M q'' + C q' + K(μ) q = 0 (M = I)."""
    A = np.zeros((4, 4))
    A[:2, 2:] = np.eye(2)
    A[2:, :2] = -stiffness(mu)
    A[2:, 2:] = -np.diag([c1, c2])
    return np.linalg.eigvals(A)


def characteristic(mu, c1=0.0, c2=0.0):
    """Coefficients (a4 .. a0) of det(λ² M + λ C + K(μ))."""
    return np.array([1.0, c1 + c2, K11 + K22 + c1 * c2, c1 * K22 + c2 * K11, K11 * K22 - (K12 - mu * K3) * K21])


def hurwitz(mu, c1, c2):
    """a3 a2 a1 − a1² − a3² a0 of the quartic: > 0 (with every a > 0) iff all roots are stable."""
    _, a3, a2, a1, a0 = characteristic(mu, c1, c2)
    return a3 * a2 * a1 - a1 * a1 - a3 * a3 * a0


def matched_distance(a, b):
    """Largest |a_i − b_j| over the best one-to-one pairing of two eigenvalue sets."""
    cost = np.abs(a[:, None] - b[None, :])
    rows, cols = linear_sum_assignment(cost)
    return float(cost[rows, cols].max())


def onset(max_real_part, lo, hi, threshold=0.0, tol=1e-12):
    """Smallest μ in [lo, hi] with max Re λ > ``threshold``, by bisection (the flutter onset)."""
    assert max_real_part(lo) <= threshold < max_real_part(hi)
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if max_real_part(mid) <= threshold else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("c1, c2", [(0.0, 0.0), (0.1, 0.1), (0.2, 0.02)])
def test_eigenvalues_over_mu_are_the_analytic_ones(c1, c2):
    for mu in np.linspace(0.025, 1.975, 40):  # the onset itself (a Jordan block) is left out
        res = stability(model(mu, c1, c2))
        lam = analytic_eigenvalues(mu, c1, c2)
        assert matched_distance(res.eigenvalues, lam) < 1e-12
        # the same spectrum from the characteristic polynomial (np.roots: ~1e-10 near double roots)
        assert matched_distance(np.roots(characteristic(mu, c1, c2)), lam) < 1e-9
        # the equilibrium of steady sliding: K(μ) q = (μ N0, 0)
        np.testing.assert_allclose(res.equilibrium, np.linalg.solve(stiffness(mu), [mu * N0, 0.0]), atol=1e-13)


def test_undamped_frequencies_merge_at_the_flutter_onset():
    # s = λ² solves s² + (k11 + k22) s + det K(μ) = 0: real (two frequencies) while its
    # discriminant (k11 − k22)² + 4 (k12 − μ k3) k21 is ≥ 0, complex (flutter) beyond
    mu_c = (K12 + (K11 - K22) ** 2 / (4.0 * K21)) / K3
    assert mu_c == 1.0
    for mu in (0.0, 0.5, 0.9, 0.99):
        res = stability(model(mu))
        omega = np.sort(np.unique(np.round(np.abs(res.eigenvalues.imag), 12)))
        np.testing.assert_allclose(omega, np.sqrt([2.0 - math.sqrt(1 - mu), 2.0 + math.sqrt(1 - mu)]), rtol=1e-12)
        assert res.max_real_part < 1e-12
    above = stability(model(1.5))
    # beyond the onset: one frequency sqrt|s|, growth rate Re sqrt(s) > 0
    s = complex(-2.0, math.sqrt(0.5))
    assert above.max_real_part == pytest.approx(abs(np.sqrt(s).real), rel=1e-12)
    assert not above.stable
    # undamped, Re λ grows like √2 (μ − μc)^½ / 4: 1e-6 (far above round-off) is passed 1e-11 after μc
    found = onset(lambda mu: stability(model(mu)).max_real_part, 0.5, 1.5, threshold=1e-6)
    assert found == pytest.approx(mu_c, abs=1e-9)


@pytest.mark.parametrize("c1, c2", [(0.1, 0.1), (0.2, 0.02)])
def test_damped_onset_is_the_root_of_the_hurwitz_condition(c1, c2):
    mu_c = brentq(lambda mu: hurwitz(mu, c1, c2), 0.0, 3.0, xtol=1e-14)
    if c1 == c2:  # equal damping: a3 a2 a1 − a1² − a3² a0 = c² (8 c² + 4 − 4 μ)
        assert mu_c == pytest.approx(1.0 + 2.0 * c1 * c1, abs=1e-12)
    found = onset(lambda mu: stability(model(mu, c1, c2)).max_real_part, 0.5, 2.0)
    assert found == pytest.approx(mu_c, abs=1e-8)
