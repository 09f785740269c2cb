"""What must happen before stickslip imports numba: Ctrl-C held during the import, and numba's
thread count read from the environment made valid.

**Ctrl-C while importing.** ``import stickslip`` takes most of a second (numpy, scipy, numba and
the package's modules), and the command line imports it before any of its own code runs. A
SIGINT then would end the process in a traceback from whatever module was being imported. So
:func:`hold` (the first thing ``stickslip/__init__.py`` does, and the command line around its own
imports and start-up) replaces the default SIGINT handler by one that records the request;
:func:`release` puts the handler back and, for a request held meanwhile, raises
KeyboardInterrupt once, at the end of the import, with a one-line report of it in place of the
traceback (``interrupted: nothing was written``; the process then ends as Python ends on an
unhandled Ctrl-C, exit status 130 in a shell). The command line releases with
``raise_pending=False`` and reports the request itself, as does
:meth:`stickslip.files.AppendLog.append`, which holds Ctrl-C while a journal record is written
and synced and raises it once the record is durable. A second Ctrl-C while held raises at
once. Only the default handler is replaced, in the main thread: a process that ignores SIGINT,
or installed its own handler, keeps it.

**Ctrl-C inside a finaliser.** Python reports an exception raised in a ``__del__`` method as
"Exception ignored" and goes on; a KeyboardInterrupt raised by a SIGINT handler while a finaliser
runs (numba frees LLVM objects in ``__del__`` all through a compilation) was lost that way, and
the process went on compiling for a minute. :func:`_redeliver_interrupts` hooks
``sys.unraisablehook`` so that such a KeyboardInterrupt is delivered again to the main thread at
its next instruction after the finaliser (``_thread.interrupt_main`` from a short-lived thread),
where it acts as the Ctrl-C the user pressed; other unraisable exceptions go to the previous hook.

**NUMBA_NUM_THREADS.** numba refuses to be imported with ``NUMBA_NUM_THREADS`` below 1 (a
``ValueError`` from deep inside its import). stickslip runs no parallel numba code, so the
setting has no effect on it: a value that is not a number ≥ 1 is removed from this process's
environment before numba is imported, and :data:`notes` says so (the command line prints it as a
warning line).

**Public names on first use.** A package's ``__init__`` that imported every module it re-exports
would make the import of any one of its modules import them all (Python runs a package's
``__init__`` before any module in it): the command line's ``models`` would load numba, and
every command every module of each layer it touches. :func:`export_on_first_use`
makes a package's public names (PEP 562) imported from the module that defines them when first
asked for, as ``from stickslip.integrate import simulate`` or ``stickslip.integrate.simulate``
asks, and keeps a public function named like a module of its package (``stickslip.analysis.classify``)
the function, as the eager import did.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import threading
import time
import types
import _thread

__all__ = ["hold", "release", "notes", "INTERRUPTED_LINE", "export_on_first_use"]

#: What a Ctrl-C during the import leaves: nothing was computed or written yet.
INTERRUPTED_LINE = "interrupted: nothing was written"

#: Messages about the environment, for the caller to show (one line each).
notes: list[str] = []

_state = {"depth": 0, "previous": None, "pending": False}


def _held(signum, frame) -> None:
    if _state["pending"]:  # a second Ctrl-C: out now
        raise KeyboardInterrupt
    _state["pending"] = True


def hold() -> None:
    """Record Ctrl-C instead of raising it, until :func:`release` (nested calls count)."""
    _state["depth"] += 1
    if _state["depth"] > 1 or threading.current_thread() is not threading.main_thread():
        return
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        try:
            _state["previous"] = signal.signal(signal.SIGINT, _held)
        except ValueError:  # pragma: no cover - not the main interpreter
            _state["previous"] = None


def release(raise_pending: bool = True) -> bool:
    """End one :func:`hold`; at the outermost, put the handler back. Returns whether a Ctrl-C was
    held (and forgets it); with ``raise_pending`` such a Ctrl-C raises KeyboardInterrupt instead,
    reported in one line if nothing catches it."""
    _state["depth"] = max(_state["depth"] - 1, 0)
    if _state["depth"] > 0:
        return False
    if _state["previous"] is not None:
        signal.signal(signal.SIGINT, _state["previous"])
        _state["previous"] = None
    pending, _state["pending"] = _state["pending"], False
    if pending and raise_pending:
        _report_once_if_unhandled()
        raise KeyboardInterrupt
    return pending


def _report_once_if_unhandled() -> None:
    """Make an unhandled KeyboardInterrupt print :data:`INTERRUPTED_LINE` instead of a traceback,
    once (the hook then puts the previous one back)."""
    previous = sys.excepthook

    def hook(kind, value, tb):
        sys.excepthook = previous
        if issubclass(kind, KeyboardInterrupt):
            print(INTERRUPTED_LINE, file=sys.stderr)
        else:
            previous(kind, value, tb)

    sys.excepthook = hook


def _check_numba_threads() -> None:
    text = os.environ.get("NUMBA_NUM_THREADS")
    if text is None:
        return
    try:
        valid = int(text.strip()) >= 1
    except ValueError:
        valid = False  # numba would warn and use its default; say it here once instead
    if not valid:
        del os.environ["NUMBA_NUM_THREADS"]
        notes.append(f"NUMBA_NUM_THREADS={text} is not a number of threads >= 1 and is ignored (stickslip runs "
                     "no parallel numba code); unset it or give a number >= 1")


def _interrupt_main_soon() -> None:
    time.sleep(0.02)
    _thread.interrupt_main(signal.SIGINT)


def _redeliver_interrupts() -> None:
    previous = sys.unraisablehook

    def hook(unraisable) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            # from another thread, a moment later: signalled at once, the handler would run inside this hook
            threading.Thread(target=_interrupt_main_soon, daemon=True).start()
        else:
            previous(unraisable)

    if getattr(previous, "__name__", "") != "redeliver_interrupts":
        hook.__name__ = "redeliver_interrupts"
        sys.unraisablehook = hook


class _Package(types.ModuleType):
    """A package whose public names are imported on first use (:func:`export_on_first_use`)."""

    def __setattr__(self, name, value):
        if isinstance(value, types.ModuleType) and name in self.__dict__.get("_EXPORTS", ()):
            return  # a module being bound over the public name it defines: the name is found by __getattr__
        super().__setattr__(name, value)


def export_on_first_use(package: str, exports: dict[str, str]) -> None:
    """Make the public names of ``package`` imported when first asked for (PEP 562).

    Parameters
    ----------
    package : str
        The package's ``__name__`` (its ``__init__`` calls this).
    exports : dict
        Public name → the module that defines it, relative to the package (``".driver"``). Every
        name is a function, class or constant, never a module: a module of the package that has a
        public name's name is not bound over it when it is imported.
    """
    module = sys.modules[package]
    module._EXPORTS = exports

    def __getattr__(name):
        if name in exports:
            value = getattr(importlib.import_module(exports[name], package), name)
            module.__dict__[name] = value
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(set(module.__dict__.get("__all__", ())) | set(exports))

    module.__getattr__ = __getattr__
    module.__dir__ = __dir__
    module.__class__ = _Package


_check_numba_threads()
_redeliver_interrupts()
