"""Durable files: one writer per output, atomic replacement, durable appends, one loader.

Every stickslip command that writes a file goes through these helpers, so that nothing the user
made is lost and no reader ever sees half a file:

:func:`write_output`
    The one way an output is written: take its lock, refuse an existing file without
    ``overwrite`` and any file the command reads, replace the file atomically, release the lock.
:class:`OutputLock`
    One writer per output: ``OUT.lock`` beside the output, locked with :mod:`filelock` (``flock``)
    and holding the holder's pid, host, start time and command line. A second writer is refused with one line
    naming the holder. The kernel drops the lock with the holder's last descriptor, so a process
    that dies, even by ``kill -9``, never blocks the next writer. The last release deletes the
    file while still holding it, and a taker keeps a lock only if the file it locked is still the
    one at that name (a waiter that locked a deleted file tries again): no two writers can hold
    two different files, and no ``.lock`` file stays beside a finished output.
:func:`atomic_write`
    Replace a file all at once: write a temporary file with a unique name in the same directory,
    ``fsync`` it, rename it onto the target and ``fsync`` the directory. A crash leaves the old
    file or the new one, never a mixture; a full disk leaves the old one and raises
    :class:`WriteError`. HDF5 files (NetCDF-4) are written by a forked child process
    (:mod:`stickslip._forked`): HDF5 does not survive a failed write (it reports errors from its
    finalisers and then crashes the process), so the crash is contained in the child and the
    command reports one line.
:class:`AppendLog`
    A journal file that grows by records, each written whole and ``fsync``-ed before the call
    returns; a record torn by a full disk is cut off again at once.
:func:`read_regular_file`
    Read an input whole, bounded: only a regular file (a folder, a pipe or a device such as
    ``/dev/zero``, also behind a symbolic link, is refused before a byte is read, and a pipe is
    opened without waiting for a writer), and only up to a size limit.
:func:`open_ours`
    Open a NetCDF file written by stickslip and check its kind and format version, with one
    :class:`FileFormatError` line for a missing, foreign, truncated or newer file.
"""

from __future__ import annotations

import datetime
import errno
import json
import os
import re
import secrets
import socket
import stat
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Callable

from filelock import FileLock, Timeout

from . import _forked, _startup
from ._loader import format_name, open_ours
from .errors import DiskFullError, FileFormatError, LockError, OutputError, StickSlipError, WriteError

__all__ = ["FileFormatError", "LockError", "WriteError", "DiskFullError", "OutputError", "OutputLock", "lock",
           "lock_path", "atomic_write", "atomic_write_text", "write_output", "refuse_output", "same_file",
           "temporary_path", "clean_temporaries", "AppendLog", "fsync_dir", "open_ours", "format_name",
           "writing_errors", "netcdf_writer", "save_netcdf", "read_regular_file", "regular_file_size"]


#: ``errno`` values of a full disk, an exhausted quota and a file over ``RLIMIT_FSIZE`` (Python
#: ignores SIGXFSZ, so a write over the size limit fails with EFBIG instead of killing the process).
FULL_ERRNOS = frozenset(e for e in (errno.ENOSPC, getattr(errno, "EDQUOT", None), errno.EFBIG) if e is not None)

#: Texts by which HDF5 reports the same conditions inside its own error messages (h5py does not
#: always carry the ``errno`` over).
_FULL_TEXTS = tuple(os.strerror(e) for e in FULL_ERRNOS)

#: Seconds a refused writer waits for the holder's details to appear in a freshly taken lock.
_HOLDER_READ_S = 0.5

#: Seconds between two tries of a writer that waits for a lock (``timeout`` > 0).
_LOCK_POLL_S = 0.05

#: Suffixes of the files HDF5 writes: these are written by a forked child (:mod:`stickslip._forked`).
HDF5_SUFFIXES = frozenset({".nc", ".nc4", ".h5", ".hdf5"})


