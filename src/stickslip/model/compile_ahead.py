"""A cold start compiles independent kernels in two processes.

A command's first call for a model class compiles a kernel and, inside its type inference, every
kernel it calls, one after the other on one core. Where those callees fall into independent
subtrees, a :class:`Split` names them: the helper's, the ones compiled here meanwhile, and the
caller that loads both from numba's on-disk cache and compiles its own body after them. So when
neither this process nor the cache holds the helper's first kernel for the model's class,
:func:`compile_apart` starts a helper process (on Linux a fork of this one, elsewhere a new
interpreter running :func:`helper_main`) that compiles its subtree into the shared cache, compiles
the other subtree here meanwhile and waits for the helper. The same
kernels are compiled either way, so the results are the same bit for bit.

Each split is declared beside the kernels it compiles: the event loop's callees
(:data:`stickslip.integrate.loop_split.EVENT_LOOP`: ``simulate`` and everything that runs the
event loop), the variational equations of the orbit tools
(:data:`stickslip.orbits.linear_flow.VARIATIONAL`) and steady sliding's complex-step chain
(:data:`stickslip.stability.steady.STEADY`). A split may start its helper before this process
turns to its own side (:func:`start_apart`, :class:`ColdStart`), and a command may hand the split
work it does later anyway (:func:`meanwhile`: the CLI imports what writes its outputs).

Where both subtrees call one large kernel (the event loop's: the friction forces of all
contacts), each process would compile it. A split then has earlier ``stages``, each a pair of the
helper's kernels and this process's: each side starts a stage once the other side's kernels of
the stage before are in the cache (it says so with a marker file), so that the kernels of a stage
load those instead of compiling them again. The stages are balanced by hand from the kernels'
compile times (``benchmarks/profile_jit.py --compile``). Where the helper's kernels of the earlier
stages are compiled or cached already, the split runs as one stage (:meth:`Split.stages_to_run`).

A split names its kernels by reference and derives their argument types: ``calls(md)`` gives
each kernel's arguments as its caller passes them, from the bundles a run builds for the model
data ``md``, and their numba types are the signature (the tests check that they are the
signatures the callers compile). Where the helper cannot run (one core, a model class its process
cannot import, a failure, kernels not cached on disk: :func:`.kernel_cache.caching`) this process
compiles everything itself: the helper only ever adds kernels to the cache.
``STICKSLIP_COMPILE_PROCESSES=1`` turns it off (the test suite does, its workers already fill the
cores; so do the workers of sweeps and basins). The helper is a fork where numba's compiler lock
and compile listeners are as the patch ``fork-helper`` of :mod:`.numba_patches` expects
(:data:`FORK_PATCH`), else a new interpreter.
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import os
import pickle
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba
from numba.core import event

from .kernel_cache import caching
from .numba_patches import Patch, active, first_problem, has

__all__ = ["Split", "ColdStart", "start_apart", "compile_apart", "meanwhile", "enabled"]

#: Seconds to wait for the helper before going on without it.
HELPER_TIMEOUT_S = 600.0


@dataclasses.dataclass(frozen=True)
class Split:
    """Kernels a cold start compiles in two processes.

    Attributes
    ----------
    helper, own : tuple of kernels
        Kernels (numba dispatchers) the helper process compiles, and this process meanwhile (the
        last stage, where the split has ``stages``); the helper's first one tells whether the
        split is a cold start.
    caller : kernel
        The kernel that calls them, compiled after both (its compile event spans the pair).
    calls : callable
        ``calls(md)``: each kernel of every stage mapped to its arguments as its caller
        passes them for the model data ``md`` (arrays, bundles and numbers of the types and layouts
        a run builds); their numba types are the signature compiled (:meth:`signatures`).
    applies : callable, optional
        ``applies(md)``: whether the split's signatures are those the caller compiles for the
        model data ``md`` (default: always).
    stages : tuple of (tuple, tuple), optional
        Earlier stages, each a pair (the helper's kernels, this process's kernels), compiled in
        order before ``helper`` and ``own`` (the last stage): each side starts a stage once the
        other side's kernels of the stage before are in the cache, so that the kernels of a
        stage may call the kernels of the stages before and load them from there.
    """

    helper: tuple
    own: tuple
    caller: Any
    calls: Callable
    applies: Callable | None = None
    stages: tuple = ()

    @property
    def all_stages(self) -> tuple:
        """Every stage, in order: :attr:`stages` and then (``helper``, ``own``)."""
        return self.stages + ((self.helper, self.own),)

    @property
    def kernels(self) -> tuple:
        """Every kernel the split compiles ahead of its caller, either side."""
        return tuple(k for helper, own in self.all_stages for k in helper + own)

    @property
    def one_stage(self) -> tuple:
        """All the stages as one: each side's kernels of every stage, in order, without waits."""
        stages = self.all_stages
        return (tuple(k for helper, _ in stages for k in helper), tuple(k for _, own in stages for k in own)),

    def stages_to_run(self, signatures) -> tuple:
        """The stages a cold start runs: :attr:`all_stages`, or :attr:`one_stage` where the
        helper's kernels of the earlier stages are compiled or cached already (a command compiled
        them before, for another purpose), so that neither side waits for kernels it has."""
        if all(kernel.available(signatures[kernel]) for helper, _ in self.stages for kernel in helper):
            return self.one_stage
        return self.all_stages

    def signatures(self, md) -> dict:
        """Each kernel's argument types for the model data ``md``: the numba types of its
        arguments in :attr:`calls`."""
        return {kernel: tuple(numba.typeof(a) for a in args) for kernel, args in self.calls(md).items()}


