"""The line the command line prints while numba compiles, and the compile time it reports."""

import numpy as np
from numba import njit

from stickslip.cli._compiling import COMPILING_LINE, compile_notice, compile_seconds


def test_one_line_as_compiling_starts_and_the_time_at_the_end():
    @njit(cache=False)
    def inner(x):
        return x * 2.0

    @njit(cache=False)
    def outer(x):
        return inner(x) + 1.0  # compiles `inner` inside its own compilation: one notice, one time

    lines = []
    with compile_notice(lines.append) as clock:
        assert outer(np.float64(1.0)) == 3.0
        assert lines == [COMPILING_LINE]
    assert len(lines) == 2 and lines[1].startswith("compiled kernels in ") and clock.seconds > 0.0
    assert clock.depth == 0

    lines.clear()
    with compile_notice(lines.append) as clock:  # compiled already: nothing to say
        outer(np.float64(2.0))
    assert lines == [] and clock.seconds == 0.0


def test_nothing_after_an_error():
    @njit(cache=False)
    def twice(x):
        return 2.0 * x

    lines = []
    try:
        with compile_notice(lines.append):
            twice(np.float64(1.0))
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        pass
    assert lines == [COMPILING_LINE]  # the interrupt's own line is the last one the user sees


def test_seconds_counted_inside_and_zero_outside():
    @njit(cache=False)
    def thrice(x):
        return 3.0 * x

    assert compile_seconds() == 0.0
    with compile_notice():  # silent: counts only
        before = compile_seconds()
        thrice(np.float64(1.0))
        spent = compile_seconds() - before
    assert spent > 0.0
    assert compile_seconds() == 0.0
