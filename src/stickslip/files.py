"""Durable files: one writer per output, atomic replacement, durable appends, one loader.

Every stickslip command that writes a file goes through these helpers, so that nothing the user
made is lost and no reader ever sees half a file:

:func:`lock`
    One writer per output. A resumable command holds ``OUT.lock`` (a :mod:`filelock` lock on a
    file beside the output, with the holder's pid, host, start time and command line written
    into it) for as long as it writes ``OUT`` or its journal. A second writer is refused with one
    line naming the holder. The lock is a kernel lock (``flock``), so a process that dies, even by
    ``kill -9``, drops it with its last open descriptor and the next writer takes it over; the
    file itself stays (deleting a lock file while others wait on it would split them across two
    files) and is empty whenever nobody holds it.
:func:`atomic_write`
    Replace a file all at once: write a temporary file with a unique name in the same directory,
    ``fsync`` it, rename it onto the target and ``fsync`` the directory. A crash leaves the old
    file or the new one, never a mixture; a full disk leaves the old one and raises
    :class:`WriteError`.
:class:`AppendLog`
    A journal file that grows by records, each written whole and ``fsync``-ed before the call
    returns; a record torn by a full disk is cut off again at once.
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
import sys
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Callable

from ._version import __version__
from .errors import FileFormatError, LockError, StickSlipError, WriteError

__all__ = ["FileFormatError", "LockError", "WriteError", "OutputLock", "lock", "lock_path", "atomic_write",
           "atomic_write_text",
           "temporary_path", "clean_temporaries", "AppendLog", "fsync_dir", "open_ours", "format_name",
           "writing_errors"]


#: ``errno`` values of a full disk, an exhausted quota and a file over ``RLIMIT_FSIZE``.
FULL_ERRNOS = frozenset(e for e in (errno.ENOSPC, getattr(errno, "EDQUOT", None), errno.EFBIG) if e is not None)

#: Texts by which HDF5 reports the same conditions inside its own error messages (h5py does not
#: always carry the ``errno`` over).
_FULL_TEXTS = tuple(os.strerror(e) for e in FULL_ERRNOS)

#: Seconds a refused writer waits for the holder's details to appear in a freshly taken lock.
_HOLDER_READ_S = 0.5


# --------------------------------------------------------------------------- errors of writing
def _is_full(exc: BaseException) -> bool:
    """Whether ``exc`` (or an exception it was raised from) reports a full disk or size limit."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, OSError) and exc.errno in FULL_ERRNOS:
            return True
        if any(text in str(exc) for text in _FULL_TEXTS):
            return True
        exc = exc.__cause__ or exc.__context__
    return False


@contextmanager
def writing_errors(path, kept: str | None = None):
    """Turn a full disk, quota or file size limit while writing ``path`` into one :class:`WriteError` line.

    Parameters
    ----------
    path : path
        The file being written (named in the message).
    kept : str, optional
        What is kept and where (e.g. the journal), appended to the message.
    """
    try:
        yield
    except Exception as exc:
        if isinstance(exc, StickSlipError) or not _is_full(exc):
            raise
        note = f"; {kept}" if kept else ""
        raise WriteError(f"cannot write {path}: the disk or the file size limit is full; free space and run the "
                         f"command again{note}") from exc


# --------------------------------------------------------------------------- atomic replacement
def temporary_path(path) -> Path:
    """A unique temporary name beside ``path``: ``NAME.<pid>-<random>.tmp`` in the same directory
    (same file system, so the final rename is atomic)."""
    path = Path(path)
    return path.with_name(f"{path.name}.{os.getpid()}-{secrets.token_hex(4)}.tmp")


_TEMPORARY = re.compile(r"\.(\d+)-[0-9a-f]{8}\.tmp$")


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
    for other in path.parent.glob(f"{path.name}.*.tmp"):
        m = _TEMPORARY.search(other.name)
        if m and other.name == f"{path.name}{m.group(0)}" and not _alive(int(m.group(1))):
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