_started: set = set()


def enabled() -> bool:
    """Whether a cold start may use a helper process: two or more cores, not turned off
    (``STICKSLIP_COMPILE_PROCESSES=1``; a value that is not a positive integer raises
    :class:`~stickslip.errors.WorkersError`), and the kernels cached on disk, where the helper puts
    what it compiles (:func:`.kernel_cache.caching`)."""
    from ..parallel import compile_processes  # not at import: `import stickslip` does not load it

    return compile_processes() >= 2 and (os.cpu_count() or 1) >= 2 and caching()


def _compile(kernels, signatures) -> None:
    for kernel in kernels:
        with contextlib.suppress(numba.core.errors.NumbaError):
            kernel.compile(signatures[kernel])


class ColdStart:
    """A split's helper at work (:func:`start_apart`): :meth:`finish` compiles this process's side
    and waits for the helper; :meth:`end` stops a helper that is still running (use as a context
    manager, so that an error or Ctrl-C on this side ends it)."""

    def __init__(self, split: Split, signatures, helper, stages: tuple | None = None):
        self.split, self.signatures, self.helper = split, signatures, helper
        self.stages = split.all_stages if stages is None else stages

    def finish(self) -> None:
        """Compile this process's kernels, stage by stage (each once the helper's kernels of the
        stage before are in the cache), run the :func:`meanwhile` work, then wait for the helper."""
        # outermost compile events around this process's compiling and its waits for the helper,
        # so that the time waited counts as compiling and the meanwhile work does not
        compiling = {"dispatcher": self.split.caller, "args": (), "return_type": None}
        for k, (_, own) in enumerate(self.stages):
            with event.trigger_event("numba:compile", data=compiling):
                if k:
                    self.helper.wait_for(f"helper-{k - 1}", HELPER_TIMEOUT_S)
                _compile(own, self.signatures)
            if k < len(self.stages) - 1:
                self.helper.mark(f"own-{k}")
        _run_meanwhile()
        with event.trigger_event("numba:compile", data=compiling):
            self.helper.wait(HELPER_TIMEOUT_S)

    def end(self) -> None:
        self.helper.end()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.end()


def start_apart(md, split: Split, split_name: str) -> ColdStart | None:
    """Start the helper of ``split`` for the model data ``md`` where that is a cold start (module
    docstring); None where it is not, or no helper can run. Once per split, model class and process.

    ``split_name`` is where a helper started as a new interpreter finds ``split``:
    ``"module:attribute"``.
    """
    md_type = numba.typeof(md)
    if (split_name, md_type) in _started or not enabled() or (split.applies is not None and not split.applies(md)):
        return None
    _started.add((split_name, md_type))
    signatures = split.signatures(md)
    probe = split.helper[0]
    if probe.available(signatures[probe]):
        return None
    stages = split.stages_to_run(signatures)
    if _FORK and active("fork-helper"):
        helper = _forked_helper(stages, signatures)
    else:
        helper = _spawned_helper(md, split_name, staged=len(stages) > 1)
    return None if helper is None else ColdStart(split, signatures, helper, stages)


