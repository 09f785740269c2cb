"""The one loader of stickslip's NetCDF files (:func:`open_ours`), re-exported by :mod:`stickslip.files`."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Callable

from ._version import __version__
from .errors import FileFormatError

__all__ = ["FileFormatError", "open_ours", "format_name"]


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
