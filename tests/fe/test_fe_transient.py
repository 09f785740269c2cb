"""Transients of finite-element models above the kernels' stack maxima (64 DOFs, 16 contacts).

A pad of 72 DOFs on a belt with nine compliant contact nodes sticks, slips and lifts off; its
run (the kernels' heap flavour, ``model/stack.py``) is checked against an event-driven scipy
integrator on the pad with one contact node, and its Craig–Bampton reduced model's run against
the full model's with all nine.
"""

import numpy as np
import pytest
import scipy.sparse.linalg as sla

from contacts.event_reference import OPEN_MODE, STICK_MODE, event_driven
from stickslip import simulate
from stickslip.model.kinematics import LARGE_KINEMATICS
from stickslip.model.library import load_model
from stickslip.reduction import reduce_model, write_model_file

from .fe_models import one_contact, pad_on_belt

#: A soft pad (E = 10 MPa) pressed 30 µm into a belt of 5 cm/s through contact springs of 1 MN/m,
#: Coulomb friction μk = 0.3, μs = 0.5, stiffness damping β = 2e-6 s: from rest every contact node
#: sticks, slips and lifts off within the first periods of the pad's first mode (520 Hz).
PAD = dict(nx=8, ny=4, mu_k=0.3, delta_mu=0.2, preload=3e-5, E=1e7, contact_stiffness=1e6, rayleigh=(0.0, 2e-6),
           speed=0.05)
PERIODS = 4
TOL = dict(rtol=1e-10, atol=1e-13)


def first_frequency(fe) -> float:
    """The pad's first natural frequency without contact [Hz] (scipy's shift-invert Lanczos)."""
    w2 = sla.eigsh(fe.stiffness.tocsc(), k=1, M=fe.mass.tocsc(), sigma=0.0, return_eigenvectors=False)
    return float(np.sqrt(w2[0]) / (2.0 * np.pi))


@pytest.fixture(scope="module")
def pad(tmp_path_factory):
    fe = pad_on_belt(**PAD)
    return fe, load_model(str(fe.write(tmp_path_factory.mktemp("pad") / "pad")))


def test_the_pad_takes_the_heap_flavour(pad):
    fe, model = pad
    assert model.n == 72 and model.n_contacts == 9 and not model.dense
    assert type(model.data.kin) is LARGE_KINEMATICS[type(model.kinematics)]
    np.testing.assert_array_equal(model.data.m[8:8 + 72 * 72].reshape(72, 72),
                                  np.linalg.inv(fe.mass.toarray()))  # the packed M⁻¹ of the sparse M


def reference_equations(fe):
    """``event_driven``'s functions of the pad with one compliant contact, in numpy from its matrices."""
    M, C, K = fe.mass.toarray(), fe.damping_matrix.toarray(), fe.stiffness.toarray()
    Minv = np.linalg.inv(M)
    n = M.shape[0]
    t, u = int(fe.tangent_dof[0]), int(fe.normal_dof[0])
    kc, g0, V = fe.contact["stiffness"], float(fe.gap[0]), fe.drive
    mu_k, mu_s = fe.friction["mu_k"], fe.friction["mu_k"] + fe.friction["delta_mu"]

    def normal(s):
        return -kc * (g0 + s[u])

    def base(s, closed):
        f = -C @ s[n:] - K @ s[:n]
        if closed:
            f[u] += normal(s)
        return f

    def stick_force(s):  # holds the tangent acceleration at zero: (M⁻¹ (f + e_t F))_t = 0
        return -(Minv[t] @ base(s, True)) / Minv[t, t]

    def field(mode):
        def rhs(time, s):
            f = base(s, mode != OPEN_MODE)
            if mode == STICK_MODE:
                f[t] += stick_force(s)
            elif mode != OPEN_MODE:
                f[t] -= mode * mu_k * normal(s)
            return np.concatenate([s[n:], Minv @ f])
        return rhs

    return dict(field=field, phi=lambda s: -(g0 + s[u]), slip_speed=lambda s: s[n + t] - V,
                stick_force=stick_force, limit=lambda s: mu_s * normal(s))


def test_one_contact_against_scipy(tmp_path):
    fe = one_contact(pad_on_belt(**PAD), 4)
    model = load_model(str(fe.write(tmp_path / "pad1")))
    assert type(model.data.kin) is LARGE_KINEMATICS[type(model.kinematics)]
    f1 = first_frequency(fe)
    traj = simulate(model, 3.0 / f1, sample_rate=100 * f1, **TOL)
    ref, switches = event_driven(**reference_equations(fe), t_eval=traj.t, y0=np.zeros(2 * model.n))
    assert traj.status == "success"
    for kind, times in switches.items():
        mine = traj.transitions.time[traj.transitions.kind == kind]
        assert mine.size == times.size and mine.size >= 1, kind
        # to 1e-7 of a period: stick is entered at |v| below 1e-6 m/s, about 1e-10 s early here
        np.testing.assert_allclose(mine, times, rtol=0, atol=1e-7 / f1)
    q, v = slice(0, model.n), slice(model.n, 2 * model.n)
    for part in (q, v):
        np.testing.assert_allclose(traj.states[:, part], ref[:, part], rtol=0, atol=1e-6 * np.abs(ref[:, part]).max())


def test_reduced_transient_equals_the_full_one(pad, tmp_path):
    """Craig–Bampton with every interior mode kept (a change of basis: the reduction exact) runs the
    transient of the full model to 1e-6 of each quantity's range, with the same modes at every sample."""
    fe, full = pad
    reduced = reduce_model(full, method="craig-bampton", max_frequency=1e12)
    assert reduced.form.n == full.n  # 18 contact DOFs and all 54 interior modes
    write_model_file(reduced.form, tmp_path / "pad_cb.toml")
    model = load_model(str(tmp_path / "pad_cb.toml"))
    T = PERIODS / first_frequency(fe)
    a = simulate(full, T, sample_rate=200 * PERIODS / T, **TOL)
    b = simulate(model, T, sample_rate=200 * PERIODS / T, **TOL)
    assert a.status == b.status == "success"
    # stick, slip and separation at the contact nodes
    slipping = ~a.stick & ~a.open
    assert np.all(a.stick.any(axis=0)) and np.all(a.open.any(axis=0)) and np.all(slipping.any(axis=0))
    np.testing.assert_array_equal(a.stick, b.stick)
    np.testing.assert_array_equal(a.open, b.open)
    kept = reduced.boundary
    for full_part, red_part in ((kept, slice(0, kept.size)), (full.n + kept, slice(model.n, model.n + kept.size))):
        x, y = a.states[:, full_part], b.states[:, red_part]
        assert np.abs(x - y).max() <= 1e-6 * np.abs(x).max()
    np.testing.assert_allclose(a.normal_force, b.normal_force, rtol=0, atol=1e-6 * np.abs(a.normal_force).max())


def test_a_model_whose_compiled_form_does_not_fit_is_refused_in_one_line(pad, monkeypatch, tmp_path):
    from typer.testing import CliRunner

    import stickslip.memory as memory
    from stickslip.cli import app

    fe, _ = pad
    path = fe.write(tmp_path / "pad")
    monkeypatch.setattr(memory, "available_memory", lambda: 2e5)
    result = CliRunner().invoke(app, ["simulate", "--model", str(path), "--t-end", "0.01", "--sample-rate", "1e5",
                                      "--no-plot"])
    lines = result.output.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1, result.output
    assert "72 dofs, 9 contacts" in lines[0] and "dofs fit" in lines[0] and "stickslip reduce" in lines[0]
