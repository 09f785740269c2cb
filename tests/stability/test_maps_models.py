"""Stability and stability maps of models other than the plates, against closed forms written here.

hoffmann: M = I, C = diag(c1, c2), friction μ N along x with N = N0 + k3 y. Steady sliding has
K(μ) q = (μ N0, 0) with K(μ) = [[k11, k12 − μ k3], [k21, k22]], and small motions obey
q'' + C q' + K(μ) q = 0 (tests/model/test_library_hoffmann.py derives it).

belt: x'' + 2ξ x' + x = F, v = x' − V, F = −μ(|v|) N sign(v), μ(s) = μk + Δμ e^(−α s). Steady
sliding has v = −V < 0, so F = μ(V) N and x_e = μ(V) N. For a small δx about it, v = −V + δx' and
F = μ(V − δx') N ≈ μ(V) N − μ'(V) N δx', so

    δx'' + (2ξ + μ'(V) N) δx' + δx = 0,   μ'(V) = −α Δμ e^(−α V),

whose eigenvalues are the roots of λ² + a λ + 1 with a = 2ξ − α Δμ N e^(−α V): stable iff a > 0,
i.e. above the belt speed V_c = ln(α Δμ N / 2ξ) / α.
"""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from stickslip.model.library import load_model
from stickslip.stability import stability, stability_map
from stickslip.stability import steady
from stickslip.stability.maps import MapGrid

K11, K12, K21, K22, K3, N0 = 2.0, 1.0, 1.0, 2.0, 1.0, 1.0
XI2, DMU, ALPHA = 0.1, 0.5, 2.0  # the belt file's 2ξ, Δμ, α


def hoffmann_max_real_part(mu, c1, c2):
    A = np.zeros((4, 4))
    A[:2, 2:] = np.eye(2)
    A[2:, :2] = -np.array([[K11, K12 - mu * K3], [K21, K22]])
    A[2:, 2:] = -np.diag([c1, c2])
    return float(np.max(np.linalg.eigvals(A).real))


def hoffmann_onset(c1, c2):
    """μ where the Hurwitz determinant a3 a2 a1 − a1² − a3² a0 of the quartic vanishes."""
    def hurwitz(mu):
        a3, a2, a1 = c1 + c2, K11 + K22 + c1 * c2, c1 * K22 + c2 * K11
        a0 = K11 * K22 - (K12 - mu * K3) * K21
        return a3 * a2 * a1 - a1 * a1 - a3 * a3 * a0
    return brentq(hurwitz, 0.0, 10.0, xtol=1e-15)


def belt_eigenvalues(V, N):
    a = XI2 - ALPHA * DMU * N * math.exp(-ALPHA * V)
    return np.roots([1.0, a, 1.0])


def test_hoffmann_map_is_the_analytic_spectrum_and_onset():
    base = load_model("hoffmann").replace(**{"damping.y.y": 0.1})
    c1 = np.linspace(0.05, 0.3, 6)
    mu = np.linspace(0.3, 2.5, 23)
    m = stability_map(base, c1, mu, axes=("damping.x.x", "contact.0.friction.mu_k"))
    assert m.max_real_part.shape == (1, 6, 23) and m.axes == ("damping.x.x", "contact.0.friction.mu_k")
    ref = np.array([[hoffmann_max_real_part(u, c, 0.1) for u in mu] for c in c1])
    # the same 4 × 4 spectrum by two LAPACK calls; a grid point near a double root (the onset)
    # could lose up to sqrt(eps) ~ 1e-8, none of these does
    assert np.max(np.abs(m.max_real_part[0] - ref)) < 1e-12
    for a, c in enumerate(c1):
        roots = m.boundary[0, a][np.isfinite(m.boundary[0, a])]
        assert roots.size == 1 and m.boundary_direction[0, a, 0] == 1  # unstable above the onset
        # brentq to 1e-10 on max Re λ, which leaves the axis like sqrt(μ − μc) at the onset
        assert roots[0] == pytest.approx(hoffmann_onset(c, 0.1), abs=1e-9)


def test_belt_map_boundary_is_the_closed_form():
    N = np.linspace(0.5, 2.0, 7)
    V = np.linspace(0.2, 3.0, 15)
    m = stability_map("belt", N, V, axes=("contact.0.normal_force", "contact.0.drive"))
    for a, n in enumerate(N):
        ref = [float(np.max(belt_eigenvalues(v, n).real)) for v in V]
        np.testing.assert_allclose(m.max_real_part[0, a], ref, rtol=1e-12, atol=1e-14)
        expected = math.log(ALPHA * DMU * n / XI2) / ALPHA
        assert m.boundary[0, a, 0] == pytest.approx(expected, abs=1e-9)
        assert m.boundary_direction[0, a, 0] == -1  # stable above V_c


