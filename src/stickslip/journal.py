"""The resumable store of one output: its lock, a checksummed journal of finished work, its snapshots.

Every resumable computation (sweeps, basin studies, continuation branches, fold curves) that
writes ``OUT`` keeps, while it works:

``OUT.lock``
    The output's lock (:class:`stickslip.files.OutputLock`), held from opening the store until
    :meth:`Journal.close` or :meth:`Journal.remove`: a second writer is refused in one line.
``OUT.journal``
    A header (format :data:`FORMAT`, kind, digest of the settings, the settings, the package
    version) and append-only records, each ``fsync``-ed before :meth:`append` returns and each
    carrying a checksum. Two record kinds:

    * :class:`RowJournal` (sweeps, basins): a folder with ``manifest.json`` (the header) and
      ``rows.f64``, fixed-width little-endian records ``[index, row (width float64), check]``;
      ``check`` is a 64-bit word, :data:`ROW_MAGIC` in its upper half and the CRC-32 of the
      index and row bytes in its lower half.
    * :class:`LineJournal` (continuation points, fold-curve N values): one text file, the header
      on line 1, then one record per line, ``JSON<TAB>CRC-32 of the JSON as 8 hex digits``.

On opening, a record that is torn (a kill inside a write), whose checksum fails or (rows) whose
index is not an integer in range is dropped and its work computed again, never trusted. Rows are
independent, so only the bad ones go; lines are a sequence (the points of a branch), so the
journal is cut at the first bad line. A journal of other settings or another kind, one of an
earlier format (``stickslip-sweep-journal-1``, ``stickslip-continuation-journal-1``: refused,
not read) and one whose header cannot be read are refused in one line naming the fix;
``overwrite`` starts over.

Snapshots of ``OUT`` go through :func:`stickslip.files.write_output` under the held lock (never
onto an input of the run); :meth:`Journal.remove` deletes the journal and releases the lock,
which deletes the lock file.
"""

from __future__ import annotations

import json
import shutil
import tempfile
import zlib
from pathlib import Path

import numpy as np

from ._version import __version__
from .errors import FileFormatError, JournalError, StickSlipError
from .files import AppendLog, OutputLock, atomic_write, fsync_dir, refuse_output, write_output

__all__ = ["Journal", "RowJournal", "LineJournal", "JournalError", "journal_path", "output_path", "finished_output", "FORMAT", "EARLIER_FORMATS",
           "ROW_MAGIC", "READ_ROWS"]

#: Format of every journal's header.
FORMAT = "stickslip-journal-2"

#: Journal formats of earlier versions (records without checksums): refused in one line.
EARLIER_FORMATS = ("stickslip-sweep-journal-1", "stickslip-continuation-journal-1")

#: Upper 32 bits of the check word of every row record ("SLJ2" in ASCII): a zeroed or foreign
#: record fails the check whatever its CRC.
ROW_MAGIC = 0x534C4A32

#: Row records read at once: 4096 records of ~88 float64 = 2.9 MB, whatever the journal length.
READ_ROWS = 4096


def output_path(out, default: str, error: type[Exception]):
    """The output of a resumable run and the temporary folder that holds it when none is given:
    ``(path, tmpdir or None)``; ``default`` names the temporary file (``sweep.nc``).

    Raises
    ------
    error
        For a path that does not end in ``.nc``.
    """
    tmpdir = None
    if out is None:
        tmpdir = tempfile.TemporaryDirectory(prefix=f"stickslip-{Path(default).stem}-")
        out = Path(tmpdir.name) / default
    out = Path(out)
    if out.suffix != ".nc":
        raise error(f"output {out}: give a path ending in .nc")
    out.parent.mkdir(parents=True, exist_ok=True)
    return out, tmpdir


def finished_output(out: Path, digest: str, load, *, what: str, error: type[Exception], overwrite: bool):
    """The result already at ``out`` of the run with ``digest`` (complete or not), or None when
    there is none to take (no file, a journal beside it to resume, or ``overwrite``).

    Parameters
    ----------
    load : callable
        ``load(path) -> xarray.Dataset``: the command's loader (it checks the file is ours).
    what : str
        The run in words for messages ("sweep", "basin study").

    Raises
    ------
    error
        The file is not ours, or holds another run (the message names ``--overwrite``).
    """
    if overwrite or not out.exists() or journal_path(out).exists():
        return None
    try:
        ds = load(out)
    except FileFormatError as exc:
        raise error(f"{exc}; refusing to overwrite it (pass overwrite=True / --overwrite)") from None
    if ds.attrs.get("digest") != digest:
        raise error(f"{out} holds a different {what}; pass overwrite=True (--overwrite) or choose another output")
    return ds


