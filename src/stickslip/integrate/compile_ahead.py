"""A cold start compiles the event loop's callees in two processes.

A model class's first ``simulate`` on a machine compiles the event loop and, inside its type
inference, every kernel it calls, one after the other on one core. The loop's callees fall into
two subtrees: the stick solve's (:func:`~stickslip.integrate.contacts.try_stick`, the release of
an overloaded stick, the contact forces and the low-speed band's direction) and the step's (the
right-hand side, the Dormand–Prince step, the crossings' probe, the samples). So when neither
this process nor numba's on-disk cache holds the stick solve's kernels for the model's class,
:func:`compile_callees` starts a helper process (:func:`helper_main`) that compiles the stick
solve's subtree into the shared cache, compiles the step's subtree here meanwhile and waits for
the helper; the event loop then loads the helper's kernels from the cache and compiles its own
body. On two cores, from an empty cache: the plates' ``simulate`` −17 % (23–25 s against
28–29 s), a model file's through the command line −18 % (36–37 s against 42–48 s); the same
kernels, so the same results bit for bit. The two subtrees share ``general_forces``, which both
compile: the split is as even as the event loop's call tree allows, and the loop's own body (a
third of the time) compiles after both.

The callees' argument types are written below as short codes (they are the event loop's own
call sites; ``tests/integrate/test_compile_ahead.py`` checks that they are the signatures the
loop compiles, for the plates and for a model file). Where the helper cannot run (one core, a
model class its process cannot import, a failure) this process compiles everything itself as
before: the helper only ever adds kernels to the cache. ``STICKSLIP_COMPILE_PROCESSES=1`` turns it off (the test
suite does, its workers already fill the cores).
"""

from __future__ import annotations

import contextlib
import os
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path

import numba
from numba import types
from numba.core import event

__all__ = ["compile_callees", "enabled", "signature", "HELPER_KERNELS", "OWN_KERNELS"]

#: Kernel → argument codes: v float64[::1], m float64[:, ::1], b int8[::1], i int64, f float64,
#: M the model data.
SIGNATURES = {
    "contacts.try_stick": "v v i M f v v",
    "physics.contact_forces": "v v M v v v",
    "physics.band_direction": "v v i M f",
    "physics.rhs": "v v M v",
    "event_loop.dp_step": "v v f v M m v v",
    "contacts.probed_crossing": "f i i v m f f f v M v v v",
    "contacts.release_most_overloaded": "v v M v v",
    "event_loop.write_samples": "i f v m f f f v M v m b m v v v v",
}

#: Compiled by the helper process: the stick solve's subtree.
HELPER_KERNELS = ("contacts.try_stick", "contacts.release_most_overloaded", "physics.contact_forces",
                  "physics.band_direction")
#: Compiled here meanwhile: the step's subtree.
OWN_KERNELS = ("physics.rhs", "event_loop.dp_step", "contacts.probed_crossing", "event_loop.write_samples")

#: Seconds to wait for the helper before going on without it.
HELPER_TIMEOUT_S = 600.0

_CODES = {"v": types.float64[::1], "m": types.float64[:, ::1], "b": types.int8[::1], "i": types.int64,
          "f": types.float64}
_started: set = set()


def enabled() -> bool:
    """Whether a cold start may use a helper process (two or more cores, not turned off)."""
    from ..parallel import COMPILE_PROCESSES_ENV  # not at import: `import stickslip` does not load it

    return os.environ.get(COMPILE_PROCESSES_ENV, "2").strip() != "1" and (os.cpu_count() or 1) >= 2


def _kernel(name: str):
    from . import contacts, event_loop
    from ..model import physics

    module, attr = name.split(".")
    return getattr({"contacts": contacts, "event_loop": event_loop, "physics": physics}[module], attr)


def signature(name: str, md_type) -> tuple:
    """The argument types of kernel ``name`` (a key of :data:`SIGNATURES`) for model data of numba
    type ``md_type``."""
    return tuple(md_type if code == "M" else _CODES[code] for code in SIGNATURES[name].split())


def _compile(names, md_type) -> None:
    for name in names:
        with contextlib.suppress(numba.core.errors.NumbaError):
            _kernel(name).compile(signature(name, md_type))


def compile_callees(md) -> bool:
    """Compile the event loop's callees for the model data ``md`` in two processes where that is a
    cold start (module docstring); returns whether a helper ran. Once per model class and process."""
    md_type = numba.typeof(md)
    if md_type in _started or not enabled():
        return False
    _started.add(md_type)
    if _kernel(HELPER_KERNELS[0]).available(signature(HELPER_KERNELS[0], md_type)):
        return False
    with tempfile.NamedTemporaryFile(suffix=".pkl", delete=False) as handle:
        path = Path(handle.name)
        try:
            pickle.dump(md, handle)
        except Exception:  # noqa: BLE001 - a model that does not pickle compiles here alone
            handle.close()
            path.unlink(missing_ok=True)
            return False
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    try:
        helper = subprocess.Popen([sys.executable, "-c", _HELPER, str(path), str(os.getpid())], env=env,
                                  stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        path.unlink(missing_ok=True)
        return False
    loop = _kernel("event_loop.event_loop")
    try:
        # one outermost compile event for the pair, so the time waited counts as compiling
        with event.trigger_event("numba:compile", data={"dispatcher": loop, "args": (), "return_type": None}):
            _compile(OWN_KERNELS, md_type)
            try:
                helper.wait(timeout=HELPER_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                helper.kill()
                helper.wait()
    finally:
        if helper.poll() is None:  # interrupted while waiting: the helper ends with us
            helper.kill()
            helper.wait()
        path.unlink(missing_ok=True)
    return True


_HELPER = "import sys; from stickslip.integrate.compile_ahead import helper_main; sys.exit(helper_main(*sys.argv[1:]))"


def helper_main(path: str, parent: str) -> int:
    """The helper process: compile :data:`HELPER_KERNELS` for the pickled model data at ``path``
    into the cache, ending with the ``parent`` process."""
    from ..parallel import watch_parent

    watch_parent(int(parent))
    with open(path, "rb") as handle:
        md = pickle.load(handle)  # noqa: S301 - written by the parent process a moment ago
    _compile(HELPER_KERNELS, numba.typeof(md))
    return 0

