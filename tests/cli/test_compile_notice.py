"""The line the command line prints while numba compiles, and the compile time it reports."""

import re
import time

import numpy as np
from numba import njit
from numba.core import event

from stickslip.cli._compiling import COMPILING_LINE, compile_notice, compile_seconds, time_text, timed


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


def test_timed_puts_the_compiling_apart_from_the_wall_time():
    @njit(cache=False)
    def four_times(x):
        return 4.0 * x

    with compile_notice():
        start = time.perf_counter()
        with timed() as timing:
            four_times(np.float64(1.0))  # compiles
            time.sleep(0.2)  # the block's own work
        elapsed = time.perf_counter() - start
    assert timing.compile_s > 0.0 and timing.wall_s >= 0.2
    # together the block's time (measured around it here, so up to a scheduling delay longer)
    assert elapsed - 0.05 <= timing.wall_s + timing.compile_s <= elapsed

    with compile_notice(), timed() as again:  # compiled already
        four_times(np.float64(2.0))
    assert again.compile_s == 0.0


def test_time_text_says_the_wall_time_and_the_compiling_apart():
    assert time_text(27.417, 25.04, "processes, 2 workers") == "27.42 s (processes, 2 workers; compiling 25.0 s apart)"
    assert time_text(2.5, 0.0, "processes, 2 workers") == "2.50 s (processes, 2 workers)"
    assert time_text(0.0123, 3.0) == "0.012 s (compiling 3.0 s apart)"
    assert time_text(0.0123, 0.0) == "0.012 s"


def _terminal():
    """A rich console writing to a string as a terminal would."""
    import io

    from rich.console import Console

    return Console(file=io.StringIO(), force_terminal=True, width=100)


def test_a_spinner_counts_the_seconds_while_numba_compiles_and_leaves_nothing_on_screen():
    @njit(cache=False)
    def five_times(x):
        return 5.0 * x

    console = _terminal()
    with compile_notice(console=console) as clock:
        five_times(np.float64(1.0))
        assert clock.spinner.live is None  # stopped when the compilation ended
    written = console.file.getvalue()
    assert re.search(r"compiling \.\.\. \d+ s", written)
    assert written.endswith("\x1b[2K")  # transient: the spinner's line is erased


def test_the_spinner_stops_on_an_interrupt_and_shows_beside_a_progress_bar():
    from rich.progress import Progress

    @njit(cache=False)
    def six_times(x):
        return 6.0 * x

    @njit(cache=False)
    def seven_times(x):
        return 7.0 * x

    console = _terminal()
    try:
        with compile_notice(console=console) as clock:
            six_times(np.float64(1.0))
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        pass
    assert clock.spinner.live is None

    class Refresh(event.Listener):  # the bar redraws as the compilation starts (after the spinner started)
        def on_start(self, ev):
            bar.refresh()

        def on_end(self, ev):
            pass

    console = _terminal()
    with Progress(console=console) as bar, compile_notice(console=console) as clock:
        bar.add_task("sweep", total=2)
        with event.install_listener("numba:compile", Refresh()):
            seven_times(np.float64(1.0))  # a study compiling its first point under its progress bar
    assert clock.seconds > 0.0 and clock.spinner.live is None
    written = console.file.getvalue()
    assert "sweep" in written and "compiling ..." in written