def _abandon_netcdf(path: Path) -> None:
    """Mark every ``h5netcdf.File`` still open on ``path`` closed, so that nothing writes to it again.

    After a failed HDF5 write (a full disk) the writer may be left open (xarray keeps it in its
    file cache when closing it fails); its next ``close``, from the cache or from ``__del__``, would
    flush the NetCDF metadata into the broken file and h5py then crashes the process. ``path``
    is a temporary that is deleted anyway.
    """
    h5netcdf = sys.modules.get("h5netcdf")
    if h5netcdf is None:
        return
    import gc

    for obj in gc.get_objects():
        if isinstance(obj, h5netcdf.File) and not getattr(obj, "_closed", True) \
                and str(getattr(obj, "_filename", "")) == str(path):  # no HDF5 call: any may crash now
            obj._closed = True  # its close() (also from __del__) must not flush again


def atomic_write(path, write: Callable[[Path], object], *, kept: str | None = None) -> Path:
    """Replace ``path`` by the file that ``write(tmp)`` creates, all at once.

    ``write`` is called with a unique temporary path in the same directory
    (:func:`temporary_path`); the temporary is then ``fsync``-ed, renamed onto ``path`` and the
    directory ``fsync``-ed. On any error the temporary is removed and ``path`` is left as it was.

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
    try:
        with writing_errors(path, kept or f"{path} is left as it was"):
            write(tmp)
            _fsync_file(tmp)
            os.replace(tmp, path)
    except BaseException:
        _abandon_netcdf(tmp)
        raise
    finally:
        tmp.unlink(missing_ok=True)
    fsync_dir(path.parent)
    return path


# --------------------------------------------------------------------------- durable appends
class AppendLog:
    """An append-only file whose records are durable when :meth:`append` returns.

    Each record is written whole (``os.write`` until done), then ``fsync``-ed. If the write fails
    (a full disk) the file is cut back to its length before the record, so it never ends in half
    a record written by this process, and :class:`WriteError` is raised. Records torn by a kill
    inside a write are for the reader to drop (each journal format marks complete records).

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

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __del__(self):
        self.close()


def atomic_write_text(path, text: str) -> Path:
    """Replace the text file ``path`` by ``text`` (UTF-8) all at once (:func:`atomic_write`)."""
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


# --------------------------------------------------------------------------- one writer per output
def lock_path(path) -> Path:
    """The lock file of output ``path``: ``OUT.lock`` beside it."""
    return Path(str(path) + ".lock")


def _holder_text() -> str:
    return json.dumps({"pid": os.getpid(), "host": socket.gethostname(),
                       "since": datetime.datetime.now().isoformat(timespec="seconds"),
                       "command": " ".join([Path(sys.argv[0]).name] + sys.argv[1:]) if sys.argv else ""})


def _read_holder(path: Path) -> dict:
    """The holder recorded in lock file ``path`` (``{}`` while it has not written it yet)."""
    deadline = time.monotonic() + _HOLDER_READ_S
    while True:
        try:
            text = path.read_text()
            return json.loads(text)
        except (OSError, ValueError):
            if time.monotonic() > deadline:
                return {}
            time.sleep(0.02)


class OutputLock:
    """The lock that makes one process at a time the writer of an output file.

    Re-entrant within a thread (a command that holds it may call another that takes it again,
    e.g. ``regions`` around ``sweep``); exclusive between threads and processes. Use as a
    context manager, or :meth:`acquire` / :meth:`release` (idempotent: one release per object).

    Parameters
    ----------
    path : path
        The output file (not the lock file): the lock is :func:`lock_path` of it.
    timeout : float
        Seconds to wait for another holder [s]: 0 refuses at once, negative waits forever.
    """

    def __init__(self, path, *, timeout: float = 0.0):
        from filelock import FileLock

        self.output = Path(path)
        self.path = lock_path(self.output)
        self.timeout = float(timeout)
        self._lock = FileLock(str(self.path), is_singleton=True)
        self._held = False
        self._pid = os.getpid()

    def acquire(self) -> "OutputLock":
        """Take the lock, or raise :class:`LockError` naming the holder and what to do."""
        from filelock import Timeout

        if self._held:
            return self
        self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self._lock.acquire(timeout=self.timeout)
        except Timeout:
            holder = _read_holder(self.path)
            who = (f"process {holder.get('pid')} on {holder.get('host')} (since {holder.get('since')}: "
                   f"{holder.get('command')})") if holder else "another process"
            raise LockError(f"{self.output} is being written by {who}; wait for it to finish (or stop it) and run "
                            f"the command again, or choose another output (--out)") from None
        self._held = True
        if self._lock.lock_counter == 1:  # first hold in this process: record us, drop dead writers' leftovers
            with open(self.path, "w") as fh:
                fh.write(_holder_text() + "\n")
            clean_temporaries(self.output)
        return self

    def release(self) -> None:
        """Give the lock back (the file stays, emptied when the last hold in this process ends)."""
        if not self._held or os.getpid() != self._pid:  # a forked child shares the parent's lock: never release it
            return
        self._held = False
        if self._lock.lock_counter == 1:
            try:
                with open(self.path, "w"):
                    pass
            except OSError:  # pragma: no cover - the next holder overwrites it anyway
                pass
        self._lock.release()

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


