"""A centre is marginal, not unstable: the verdict of linear stability against a closed form.

An undamped linear oscillator m x'' + k x = μk N on a belt (Coulomb friction, constant in slip)
has steady sliding x_e = μk N / k and eigenvalues ±iω, ω = √(k/m), exactly: Re λ = 0, which the
linearisation leaves undecided. With a viscous damper c the eigenvalues are −c/2m ± i√(ω² − c²/4m²).
"""

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

import stickslip
from stickslip.cli import app
from stickslip.model.model_file import model_from_spec
from stickslip.stability.verdict import MARGINAL_RTOL, stability_verdict, verdict_text

runner = CliRunner()

K, MU, N = 4.0, 0.3, 1.0  # ω = 2 rad/s, x_e = 0.075 m

TOML = f"""
name = "centre"
dofs = ["x"]
mass = [[1.0]]
damping = [["c"]]
stiffness = [[{K}]]
[parameters]
c = 0.0
[[contact]]
tangent = [[1.0]]
drive = [1.0]
normal_force = {N}
[contact.friction]
law = "coulomb"
mu_k = {MU}
delta_mu = 0.1
"""


def oscillator(c=0.0):
    spec = {"name": "centre", "dofs": ["x"], "mass": [[1.0]], "damping": [[c]], "stiffness": [[K]],
            "contact": [{"tangent": [[1.0]], "drive": [1.0], "normal_force": N,
                         "friction": {"law": "coulomb", "mu_k": MU, "delta_mu": 0.1}}]}
    return model_from_spec(spec)


def test_an_undamped_oscillator_is_marginal_with_its_closed_form_eigenvalues():
    result = stickslip.stability(oscillator())
    omega = math.sqrt(K)
    np.testing.assert_allclose(np.sort_complex(result.eigenvalues), [-1j * omega, 1j * omega], rtol=0, atol=1e-15)
    assert math.isclose(result.equilibrium[0], MU * N / K, rel_tol=1e-14)
    # ‖J‖₂ of [[0, 1], [−k, 0]] is k
    assert math.isclose(result.tolerance, MARGINAL_RTOL * K, rel_tol=1e-12)
    assert result.verdict == "marginal" and not result.stable
    summary = result.summary()
    assert summary["verdict"] == "marginal" and summary["stable"] is False
    assert math.isclose(summary["marginal_tolerance"], MARGINAL_RTOL * K, rel_tol=1e-12)
    assert result.to_xarray().attrs["verdict"] == "marginal"


def test_a_damped_oscillator_is_stable_with_its_closed_form_eigenvalues():
    c = 1e-3
    result = stickslip.stability(oscillator(c))
    ref = np.array([-c / 2 - 1j * math.sqrt(K - c * c / 4), -c / 2 + 1j * math.sqrt(K - c * c / 4)])
    np.testing.assert_allclose(np.sort_complex(result.eigenvalues), ref, rtol=0, atol=1e-14)
    assert result.verdict == "stable" and result.stable


def test_the_verdict_turns_at_the_tolerance():
    tol = 1e-8
    assert stability_verdict(0.0, tol) == "marginal"
    assert stability_verdict(0.9 * tol, tol) == stability_verdict(-0.9 * tol, tol) == "marginal"
    assert stability_verdict(1.1 * tol, tol) == "unstable" and stability_verdict(-1.1 * tol, tol) == "stable"
    assert "neither decays nor grows" in verdict_text(0.0, tol) and "unstable" not in verdict_text(0.0, tol)
    assert verdict_text(0.5, tol).startswith("unstable (max Re λ = 0.5 1/s")


def test_the_command_line_says_marginal(tmp_path):
    path = tmp_path / "centre.toml"
    path.write_text(TOML)
    table = runner.invoke(app, ["stability", "--model", str(path)])
    assert table.exit_code == 0, table.output
    assert "steady sliding is marginal" in table.stdout and "unstable" not in table.stdout
    data = json.loads(runner.invoke(app, ["stability", "--model", str(path), "--json"]).stdout)
    assert data["verdict"] == "marginal" and data["stable"] is False
    damped = json.loads(runner.invoke(app, ["stability", "--model", str(path), "--set", "c=0.01", "--json"]).stdout)
    assert damped["verdict"] == "stable" and damped["stable"] is True


@pytest.mark.parametrize("ic", ["equilibrium"])
def test_a_run_at_rest_on_a_centre_is_called_marginal_not_unstable(ic):
    traj = stickslip.simulate(oscillator(), 20.0, ic=ic, sample_rate=100.0)
    verdict = stickslip.attractor(traj)
    assert verdict.attractor == "unsettled"
    reason = verdict.evidence["reason"]
    assert reason.startswith("at rest, but steady sliding is marginal") and "unstable" not in reason
    assert verdict.evidence["stability"]["verdict"] == "marginal"


def test_a_map_of_centres_is_marginal_everywhere(tmp_path):
    """Over the belt speed and the load the undamped oscillator stays a centre (Re λ = 0): every
    point of its map is marginal, none stable or unstable, also read back from its file; with a
    damper every point is stable (Re λ = −c/2)."""
    axes = ("contact.0.drive", "contact.0.normal_force")
    smap = stickslip.stability_map(oscillator(), [0.5, 1.0, 2.0], [0.5, 1.0], axes=axes, boundary=False)
    np.testing.assert_allclose(smap.tolerance, MARGINAL_RTOL * K, rtol=1e-12)
    assert smap.marginal.all() and not smap.stable.any() and (smap.verdicts == "marginal").all()
    back = stickslip.load_stability_map(smap.to_netcdf(tmp_path / "map.nc"))
    assert (back.verdicts == "marginal").all()
    damped = stickslip.stability_map(oscillator(1e-3), [0.5, 1.0, 2.0], [0.5, 1.0], axes=axes, boundary=False)
    np.testing.assert_allclose(damped.max_real_part, -0.5e-3, rtol=1e-9)
    assert damped.stable.all() and not damped.marginal.any()


def test_a_neutral_cycle_is_marginal_not_stable():
    """The undamped oscillator slipping about x_e without reaching the belt speed is a linear
    motion: its monodromy over a period 2π/ω is the identity, both multipliers 1 (closed form):
    the cycle is marginal, neither stable nor unstable. With a damper there is no cycle to shoot."""
    omega = math.sqrt(K)
    orbit = stickslip.periodic_orbit(oscillator(), {"x": MU * N / K + 0.05}, search_time=10.0)
    assert orbit.stick_phases == 0 and orbit.period == pytest.approx(2 * math.pi / omega, rel=1e-9)
    np.testing.assert_allclose(orbit.monodromy, np.eye(2), atol=1e-7)
    assert orbit.verdict == "marginal" and not orbit.stable
