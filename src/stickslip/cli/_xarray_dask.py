"""xarray without :mod:`dask.array` until something imports it.

The first variable xarray builds asks whether its data is a dask array, and with dask installed
(it is a dependency, for the studies' clusters) xarray imports :mod:`dask.array` to get the
``Array`` type: 0.35–0.7 s on the 2-core machine, in every command that writes a NetCDF file,
though no command holds a dask array. No object is a dask array while :mod:`dask.array` is not
imported, so the command line answers xarray's question with the empty tuple until then and with
:mod:`dask.array`'s ``Array`` once it is imported: the same answer for every object, in either
order. The answer is put in xarray's cache of array modules as xarray is imported
(:func:`defer_dask_array`); where that cache is not there (another xarray) or already holds dask,
nothing changes.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys

__all__ = ["defer_dask_array"]

#: The xarray module that holds the cache of array modules.
PYCOMPAT = "xarray.namedarray.pycompat"


def _install(pycompat) -> None:
    """Put the deferred dask entry in ``pycompat``'s cache (unless it has no such cache, or one
    with dask in it)."""
    cache, base = getattr(pycompat, "_cached_duck_array_modules", None), getattr(pycompat, "DuckArrayModule", None)
    if not isinstance(cache, dict) or base is None or "dask" in cache or importlib.util.find_spec("dask") is None:
        return

    class DaskOnceImported(base):
        """xarray's record of the dask module, with the array type looked up when asked."""

        def __init__(self) -> None:  # base.__init__ imports dask.array
            pass

        available = True

        @property
        def module(self):
            return importlib.import_module("dask")

        @property
        def version(self):
            from packaging.version import Version

            return Version(self.module.__version__)

        @property
        def type(self):
            array = getattr(sys.modules.get("dask.array"), "Array", None)
            return () if array is None else (array,)

    cache["dask"] = DaskOnceImported()


class _OnImport:
    """Finds nothing itself: as :data:`PYCOMPAT` is imported, lets the other finders load it and
    then calls :func:`_install` on it; removes itself at that first import. A meta path finder by
    its ``find_spec`` alone (importing :mod:`importlib.abc` for its base class costs 10 ms of
    every command's start)."""

    def find_spec(self, fullname, path, target=None):
        if fullname != PYCOMPAT:
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        execute = spec.loader.exec_module

        def exec_module(module):
            execute(module)
            _install(module)

        spec.loader.exec_module = exec_module  # this module's own loader (a new one per spec)
        return spec


def defer_dask_array() -> None:
    """Let xarray tell dask arrays apart without importing :mod:`dask.array` before anything
    else does (module docstring): now if xarray is imported, else as it is imported."""
    if PYCOMPAT in sys.modules:
        _install(sys.modules[PYCOMPAT])
    elif not any(isinstance(finder, _OnImport) for finder in sys.meta_path):
        sys.meta_path.insert(0, _OnImport())