# --------------------------------------------------------------------------- one loader
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_FORMAT = re.compile(r"^stickslip-([a-z]+)-(\d+)$")


def format_name(kind: str, version: int = 1) -> str:
    """The ``format`` attribute of a stickslip file: ``stickslip-<kind>-<version>``."""
    return f"stickslip-{kind}-{version}"


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}".rstrip(": ")


def open_ours(path, kind: str, *, what: str, versions=(1,), noun: str | None = None,
              load: bool | Callable[[object], bool] = True):
    """Open a NetCDF file written by stickslip and check that it is a ``kind`` file we can read.

    Parameters
    ----------
    path : path
    kind : str
        The expected kind, the middle of the ``format`` attribute (``sweep``, ``trajectory``,
        ``branch``, ...; see :func:`format_name`).
    what : str
        What the user should give instead, for the messages (e.g. "a .nc file written by
        `stickslip sweep`").
    versions : sequence of int
        Format versions this code reads.
    noun : str, optional
        How the messages name the kind (default ``kind``).
    load : bool or callable
        Read every variable into memory and close the file, or keep the dataset lazily backed by
        the open file; a callable decides from the opened dataset.

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    FileFormatError
        One line: the file is missing, not NetCDF-4/HDF5, truncated or corrupt, not written by
        stickslip, of another kind, or of a format version this code does not read.
    """
    import xarray as xr

    path = Path(path)
    noun = noun or kind
    if not path.is_file():
        raise FileFormatError(f"{path} does not exist; give {what}")
    try:
        with open(path, "rb") as fh:
            head = fh.read(len(_HDF5_SIGNATURE))
    except OSError as exc:
        raise FileFormatError(f"{path} cannot be read ({_first_line(exc)}); give {what}") from exc
    if head != _HDF5_SIGNATURE:
        raise FileFormatError(f"{path} is not a stickslip NetCDF file (not NetCDF-4/HDF5: "
                              f"{'empty' if not head else 'wrong signature'}); give {what}")
    ds = None
    try:
        ds = xr.open_dataset(path, engine="h5netcdf")
        fmt = ds.attrs.get("format")
        m = _FORMAT.match(fmt) if isinstance(fmt, str) else None
        if m is None:
            raise FileFormatError(f"{path} is not a stickslip {noun} file (format attribute {fmt!r}); give {what}")
        if m.group(1) != kind:
            raise FileFormatError(f"{path} is a stickslip {m.group(1)} file, not a stickslip {noun} file; give {what}")
        if int(m.group(2)) not in versions:
            raise FileFormatError(
                f"{path} is a stickslip {noun} file of format version {m.group(2)}, which stickslip {__version__} "
                f"does not read (it reads {', '.join(map(str, versions))}); open it with the stickslip version that "
                f"wrote it, or run the command that made it again")
        if load is True or (callable(load) and load(ds)):
            ds.load()
            ds.close()
    except FileFormatError:
        if ds is not None:
            ds.close()
        raise
    except Exception as exc:  # h5py/xarray raise many types for damaged files
        if ds is not None:
            ds.close()
        raise FileFormatError(f"{path} is truncated or corrupt ({_first_line(exc)}); give {what}, or run the "
                              f"command that wrote it again") from exc
    return ds
