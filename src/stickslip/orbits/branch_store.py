"""Append-only journals that make long continuation runs resumable.

A run that writes to ``OUT.nc`` holds the output's lock ``OUT.nc.lock`` (:func:`stickslip.files.lock`:
a second run on the same output is refused with one line naming the holder) and keeps, while it
works, a journal ``OUT.nc.journal`` beside it (as :mod:`stickslip.sweep.store` does for sweeps):
a text file of JSON lines,

* line 1, the header: ``{"format", "kind", "digest", "settings", "stickslip_version"}``,
  written atomically (:func:`stickslip.files.atomic_write`) when the journal is created;
* then one record per finished unit of work (a branch point of
  :func:`~stickslip.orbits.continuation.continue_orbit`, one N of
  :func:`~stickslip.orbits.continuation.fold_curve`), each written with one ``write`` ending in a
  newline and ``fsync``-ed (:class:`stickslip.files.AppendLog`), so a killed process or a power
  cut loses only the unit it was working on, and a full disk loses nothing written before.

On reopening, a torn last line (a kill inside a write: no final newline, or not valid JSON) is cut
off. The digest covers everything that determines the results; a journal or an output file with
another digest is refused (:class:`JournalMismatch`), never mixed in. When the run ends, the
caller writes ``OUT.nc`` atomically (:func:`write_atomically`) and removes the journal, which
releases the lock.

Floats go through JSON as ``repr`` text, which round-trips float64 exactly (NaN as ``NaN``), so a
resumed run restarts from bit-identical numbers.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from .. import __version__
from ..files import AppendLog, FileFormatError, OutputLock, atomic_write, fsync_dir
from .section import OrbitError

__all__ = ["Journal", "JournalMismatch", "journal_path", "digest_of", "array_digest", "encode_array",
           "decode_array", "write_atomically", "check_output", "open_output", "JOURNAL_FORMAT"]

JOURNAL_FORMAT = "stickslip-continuation-journal-1"


class JournalMismatch(OrbitError):
    """A journal or output file at the requested path belongs to a run with other settings."""


def journal_path(out) -> Path:
    """The journal beside the output ``out`` (``OUT.nc.journal``)."""
    return Path(str(out) + ".journal")


def digest_of(settings: dict) -> str:
    """16 hex digits of the SHA-256 of ``settings`` as canonical JSON (sorted keys)."""
    text = json.dumps(settings, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def array_digest(*arrays) -> str:
    """16 hex digits of the SHA-256 of the arrays' dtypes, shapes and bytes."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    return h.hexdigest()[:16]


def encode_array(a) -> dict:
    """An ndarray as JSON-ready ``{"shape", "re"[, "im"]}`` (exact for float64/complex128)."""
    a = np.asarray(a)
    out = {"shape": list(a.shape), "re": np.real(a).astype(float).ravel().tolist()}
    if np.iscomplexobj(a):
        out["im"] = np.imag(a).astype(float).ravel().tolist()
    return out


def decode_array(d: dict) -> np.ndarray:
    """Inverse of :func:`encode_array`."""
    a = np.array(d["re"], dtype=float)
    if "im" in d:
        a = a + 1j * np.array(d["im"], dtype=float)
    return a.reshape(d["shape"])


def write_atomically(path: Path, write) -> Path:
    """Call ``write(tmp)`` on a unique temporary file beside ``path``, then replace ``path`` by it
    (:func:`stickslip.files.atomic_write`: fsync-ed; a full disk raises WriteError, ``path`` unchanged)."""
    return atomic_write(path, write)


def _read_lines(path: Path) -> tuple[list, int]:
    """Complete JSON lines of ``path`` and the byte length they span (a torn tail excluded)."""
    data = path.read_bytes()
    records, good = [], 0
    for line in data.split(b"\n")[:-1]:  # the piece after the last newline is torn or empty
        try:
            records.append(json.loads(line))
        except ValueError:
            break
        good += len(line) + 1
    return records, good


