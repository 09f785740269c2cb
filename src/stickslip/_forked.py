"""Writing a file in a forked child process, so that a crash of the writer ends only the child.

HDF5 does not survive a failed write (a full disk, a file size limit): the errors of its object
finalisers are printed as "Exception ignored" tracebacks, and a later HDF5 call crashes the
process with a segmentation fault, inside the writer or when the file object is finalised (both
measured: xarray's ``to_netcdf`` crashed in ``create_variable``, and ``h5netcdf.File.close``
crashed when the traceback of the error was freed). No cleanup in the same process can prevent
that, so :func:`stickslip.files.atomic_write` writes HDF5 files through :func:`write_in_child`:
the child calls the writer, sends its first error (also one HDF5 could only report from a
finaliser) and its warnings through a pipe, and the parent raises that error and never calls HDF5
on the broken file.
"""

from __future__ import annotations

import io
import os
import pickle
import signal
import sys
import traceback
import warnings
from pathlib import Path

__all__ = ["write_in_child", "in_child", "ChildTraceback"]


class ChildTraceback(Exception):
    """The traceback of an error raised in the writer child (:func:`write_in_child`), as text."""


#: True in a writer child: nested atomic writes run in it directly.
_in_child = False


def in_child() -> bool:
    """Whether this process is a writer child (nested atomic writes then run in it directly)."""
    return _in_child



def _portable(exc: BaseException) -> BaseException:
    """``exc`` if it survives pickling, else an exception of a builtin type with its text (and errno)."""
    try:
        pickle.loads(pickle.dumps(exc))
        return exc
    except Exception:
        if isinstance(exc, OSError):
            return OSError(exc.errno, str(exc))
        return RuntimeError(f"{type(exc).__name__}: {exc}")


def _child_writes(write, tmp: Path, fd: int) -> None:
    """The forked child: ``write(tmp)``, each error and warning sent to the parent through ``fd``.

    An error HDF5 can only report from a finaliser ("Exception ignored in ...") fails the write as
    well: it is sent at once (the child may crash right after), and the file is not trusted.
    Never returns.
    """
    global _in_child
    _in_child = True
    failed = False

    def send(*message) -> None:
        data = pickle.dumps(message)
        while data:
            data = data[os.write(fd, data):]

    def unraisable(info) -> None:
        nonlocal failed
        failed = True
        exc = info.exc_value if info.exc_value is not None else RuntimeError(str(info.err_msg))
        send("error", _portable(exc), "".join(traceback.format_exception(exc)))

    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides what a Ctrl-C does to the write
        sys.unraisablehook = unraisable
        sys.excepthook = lambda *exc_info: None  # Cython prints such errors with it too, before the unraisable hook
        with warnings.catch_warnings(record=True) as caught:
            write(tmp)
        for w in caught:
            send("warning", _portable(w.message))
    except BaseException as exc:
        failed = True
        try:
            send("error", _portable(exc), traceback.format_exc())
        except BaseException:  # pragma: no cover - nothing left to report with
            pass
    finally:
        os._exit(1 if failed else 0)


def write_in_child(write, tmp: Path) -> None:
    """Call ``write(tmp)`` in a forked child process and raise its first error here (module
    docstring); the child's warnings are issued here. Ctrl-C kills the child and raises here.
    Where no child can be started (fork fails), ``write`` runs in this process.

    Raises
    ------
    Exception
        The child's first error, from a :class:`ChildTraceback` holding its traceback; or
        RuntimeError if the child died without reporting one.
    """
    read_fd, write_fd = os.pipe()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # Python >= 3.12 on fork with threads running
            pid = os.fork()
    except OSError:  # no memory or processes left for a child: write here, as without fork
        os.close(read_fd)
        os.close(write_fd)
        write(tmp)
        return
    if pid == 0:  # pragma: no cover - the child; reported through the pipe
        os.close(read_fd)
        _child_writes(write, tmp, write_fd)
    os.close(write_fd)
    chunks, status = [], None
    try:
        while chunk := os.read(read_fd, 1 << 16):
            chunks.append(chunk)
        _, status = os.waitpid(pid, 0)
    except BaseException:  # Ctrl-C: stop the child, then let the caller remove the temporary
        if status is None:
            try:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
            except (ProcessLookupError, ChildProcessError):  # pragma: no cover - it had ended
                pass
        raise
    finally:
        os.close(read_fd)
    messages, stream = [], io.BytesIO(b"".join(chunks))
    while True:
        try:
            messages.append(pickle.load(stream))
        except Exception:  # the end, or a message cut short by a crash of the child
            break
    for kind, *body in messages:
        if kind == "warning":
            warnings.warn(body[0], stacklevel=3)
    errors = [body for kind, *body in messages if kind == "error"]
    if errors:
        exc, text = errors[0]
        raise exc from ChildTraceback(text)
    if status != 0:
        how = f"signal {os.WTERMSIG(status)}" if os.WIFSIGNALED(status) else f"exit code {os.WEXITSTATUS(status)}"
        raise RuntimeError(f"writing {tmp} failed: the writer process ended by {how} without an error")
