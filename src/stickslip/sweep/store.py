"""Durable, resumable storage of sweep results.

Layout beside the NetCDF output ``OUT.nc``:

``OUT.nc.journal/manifest.json``
    The :class:`~stickslip.sweep.spec.SweepSpec` (as JSON, with its digest) and the row layout.
``OUT.nc.journal/rows.f64``
    Append-only float64 records ``[flat index, row..., SENTINEL]``, one per finished point,
    appended by the driver as each batch arrives (one ``write`` per batch, flushed to the OS, so
    a killed process loses nothing it had received). On reopening, a torn last record (a kill
    inside a write) and any record without the sentinel are dropped and recomputed.

``OUT.nc`` is assembled from the journal, one variable at a time through a memory map (memory
bounded by one variable, not by the whole result), into a temporary file that replaces the
output atomically, at intervals while the sweep runs and at the end; the journal is then
removed. A killed sweep therefore always leaves either a complete earlier snapshot or none.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np

from .. import __version__
from ..model.parameters import PARAMETER_UNITS, parameter_attrs
from .spec import NAMED_ICS, SweepError, SweepSpec

__all__ = ["Journal", "assemble", "load_sweep", "FORMAT", "journal_dir"]

FORMAT = "stickslip-sweep-1"
JOURNAL_FORMAT = "stickslip-sweep-journal-1"
#: Last value of every journal record: a record without it was torn by a kill mid-write.
SENTINEL = 8.0e300


def journal_dir(out: Path) -> Path:
    return Path(str(out) + ".journal")


class Journal:
    """The append-only record of finished points of one sweep."""

    def __init__(self, out: Path, spec: SweepSpec, *, overwrite: bool = False):
        self.out = Path(out)
        self.dir = journal_dir(self.out)
        self.spec = spec
        self.width = spec.row_width + 2
        manifest = self.dir / "manifest.json"
        if overwrite and self.dir.exists():
            shutil.rmtree(self.dir)
        if manifest.exists():
            old = json.loads(manifest.read_text())
            if old.get("format") != JOURNAL_FORMAT or old.get("digest") != spec.digest:
                raise SweepError(
                    f"{self.dir} holds the journal of a different sweep (grid or options differ); "
                    "resume with the same arguments, pass overwrite=True (--overwrite), or choose another output"
                )
        else:
            self.dir.mkdir(parents=True, exist_ok=True)
            tmp = manifest.with_suffix(".tmp")
            tmp.write_text(json.dumps({"format": JOURNAL_FORMAT, "digest": spec.digest, "spec": spec.to_json(),
                                       "row_width": spec.row_width, "stickslip_version": __version__}))
            os.replace(tmp, manifest)
        self.path = self.dir / "rows.f64"
        self._repair()
        self._fh = open(self.path, "ab")

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
        rows = self._memmap()
        if rows is not None and not np.all(rows[:, -1] == SENTINEL):
            good = np.asarray(rows[rows[:, -1] == SENTINEL])
            del rows
            tmp = self.path.with_suffix(".tmp")
            good.tofile(tmp)
            os.replace(tmp, self.path)

    def _memmap(self):
        n = self.path.stat().st_size // (self.width * 8)
        if n == 0:
            return None
        return np.memmap(self.path, dtype=np.float64, mode="r", shape=(n, self.width))

    def done_mask(self) -> np.ndarray:
        """Boolean (size,) of the points already in the journal."""
        mask = np.zeros(self.spec.size, dtype=bool)
        rows = self._memmap()
        if rows is not None:
            for start in range(0, rows.shape[0], 65536):  # bounded memory for any journal length
                mask[rows[start : start + 65536, 0].astype(np.int64)] = True
        return mask

    def append(self, indices: np.ndarray, rows: np.ndarray) -> None:
        """Record finished points (one write, flushed to the operating system)."""
        rec = np.empty((len(indices), self.width))
        rec[:, 0] = indices
        rec[:, 1:-1] = rows
        rec[:, -1] = SENTINEL
        self._fh.write(rec.tobytes())
        self._fh.flush()

    def close(self) -> None:
        self._fh.close()

    def remove(self) -> None:
        self.close()
        shutil.rmtree(self.dir, ignore_errors=True)

    def column_arrays(self):
        """Yield (name, array of shape grid (+ width), attrs) per column, filled with NaN where missing."""
        rows = self._memmap()
        spec = self.spec
        j = 1
        for name, width, attrs in spec.columns:
            shape = spec.shape + ((width,) if name == "peaks" else ())
            arr = np.full((spec.size,) + shape[len(spec.shape):], np.nan)
            if rows is not None:
                for start in range(0, rows.shape[0], 65536):
                    block = rows[start : start + 65536]
                    idx = block[:, 0].astype(np.int64)
                    arr[idx] = block[:, j] if width == 1 and name != "peaks" else block[:, j : j + width]
            yield name, arr.reshape(shape), attrs
            j += width


def _coords(spec: SweepSpec):
    coords = {}
    for name, values in spec.dims:
        if name in ("model", "ic"):
            attrs = {"long_name": "model variant" if name == "model" else "initial condition"}
            if name == "ic":
                attrs["description"] = json.dumps({v: NAMED_ICS[v] for v in values})
            coords[name] = (name, np.array(values, dtype=object), attrs)
        else:
            unit = PARAMETER_UNITS.get(name, "")
            if name.startswith("perturb_"):
                state = name[8:]
                unit = "rad" if state in ("phi", "psi") else "rad/s" if state in ("dphi", "dpsi") else \
                    "m/s" if state.startswith("d") else "m"
            coords[name] = (name, np.array(values, dtype=float), {"units": unit, "long_name": name})
    return coords


def assemble(journal: Journal, path: Path, *, extra_attrs: dict | None = None) -> Path:
    """Write the journal as a NetCDF-4 dataset (dims = swept names, plus ``peak``) atomically."""
    import xarray as xr

    spec = journal.spec
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    done = journal.done_mask()
    attrs = {
        "format": FORMAT,
        "stickslip_version": __version__,
        "title": "stickslip parameter sweep of the two-plate friction model (reductions per point)",
        "spec": spec.to_json(),
        "digest": spec.digest,
        "parameters": json.dumps(spec.params),
        "model": spec.model, "ic": spec.ic, "method": spec.method,
        "t_end": spec.t_end, "t_from": spec.t_from, "sample_rate": spec.sample_rate,
        "rtol": spec.rtol, "atol": spec.atol,
        "points": spec.size, "points_done": int(done.sum()),
        "complete": int(done.all()),
    }
    attrs.update(parameter_attrs(spec.params))
    attrs.update(extra_attrs or {})
    coords = _coords(spec)
    base = xr.Dataset({"done": (spec.names, done.reshape(spec.shape).astype(np.int8),
                                {"long_name": "point computed (1) or pending (0)"})},
                      coords=coords, attrs=attrs)
    base.to_netcdf(tmp, engine="h5netcdf", mode="w")
    for name, arr, col_attrs in journal.column_arrays():
        dims = spec.names + (("peak",) if name == "peaks" else ())
        xr.Dataset({name: (dims, arr, col_attrs)}, coords=coords).to_netcdf(tmp, engine="h5netcdf", mode="a")
    os.replace(tmp, path)
    return path


def load_sweep(path):
    """Open a sweep written by :func:`stickslip.sweep.sweep` as an ``xarray.Dataset`` (loaded).

    Raises
    ------
    SweepError
        If the file is missing, unreadable, or not a stickslip sweep.
    """
    import xarray as xr

    path = Path(path)
    if not path.is_file():
        raise SweepError(f"{path} does not exist; give a .nc file written by `stickslip sweep`")
    try:
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            ds.load()
    except Exception as exc:  # h5py/xarray raise many types for foreign files
        raise SweepError(f"{path} is not a NetCDF file written by stickslip ({type(exc).__name__}: {exc})") from exc
    if ds.attrs.get("format") != FORMAT:
        raise SweepError(
            f"{path} is not a stickslip sweep (format attribute {ds.attrs.get('format')!r}, expected {FORMAT!r}); "
            "give a file written by `stickslip sweep`, `bifurcation` or `regions`"
        )
    return ds
