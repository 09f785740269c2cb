"""Ctrl-C for compiled loops: asked for between chunks, never inside one.

A KeyboardInterrupt raised while a compiled kernel returns its result lands inside numba's
boxing of that result and surfaces as a ``SystemError``; and a kernel cannot be stopped while it
runs. So long computations run their kernels in short chunks inside :class:`interruptible`,
which replaces the SIGINT handler by one that only records the request; the caller checks
:attr:`interruptible.requested` between chunks and returns what is done. A second Ctrl-C raises
KeyboardInterrupt at once (the previous handler's behaviour), for a user who wants out now.

A process started with SIGINT ignored (``nohup``, a background job of a script) keeps ignoring
it, as Python itself does: the handler is installed only over the default one or a handler of the
caller's, never over SIG_IGN. Otherwise a Ctrl-C would be honoured only when it happened to land
inside a run, and lost in between.

Work made of many runs (a sweep, a continuation, shooting) has no use for a partial run: inside
``on_ctrl_c(partial=False)`` an interrupted run raises KeyboardInterrupt once its chunk ends.
"""

from __future__ import annotations

import contextlib
import signal
import threading

__all__ = ["interruptible", "on_ctrl_c", "partial_on_ctrl_c"]

_partial = [True]


@contextlib.contextmanager
def on_ctrl_c(partial: bool):
    """Within: a run interrupted by Ctrl-C returns the part done (``partial``, the default
    outside) or raises KeyboardInterrupt when its chunk ends."""
    previous, _partial[0] = _partial[0], bool(partial)
    try:
        yield
    finally:
        _partial[0] = previous


def partial_on_ctrl_c() -> bool:
    """Whether an interrupted run returns the part done (True) or raises (see :func:`on_ctrl_c`)."""
    return _partial[0]


class interruptible:
    """Context manager: ``with interruptible() as stop: ... if stop.requested: break``.

    Only the main thread can own signal handlers; elsewhere (worker threads), and in a process
    that ignores SIGINT (module docstring), this is inert and ``requested`` stays False.
    """

    def __init__(self) -> None:
        self.requested = False
        self._previous = None

    def _handler(self, signum, frame) -> None:
        if self.requested:  # a second Ctrl-C: out now
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> "interruptible":
        if (threading.current_thread() is threading.main_thread()
                and signal.getsignal(signal.SIGINT) is not signal.SIG_IGN):
            try:
                self._previous = signal.signal(signal.SIGINT, self._handler)
            except ValueError:  # pragma: no cover - not the main interpreter
                self._previous = None
        return self

    def __exit__(self, *exc) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
