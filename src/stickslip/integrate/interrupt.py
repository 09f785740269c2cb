"""Ctrl-C: taken between chunks of compiled loops, and held while a result is being written.

A KeyboardInterrupt raised while a compiled kernel returns its result lands inside numba's
boxing of that result and surfaces as a ``SystemError``; and a kernel cannot be stopped while it
runs. So long computations run their kernels in short chunks inside :class:`interruptible`,
which replaces the SIGINT handler by one that only records the request; the caller checks
:attr:`interruptible.requested` between chunks and returns what is done. A second Ctrl-C raises
KeyboardInterrupt at once (the previous handler's behaviour), for a user who wants out now.

The same holding keeps a result that is done: inside :func:`finish_first` (writing a finished
or interrupted run, an orbit, a study's file) a first Ctrl-C lets the block finish and then
raises KeyboardInterrupt; a second one stops the block at once.

Every request taken by a handler here is also recorded for the process (:func:`ctrl_c_taken`),
so a caller that got a result back (a run that ended as Ctrl-C was pressed, a study that
returned its part done) still learns that the user asked to stop, and stops with
:func:`stop_if_interrupted`.

Inside an :class:`interruptible` another one is inert: the outer one owns the request (a basin
study stops between its batches, and the runs inside a batch go on to their end).

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

__all__ = ["interruptible", "on_ctrl_c", "partial_on_ctrl_c", "finish_first", "ctrl_c_taken", "stop_if_interrupted",
           "forget_ctrl_c"]

_partial = [True]

#: Whether a Ctrl-C was taken by a handler of this module and not acted on yet.
_taken = [False]


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


def ctrl_c_taken() -> bool:
    """Whether a Ctrl-C was taken (recorded by :class:`interruptible`) and not acted on yet."""
    return _taken[0]


def forget_ctrl_c() -> None:
    """Forget a Ctrl-C taken earlier (a command starting afresh in the same process)."""
    _taken[0] = False


def stop_if_interrupted() -> None:
    """Raise KeyboardInterrupt for a Ctrl-C taken earlier and not acted on yet (:func:`ctrl_c_taken`)."""
    if _taken[0]:
        _taken[0] = False
        raise KeyboardInterrupt


class interruptible:
    """Context manager: ``with interruptible() as stop: ... if stop.requested: break``.

    Only the main thread can own signal handlers; elsewhere (worker threads), inside another
    :class:`interruptible`, and in a process that ignores SIGINT (module docstring), this is
    inert and ``requested`` stays False.
    """

    def __init__(self) -> None:
        self.requested = False
        self._previous = None

    def _handler(self, signum, frame) -> None:
        if self.requested:  # a second Ctrl-C: out now
            raise KeyboardInterrupt
        self.requested = True
        _taken[0] = True

    def __enter__(self) -> "interruptible":
        if threading.current_thread() is not threading.main_thread():
            return self
        current = signal.getsignal(signal.SIGINT)
        if current is signal.SIG_IGN or isinstance(getattr(current, "__self__", None), interruptible):
            return self
        try:
            self._previous = signal.signal(signal.SIGINT, self._handler)
        except ValueError:  # pragma: no cover - not the main interpreter
            self._previous = None
        return self

    def __exit__(self, *exc) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            self._previous = None


@contextlib.contextmanager
def finish_first():
    """Within: a first Ctrl-C is held until the block has finished, which then raises
    KeyboardInterrupt; a second one raises at once. For writing what is done (a file replaced
    whole: stopped halfway, nothing of it is written)."""
    with interruptible() as ctrl_c:
        yield ctrl_c
    if ctrl_c.requested:
        _taken[0] = False
        raise KeyboardInterrupt
