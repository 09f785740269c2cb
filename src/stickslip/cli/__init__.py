"""Command line: ``stickslip <command>``. Parse → library call → write; no physics here.

Each command lives in its own module and registers itself on :data:`app` when imported. Ctrl-C
is held while they are imported (:mod:`stickslip._startup`): one pressed then ends the process
with one line, as one pressed while ``stickslip`` itself is imported.
"""

from .. import _startup

_startup.hold()

from ._xarray_dask import defer_dask_array  # noqa: E402

defer_dask_array()  # before anything imports xarray: its first variable then skips importing dask.array

from ._app import app  # noqa: E402

from . import simulate  # noqa: E402,F401  (registers `stickslip simulate`)
from . import stability  # noqa: E402,F401
from . import study  # noqa: E402,F401  (registers `stickslip study timestep`)
from . import reproduce  # noqa: E402,F401  (registers `stickslip reproduce`)
from . import sweep  # noqa: E402,F401  (registers `stickslip sweep`, `bifurcation`, `regions`)
from . import continue_  # noqa: E402,F401  (registers `stickslip continue`)
from . import orbit  # noqa: E402,F401  (registers `stickslip orbit`, `lyapunov`)
from . import basins  # noqa: E402,F401  (registers `stickslip basins`)
from . import models  # noqa: E402,F401  (registers `stickslip models`)
from . import warmup  # noqa: E402,F401  (registers `stickslip warmup`)
from . import reduce  # noqa: E402,F401  (registers `stickslip reduce`)
from . import mode_coupling  # noqa: E402,F401  (registers `stickslip mode-coupling`)

_startup.release()  # a Ctrl-C held during these imports is raised here, reported in one line

__all__ = ["app"]
