"""The one vocabulary of outcomes: codes, names, NetCDF flags and the stick character."""

import numpy as np
import pytest

import stickslip
from stickslip.analysis.outcome import (MOTIONS, OUTCOMES, STOPPED, is_stick_slip, outcome_code, outcome_flags,
                                        outcome_names)


def test_codes_are_the_positions_in_the_one_tuple():
    assert stickslip.OUTCOMES is OUTCOMES
    assert [outcome_code(name) for name in OUTCOMES] == list(range(8))
    # the codes that sweeps and basin studies wrote before the vocabulary was one: unchanged
    assert OUTCOMES[:6] == ("equilibrium", "periodic", "quasiperiodic", "chaotic", "unbounded", "unsettled")
    assert OUTCOMES[6:] == ("contact-lost", "failed")
    assert set(MOTIONS) | set(STOPPED) | {"equilibrium"} == set(OUTCOMES) and not set(MOTIONS) & set(STOPPED)


def test_an_unknown_name_is_refused_naming_the_outcomes():
    with pytest.raises(ValueError, match="unknown outcome 'periodic-slip'; the outcomes are equilibrium, periodic"):
        outcome_code("periodic-slip")


def test_names_of_codes_with_missing_points():
    names = outcome_names([[0.0, 1.0], [np.nan, 7.0]])
    assert names.tolist() == [["equilibrium", "periodic"], ["failed", "failed"]]
    assert outcome_names([np.nan, 9.0], missing="pending").tolist() == ["pending", "pending"]


def test_netcdf_flags_name_every_code():
    flags = outcome_flags()
    assert flags["flag_values"].tolist() == list(range(8))
    assert flags["flag_meanings"].split() == list(OUTCOMES)


def test_stick_slip_is_a_moving_outcome_with_stick():
    assert is_stick_slip("periodic", 0.3) and is_stick_slip("chaotic", 0.01) and is_stick_slip("unsettled", 1e-9)
    assert not is_stick_slip("periodic", 0.0)                # a pure-slip orbit
    assert not is_stick_slip("equilibrium", 1.0)             # at rest, stuck: no oscillation
    assert not is_stick_slip("failed", 0.5) and not is_stick_slip("periodic", np.nan)
    codes = np.array([1.0, 1.0, 0.0, 7.0, np.nan])
    np.testing.assert_array_equal(is_stick_slip(codes, [0.2, 0.0, 0.2, 0.2, 0.2]), [True, False, False, False, False])