def journal_path(out) -> Path:
    """The journal beside the output ``out``: ``OUT.journal`` (a folder or a file)."""
    return Path(str(out) + ".journal")


class Journal:
    """The journal of one resumable run writing ``out``, and the output's lock (module docstring).

    Parameters
    ----------
    out : path
        The run's output file.
    kind : str
        What the records are (``sweep``, ``basins``, ``branch``, ``fold-curve``).
    digest : str
        Digest of everything that determines the results.
    settings : dict
        Those settings, kept in the header for the record.
    noun : str
        The run in messages ("sweep", "basin study", "branch run").
    differs : str
        What differs when the digest does, in messages ("grid or options differ").
    error : type
        The :class:`~stickslip.errors.StickSlipError` subclass raised (default :class:`JournalError`).
    overwrite : bool
        Discard an existing journal (start over) instead of resuming or refusing it.
    lock : OutputLock, optional
        The output's lock, if the caller holds it already (default: taken here).
    inputs : dict of option → path, optional
        Files the run reads: ``out`` must not be one of them (:func:`stickslip.files.refuse_output`).
    saved : str
        What the records hold, plural, for the messages of a full disk ("the finished points").
    restart : str
        How to start over, for the messages.

    Raises
    ------
    stickslip.files.LockError
        Another process writes ``out``.
    stickslip.files.OutputError
        ``out`` is one of ``inputs`` or a folder.
    error
        The journal is of other settings or kind, of an earlier format, or its header is corrupt.
    """

    #: The file that the records are appended to (set by the subclasses).
    path: Path

    def __init__(self, out, *, kind: str, digest: str, settings, noun: str, differs: str, error=JournalError,
                 overwrite: bool = False, lock: OutputLock | None = None, inputs: dict | None = None,
                 saved: str = "the finished records", restart: str = "pass overwrite=True (--overwrite)"):
        self.out = Path(out)
        self.location = journal_path(self.out)
        self.kind, self.digest, self.settings = kind, digest, settings
        self.noun, self.differs, self.error, self.restart, self.saved = noun, differs, error, restart, saved
        self.inputs = dict(inputs or {})
        self._log = None
        self.lock = (lock or OutputLock(self.out)).acquire()
        with self.lock.released_on_error():
            refuse_output(self.out, overwrite=True, inputs=self.inputs)
            if overwrite:
                self._discard()
            header = self._read_header()
            if header is None:
                self._create(json.dumps(self._header(), default=str))
            else:
                self._check(header)
            self._open()
            self._log = AppendLog(self.path, kept=f"{saved} are kept in {self.location}")

    # ------------------------------------------------------------------ header
    def _header(self) -> dict:
        return {"format": FORMAT, "kind": self.kind, "digest": self.digest, "settings": self.settings,
                "stickslip_version": __version__}

    def _corrupt(self, why: str) -> StickSlipError:
        return self.error(f"{self.location} is corrupt ({why}); {self.restart} to start over (what it holds is "
                          f"computed again), or delete {self.location}")

    def _check(self, header) -> None:
        """Refuse a header that is not this run's (one line naming the fix)."""
        fmt = header.get("format") if isinstance(header, dict) else None
        if not isinstance(fmt, str):
            raise self._corrupt("its header is not that of a stickslip journal")
        if fmt in EARLIER_FORMATS:
            raise self.error(f"{self.location} is the journal of an earlier stickslip (format {fmt}), which stickslip "
                             f"{__version__} does not resume; finish the run with the version that started it, or "
                             f"{self.restart} to start over")
        if fmt != FORMAT:
            raise self.error(f"{self.location} has journal format {fmt!r}, which stickslip {__version__} does not read "
                             f"(it reads {FORMAT}); resume with the stickslip that wrote it, or {self.restart} to "
                             f"start over")
        if header.get("kind") != self.kind or header.get("digest") != self.digest:
            raise self.error(f"{self.location} holds the journal of a different {self.noun} ({self.differs}: digest "
                             f"{header.get('digest')} vs {self.digest}); resume with the same arguments, "
                             f"{self.restart}, or choose another output (--out)")

    # ------------------------------------------------------------------ for the subclasses
    def _read_header(self):
        """The header read back (any JSON value), or None when there is no journal yet."""
        raise NotImplementedError

    def _create(self, header_text: str) -> None:
        """Start a journal whose header is ``header_text`` (one JSON line)."""
        raise NotImplementedError

    def _open(self) -> None:
        """Read the records back, drop the bad ones (module docstring), ready the file for appends."""
        raise NotImplementedError

    def _discard(self) -> None:
        if self.location.is_dir():
            shutil.rmtree(self.location)
        else:
            self.location.unlink(missing_ok=True)

    # ------------------------------------------------------------------ life
    def snapshot(self, write, path=None) -> Path:
        """Write ``path`` (default the output) with ``write(tmp)`` atomically, under the held lock.

        Raises
        ------
        stickslip.files.WriteError
            The disk is full: the file is left as it was, the journal keeps every record.
        """
        path = self.out if path is None else Path(path)
        return write_output(path, write, overwrite=True, inputs=self.inputs,
                            kept=f"{path} is left as it was and {self.saved} are kept in {self.location}")

    def close(self) -> None:
        """Close the journal (it stays on disk, to resume from) and release the output's lock."""
        if self._log is not None:
            self._log.close()
        self.lock.release()

    def remove(self) -> None:
        """Delete the journal (the output is written) and release the output's lock."""
        if self._log is not None:
            self._log.close()
        self._discard()
        fsync_dir(self.location.parent)
        self.lock.release()