class Journal:
    """The append-only journal of one resumable run.

    Parameters
    ----------
    out : path
        The run's output file; the journal is ``OUT.journal`` beside it.
    kind : str
        What the records are (``branch``, ``fold-curve``); part of the header.
    digest : str
        :func:`digest_of` the settings that determine the results.
    settings : dict
        Stored in the header (JSON), for the record and for :meth:`header`.
    lock : OutputLock, optional
        The output's lock, already held by the caller (default: taken here). Held until
        :meth:`close` or :meth:`remove`.

    Raises
    ------
    JournalMismatch
        If a journal with another kind or digest exists at that path.
    stickslip.files.LockError
        If another process is writing ``out``.
    """

    def __init__(self, out, kind: str, digest: str, settings: dict, lock: OutputLock | None = None):
        self.path = journal_path(out)
        self.kind, self.digest = kind, digest
        self.lock = (lock or OutputLock(out)).acquire()
        with self.lock.released_on_error():
            self._open(settings)

    def _open(self, settings: dict) -> None:
        kind, digest = self.kind, self.digest
        if self.path.exists():
            lines, good = _read_lines(self.path)
            head = lines[0] if lines else {}
            if head.get("format") != JOURNAL_FORMAT or head.get("kind") != kind or head.get("digest") != digest:
                raise JournalMismatch(
                    f"{self.path} is the journal of a different {kind} run (settings or start differ: digest "
                    f"{head.get('digest')} vs {digest}); run again with the same arguments to resume, choose "
                    f"another output (--out) or delete {self.path}")
            if good < self.path.stat().st_size:
                with open(self.path, "r+b") as fh:
                    fh.truncate(good)  # drop the torn last record
            self.records = lines[1:]
        else:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            header = {"format": JOURNAL_FORMAT, "kind": kind, "digest": digest, "settings": settings,
                      "stickslip_version": __version__}
            write_atomically(self.path, lambda tmp: tmp.write_text(json.dumps(header, default=str) + "\n"))
            self.records = []
        self._log = AppendLog(self.path, kept=f"the {kind} computed so far is kept in {self.path}")

    def append(self, record: dict) -> None:
        """Write one record (one line, one ``write``, ``fsync``-ed)."""
        self._log.append((json.dumps(record) + "\n").encode())
        self.records.append(record)

    def close(self) -> None:
        """Close the file (the journal stays on disk) and release the output's lock."""
        self._log.close()
        self.lock.release()

    def remove(self) -> None:
        """Close and delete the journal (after the output is written), then release the lock."""
        self._log.close()
        self.path.unlink(missing_ok=True)
        fsync_dir(self.path.parent)
        self.lock.release()


def check_output(out, kind: str, digest: str, attrs: dict) -> None:
    """Refuse a finished output whose attributes do not carry ``digest``.

    Raises
    ------
    JournalMismatch
        The file was written by a run with other settings (or by an older version, no digest).
    """
    if attrs.get("digest") != digest:
        raise JournalMismatch(f"{out} holds a {kind} of different settings or start (digest {attrs.get('digest')} "
                              f"vs {digest}); choose another output (--out) or delete {out}")


def open_output(out, kind: str, digest: str, settings: dict, resume: bool, read):
    """The journal to continue, or the finished result, of a run writing to ``out``.

    Parameters
    ----------
    out : path
    kind, digest, settings
        As :class:`Journal`.
    resume : bool
        False: delete an existing output and journal first (start over).
    read : callable
        ``read(out)`` → (attrs dict, finished result) of an existing output file.

    Returns
    -------
    (Journal or None, result or None)
        A journal (new, or with the records of an interrupted run) when there is work to do;
        ``(None, result)`` when ``out`` is a finished output of the same settings.

    Raises
    ------
    JournalMismatch
        If the journal or the output file belongs to a run with other settings, or the output
        is not a stickslip file of this kind.
    stickslip.files.LockError
        If another process is writing ``out``.
    """
    out, jp = Path(out), journal_path(out)
    lock = OutputLock(out).acquire()  # before anything is deleted or read: one writer at a time
    with lock.released_on_error():
        if not resume:
            jp.unlink(missing_ok=True)
            out.unlink(missing_ok=True)
        if out.exists() and not jp.exists():
            try:
                attrs, result = read(out)
            except FileFormatError as exc:
                raise JournalMismatch(f"{exc}; refusing to overwrite it: choose another output (--out) or delete "
                                      f"{out}") from None
            check_output(out, kind, digest, attrs)
            lock.release()
            return None, result
        return Journal(out, kind, digest, settings, lock=lock), None
