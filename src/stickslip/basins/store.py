"""Durable, resumable storage of a basin-stability study.

Beside the NetCDF output ``OUT.nc`` (the resumable store of :mod:`stickslip.journal`):

``OUT.nc.lock``
    Held by the one process writing ``OUT.nc`` and its journal (:class:`stickslip.files.OutputLock`).
``OUT.nc.journal/manifest.json``
    The journal's header: format, the study (:meth:`~.spec.BasinSpec.to_json`) with its digest,
    the row width and the package version.
``OUT.nc.journal/rows.f64``
    Append-only checksummed records ``[flat index, outcome row..., check]``
    (:class:`stickslip.journal.RowJournal`), one per classified state, one ``write`` per batch,
    ``fsync``-ed before the next batch is recorded. A torn record, one whose checksum fails and
    one whose index is out of range are dropped on reopening and computed again.

``OUT.nc`` is written from the journal under a temporary name and renamed onto the output
(:func:`stickslip.files.write_output`): at intervals while the study runs, when it is
interrupted, and at the end, after which the journal is removed. The CSV file of the states
(``--ics``) is never written, with or without ``overwrite``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import BasinError
from ..files import format_name, netcdf_writer, open_ours, write_output
from ..journal import RowJournal, journal_path

__all__ = ["Journal", "journal_dir", "write_dataset", "load_basins", "FORMAT"]

FORMAT = format_name("basins", 1)

#: The journal beside an output (``OUT.nc.journal``).
journal_dir = journal_path


class Journal(RowJournal):
    """The append-only record of classified states of one study, and the lock of its output.

    Raises
    ------
    stickslip.files.LockError
        If another process is writing the same output.
    stickslip.files.OutputError
        If the output is the CSV file the states were read from.
    BasinError
        If the journal beside ``out`` belongs to a different study, is of an earlier format or is
        corrupt (and not ``overwrite``).
    """

    def __init__(self, out: Path, spec, *, overwrite: bool = False):
        self.spec = spec
        super().__init__(out, width=spec.row_width, size=spec.size, kind="basins", digest=spec.digest,
                         settings=json.loads(spec.to_json()), noun="basin study",
                         differs="model, states or options differ", error=BasinError, overwrite=overwrite,
                         inputs={"--ics": spec.states.source or None}, saved="the classified states")

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """(flat indices (m,), rows (m, row width)) of every record, the last record of an index kept."""
        blocks = list(self.blocks())
        idx = np.concatenate([b[0] for b in blocks]) if blocks else np.empty(0, dtype=np.int64)
        rows = np.concatenate([b[1] for b in blocks]) if blocks else np.empty((0, self.width))
        _, last = np.unique(idx[::-1], return_index=True)
        keep = np.sort(idx.size - 1 - last)
        return idx[keep], np.ascontiguousarray(rows[keep], dtype=np.float64)


def write_dataset(ds, path: Path, journal: Journal | None = None) -> Path:
    """Write ``ds`` to ``path`` atomically, under the output's lock (never onto the study's input).

    Raises
    ------
    stickslip.files.WriteError
        If the disk is full; ``path`` is left as it was (and the journal keeps every state).
    """
    write = netcdf_writer(ds)
    if journal is not None:
        return journal.snapshot(write, path)
    return write_output(path, write, overwrite=True)


def load_basins(path, *, load: bool = True):
    """Open a result of :func:`stickslip.basins.basin_stability` as an ``xarray.Dataset``.

    Raises
    ------
    stickslip.files.FileFormatError
        If the file is missing, unreadable, truncated, not a stickslip basins file or of a newer format.
    """
    return open_ours(path, "basins", load=load, what="a .nc file written by `stickslip basins`")