# --------------------------------------------------------------------------- errors of writing
def _full_reason(exc: BaseException) -> str | None:
    """The system's words for a full disk or size limit if ``exc`` (or an exception it was
    raised from) reports one ("No space left on device"), else None."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, OSError) and exc.errno in FULL_ERRNOS:
            return os.strerror(exc.errno)
        found = [text for text in _FULL_TEXTS if text in str(exc)]
        if found:
            return found[0]
        exc = exc.__cause__ or exc.__context__
    return None


@contextmanager
def writing_errors(path, kept: str | None = None):
    """Turn a full disk, quota or file size limit while writing ``path`` into one :class:`DiskFullError` line.

    Parameters
    ----------
    path : path
        The file being written (named in the message).
    kept : str, optional
        What is kept and where (e.g. the journal), appended to the message.
    """
    try:
        yield
    except Exception as exc:  # a full disk met by a nested write (a temporary of this one) is named here too
        reason = _full_reason(exc)
        if not isinstance(exc, DiskFullError) and (isinstance(exc, StickSlipError) or reason is None):
            raise
        why = f" ({reason})" if reason else ""
        note = f"; {kept}" if kept else ""
        raise DiskFullError(f"cannot write {path}: the disk or the file size limit is full{why}; free space and run "
                            f"the command again{note}") from exc


# --------------------------------------------------------------------------- atomic replacement
def temporary_path(path) -> Path:
    """A unique temporary name beside ``path``, with its suffix: ``STEM.<pid>-<random>.tmp.SUFFIX``
    (same file system, so the final rename is atomic; same suffix, so writers that choose the
    format by it, such as figures, write the right one)."""
    path = Path(path)
    return path.with_name(f"{path.stem}.{os.getpid()}-{secrets.token_hex(4)}.tmp{path.suffix}")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def clean_temporaries(path) -> list[Path]:
    """Delete the temporary files of ``path`` (:func:`temporary_path`) whose writer is dead.

    Called while holding ``path``'s lock: a temporary of a dead process is never renamed into
    place, so it is garbage (a run killed while writing a snapshot leaves one). Returns the
    files removed.
    """
    path = Path(path)
    removed = []
    if not path.parent.is_dir():
        return removed
    pattern = re.compile(rf"^{re.escape(path.stem)}\.(\d+)-[0-9a-f]{{8}}\.tmp{re.escape(path.suffix)}$")
    for other in path.parent.glob(f"{path.stem}.*.tmp{path.suffix}"):
        m = pattern.match(other.name)
        if m and not _alive(int(m.group(1))):
            other.unlink(missing_ok=True)
            removed.append(other)
    return removed


def fsync_dir(directory) -> None:
    """``fsync`` a directory, so that a rename or a new file in it survives a power cut
    (a no-op where directories cannot be opened, e.g. Windows)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:  # pragma: no cover - Windows
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover - file systems without directory fsync
        pass
    finally:
        os.close(fd)


def _fsync_file(path: Path) -> None:
    with open(path, "rb+") as fh:
        os.fsync(fh.fileno())


def atomic_write(path, write: Callable[[Path], object], *, kept: str | None = None) -> Path:
    """Replace ``path`` by the file that ``write(tmp)`` creates, all at once.

    ``write`` is called with a unique temporary path in the same directory
    (:func:`temporary_path`), in a forked child process for HDF5 files (:data:`HDF5_SUFFIXES`;
    :func:`stickslip._forked.write_in_child`); the temporary is then ``fsync``-ed, renamed onto
    ``path`` and the directory ``fsync``-ed. On any error the temporary is removed and ``path`` is
    left as it was. This does not take the output's lock: outputs go through :func:`write_output`.

    Parameters
    ----------
    path : path
        Target file.
    write : callable
        ``write(tmp: Path)`` writes the whole new content to ``tmp``.
    kept : str, optional
        For the :class:`WriteError` message: what is kept where (e.g. "finished points are kept in
        the journal OUT.nc.journal").

    Returns
    -------
    Path

    Raises
    ------
    WriteError
        If the disk, a quota or the file size limit is full (one line; ``path`` unchanged).
    """
    path = Path(path)
    tmp = temporary_path(path)
    isolate = path.suffix.lower() in HDF5_SUFFIXES and hasattr(os, "fork") and not _forked.in_child()
    try:
        with writing_errors(path, kept or f"{path} is left as it was"):
            if isolate:
                _forked.write_in_child(write, tmp)
            else:
                write(tmp)
            _fsync_file(tmp)
            os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    fsync_dir(path.parent)
    return path