class RowJournal(Journal):
    """A journal of fixed-width float64 rows, one per finished point of a grid (a folder).

    Parameters
    ----------
    out : path
    width : int
        Floats per row.
    size : int
        Points of the grid: a record's index must be an integer in [0, size).
    **kwargs
        As :class:`Journal`.
    """

    def __init__(self, out, *, width: int, size: int, **kwargs):
        self.width, self.size = int(width), int(size)
        self.record_bytes = 8 * (self.width + 2)
        self.dir = journal_path(out)
        self.manifest = self.dir / "manifest.json"
        self.path = self.dir / "rows.f64"
        super().__init__(out, **kwargs)

    def _header(self) -> dict:
        return {**super()._header(), "row_width": self.width}

    def _read_header(self):
        if not self.manifest.exists():
            if self.path.exists() and self.path.stat().st_size:
                raise self._corrupt("rows without manifest.json")
            return None
        try:
            return json.loads(self.manifest.read_bytes().decode("utf-8"))
        except ValueError as exc:  # also UnicodeDecodeError
            raise self._corrupt(f"manifest.json cannot be read: {exc}") from None

    def _check(self, header) -> None:
        super()._check(header)
        if header.get("row_width") != self.width:
            raise self.error(f"{self.location} holds rows of {header.get('row_width')!r} numbers where this "
                             f"stickslip writes {self.width} (a journal of another version); finish it with the "
                             f"version that started it, or {self.restart} to start over")

    def _create(self, header_text: str) -> None:
        self.dir.mkdir(parents=True, exist_ok=True)
        fsync_dir(self.dir.parent)
        atomic_write(self.manifest, lambda tmp: tmp.write_text(header_text))

    def _open(self) -> None:
        """Cut a torn tail; rewrite the file without its bad records if it has any (bounded memory)."""
        if not self.path.exists():
            self.path.touch()
            return
        size = self.path.stat().st_size
        if size % self.record_bytes:
            with open(self.path, "r+b") as fh:
                fh.truncate(size - size % self.record_bytes)
        if all(self._decode(raw)[0].all() for raw in self._raw_blocks(READ_ROWS)):
            return

        def keep_good(tmp):
            with open(tmp, "wb") as fh:
                for raw in self._raw_blocks(READ_ROWS):
                    fh.write(raw[self._decode(raw)[0]].tobytes())

        atomic_write(self.path, keep_good)

    def _checks(self, raw: np.ndarray) -> np.ndarray:
        """The check words (m,) uint64 of records ``raw`` (m, record bytes) uint8."""
        crc = np.fromiter((zlib.crc32(r) for r in raw[:, :-8]), dtype=np.uint64, count=raw.shape[0])
        return (np.uint64(ROW_MAGIC) << np.uint64(32)) | crc

    def _decode(self, raw: np.ndarray):
        """(valid (m,) bool, indices (m,) float64, rows (m, width) float64) of records ``raw``."""
        m = raw.shape[0]
        idx = raw[:, :8].copy().view("<f8")[:, 0]
        rows = raw[:, 8:-8].copy().view("<f8").reshape(m, self.width)
        check = raw[:, -8:].copy().view("<u8")[:, 0]
        with np.errstate(invalid="ignore"):
            valid = (check == self._checks(raw)) & np.isfinite(idx) & (idx == np.floor(idx)) \
                & (idx >= 0) & (idx < self.size)
        return valid, idx, rows

    def _raw_blocks(self, rows: int):
        n = self.path.stat().st_size // self.record_bytes
        with open(self.path, "rb") as fh:
            for start in range(0, n, rows):
                count = min(rows, n - start)
                yield np.fromfile(fh, dtype=np.uint8, count=count * self.record_bytes).reshape(count, -1)

    def n_records(self) -> int:
        """Records in the journal file (all checked when it was opened)."""
        return self.path.stat().st_size // self.record_bytes

    def blocks(self, rows: int = READ_ROWS):
        """Yield the good records as (indices (m,) int64, rows (m, width) float64), ``rows`` records at a time."""
        for raw in self._raw_blocks(rows):
            valid, idx, values = self._decode(raw)
            yield idx[valid].astype(np.int64), values[valid]

    def append(self, indices, rows) -> None:
        """Record finished points (one write, ``fsync``-ed before returning)."""
        m = len(indices)
        rec = np.empty((m, self.width + 2), dtype="<f8")
        rec[:, 0] = indices
        rec[:, 1:-1] = rows
        raw = rec.view(np.uint8).reshape(m, self.record_bytes)
        raw[:, -8:] = self._checks(raw).astype("<u8").view(np.uint8).reshape(m, 8)
        self._log.append(raw.tobytes())


