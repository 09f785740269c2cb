"""Fixtures of the constructed continuation problem (:mod:`tests.orbits.constructed`)."""

import pytest

from .constructed import constructed_orbit, fold_and_period_doubling, install


@pytest.fixture
def constructed_with(monkeypatch):
    """``make(monodromy)``: the constructed start orbit (one stick phase per period), its shooting
    map the algebraic one with the monodromy matrix ``monodromy(v)``."""

    def make(monodromy=fold_and_period_doubling):
        install(monkeypatch, monodromy)
        return constructed_orbit()

    return make


@pytest.fixture
def constructed(constructed_with):
    """The constructed start orbit with a fold (a real multiplier through +1 at alpha = 10) and a
    period doubling (a real multiplier through −1 at alpha = 5 (2 − 1/9))."""
    return constructed_with()