def atomic_write_text(path, text: str) -> Path:
    """Replace the text file ``path`` by ``text`` (UTF-8) all at once (:func:`atomic_write`)."""
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


# --------------------------------------------------------------------------- durable appends
class AppendLog:
    """An append-only file whose records are durable when :meth:`append` returns.

    Each record is written whole (``os.write`` until done), then ``fsync``-ed. If the write fails
    (a full disk) the file is cut back to its length before the record, so it never ends in half
    a record written by this process, and :class:`WriteError` is raised. A Ctrl-C during the
    write and ``fsync`` is held until the record is durable and then raised, so the record of
    finished work is kept (a second Ctrl-C stops at once and cuts the record). Records torn by a
    kill inside a write are for the reader to drop (:mod:`stickslip.journal` checksums every
    record).

    Parameters
    ----------
    path : path
        Created if missing.
    kept : str, optional
        For the :class:`WriteError` message: what is kept.
    """

    def __init__(self, path, *, kept: str | None = None):
        self.path = Path(path)
        self.kept = kept or f"the records before this one are kept in {self.path}"
        self._fd = None
        with writing_errors(self.path, self.kept):
            self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)

    def append(self, data: bytes) -> None:
        """Write ``data`` at the end of the file and ``fsync`` it."""
        start = os.fstat(self._fd).st_size
        view = memoryview(data)
        _startup.hold()
        try:
            with writing_errors(self.path, self.kept):
                while view:
                    view = view[os.write(self._fd, view):]
                os.fsync(self._fd)
        except BaseException:
            try:
                os.ftruncate(self._fd, start)
            except OSError:  # pragma: no cover - the reader drops a torn record anyway
                pass
            raise
        finally:
            ctrl_c = _startup.release(raise_pending=False)
        if ctrl_c:  # pressed during the write: the record is durable now, and the Ctrl-C acts
            raise KeyboardInterrupt

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __del__(self):
        self.close()


# --------------------------------------------------------------------------- one writer per output
def lock_path(path) -> Path:
    """The lock file of output ``path``: ``OUT.lock`` beside it."""
    return Path(str(path) + ".lock")


def _holder_text() -> bytes:
    return (json.dumps({"pid": os.getpid(), "host": socket.gethostname(),
                        "since": datetime.datetime.now().isoformat(timespec="seconds"),
                        "command": " ".join([Path(sys.argv[0]).name] + sys.argv[1:]) if sys.argv else ""})
            + "\n").encode()


def _read_holder(path: Path) -> dict:
    """The holder recorded in lock file ``path`` (``{}`` while it has not written it yet)."""
    deadline = time.monotonic() + _HOLDER_READ_S
    while True:
        try:
            return json.loads(path.read_text())
        except (OSError, ValueError):
            if time.monotonic() > deadline:
                return {}
            time.sleep(0.02)


class _Stale(Exception):
    """The lock file just locked is no longer the one at its name (a holder deleted it on release)."""


