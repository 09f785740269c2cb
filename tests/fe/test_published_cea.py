"""The CEA against a published mode-coupling onset: Beck's column, P_k = 20.05 EI/L² (Beck 1952).

The column (tests/fe/beck_column.py) is assembled from textbook beam-element matrices; its
non-symmetric stiffness goes through stickslip's public sparse path (``stability`` of a sparse form
with ``max_frequency``), dense in the band up to 200 DOFs and shift-invert Arnoldi above. The
published number is asserted to its own precision (±0.005, half a unit in Beck's last digit); the
exact onset of the continuum (its boundary determinant, solved here) checks the convergence as
the elements are refined and the frequency at the onset.
"""

import math

import numpy as np
import pytest

from stickslip.stability import stability
from stickslip.stability.cea import DENSE_STATES

from .beck_column import BAND, BECK_DIGITS, BECK_LOAD, beck_column, continuum_onset, flutter_onset, pair


def test_continuum_onset_is_becks():
    """The test's own reference: the continuum's onset rounds to Beck's published 20.05."""
    load, frequency = continuum_onset()
    assert abs(load - BECK_LOAD) <= BECK_DIGITS
    assert 11.0 < frequency < 11.03  # the two lowest frequencies (3.52, 22.0 unloaded) meet near 11


@pytest.mark.parametrize("elements", [8, 16])
def test_verdict_brackets_becks_load(elements):
    """Below Beck's load the undamped column has no growing mode (marginal: every real part within
    the round-off tolerance of 0); a unit of his last digit above it, the CEA finds the flutter pair."""
    below = stability(beck_column(elements, BECK_LOAD - 2 * BECK_DIGITS), max_frequency=BAND)
    above = stability(beck_column(elements, BECK_LOAD + 2 * BECK_DIGITS), max_frequency=BAND)
    assert below.verdict == "marginal" and above.verdict == "unstable"
    a, b = sorted(pair(above), key=lambda z: -z.real)  # the growing and the decaying member of one frequency
    assert a.real > 0.05 and abs(a.real + b.real) < 1e-9 * abs(a) and abs(a.imag - b.imag) < 1e-9 * abs(a)


def test_onset_converges_to_becks_load():
    """The finite-element onsets round to 20.05 from 8 elements on and converge to the continuum's at
    the fourth order of the element size (error ratios near 2⁴ = 16 per halving), the frequency with
    them."""
    exact_load, exact_frequency = continuum_onset()
    meshes = (4, 8, 16)
    onsets = [flutter_onset(n) for n in meshes]
    for n, (load, frequency, band) in zip(meshes, onsets):
        a, b = pair(band)  # at the onset the two frequencies are one
        assert abs(a.imag - b.imag) < 1e-4 * frequency
        if n >= 8:
            assert abs(load - BECK_LOAD) <= BECK_DIGITS
    errors = [load - exact_load for load, _, _ in onsets]
    assert all(e > 0 for e in errors)  # from above, as measured
    ratios = [errors[i] / errors[i + 1] for i in range(len(errors) - 1)]
    assert all(12.0 < r < 20.0 for r in ratios), ratios
    frequency_errors = [abs(frequency - exact_frequency) for _, frequency, _ in onsets]
    assert frequency_errors[-1] < 1e-4 * exact_frequency and frequency_errors[-1] < frequency_errors[0] / 50


def test_onset_at_finite_element_scale():
    """128 elements (256 DOFs, 512 states: the Arnoldi path, not the dense one): Beck's load to his
    precision and the continuum's to 1e-7, the frequency to 1e-5 (round-off near the double
    eigenvalue splits the pair by ~√ε relative)."""
    elements = 128
    assert 2 * (2 * elements) > DENSE_STATES
    exact_load, exact_frequency = continuum_onset()
    load, frequency, band = flutter_onset(elements)
    assert abs(load - BECK_LOAD) <= BECK_DIGITS
    assert abs(load - exact_load) < 1e-7 * exact_load
    assert abs(frequency - exact_frequency) < 1e-5 * exact_frequency
    assert float(np.max(band.backward_error)) < 1e-12 and band.frictionless_count == 2
    # a unit of Beck's last digit above it the pair grows, at about the onset's frequency
    above = stability(beck_column(elements, BECK_LOAD + 2 * BECK_DIGITS), max_frequency=BAND)
    assert above.verdict == "unstable" and math.isclose(pair(above)[0].imag, frequency, rel_tol=1e-2)
