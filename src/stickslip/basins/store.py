"""Durable, resumable storage of a basin-stability study.

Beside the NetCDF output ``OUT.nc``, as for sweeps (:mod:`stickslip.sweep.store`, whose journal
this is):

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

from pathlib import Path

import numpy as np

from ..errors import BasinError, SweepError
from ..files import atomic_write, format_name, open_ours
from ..sweep.store import Journal as SweepJournal
from ..sweep.store import journal_dir

__all__ = ["Journal", "journal_dir", "write_dataset", "load_basins", "FORMAT"]

FORMAT = format_name("basins", 1)


class Journal(SweepJournal):
    """The append-only record of classified states of one study, and the lock of its output
    (the sweep journal, :class:`stickslip.sweep.store.Journal`, with a study for a grid).

    Raises
    ------
    stickslip.files.LockError
        If another process is writing the same output.
    BasinError
        If the journal beside ``out`` belongs to a different study (and not ``overwrite``).
    """

    def _open(self, overwrite: bool) -> None:
        try:
            super()._open(overwrite)
        except SweepError:
            raise BasinError(f"{self.dir} holds the journal of a different basin study (model, states or options "
                             "differ); resume with the same arguments, pass overwrite=True (--overwrite), or "
                             "choose another output") from None

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """(flat indices (m,), rows (m, row width)) of every record, the last record of an index kept."""
        blocks = list(self.blocks())
        records = np.concatenate(blocks) if blocks else np.empty((0, self.width))
        idx = records[:, 0].astype(np.int64)
        _, last = np.unique(idx[::-1], return_index=True)
        keep = np.sort(idx.size - 1 - last)
        return idx[keep], records[keep, 1:-1]


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
