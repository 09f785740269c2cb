"""Durable, resumable storage of a basin-stability study.

Beside the NetCDF output ``OUT.nc``:

``OUT.nc.lock``
    Held by the one process writing ``OUT.nc`` and its journal (:class:`stickslip.files.OutputLock`).
``OUT.nc.journal/manifest.json``
    The study (:meth:`~.spec.BasinSpec.to_json`) and its digest.
``OUT.nc.journal/rows.f64``
    Append-only float64 records ``[flat index, outcome row..., SENTINEL]``, one per classified
    state, one ``write`` per batch, ``fsync``-ed before the next batch is recorded
    (:class:`stickslip.files.AppendLog`). A torn last record (a kill inside a write) or one
    without the sentinel is dropped on reopening and computed again.

``OUT.nc`` is written from the journal under a temporary name and renamed onto the output
(:func:`stickslip.files.atomic_write`): at intervals while the study runs, when it is
interrupted, and at the end, after which the journal is removed.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np

from .. import __version__
from ..files import AppendLog, OutputLock, atomic_write, format_name, fsync_dir, open_ours
from .spec import BasinSpec
from .states import BasinError

__all__ = ["Journal", "journal_dir", "write_dataset", "load_basins", "FORMAT"]

FORMAT = format_name("basins", 1)
JOURNAL_FORMAT = "stickslip-basins-journal-1"
#: Last value of every journal record: a record without it was torn by a kill mid-write.
SENTINEL = 8.0e300


def journal_dir(out: Path) -> Path:
    return Path(str(out) + ".journal")


class Journal:
    """The append-only record of classified states of one study, and the lock of its output.

    Opening it takes the output's lock and keeps it until :meth:`close` or :meth:`remove`.

    Raises
    ------
    stickslip.files.LockError
        If another process is writing the same output.
    BasinError
        If the journal beside ``out`` belongs to a different study (and not ``overwrite``).
    """

    def __init__(self, out: Path, spec: BasinSpec, *, overwrite: bool = False):
        self.out = Path(out)
        self.dir = journal_dir(self.out)
        self.spec = spec
        self.width = spec.row_width + 2
        self.lock = OutputLock(self.out).acquire()
        with self.lock.released_on_error():
            self._open(overwrite)

    def _open(self, overwrite: bool) -> None:
        manifest = self.dir / "manifest.json"
        if overwrite and self.dir.exists():
            shutil.rmtree(self.dir)
        if manifest.exists():
            old = json.loads(manifest.read_text())
            if old.get("format") != JOURNAL_FORMAT or old.get("digest") != self.spec.digest:
                raise BasinError(f"{self.dir} holds the journal of a different basin study (model, states or options "
                                 "differ); resume with the same arguments, pass overwrite=True (--overwrite), or "
                                 "choose another output")
        else:
            self.dir.mkdir(parents=True, exist_ok=True)
            fsync_dir(self.dir.parent)
            text = json.dumps({"format": JOURNAL_FORMAT, "digest": self.spec.digest, "spec": self.spec.to_json(),
                               "row_width": self.spec.row_width, "stickslip_version": __version__})
            atomic_write(manifest, lambda tmp: tmp.write_text(text))
        self.path = self.dir / "rows.f64"
        self._repair()
        self._log = AppendLog(self.path, kept=f"classified states are kept in {self.dir}")

    def _repair(self) -> None:
        """Drop a torn tail and records without the sentinel."""
        if not self.path.exists():
            self.path.touch()
            return
        rec = self.width * 8
        size = self.path.stat().st_size
        if size % rec:
            with open(self.path, "r+b") as fh:
                fh.truncate(size - size % rec)
        records = np.fromfile(self.path, dtype=np.float64).reshape(-1, self.width)
        good = records[:, -1] == SENTINEL
        if not np.all(good):
            atomic_write(self.path, lambda tmp: records[good].tofile(tmp))

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """(flat indices (m,), rows (m, row width)) of every record, the last record of an index kept."""
        records = np.fromfile(self.path, dtype=np.float64).reshape(-1, self.width)
        idx = records[:, 0].astype(np.int64)
        _, last = np.unique(idx[::-1], return_index=True)
        keep = np.sort(idx.size - 1 - last)
        return idx[keep], records[keep, 1:-1]

    def append(self, indices: np.ndarray, rows: np.ndarray) -> None:
        """Record classified states (one write, ``fsync``-ed before returning)."""
        rec = np.empty((len(indices), self.width))
        rec[:, 0] = indices
        rec[:, 1:-1] = rows
        rec[:, -1] = SENTINEL
        self._log.append(rec.tobytes())

    def close(self) -> None:
        """Close the journal (it stays on disk) and release the output's lock."""
        self._log.close()
        self.lock.release()

    def remove(self) -> None:
        """Delete the journal (after the output is written) and release the output's lock."""
        self._log.close()
        shutil.rmtree(self.dir, ignore_errors=True)
        fsync_dir(self.dir.parent)
        self.lock.release()


def write_dataset(ds, path: Path, journal: Journal | None = None) -> Path:
    """Write ``ds`` to ``path`` atomically.

    Raises
    ------
    stickslip.files.WriteError
        If the disk is full; ``path`` is left as it was (and the journal keeps every state).
    """
    kept = f"{path} is left as it was" + (f" and classified states are kept in {journal.dir}" if journal else "")
    return atomic_write(path, lambda tmp: ds.to_netcdf(tmp, engine="h5netcdf"), kept=kept)


def load_basins(path, *, load: bool = True):
    """Open a result of :func:`stickslip.basins.basin_stability` as an ``xarray.Dataset``.

    Raises
    ------
    stickslip.files.FileFormatError
        If the file is missing, unreadable, truncated, not a stickslip basins file or of a newer format.
    """
    return open_ours(path, "basins", load=load, what="a .nc file written by `stickslip basins`")
