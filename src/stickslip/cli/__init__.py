"""Command line: ``stickslip <command>``. Parse → library call → write; no physics here.

Each command lives in its own module and registers itself on :data:`app` when imported, which
happens when the command runs or its help is asked for (:mod:`._lazy`): ``stickslip --version``
and ``stickslip --help`` import none of them. Ctrl-C is held while the application is imported
(:mod:`stickslip._startup`): one pressed then ends the process with one line, as one pressed
while ``stickslip`` itself is imported.
"""

from .. import _startup

_startup.hold()

from ._xarray_dask import defer_dask_array  # noqa: E402

defer_dask_array()  # before anything imports xarray: its first variable then skips importing dask.array

from ._app import app  # noqa: E402

_startup.release()  # a Ctrl-C held during these imports is raised here, reported in one line

__all__ = ["app"]