def compile_apart(md, split: Split, split_name: str) -> bool:
    """Compile ``split``'s kernels for ``md`` in two processes where that is a cold start
    (:func:`start_apart`, then :meth:`ColdStart.finish`); returns whether a helper ran."""
    cold = start_apart(md, split, split_name)
    if cold is None:
        return False
    with cold:
        cold.finish()
    return True


_meanwhile: list = []


def _run_meanwhile() -> None:
    while _meanwhile:
        with contextlib.suppress(Exception):  # preparation only: the same work fails again where it is due
            _meanwhile.pop(0)()


@contextlib.contextmanager
def meanwhile(work):
    """Within the block, a cold start's :meth:`ColdStart.finish` calls ``work()`` once, in this
    process, after compiling its own kernels and before waiting for the helper: work the command
    does later anyway (the CLI imports what writes its outputs), which then costs no time where
    the helper's side is the longer one. Errors of ``work`` are ignored there."""
    _meanwhile.append(work)
    try:
        yield
    finally:
        with contextlib.suppress(ValueError):
            _meanwhile.remove(work)


#: Whether the helper is a forked copy of this process (Linux): it then starts at once, with the
#: package imported and the model's data in memory. Elsewhere it is a new interpreter, which
#: imports the package and reads the pickled data first.
_FORK = hasattr(os, "fork") and sys.platform.startswith("linux")


def _helper_side(stages: tuple, signatures, folder: Path) -> None:
    """What the helper process compiles: its kernels of each of the ``stages`` (pairs of the
    helper's kernels and this process's), once this process's kernels of the stage before are in
    the cache (their marker in ``folder``), marking its own when done."""
    for k, (helper, _) in enumerate(stages):
        if k:
            _wait_until((folder / f"own-{k - 1}").exists, lambda: True, HELPER_TIMEOUT_S)
        _compile(helper, signatures)
        if k < len(stages) - 1:
            with contextlib.suppress(OSError):  # without it the other side waits for this one's end
                (folder / f"helper-{k}").touch()


def _wait_until(done, alive, timeout: float) -> None:
    """Wait until ``done()``, while ``alive()``, at most ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while not done() and alive() and time.monotonic() < deadline:
        time.sleep(0.005)


class _Helper:
    """A helper process at work; its stages' marker files and ours in ``folder``."""

    def __init__(self, folder: Path):
        self.folder = folder

    def running(self) -> bool:
        raise NotImplementedError

    def wait(self, timeout: float) -> None:
        """Wait for the helper's end (at most ``timeout`` seconds)."""
        _wait_until(lambda: False, self.running, timeout)

    def wait_for(self, marker: str, timeout: float) -> None:
        """Wait until the helper creates ``marker`` (its kernels of a stage are in the cache), or its end."""
        _wait_until((self.folder / marker).exists, self.running, timeout)

    def mark(self, marker: str) -> None:
        """Tell the helper that this process's kernels of a stage are in the cache; where that
        fails, end the helper (this process compiles the rest)."""
        try:
            (self.folder / marker).touch()
        except OSError:
            self._stop()

    def end(self) -> None:
        """Stop the helper if it still runs, and remove its files."""
        self._stop()
        shutil.rmtree(self.folder, ignore_errors=True)

    def _stop(self) -> None:
        raise NotImplementedError


def _folder() -> Path:
    return Path(tempfile.mkdtemp(prefix="stickslip-cold-"))