class LineJournal(Journal):
    """A journal of JSON records in sequence, one per line of one text file.

    ``records`` holds the good records read back (a prefix of the file's: the journal is cut at
    the first bad one), then those appended.
    """

    def __init__(self, out, **kwargs):
        self.path = journal_path(out)
        self.records: list = []
        super().__init__(out, **kwargs)

    def _read_header(self):
        if not self.path.exists():
            return None
        first, newline, _ = self.path.read_bytes().partition(b"\n")
        try:
            if not newline:
                raise ValueError("no complete first line")
            return json.loads(first.decode("utf-8"))
        except ValueError as exc:  # also UnicodeDecodeError
            raise self._corrupt(f"its header line cannot be read: {exc}") from None

    def _create(self, header_text: str) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(self.path, lambda tmp: tmp.write_text(header_text + "\n"))

    def _open(self) -> None:
        data = self.path.read_bytes()
        good = data.index(b"\n") + 1
        for line in data[good:].split(b"\n")[:-1]:  # the piece after the last newline is torn or empty
            record = _decode_line(line)
            if record is None:
                break
            self.records.append(record)
            good += len(line) + 1
        if good < len(data):
            with open(self.path, "r+b") as fh:
                fh.truncate(good)

    def append(self, record: dict) -> None:
        """Write one record (one line, one ``write``, ``fsync``-ed)."""
        self._log.append(_encode_line(record))
        self.records.append(record)


def _encode_line(record: dict) -> bytes:
    """``JSON<TAB>crc\\n`` (JSON text has no raw tab or newline: json escapes them in strings)."""
    text = json.dumps(record).encode()
    return text + b"\t" + f"{zlib.crc32(text):08x}".encode() + b"\n"


def _decode_line(line: bytes):
    """The record of a line written by :func:`_encode_line`, or None if it is not one."""
    text, tab, crc = line.rpartition(b"\t")
    if not tab or len(crc) != 8 or crc != f"{zlib.crc32(text):08x}".encode():
        return None
    try:
        record = json.loads(text)
    except ValueError:
        return None
    return record if isinstance(record, dict) else None