def _take_current(path: Path):
    """``on_acquired`` callback of :class:`filelock.FileLock`: keep the lock only when the file it
    locked is still the one at ``path`` (else roll the acquisition back), then record the holder."""

    def on_acquired(fd: int) -> None:
        try:
            current = os.path.samestat(os.fstat(fd), os.stat(path))
        except FileNotFoundError:
            current = False
        if not current:
            raise _Stale
        try:  # who holds it, for a refused writer's message (best effort: a full disk leaves it empty)
            os.ftruncate(fd, 0)
            os.pwrite(fd, _holder_text(), 0)
        except OSError:
            pass

    return on_acquired


class _Hold:
    """A lock this process holds: the file lock, the thread that holds it and how often."""

    def __init__(self, file_lock: FileLock):
        self.file_lock, self.thread, self.count, self.pid = file_lock, threading.get_ident(), 1, os.getpid()


#: Locks held by this process, by the real path of the lock file.
_HOLDS: dict[str, _Hold] = {}
_HOLDS_GUARD = threading.Lock()


class OutputLock:
    """The lock that makes one process at a time the writer of an output file.

    Re-entrant within a thread (a command that holds it may call another that takes it again,
    e.g. ``regions`` around ``sweep``); exclusive between threads and processes. Use as a
    context manager, or :meth:`acquire` / :meth:`release` (idempotent: one release per object).
    The locking is :mod:`filelock`'s (``flock``); the last release in the process deletes the
    lock file while holding it, and a lock taken on a file no longer at its name is given back and
    taken again (module docstring).

    Parameters
    ----------
    path : path
        The output file (not the lock file): the lock is :func:`lock_path` of it.
    timeout : float
        Seconds to wait for another holder [s]: 0 refuses at once, negative waits forever.
    """

    def __init__(self, path, *, timeout: float = 0.0):
        self.output = Path(path)
        self.path = lock_path(self.output)
        self.timeout = float(timeout)
        self._key = os.path.realpath(self.path)
        self._held = False
        self._pid = os.getpid()

    def _refuse(self) -> LockError:
        holder = _read_holder(self.path)
        who = (f"process {holder.get('pid')} on {holder.get('host')} (since {holder.get('since')}: "
               f"{holder.get('command')})") if holder else "another process"
        return LockError(f"{self.output} is being written by {who}; wait for it to finish (or stop it) and run the "
                         f"command again, or choose another output (--out)")

    def _cannot(self, exc: OSError, what: str) -> WriteError:
        return WriteError(f"cannot write {self.output}: {what} fails ({exc.strerror or exc}); choose another path")

    def _try_take(self) -> FileLock | None:
        """The lock of the file at the lock's name, or None while another holds it."""
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise self._cannot(exc, f"creating the folder {self.path.parent}") from None
        try:  # a folder that takes no files (/proc, read-only) is said as such, not as a busy lock
            os.close(os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644))
        except OSError as exc:
            raise self._cannot(exc, f"creating a file in {self.path.parent}") from None
        while True:
            file_lock = FileLock(self.path, timeout=0, thread_local=False, on_acquired=_take_current(self.path))
            try:
                file_lock.acquire()
            except Timeout:
                return None
            except _Stale:
                continue  # locked a file its holder had just deleted: the name holds a new one
            except OSError as exc:
                raise self._cannot(exc, f"locking a file in {self.path.parent}") from None
            return file_lock

    def acquire(self) -> "OutputLock":
        """Take the lock, or raise :class:`LockError` naming the holder and what to do.

        Raises
        ------
        LockError
            Another process or thread holds it (after ``timeout`` seconds).
        WriteError
            The lock file cannot be created or locked there (e.g. ``/proc``, a read-only folder).
        """
        if self._held:
            return self
        deadline = time.monotonic() + self.timeout
        while True:
            with _HOLDS_GUARD:
                hold = _HOLDS.get(self._key)
                if hold is not None and hold.pid != os.getpid():  # a forked child: the parent's, not ours
                    hold = None
                if hold is not None and hold.thread == threading.get_ident():
                    hold.count += 1
                    self._held = True
                    return self
                file_lock = None
                if hold is None:
                    file_lock = self._try_take()
                    if file_lock is not None:
                        _HOLDS[self._key] = _Hold(file_lock)
            if file_lock is not None:
                break
            if 0 <= self.timeout and time.monotonic() >= deadline:
                raise self._refuse()
            time.sleep(_LOCK_POLL_S)
        self._held = True
        clean_temporaries(self.output)
        return self

    def release(self) -> None:
        """Give the lock back; the last release in this process deletes the lock file, then unlocks it."""
        if not self._held or os.getpid() != self._pid:  # a forked child shares the parent's lock: never release it
            return
        self._held = False
        with _HOLDS_GUARD:
            hold = _HOLDS.get(self._key)
            if hold is None:  # pragma: no cover - released twice through another object
                return
            hold.count -= 1
            if hold.count > 0:
                return
            del _HOLDS[self._key]
            try:
                os.unlink(self.path)  # while locked: a waiter that locks the deleted file takes the new one
            except OSError:  # pragma: no cover - the next holder overwrites it anyway
                pass
            hold.file_lock.release()

    @property
    def held(self) -> bool:
        return self._held

    @contextmanager
    def released_on_error(self):
        """Release the lock if the block raises (setting up what it guards failed), then re-raise."""
        try:
            yield self
        except BaseException:
            self.release()
            raise

    def __enter__(self) -> "OutputLock":
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()

    def __del__(self):
        try:
            self.release()
        except Exception:  # pragma: no cover - interpreter shutdown
            pass