@pytest.mark.parametrize("V, N", [(0.5, 1.0), (1.5, 1.0), (2.5, 0.7), (1.0, 2.0)])
def test_belt_stability_is_the_closed_form(V, N):
    res = stability(load_model("belt").replace(**{"contact.0.drive": V, "contact.0.normal_force": N}))
    mu = 0.5 + DMU * math.exp(-ALPHA * V)
    assert res.equilibrium[0] == pytest.approx(mu * N, rel=1e-14)
    lam = belt_eigenvalues(V, N)
    np.testing.assert_allclose(np.sort_complex(res.eigenvalues), np.sort_complex(lam), rtol=1e-13, atol=1e-15)
    assert res.stable == (XI2 - ALPHA * DMU * N * math.exp(-ALPHA * V) > 0)


def test_parameters_that_share_numbers_are_built_point_by_point():
    # with a coupled mass matrix, M⁻¹ depends on both masses at once: not separable, not affine
    base = load_model("hoffmann").replace(**{"mass.0.1": 0.2, "mass.1.0": 0.2, "damping.x.x": 0.2,
                                             "damping.y.y": 0.2, "contact.0.friction.mu_k": 0.9})
    a, b = np.array([0.8, 1.0, 1.3]), np.array([0.9, 1.2])
    grid = MapGrid.build(base, ("mass.0.0", "mass.1.1"), a, b)
    assert not grid.separable
    m = stability_map(base, a, b, axes=("mass.0.0", "mass.1.1"), boundary=False)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            ref = stability(base.replace(**{"mass.0.0": x, "mass.1.1": y})).max_real_part
            assert m.max_real_part[0, i, j] == pytest.approx(ref, rel=1e-12, abs=1e-14)


def test_plates_axes_are_separable_and_exact():
    from stickslip.model.library import two_plates

    grid = MapGrid.build(two_plates(), ("N", "Omega"), np.array([10.0, 50.0, 90.0]), np.array([0.5, 5.0]))
    assert grid.separable and grid.axis_a.fast and grid.axis_b.fast
    J, found = grid.jacobians(np.array([1]), np.array([1]))
    assert found[0] == steady.STEADY_PRESSED
    ref = stability(two_plates().replace(N=50.0, Omega=5.0)).jacobian
    np.testing.assert_array_equal(J[0], ref)


def test_map_family_and_netcdf_of_a_model_file(tmp_path):
    from stickslip.stability import load_stability_map

    m = stability_map("belt", [0.5, 1.0], [0.5, 1.5, 2.5], axes=("contact.0.normal_force", "contact.0.drive"),
                      family=("contact.0.friction.alpha", [1.5, 2.0]))
    assert m.family_values == [1.5, 2.0] and m.params is None
    back = load_stability_map(m.to_netcdf(tmp_path / "belt.nc"))
    np.testing.assert_array_equal(back.max_real_part, m.max_real_part)
    assert back.axes == m.axes and back.system.name == "belt"


def test_map_bad_axes():
    with pytest.raises(Exception, match="no key 'nonsense'"):
        stability_map("belt", [1.0, 2.0], [1.0, 2.0], axes=("contact.0.nonsense", "contact.0.drive"))
    with pytest.raises(ValueError, match="different parameters"):
        stability_map("belt", [1.0, 2.0], [1.0, 2.0], axes=("contact.0.drive", "contact.0.drive"))
    with pytest.raises(ValueError, match="family of models"):
        stability_map("belt", [1.0, 2.0], [1.0, 2.0], axes=("contact.0.normal_force", "contact.0.drive"),
                      family=("model", ["full"]))


def test_figure_of_a_model_map_names_its_parameters(tmp_path):
    from stickslip.plot.stability import plot_stability_map, save_stability_map_figure

    m = stability_map("belt", [0.5, 1.0, 1.5], [0.5, 1.5, 2.5], axes=("contact.0.normal_force", "contact.0.drive"))
    assert save_stability_map_figure(m, tmp_path / "belt.png").stat().st_size > 10_000
    ax = plot_stability_map(m)
    assert ax.get_xlabel() == "contact.0.normal_force" and ax.get_ylabel() == "contact.0.drive"
