"""FrictionModel.natural_frequencies: the linear modes against the eigenvalues of the stability module."""

import numpy as np
import pytest

from stickslip import Parameters, stability
from stickslip.model.library import load_model, two_plates

#: No damping and no friction: the linearised steady sliding is undamped, its eigenvalues ±i 2π f.
UNDAMPED = dict(c_px=0.0, c_py=0.0, c_dx=0.0, c_dy=0.0, c_pphi=0.0, c_dpsi=0.0, mu_k=0.0, delta_mu=0.0)


@pytest.mark.parametrize("model, changes", [
    ("full", {}),
    ("rotation", {"k_pphi": 900.0}),
    ("x", {"k_dx": 50.0, "m_d": 2.0}),
])
def test_frequencies_are_the_undamped_eigenvalues(model, changes):
    params = Parameters(**UNDAMPED, **changes)
    eig = stability(two_plates(params, model)).eigenvalues
    from_eigenvalues = np.sort(eig.imag[eig.imag > 0]) / (2 * np.pi)
    assert np.allclose(eig.real, 0.0, atol=1e-9)
    assert np.allclose(two_plates(params, model).natural_frequencies(), from_eigenvalues, rtol=1e-9)


def test_table_1_highest_frequency_is_the_upper_plate_translation():
    # Table 1: k_px = 300 N/m on m_p = 1 kg gives sqrt(300)/(2π) = 2.7566 Hz, the highest of the six
    assert two_plates(Parameters()).natural_frequencies().max() == pytest.approx(2.7566444771, rel=1e-9)


def test_belt_frequency_is_its_undamped_oscillator():
    # x'' + 2 ξ x' + x = friction: ω = 1 rad/s, f = 1/(2π)
    assert load_model("belt").natural_frequencies() == pytest.approx([1.0 / (2 * np.pi)], rel=1e-12)