def lock(path, *, timeout: float = 0.0) -> OutputLock:
    """Take the lock of output ``path`` (:class:`OutputLock`); use ``with lock(path): ...``.

    Raises
    ------
    LockError
        If another process (or thread) holds it after ``timeout`` seconds.
    """
    return OutputLock(path, timeout=timeout).acquire()


# --------------------------------------------------------------------------- the one writer path
def same_file(a, b) -> bool:
    """Whether paths ``a`` and ``b`` name the same file (also through links)."""
    a, b = Path(a), Path(b)
    try:
        return a.resolve() == b.resolve() or (a.exists() and b.exists() and a.samefile(b))
    except OSError:
        return False


def refuse_output(path, *, overwrite: bool, inputs=None, flag: str = "--out", what: str | None = None,
                  overwrite_hint: str = "--overwrite") -> None:
    """Refuse to write ``path`` onto an input, a folder, or (without ``overwrite``) an existing file.

    Parameters
    ----------
    path : path
    overwrite : bool
        Replace an existing file.
    inputs : dict of option → path, optional
        Files the command reads (None entries skipped); never written, not even with ``overwrite``.
    flag : str
        The option that names ``path``, for the messages.
    what : str, optional
        How the messages name ``path`` (default ``"{flag} {path}"``; e.g. a figure beside the output).
    overwrite_hint : str
        How the caller asks for a replacement (``--overwrite`` on the command line,
        ``overwrite=True`` in Python).

    Raises
    ------
    OutputError
    """
    path = Path(path)
    what = what or f"{flag} {path}"
    for in_flag, in_path in (inputs or {}).items():
        if in_path is not None and same_file(path, in_path):
            raise OutputError(f"{what} is the file given to {in_flag}; an input is never overwritten, "
                              f"give another {flag}")
    if path.is_dir():
        raise OutputError(f"{what} is a directory; give a file name")
    if (path.exists() or path.is_symlink()) and not overwrite:
        raise OutputError(f"{path} exists; pass {overwrite_hint} to replace it, or give another {flag}")


