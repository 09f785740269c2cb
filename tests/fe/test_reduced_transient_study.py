"""The study behind docs/fe.md's table of truncated Craig–Bampton transients (``pytest -m slow -s``).

The lined pad of ``test_reduced_transient.py`` over four periods of its first mode, reduced with
2 to 32 fixed-interface modes and 0 to 2 blocks of residual vectors; each row prints the largest
differences of the contact dofs' displacements, velocities and normal forces from the full run
(relative to their ranges). Then the two conditions it rests on, each taken away: the pad with
its consistent mass matrix, and the uniform soft pad of ``test_fe_transient.py`` with lumped
masses, whose fixed-interface modes lie inside its contact nodes' band — no truncated basis comes
near either (docs/fe.md).
"""

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp

from stickslip import simulate
from stickslip.model.library import load_model
from stickslip.reduction import reduce_model, write_model_file

from .fe_models import pad_on_belt
from .lined_pad import lined_pad
from .test_reduced_transient import LINED, TOL, errors, first_frequency

pytestmark = pytest.mark.slow

PERIODS = 4
ROWS = [(modes, residual) for modes in (2, 8, 16, 32) for residual in (0, 1, 2)]


def study(fe, folder, rows):
    """{(modes, residual): (reduced dofs, [q, v, N] errors, same flags)} and the full run."""
    full = load_model(str(fe.write(folder / "full")))
    t_end = PERIODS / first_frequency(fe)
    rate = 200 * PERIODS / t_end
    run = simulate(full, t_end, sample_rate=rate, **TOL)
    assert run.status == "success"
    out = {}
    for modes, residual in rows:
        reduced = reduce_model(full, method="craig-bampton", modes=modes, residual=residual)
        write_model_file(reduced.form, folder / f"cb_{modes}_{residual}.toml")
        model = load_model(str(folder / f"cb_{modes}_{residual}.toml"))
        red = simulate(model, t_end, sample_rate=rate, **TOL)
        assert red.status == "success"
        same = bool(np.array_equal(run.stick, red.stick) and np.array_equal(run.open, red.open))
        out[modes, residual] = (model.n, errors(run, red, reduced.boundary, full.n, model.n), same,
                                float(reduced.frequencies[-1] / (2 * np.pi)))
        n, (q, v, nf), _, top = out[modes, residual]
        print(f"| {modes} | {top / 1e3:.1f} | {residual} | {n} | {q:.1e} | {v:.1e} | {nf:.1e} | {same} |")
    return full, run, out


def test_lumped_pad_converges_as_modes_and_residual_vectors_are_added(tmp_path):
    fe = lined_pad(**LINED)
    full, run, out = study(fe, tmp_path, ROWS)
    slipping = ~run.stick & ~run.open
    assert np.all(run.stick.any(axis=0)) and np.all(run.open.any(axis=0)) and np.all(slipping.any(axis=0))
    largest = {key: max(row[1]) for key, row in out.items()}
    for modes in (2, 8, 16, 32):
        assert largest[modes, 1] <= largest[modes, 0] / 3 and largest[modes, 2] <= largest[modes, 1] / 3, largest
        assert largest[modes, 1] <= 1e-6 and all(out[modes, r][2] for r in (1, 2)), (modes, out)
    assert largest[32, 0] <= largest[2, 0] / 3  # more modes help as well, more slowly


def test_consistent_mass_keeps_a_truncated_basis_far_off(tmp_path):
    fe = lined_pad(4, 4, **{k: v for k, v in LINED.items() if k not in ("nx", "ny")}, lumped=False)
    _, _, out = study(fe, tmp_path, [(4, 0), (4, 1), (4, 2)])
    assert all(max(row[1]) > 1e-3 for row in out.values()), out


def test_without_separation_a_truncated_basis_stays_far_off(tmp_path):
    # test_fe_transient.py's soft pad (72 dofs, nine contact nodes on 1 MN/m springs), masses lumped:
    # its fixed-interface modes (1.1-4.5 kHz) lie inside its contact nodes' band (0.5-9.5 kHz)
    fe = pad_on_belt(nx=8, ny=4, mu_k=0.3, delta_mu=0.2, preload=3e-5, E=1e7, contact_stiffness=1e6,
                     rayleigh=(0.0, 2e-6), speed=0.05)
    fe = dataclasses.replace(fe, mass=sp.diags(np.asarray(fe.mass.sum(axis=1)).ravel(), format="csr"))
    _, _, out = study(fe, tmp_path, [(50, 0), (40, 0)])  # of its 54 interior modes
    assert all(max(row[1]) > 1e-1 for row in out.values()), out


def test_a_finer_plate_keeps_the_reduced_size_and_error(tmp_path):
    """The plate meshed in 11 rows instead of 7 (216 dofs): the reduced models keep their sizes (set by
    the contact dofs) and their errors."""
    fe = lined_pad(**{**LINED, "ny": 12})
    full, _, out = study(fe, tmp_path, [(2, 0), (2, 1), (16, 0)])
    assert full.n == 216 and out[2, 1][0] == 38
    assert max(out[2, 1][1]) <= 1e-6 and max(out[16, 0][1]) <= 1e-6 and out[2, 1][2], out
