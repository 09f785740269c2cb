import math

import pytest

from stickslip import ParameterError, Parameters


def test_defaults_are_table_1_and_the_operating_point():
    p = Parameters()
    assert (p.m_p, p.m_d, p.J_p, p.J_d) == (1.0, 10.0, 0.5, 5.0)
    assert (p.k_px, p.k_py, p.k_dx, p.k_dy, p.k_pphi, p.k_dpsi) == (300.0, 300.0, 3000.0, 3000.0, 100.0, 1000.0)
    assert (p.c_px, p.c_py, p.c_dx, p.c_dy, p.c_pphi, p.c_dpsi) == (0.1,) * 6
    assert p.r == 0.2
    assert (p.N, p.Omega, p.mu_k, p.delta_mu, p.alpha) == (50.0, 5.0, 0.2, 0.1, 5.0)
    assert math.isclose(p.mu_s, 0.3)


@pytest.mark.parametrize(
    "change, words",
    [
        ({"m_p": -1.0}, "m_p"),
        ({"N": 0.0}, "N"),
        ({"N": -5.0}, "pressed together"),
        ({"k_px": -1.0}, ">= 0"),
        ({"alpha": float("nan")}, "not finite"),
        ({"Omega": float("inf")}, "not finite"),
        ({"r": "abc"}, "must be a number"),
        ({"friction_law": "stribeck"}, "exponential"),
        ({"nonsense": 1.0}, "unknown parameter"),
    ],
)
def test_invalid_values_name_the_field_and_the_fix(change, words):
    with pytest.raises(ParameterError, match=words):
        Parameters().replace(**change)


def test_frozen():
    with pytest.raises(Exception):
        Parameters().N = 3.0


def test_toml_round_trip(tmp_path):
    p = Parameters(N=70.0, Omega=0.5, friction_law="coulomb")
    path = tmp_path / "p.toml"
    p.save_toml(path)
    assert Parameters.load_toml(path) == p


def test_toml_partial_and_errors(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text("N = 30\n")
    assert Parameters.load_toml(path).N == 30.0
    path.write_text("[parameters]\nN = \n")
    with pytest.raises(ParameterError, match="not valid TOML"):
        Parameters.load_toml(path)
    with pytest.raises(ParameterError, match="does not exist"):
        Parameters.load_toml(tmp_path / "missing.toml")
    path.write_text("[parameters]\nmass = 3\n")
    with pytest.raises(ParameterError, match="unknown parameter"):
        Parameters.load_toml(path)