class _ForkedHelper(_Helper):
    """A helper forked from this process (:func:`_forked_helper`), by its pid."""

    def __init__(self, pid: int, folder: Path):
        super().__init__(folder)
        self.pid = pid
        self.alive = True

    def running(self) -> bool:
        if self.alive and os.waitpid(self.pid, os.WNOHANG)[0]:
            self.alive = False
        return self.alive

    def _stop(self) -> None:
        if self.alive:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.pid, signal.SIGKILL)
            with contextlib.suppress(ChildProcessError):
                os.waitpid(self.pid, 0)
            self.alive = False


def _forked_helper(stages: tuple, signatures) -> _ForkedHelper | None:
    """Fork the helper: the child compiles the helper's kernels of the ``stages`` of a split into
    the cache and exits, without running anything else of this process (no exit handlers, no
    buffered output)."""
    from numba.core.compiler_lock import global_compiler_lock

    from ..parallel import watch_parent

    parent = os.getpid()
    folder = _folder()
    try:
        with global_compiler_lock:  # no other thread is inside numba's compiler across the fork
            pid = os.fork()
    except OSError:
        shutil.rmtree(folder, ignore_errors=True)
        return None
    if pid:
        return _ForkedHelper(pid, folder)
    status = 1
    try:
        event._registered.clear()  # this process's compile listeners (a command's notice) stay silent
        watch_parent(parent)
        _helper_side(stages, signatures, folder)
        status = 0
    finally:
        os._exit(status)


def _check_fork() -> str | None:
    from numba.core import compiler_lock

    lock = getattr(compiler_lock, "global_compiler_lock", None)
    return first_problem(
        has(compiler_lock, "global_compiler_lock"),
        None if hasattr(lock, "__enter__") and hasattr(lock, "__exit__") else "numba's compiler lock is no context manager",
        None if isinstance(getattr(event, "_registered", None), dict) else "numba.core.event has no _registered dict")


#: Forking the helper with numba's compiler lock held and its listeners cleared in the child, as a
#: patch of :mod:`.numba_patches` (without it the helper is a new interpreter).
FORK_PATCH = Patch("fork-helper", _check_fork, lambda: None)


class _SpawnedHelper(_Helper):
    """A helper started as a new interpreter (:func:`_spawned_helper`); ``path`` the pickled
    model data, in the helper's folder."""

    def __init__(self, process: subprocess.Popen, path: Path):
        super().__init__(path.parent)
        self.process = process
        self.path = path

    def running(self) -> bool:
        return self.process.poll() is None

    def _stop(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


def _spawned_helper(md, split_name: str, staged: bool = True) -> _SpawnedHelper | None:
    """Start the helper as a new interpreter (:func:`helper_main`), with ``md`` pickled to a file;
    ``staged``: whether it runs the split's stages or :attr:`Split.one_stage`."""
    path = _folder() / "model.pkl"
    try:
        with open(path, "wb") as handle:
            pickle.dump(md, handle)
    except Exception:  # noqa: BLE001 - a model that does not pickle compiles here alone
        shutil.rmtree(path.parent, ignore_errors=True)
        return None
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    try:
        process = subprocess.Popen([sys.executable, "-c", _HELPER, str(path), str(os.getpid()), split_name,
                                    "1" if staged else "0"], env=env, stdin=subprocess.DEVNULL,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    except OSError:
        shutil.rmtree(path.parent, ignore_errors=True)
        return None
    return _SpawnedHelper(process, path)


_HELPER = "import sys; from stickslip.model.compile_ahead import helper_main; sys.exit(helper_main(*sys.argv[1:]))"


def helper_main(path: str, parent: str, split_name: str, staged: str = "1") -> int:
    """The helper process: compile the helper's kernels of the split ``split_name``
    (``"module:attribute"``) for the pickled model data at ``path`` into the cache, ending with the
    ``parent`` process; in its stages (``staged`` "1", their marker files beside ``path``) or as one
    stage ("0")."""
    from ..parallel import watch_parent

    watch_parent(int(parent))
    module, attr = split_name.split(":")
    split = getattr(importlib.import_module(module), attr)
    with open(path, "rb") as handle:
        md = pickle.load(handle)  # noqa: S301 - written by the parent process a moment ago
    stages = split.all_stages if staged == "1" else split.one_stage
    _helper_side(stages, split.signatures(md), Path(path).parent)
    return 0
