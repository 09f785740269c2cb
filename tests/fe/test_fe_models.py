"""The test-model generator (tests/fe/fe_models.py) against what the mechanics says, independent of stickslip:
the Q4 element's rigid-body modes and mass, the chain's closed-form frequencies, and the pad's
frequencies converging from above as its mesh is refined (a consistent mass gives upper bounds)."""

import numpy as np
import scipy.linalg
import scipy.sparse.linalg as sla

from .fe_models import bar_chain, pad_on_belt, q4_element


def test_q4_element_has_three_rigid_body_modes_and_its_mass():
    a, b, rho, t = 0.02, 0.01, 2000.0, 0.005
    Ke, Me = q4_element(a, b, 1e9, 0.3, rho, t)
    x = np.array([0.0, a, a, 0.0])
    y = np.array([0.0, 0.0, b, b])
    rigid = np.zeros((8, 3))
    rigid[0::2, 0] = 1.0  # translation along x
    rigid[1::2, 1] = 1.0  # along y
    rigid[0::2, 2], rigid[1::2, 2] = -y, x  # a small rotation
    assert np.abs(Ke @ rigid).max() < 1e-6 * np.abs(Ke).max()
    lam = np.linalg.eigvalsh(Ke)
    assert np.sum(lam > 1e-9 * lam.max()) == 5  # three rigid-body modes, five deformation modes
    assert np.allclose(Ke, Ke.T) and np.allclose(Me, Me.T)
    assert np.isclose(rigid[:, 0] @ Me @ rigid[:, 0], rho * t * a * b, rtol=1e-14)
    # a uniform stretch along x, u = ε x: σxx = E ε / (1 − ν²), and the nodal forces are its
    # tractions on the faces x = 0 and x = a: ∓σxx b t / 2 at each of their two nodes
    eps, E, nu = 1e-3, 1e9, 0.3
    u = np.zeros(8)
    u[0::2] = eps * x
    force = Ke @ u
    sigma = E * eps / (1 - nu ** 2)
    assert np.allclose(force[0::2], sigma * b * t / 2 * np.array([-1, 1, 1, -1]), rtol=1e-12)
    assert np.allclose(force[1::2], nu * sigma * a * t / 2 * np.array([-1, -1, 1, 1]), rtol=1e-12, atol=1e-9)


def test_chain_frequencies_are_the_closed_form():
    fe = bar_chain(12, mass=2.0, stiffness=50.0)
    lam = scipy.linalg.eigh(fe.stiffness.toarray(), fe.mass.toarray(), eigvals_only=True)
    assert np.allclose(np.sqrt(lam), fe.closed_form_frequencies(), rtol=1e-12)


def test_pad_frequencies_converge_from_above():
    first = []
    for nx, ny in ((10, 2), (20, 4), (40, 8)):
        fe = pad_on_belt(nx, ny)
        assert fe.n == 2 * (nx + 1) * ny
        assert abs(fe.mass - fe.mass.T).max() == 0.0 and abs(fe.stiffness - fe.stiffness.T).max() < 1e-6
        lam = sla.eigsh(fe.stiffness, k=3, M=fe.mass, sigma=0.0, return_eigenvectors=False)
        first.append(np.sqrt(np.sort(lam)))
    first = np.array(first)
    assert np.all(np.diff(first, axis=0) < 0.0)  # each refinement lowers every frequency
    steps = -np.diff(first[:, 0])
    assert steps[1] < 0.5 * steps[0]  # and by less each time: converging


def test_pad_mass_is_the_pad_less_its_clamped_row():
    """A translation of the free nodes along x moves every element below the top row whole, and
    of each top-row element the part of its consistent mass on its two lower nodes: (4 + 2 + 2 + 4)/36
    of it (the Q4 mass matrix is ρ t a b / 36 [[4, 2, 1, 2], [2, 4, 2, 1], [1, 2, 4, 2], [2, 1, 2, 4]])."""
    nx, ny, L, H, t, rho = 8, 3, 0.1, 0.02, 0.01, 2000.0
    fe = pad_on_belt(nx, ny, length=L, height=H, thickness=t, rho=rho)
    along_x = np.zeros(fe.n)
    along_x[0::2] = 1.0
    b = H / ny
    assert np.isclose(along_x @ fe.mass @ along_x, rho * t * L * (H - b + b / 3.0), rtol=1e-13)
