"""A truncated Craig–Bampton model's transient against the full model's, to 1e-6.

The lined pad (``lined_pad.py``: a stiff plate on a soft lining, lumped masses, 144 dofs, nine
contact nodes) is run from rest by the compiled integrator as the full model and as reduced models
that keep the 18 contact dofs, the two lowest fixed-interface modes and 0–2 blocks of residual
vectors (20–56 dofs). Every contact node sticks, slips and lifts off in the first periods. The
reduced runs keep the full one's stick and open flags at every sample; with one block of residual
vectors (38 dofs) they hold its contact displacements, velocities and normal forces to 1e-6 of
their ranges, and the error falls with each block. docs/fe.md gives the study behind it (``-m slow``: more modes, the
consistent-mass pad for comparison).
"""

import json

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from typer.testing import CliRunner

from stickslip import simulate
from stickslip.cli import app
from stickslip.model.library import load_model
from stickslip.reduction import reduce_model, write_model_file

from .lined_pad import lined_pad

#: 9 contact nodes on a 6 mm lining (E = 3 MPa) under a 14 mm plate (E = 20 GPa), contact springs of
#: 0.1 MN/m pressed 30 µm, Coulomb μk = 0.3, μs = 0.5, belt at 5 cm/s: the contact nodes' modes lie
#: at 0.9–2.9 kHz, the plate's fixed-interface modes from 27 kHz.
LINED = dict(nx=8, ny=8, lining=0.006, E_lining=3e6, E_plate=2e10, contact_stiffness=1e5)
PERIODS = 3
TOL = dict(rtol=1e-10, atol=1e-13)


def first_frequency(fe) -> float:
    """The pad's first natural frequency on its contact springs [Hz] (scipy's shift-invert Lanczos)."""
    nc = len(fe.normal_dof)
    springs = sp.csr_matrix((np.full(nc, fe.contact["stiffness"]), (fe.normal_dof, fe.normal_dof)), shape=(fe.n, fe.n))
    w2 = sla.eigsh((fe.stiffness + springs).tocsc(), k=1, M=fe.mass.tocsc(), sigma=0.0, return_eigenvectors=False)
    return float(np.sqrt(w2[0]) / (2.0 * np.pi))


def errors(full_run, reduced_run, kept, n_full, n_reduced):
    """Largest differences of the kept dofs' displacements, velocities and the normal forces, each
    relative to the full run's largest magnitude of that quantity."""
    out = []
    for a, b in ((full_run.states[:, kept], reduced_run.states[:, :kept.size]),
                 (full_run.states[:, n_full + kept], reduced_run.states[:, n_reduced:n_reduced + kept.size]),
                 (full_run.normal_force, reduced_run.normal_force)):
        out.append(float(np.abs(a - b).max() / np.abs(a).max()))
    return out


@pytest.fixture(scope="module")
def pad(tmp_path_factory):
    fe = lined_pad(**LINED)
    folder = tmp_path_factory.mktemp("lined")
    full = load_model(str(fe.write(folder / "full")))
    t_end = PERIODS / first_frequency(fe)
    run = simulate(full, t_end, sample_rate=200 * PERIODS / t_end, **TOL)
    return folder, full, t_end, run


def reduced_run(pad, residual):
    folder, full, t_end, _ = pad
    reduced = reduce_model(full, method="craig-bampton", modes=2, residual=residual)
    path = folder / f"cb_{residual}.toml"
    write_model_file(reduced.form, path)
    model = load_model(str(path))
    return reduced, model, simulate(model, t_end, sample_rate=200 * PERIODS / t_end, **TOL)


def test_every_contact_node_sticks_slips_and_lifts_off(pad):
    _, full, _, run = pad
    assert full.n == 144 and full.n_contacts == 9 and run.status == "success"
    slipping = ~run.stick & ~run.open
    assert np.all(run.stick.any(axis=0)) and np.all(run.open.any(axis=0)) and np.all(slipping.any(axis=0))


def test_the_full_run_before_its_first_transition_against_scipy(pad):
    """Until the first transition every contact is closed and slips against the belt: a linear ODE
    that scipy's DOP853 integrates from the matrices alone (normal force k (preload − u_y), friction
    μk N along +x, the belt's direction)."""
    from scipy.integrate import solve_ivp

    _, full, _, run = pad
    fe = lined_pad(**LINED)
    M, C, K = fe.mass.toarray(), fe.damping_matrix.toarray(), fe.stiffness.toarray()
    Minv, n, kc = np.linalg.inv(M), fe.n, fe.contact["stiffness"]

    def rhs(t, s):
        f = -C @ s[n:] - K @ s[:n]
        normal = -kc * (fe.gap + s[fe.normal_dof])
        f[fe.normal_dof] += normal
        f[fe.tangent_dof] += fe.friction["mu_k"] * normal
        return np.concatenate([s[n:], Minv @ f])

    first = float(run.transitions.time[0])
    short = simulate(full, 0.99 * first, sample_rate=50 / first, **TOL)  # 50 samples before it
    assert short.transitions.time.size == 0 and np.all(~short.stick & ~short.open)
    ref = solve_ivp(rhs, (0.0, short.t[-1]), np.zeros(2 * n), method="DOP853", t_eval=short.t, rtol=1e-12, atol=1e-16)
    for part in (slice(0, n), slice(n, 2 * n)):  # displacements, velocities: each to 1e-8 of its range
        expected = ref.y.T[:, part]
        np.testing.assert_allclose(short.states[:, part], expected, rtol=0, atol=1e-8 * np.abs(expected).max())


def test_truncated_craig_bampton_runs_the_full_transient_to_1e_6(pad):
    _, full, _, run = pad
    measured = {}
    for residual in (0, 1, 2):
        reduced, model, red = reduced_run(pad, residual)
        assert red.status == "success"
        assert model.n == 18 + 2 + 18 * residual  # the contact dofs, two modes, a block of 18 per residual
        np.testing.assert_array_equal(run.stick, red.stick)
        np.testing.assert_array_equal(run.open, red.open)
        measured[residual] = errors(run, red, reduced.boundary, full.n, model.n)
    print(measured)
    largest = {residual: max(values) for residual, values in measured.items()}
    # 38 of 144 dofs hold the transient to 1e-6 (measured 2e-7); the modes alone (20 dofs) come to 2e-6,
    # and each block of residual vectors takes the error down by about 7
    assert largest[1] <= 1e-6, measured
    assert largest[1] <= largest[0] / 3 and largest[2] <= largest[1] / 3, measured


def test_reduce_command_adds_residual_vectors(tmp_path):
    pad = lined_pad(4, 4).write(tmp_path / "pad")
    out = tmp_path / "red.toml"
    result = CliRunner().invoke(app, ["reduce", "--model", str(pad), "--modes", "2", "--residual", "1", "--no-check",
                                      "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output)
    assert summary["kept_dofs"] == 10 and summary["residual_vectors"] == 10 and summary["reduced_dofs"] == 22
    bad = CliRunner().invoke(app, ["reduce", "--model", str(pad), "--modes", "2", "--residual", "-1", "--out",
                                   str(tmp_path / "b.toml")])
    assert bad.exit_code == 2 and "--residual -1 must be >= 0" in bad.output
    assert len(bad.output.strip().splitlines()) == 1
