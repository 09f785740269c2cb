"""A line on stderr while numba compiles, and the compile time apart from the run's.

A command's first call on a machine (or after stickslip or a model's kinematics changed) compiles
the kernels of its model class: 15 to 40 s on two cores, during which nothing else would
appear. numba announces each compilation it starts (the ``numba:compile`` event; a kernel loaded
from the on-disk cache is not one), so :func:`compile_notice` counts the seconds spent compiling
while a command runs (:func:`compile_seconds`, which a command subtracts from its wall time and
reports apart), and can print one line when the first compilation starts and, at the end, how
long compiling took in all, with a spinner below the first line that counts the seconds while
numba compiles (beside a study's progress bar where one is on screen). The command line prints the
two lines on stderr when stderr is a terminal, and the transient spinner where stdout is one too
(``--json`` output on stdout stays clean; a log of a script or a test's captured output keeps only
the command's own lines).

Every computing command reports its time the same way (:func:`timed`, :func:`time_text`): the wall
time of its computation without the compiling, and the compiling apart. Its ``--json`` summary
holds both, ``wall_time_s`` and ``compile_time_s``; its table or last line reads ``2.41 s
(processes, 2 workers; compiling 25.0 s apart)``. Compiling is what numba compiles in this process
and the time it waits for a cold start's helper process compiling the rest
(:mod:`stickslip.model.compile_ahead`); workers of a sweep or basins inherit the kernels or load
them from the cache.
"""

from __future__ import annotations

import contextlib
import dataclasses
import time

from numba.core import event

__all__ = ["compile_notice", "compile_seconds", "COMPILING_LINE", "Timing", "timed", "time_text"]

#: The line printed when the first kernel starts compiling.
COMPILING_LINE = ("compiling kernels for this kind of model (once per machine: later runs load them from numba's "
                  "cache; 15 to 40 s on 2 cores) ...")


class _Spinner:
    """A transient spinner on ``console`` with the seconds ``clock`` has compiled so far, shown
    while an outermost compilation runs."""

    def __init__(self, console, clock: "_CompileClock") -> None:
        from rich.spinner import Spinner

        self.console, self.clock, self.live = console, clock, None
        self.spinner = Spinner("dots", style="dim")

    def start(self) -> None:
        from rich.errors import LiveError
        from rich.live import Live

        live = Live(self, console=self.console, transient=True, refresh_per_second=8, redirect_stdout=False,
                    redirect_stderr=False)
        try:
            live.start()
        except LiveError:  # another live display that cannot hold this one: it shows that the command is alive
            return
        self.live = live

    def stop(self) -> None:
        if self.live is not None:
            self.live.stop()
            self.live = None

    def __rich__(self):
        from rich.text import Text

        self.spinner.text = Text(f"compiling ... {self.clock.running_seconds():.0f} s", style="dim")
        return self.spinner


class _CompileClock(event.Listener):
    """Counts the seconds spent in outermost compilations (a kernel compiles its callees inside
    its own compilation), calls ``announce`` as the first one starts and, with a ``console``,
    shows a :class:`_Spinner` during each."""

    def __init__(self, announce, console=None) -> None:
        self.announce = announce
        self.spinner = None if console is None else _Spinner(console, self)
        self.depth = 0
        self.started = 0.0
        self.seconds = 0.0

    def running_seconds(self) -> float:
        """Seconds compiled so far, the compilation running now included."""
        return self.seconds + (time.perf_counter() - self.started if self.depth > 0 else 0.0)

    def on_start(self, ev) -> None:
        if self.depth == 0:
            if self.announce is not None:
                self.announce(COMPILING_LINE)
                self.announce = None
            self.started = time.perf_counter()
            if self.spinner is not None:
                self.spinner.start()
        self.depth += 1

    def on_end(self, ev) -> None:
        self.depth = max(self.depth - 1, 0)
        if self.depth == 0:
            self.seconds += time.perf_counter() - self.started
            if self.spinner is not None:
                self.spinner.stop()


_clocks: list[_CompileClock] = []


def compile_seconds() -> float:
    """Seconds spent compiling so far inside the innermost :func:`compile_notice` (0 outside one)."""
    return _clocks[-1].running_seconds() if _clocks else 0.0


@contextlib.contextmanager
def compile_notice(say=None, console=None):
    """Within: compile time counted (:func:`compile_seconds`); with ``say``, ``say(line)`` once when
    numba starts compiling and once at the end with the time it took (nothing when every kernel
    came from the cache); with a rich ``console`` (a terminal), a spinner with the seconds
    compiled while numba compiles."""
    clock = _CompileClock(say, console)
    _clocks.append(clock)
    try:
        with event.install_listener("numba:compile", clock):
            yield clock
    finally:
        _clocks.remove(clock)
        if clock.spinner is not None:
            clock.spinner.stop()
    if say is not None and clock.seconds > 0.0:  # not after an error or Ctrl-C: their line is the last
        say(f"compiled kernels in {clock.seconds:.1f} s (cached for later runs)")


@dataclasses.dataclass
class Timing:
    """What :func:`timed` measured: ``wall_s`` [s], the block's wall time without its compiling;
    ``compile_s`` [s], the compiling (:func:`compile_seconds`) within it."""

    wall_s: float = 0.0
    compile_s: float = 0.0


@contextlib.contextmanager
def timed():
    """Measure the block: a :class:`Timing`, filled in when the block ends."""
    timing = Timing()
    start, compiling = time.perf_counter(), compile_seconds()
    try:
        yield timing
    finally:
        timing.compile_s = compile_seconds() - compiling
        timing.wall_s = time.perf_counter() - start - timing.compile_s


def time_text(wall_s: float, compile_s: float, detail: str = "") -> str:
    """A command's time as its summary prints it: ``2.41 s (processes, 2 workers; compiling 25.0 s
    apart)``, without the compiling part when nothing was compiled (milliseconds below 1 s)."""
    notes = [note for note in (detail, f"compiling {compile_s:.1f} s apart" if compile_s > 0 else "") if note]
    number = f"{wall_s:.3f}" if wall_s < 1 else f"{wall_s:.2f}"
    return f"{number} s" + (f" ({'; '.join(notes)})" if notes else "")
