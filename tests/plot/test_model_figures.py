"""The library models' figures read the run's modes through the helpers of
:mod:`stickslip.analysis.modes`, so they draw the same from a narrow mode integer and from the wide
mode words (63 flags a word) that a model of many contacts stores."""

import dataclasses

import matplotlib.pyplot as plt
import numpy as np
import pytest

import stickslip
from stickslip.analysis.modes import MODE_WORD_BITS, flag_bits
from stickslip.plot.models import plot_popp_stelter


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _drawn(fig):
    """Per axes: the lines' data and the shaded spans' extents."""
    out = []
    for ax in fig.axes:
        lines = [(np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)) for ln in ax.get_lines()]
        spans = sorted(tuple(np.round(p.get_extents().bounds, 6)) for p in ax.patches)
        out.append((lines, spans))
    return out


def test_popp_stelter_figure_is_the_same_from_wide_mode_words():
    run = stickslip.simulate("popp-stelter", 120.0, ic={"x1": 0.5, "x2": -0.5}, sample_rate=200.0)
    flags = run.mode.astype(np.int64)
    # the same flags as a (k, 2) array of words: word 0 holds flags 0-62, word 1 is empty
    wide = dataclasses.replace(run, mode=np.stack([flags, np.zeros_like(flags)], axis=1))
    assert (flag_bits(wide.mode, 0, 2) == flag_bits(run.mode, 0, 2)).all() and MODE_WORD_BITS == 63
    assert flag_bits(run.mode, 0, 2).any()  # the run sticks
    narrow_drawn, wide_drawn = _drawn(plot_popp_stelter(run)), _drawn(plot_popp_stelter(wide))
    for (lines_a, spans_a), (lines_b, spans_b) in zip(narrow_drawn, wide_drawn):
        assert spans_a == spans_b
        assert len(lines_a) == len(lines_b)
        for (xa, ya), (xb, yb) in zip(lines_a, lines_b):
            np.testing.assert_array_equal(xa, xb)
            np.testing.assert_array_equal(ya, yb)