def write_output(path, write: Callable[[Path], object], *, overwrite: bool = False, inputs=None,
                 flag: str = "--out", kept: str | None = None, overwrite_hint: str = "--overwrite") -> Path:
    """Write the output file ``path``: the one path every command's outputs take.

    Takes ``path``'s lock (re-entrant: a command that holds it already keeps it), refuses an
    existing file without ``overwrite`` and any of ``inputs`` (:func:`refuse_output`), replaces
    the file atomically (:func:`atomic_write`) and releases the lock.

    Parameters
    ----------
    path : path
    write : callable
        ``write(tmp: Path)`` writes the whole file to ``tmp``.
    overwrite : bool
        Replace an existing file.
    inputs : dict of option → path, optional
        Files the command reads: never written.
    flag : str
        The option that names ``path`` (messages).
    kept : str, optional
        What a full disk leaves, for the :class:`WriteError` message.
    overwrite_hint : str
        How the caller asks for a replacement, for the :class:`OutputError` message.

    Raises
    ------
    LockError
        Another process writes ``path``.
    OutputError
        ``path`` exists (without ``overwrite``), is a folder or an input.
    WriteError
        The disk is full or the folder takes no files (``path`` unchanged).
    """
    path = Path(path)
    with OutputLock(path):
        refuse_output(path, overwrite=overwrite, inputs=inputs, flag=flag, overwrite_hint=overwrite_hint)
        path.parent.mkdir(parents=True, exist_ok=True)
        return atomic_write(path, write, kept=kept)


def netcdf_writer(ds) -> Callable[[Path], object]:
    """The ``write(tmp)`` callback of :func:`write_output` that writes the ``xarray.Dataset``
    ``ds`` as NetCDF-4 (h5netcdf engine)."""
    return lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf")


def save_netcdf(ds, path, *, overwrite: bool = False, kept: str | None = None) -> Path:
    """Write ``ds`` to ``path`` for a result's ``to_netcdf`` method (:func:`write_output`).

    An existing ``path`` is replaced only with ``overwrite=True`` (else :class:`OutputError`), so
    a finished run is never lost to a second call with the same name.
    """
    return write_output(path, netcdf_writer(ds), overwrite=overwrite, flag="path", kept=kept,
                        overwrite_hint="overwrite=True")


def _open_regular(path, what: str, error: type[StickSlipError]) -> int:
    """A descriptor of ``path`` opened for reading, refused unless it is a regular file (opened
    non-blocking, so that a pipe without a writer does not hang the open; checked on the opened
    file itself, so that nothing can swap it between the check and the read)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise error(f"{what} {path} does not exist; give the path of an existing file") from None
    except OSError as exc:
        raise error(f"{what} {path} cannot be read ({exc.strerror}); give a readable file") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise error(f"{what} {path} is not a regular file (a folder, a pipe or a device); give the path of a file")
    return fd


def regular_file_size(path, what: str, error: type[StickSlipError]) -> int:
    """The size [bytes] of the regular file ``path`` (refused as :func:`read_regular_file` refuses)."""
    fd = _open_regular(path, what, error)
    try:
        return os.fstat(fd).st_size
    finally:
        os.close(fd)


def read_regular_file(path, limit: int, what: str, error: type[StickSlipError],
                      fix: str = "give a smaller file") -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them.

    Raises
    ------
    error
        One line naming ``what`` and ``path``: it does not exist, cannot be read, is not a regular
        file (a folder, a pipe, a device), or holds more than ``limit`` bytes (also when it grows
        past the limit while being read).
    """
    fd = _open_regular(path, what, error)
    too_large = error(f"{what} {path} is larger than {limit:,} bytes, the most such a file may be; {fix}")
    try:
        size = os.fstat(fd).st_size
        if size > limit:
            raise too_large
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(size + 1)  # one byte more than stated: a file that grows is read on
            while 0 < len(data) <= limit:
                more = fh.read(min(2**20, limit + 1 - len(data)))
                if not more:
                    break
                data += more
    except OSError as exc:
        raise error(f"{what} {path} cannot be read ({exc.strerror}); give a readable file") from None
    finally:
        os.close(fd)
    if len(data) > limit:
        raise too_large
    return data
