"""Durable, resumable storage of sweep results.

Layout beside the NetCDF output ``OUT.nc`` (the resumable store of :mod:`stickslip.journal`):

``OUT.nc.lock``
    Held by the one process writing ``OUT.nc`` and its journal (:class:`stickslip.files.OutputLock`):
    a second sweep on the same output is refused with one line naming the holder.
``OUT.nc.journal/manifest.json``
    The journal's header: format, the :class:`~stickslip.sweep.spec.SweepSpec` (as JSON) with its
    digest, the row width and the package version.
``OUT.nc.journal/rows.f64``
    Append-only checksummed records ``[flat index, row..., check]``
    (:class:`stickslip.journal.RowJournal`), one per finished point, appended by the driver as each
    batch arrives (one ``write`` per batch, ``fsync``-ed before the next batch is taken, so neither
    a killed process nor a power cut loses a batch it had received). On reopening, a torn record,
    one whose checksum fails and one whose index is out of range are dropped and recomputed.

``OUT.nc`` is assembled from the journal into a temporary file that replaces the output
atomically (:meth:`stickslip.journal.Journal.snapshot`), at intervals while the sweep runs and at
the end; the journal is then removed. A killed sweep therefore always leaves either a complete
earlier snapshot or none, and a full disk leaves the journal and the previous ``OUT.nc``.

Memory of the assembly does not grow with the grid (beyond one byte per point for the ``done``
mask): the journal is read in blocks of :data:`READ_ROWS` records (plain reads, no memory map,
whose touched pages would count as resident memory), scattered into an index-ordered scratch
file ``OUT.nc.journal/ordered.f64``, and that file is read back in slabs of :data:`SLAB_POINTS`
consecutive grid points, each written into every NetCDF variable as at most 2 × (dimensions)
hyperslabs (:func:`flat_hyperslabs`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .._version import __version__
from ..analysis.outcome import outcome_code
from ..errors import SweepError
from ..files import format_name, open_ours
from ..integrate.initial import start_description
from ..journal import READ_ROWS as JOURNAL_READ_ROWS
from ..journal import RowJournal, journal_path
from ..model.library import describe_system
from ..model.parameters import parameter_attrs
from .spec import ATTRACTOR_ATTRS, SweepSpec, spec_system

__all__ = ["Journal", "assemble", "load_sweep", "FORMAT", "journal_dir", "flat_hyperslabs", "LOAD_LIMIT_POINTS"]

FORMAT = format_name("sweep", 2)

#: Sweeps of this format still read (:func:`load_sweep` gives them in the current one's terms).
EARLIER_FORMAT = format_name("sweep", 1)

#: Journal records read at once (:data:`stickslip.journal.READ_ROWS`, 2.9 MB of ~88 float64 rows;
#: 16384 measured 20 MB more peak at 10^5 points: two blocks and their sorted copies in flight).
READ_ROWS = JOURNAL_READ_ROWS

#: Consecutive grid points written to the NetCDF variables at once: the largest array of the
#: assembly holds SLAB_POINTS × row width float64 (4096 × 86 × 8 B = 2.8 MB with 64 peaks), and
#: 10^6 points still take only ~250 slabs × 23 variables × ≤ 3 hyperslab writes.
SLAB_POINTS = 4096

#: Sweeps up to this many points are returned loaded into memory; larger ones are
#: opened lazily (values read from the file on access), so that returning the result does not
#: hold the whole grid in memory: 65536 points × ~88 float64 = 46 MB at most.
LOAD_LIMIT_POINTS = 65536

#: The journal beside an output (``OUT.nc.journal``).
journal_dir = journal_path


class Journal(RowJournal):
    """The append-only record of finished points of one sweep, and the lock of its output.

    Opening it takes the output's lock (:class:`~stickslip.files.OutputLock`) and keeps it until
    :meth:`close` or :meth:`remove`.

    Raises
    ------
    stickslip.files.LockError
        If another process is writing the same output.
    SweepError
        If the journal beside ``out`` belongs to a different sweep, is of an earlier format or is
        corrupt (and not ``overwrite``).
    """

    def __init__(self, out: Path, spec: SweepSpec, *, overwrite: bool = False):
        self.spec = spec
        super().__init__(out, width=spec.row_width, size=spec.size, kind="sweep", digest=spec.digest,
                         settings=json.loads(spec.to_json()), noun="sweep", differs="grid or options differ",
                         error=SweepError, overwrite=overwrite, saved="the finished points")

    def done_mask(self) -> np.ndarray:
        """Boolean (size,) of the points already in the journal."""
        mask = np.zeros(self.spec.size, dtype=bool)
        for idx, _ in self.blocks(READ_ROWS):
            mask[idx] = True
        return mask

    def write_ordered(self, path: Path) -> None:
        """Scatter the journal rows into ``path`` as (size, row width) float64 in grid order.

        Rows of points not in the journal are left as zeros (a sparse file); the reader masks
        them with :meth:`done_mask`. Each journal block is sorted by index and written as runs
        of consecutive points, so a journal that arrived in order is copied with few writes; a
        point recorded twice keeps its last record.
        """
        row_bytes = self.spec.row_width * 8
        with open(path, "wb") as fh:
            fh.truncate(self.spec.size * row_bytes)
            for idx, rows in self.blocks(READ_ROWS):
                order = np.argsort(idx, kind="stable")
                idx, rows = idx[order], rows[order]
                breaks = np.flatnonzero(np.diff(idx) != 1) + 1
                for lo, hi in zip(np.concatenate([[0], breaks]), np.concatenate([breaks, [idx.size]])):
                    fh.seek(int(idx[lo]) * row_bytes)
                    fh.write(np.ascontiguousarray(rows[lo:hi], dtype=np.float64).tobytes())


def flat_hyperslabs(shape, start: int, stop: int) -> list:
    """The C-order flat index range [start, stop) of an array of ``shape`` as hyperslabs.

    Returns
    -------
    list of (tuple of slice, int, int)
        ``(index, lo, hi)``: ``array[index]`` holds, in C order, the flat elements [lo, hi);
        the ranges tile [start, stop) in order, at most 2 × len(shape) − 1 of them.
    """
    out: list = []

    def split(prefix, shape, a, b, base):
        if a >= b:
            return
        if len(shape) == 1:
            out.append((prefix + (slice(a, b),), base + a, base + b))
            return
        inner = int(np.prod(shape[1:]))
        i0, r0 = divmod(a, inner)
        i1, r1 = divmod(b, inner)
        if i0 == i1:
            split(prefix + (slice(i0, i0 + 1),), shape[1:], r0, r1, base + i0 * inner)
            return
        if r0:
            split(prefix + (slice(i0, i0 + 1),), shape[1:], r0, inner, base + i0 * inner)
            i0 += 1
        if i1 > i0:
            out.append((prefix + (slice(i0, i1),) + tuple(slice(0, n) for n in shape[1:]),
                        base + i0 * inner, base + i1 * inner))
        if r1:
            split(prefix + (slice(i1, i1 + 1),), shape[1:], 0, r1, base + i1 * inner)

    split((), tuple(int(n) for n in shape), int(start), int(stop), 0)
    return out


def _coords(spec: SweepSpec):
    system = spec_system(spec)
    coords = {}
    for name, values in spec.dims:
        if name in ("model", "ic"):
            attrs = {"long_name": "model variant" if name == "model" else "initial condition"}
            if name == "ic":
                attrs["description"] = json.dumps({v: start_description(system, v) for v in values})
            coords[name] = (name, np.array(values, dtype=object), attrs)
        else:
            unit = dict(zip(system.state_names, system.state_units))[name[8:]] if name.startswith("perturb_") \
                else system.units.get(name, "")
            coords[name] = (name, np.array(values, dtype=float), {"units": unit, "long_name": name})
    return coords


def assemble(journal: Journal, path: Path, *, extra_attrs: dict | None = None) -> Path:
    """Write the journal as a NetCDF-4 dataset (dims = swept names, plus ``peak``) atomically.

    Raises
    ------
    stickslip.files.WriteError
        If the disk is full; ``path`` is left as it was and the journal keeps every point.
    """
    import xarray as xr

    spec = journal.spec
    done = journal.done_mask()
    attrs = {
        "format": FORMAT,
        "stickslip_version": __version__,
        "title": f"stickslip parameter sweep of model {spec.model} (reductions per point)",
        "spec": spec.to_json(),
        "digest": spec.digest,
        "parameters": json.dumps(spec.params),
        "model": spec.model, "ic": spec.ic, "method": spec.method,
        "t_end": spec.t_end, "t_from": spec.t_from, "sample_rate": spec.sample_rate,
        "rtol": spec.rtol, "atol": spec.atol,
        "points": spec.size, "points_done": int(done.sum()),
        "complete": int(done.all()),
    }
    system = spec_system(spec)
    attrs.update(parameter_attrs(spec.params, system.units))
    attrs["system"] = json.dumps(describe_system(system))
    attrs["observed"] = system.dofs[system.observed_index]
    attrs.update(extra_attrs or {})
    base = xr.Dataset({"done": (spec.names, done.reshape(spec.shape).astype(np.int8),
                                {"long_name": "point computed (1) or pending (0)"})},
                      coords=_coords(spec), attrs=attrs)
    ordered = journal.dir / "ordered.f64"

    def write(tmp):
        base.to_netcdf(tmp, engine="h5netcdf", mode="w")
        try:
            journal.write_ordered(ordered)
            _write_columns(tmp, ordered, spec, done)
        finally:
            ordered.unlink(missing_ok=True)

    return journal.snapshot(write, path)


def _write_columns(nc_path: Path, ordered: Path, spec: SweepSpec, done: np.ndarray) -> None:
    """Create every reduction variable in ``nc_path`` and fill it slab by slab from ``ordered``."""
    import h5netcdf

    with h5netcdf.File(nc_path, "a") as f:
        f.dimensions["peak"] = spec.n_peaks
        variables = []
        for name, width, attrs in spec.columns:
            dims = spec.names + (("peak",) if name == "peaks" else ())
            var = f.create_variable(name, dims, dtype="f8", fillvalue=np.nan)
            var.attrs.update(attrs)
            variables.append((var, width, name == "peaks"))
        with open(ordered, "rb") as fh:
            for a in range(0, spec.size, SLAB_POINTS):
                b = min(a + SLAB_POINTS, spec.size)
                rows = np.fromfile(fh, dtype=np.float64, count=(b - a) * spec.row_width).reshape(b - a, -1)
                rows[~done[a:b]] = np.nan
                slabs = flat_hyperslabs(spec.shape, a, b)
                j = 0
                for var, width, is_peaks in variables:
                    col = rows[:, j : j + width] if is_peaks else rows[:, j]
                    for index, lo, hi in slabs:
                        block_shape = tuple(s.stop - s.start for s in index) + ((width,) if is_peaks else ())
                        var[index] = col[lo - a : hi - a].reshape(block_shape)
                    j += width


def load_sweep(path, *, load: bool | str = True):
    """Open a sweep written by :func:`stickslip.sweep.sweep` as an ``xarray.Dataset``.

    Parameters
    ----------
    path : path
    load : bool or "auto"
        Read every variable into memory and close the file (``True``), or keep the dataset
        lazily backed by the open file (``False``); ``"auto"`` loads sweeps of at most
        :data:`LOAD_LIMIT_POINTS` points.

    Raises
    ------
    stickslip.files.FileFormatError
        If the file is missing, unreadable, truncated, not a stickslip sweep or of a newer format.
    """
    if load == "auto":
        load = lambda ds: "done" not in ds or ds["done"].size <= LOAD_LIMIT_POINTS  # noqa: E731
    ds = open_ours(path, "sweep", load=load, versions=(1, 2),
                   what="a .nc file written by `stickslip sweep`, `bifurcation` or `regions`")
    return _in_current_terms(ds)


#: The outcome of each steady-state kind code of a format-1 sweep without an ``attractor``
#: variable (equilibrium, periodic slip, periodic stick-slip, non-periodic; −1 failed).
_KIND_OUTCOMES = {0: "equilibrium", 1: "periodic", 2: "periodic", 3: "unsettled", -1: "failed"}


def _in_current_terms(ds):
    """A format-1 sweep as format 2 has it: the outcome of each point in ``attractor`` (a failed
    run's −1 as ``failed``; from the steady-state kind where the file has no ``attractor``) and
    the kind, which the outcome and ``stick_fraction`` say, dropped. The file is not changed."""
    if ds.attrs.get("format") != EARLIER_FORMAT or "kind" not in ds.variables:
        return ds
    failed = outcome_code("failed")
    if "attractor" in ds.variables:
        attractor = ds["attractor"].where(ds["attractor"] != -1, failed)
    else:
        kind = ds["kind"]
        attractor = kind.copy(data=np.full(kind.shape, np.nan))
        for code, name in _KIND_OUTCOMES.items():
            attractor = attractor.where(kind != code, outcome_code(name))
    attractor.attrs = dict(ATTRACTOR_ATTRS)
    return ds.drop_vars("kind").assign(attractor=attractor)
