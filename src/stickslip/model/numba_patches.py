"""Every change stickslip makes to numba's behaviour, installed by one :func:`install`, each checked first.

The compiled layer changes numba in ten ways. Each is a :class:`Patch`: what it changes, a check
that the private names it needs exist with the shape it expects, and what applies it.
:func:`install` (run when :mod:`stickslip.model.jit` is imported) applies the patches whose checks
pass, once per process.

==========================  ==============================================================  ===========================
patch                       what it changes                                                 numba's private names
==========================  ==============================================================  ===========================
``inline-scope-copy``       an inlined callee's variable scope copied once per call, not    ``InlineWorker.inline_ir``,
                            once per block (:mod:`.compile_speedups`)                       ``inline_closurecall.copy``
``inline-ir-once``          an inlined callee translated to IR once per function, not once  ``InlineWorker.inline_function``
                            per call site (:mod:`.compile_speedups`)                        (its source), ``run_untyped_passes``
``flags-hash``              compiler flags hashed once per class (:mod:`.compile_speedups`) ``TargetConfig.__hash__``, ``__eq__``,
                                                                                            ``options``, ``_values``
``call-type-once``          a builtin call typed once per argument types                    ``BaseFunction.get_call_type``
                            (:mod:`.compile_speedups`)                                      (its source), ``_impl_keys``
``live-map-once``           the definitions reaching each block of a function found in one  ``analysis.compute_live_map``
                            pass (:mod:`.compile_speedups`)                                 (its source), ``ir_utils``' import
                                                                                            of it, ``CFGraph.topo_order``
``inline-overload-typed``   an inlined overload's implementation typed, not compiled as a   ``_OverloadFunctionTemplate``'s
                            function of its own (:mod:`.compile_speedups`)                  ``_get_jit_decorator``, ``_build_impl``,
                                                                                            ``generic`` (their source),
                                                                                            ``Dispatcher._can_compile``
``python-entry``            a kernel's CPython wrapper compiled only for Python's calls     ``Dispatcher._compile_for_args``,
                            (:class:`~stickslip.model.jit.KernelDispatcher`)                ``_compiler.targetoptions``,
                                                                                            ``add_overload``, ``overloads``
``standalone-linking``      the largest kernels called, not linked, by their callers        ``FunctionDescriptor._from_python_function``,
                            (:mod:`.linking`)                                               ``CPUCodeLibrary.finalize``,
                                                                                            ``_linking_libraries``,
                                                                                            ``CompileResultCacheImpl.reduce``,
                                                                                            ``rebuild``, ``Cache._load_overload``,
                                                                                            ``JitEngine.is_symbol_defined``
``cache-keeping``           the package's kernels cached with the whole compiled layer's    ``CacheImpl._locator_classes``, the
                            digest, the user code they inline, checksums; an unreadable     in-tree and user-provided locators,
                            index or a failed write survived (:mod:`.kernel_cache`)         ``Cache._index_key``, ``save_overload``,
                                                                                            ``IndexDataCacheFile._load_index``,
                                                                                            ``_save_index``, ``_load_data``,
                                                                                            ``_save_data``, ``_dump``,
                                                                                            ``_open_for_write``
``cache-load``              a cached kernel of the package loaded without numba's           ``Cache.load_overload`` (its
                            implementation registries (:mod:`.kernel_cache`): only the      source), ``_load_overload``,
                            runtime its code links against is initialised                   ``rtsys.initialize``
``fork-helper``             a cold start's helper forked with numba's compiler lock held    ``compiler_lock.global_compiler_lock``,
                            and the compile listeners cleared in the child                  ``event._registered``
                            (:mod:`.compile_ahead`)
==========================  ==============================================================  ===========================

The patches are independent of each other: a patch whose check fails is skipped and the others
install. Each of the groups above is one patch, all of its wrappers or none, because its parts
only work together (a standalone kernel's symbol, its callers' declarations and the cache payload
that records them). Without ``cache-keeping`` the package's kernels are not cached on disk:
numba's own cache checks a kernel against its own file only, and would load a kernel with the old
code of a module it inlines; each process then compiles what it runs, and no cold start forks a
helper (it fills the cache). Without ``standalone-linking`` or ``python-entry`` kernels are
linked and wrapped as numba does; without ``fork-helper`` a cold start's helper is a new
interpreter. The results are the same bit for bit in every case: the patches change how much
numba compiles and when, never the code it emits for a kernel.

Cached kernels of different patch sets never mix: ``cache-keeping`` keys each entry by the
patches that change what an entry holds (a standalone kernel's payload and symbols, a version
without its Python entry), and writes a file format (checksummed) that stock numba reads as
another numba version's, never as its own.

**Versions.** The patches install on the numba versions of :data:`TESTED` (those the test suite
passed on). On another version, or with ``STICKSLIP_NUMBA_PATCHES=0``, none installs and numba
runs as it comes (no on-disk cache of the package's kernels, slower compiles, the same results),
and stderr gets one line saying so. One line also names the patches whose check failed on a
tested version. Such a line is printed once per run: the processes a command starts (the workers
of a sweep, a cold start's helper) share it (:func:`notice`).

**Other numba internals (not patches).** These are used, unchanged, by the compiled layer, and are
part of what the versions of :data:`TESTED` were tested for: :mod:`.stack` builds arrays on a
kernel's stack with ``numba.np.arrayobj.populate_array`` and ``numba.core.cgutils.alloca_once``;
:mod:`.frame_pointers` calls a compiled function through its address in numba's calling
convention (``context.call_conv.get_function_type``, ``get_return_type``, ``_get_arg_packer``,
``numba.core.callconv.excinfo_t``, ``cgutils.get_null_value``, ``context.get_returned_value``), reads
its address with ``library.get_pointer_to_function`` and logs recompiles from
``Dispatcher._cache_misses``; :class:`~stickslip.model.jit.KernelDispatcher` subclasses
``numba.core.registry.CPUDispatcher`` and asks its ``_cache.load_overload`` whether a version is
cached; :mod:`.compile_ahead` and the command line's compile notice listen to numba's compile
events (``numba.core.event``).
"""

from __future__ import annotations

import atexit
import contextlib
import dataclasses
import hashlib
import importlib
import inspect
import json
import os
import secrets
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

import numba

__all__ = ["TESTED", "ENV", "Patch", "install", "active", "status", "notice", "has", "source_has", "end_run"]

#: numba versions (major.minor) the test suite passed on with the patches installed, and stock.
TESTED = ("0.57", "0.58", "0.59", "0.60", "0.61", "0.62", "0.63", "0.64", "0.65", "0.66", "0.67", "0.68")

#: ``STICKSLIP_NUMBA_PATCHES=0``: numba as it comes, none of the patches.
ENV = "STICKSLIP_NUMBA_PATCHES"

#: Shared by the processes of one run (a command and the processes it starts): whose notices are said.
RUN_ENV = "STICKSLIP_RUN_ID"


@dataclasses.dataclass(frozen=True)
class Patch:
    """One change to numba's behaviour.

    Attributes
    ----------
    name : str
        As :func:`active` asks for it and the notices name it.
    check : callable
        ``check()``: None where numba has what the patch needs, else what is missing (one phrase).
    apply : callable
        ``apply()``: makes the change; only called after ``check()`` returned None.
    """

    name: str
    check: Callable[[], str | None]
    apply: Callable[[], None]


_STATUS: dict = {}


def install(patches=None) -> dict:
    """Apply every patch of ``patches`` (a sequence of :class:`Patch`) whose check passes, on a
    numba of :data:`TESTED` and unless ``STICKSLIP_NUMBA_PATCHES=0``; once per process. Returns
    :func:`status`. :mod:`.jit` installs the package's patches as it is imported, before it
    declares kernels, and names them (this module imports none of the modules that define them,
    as each of them imports :class:`Patch` from here); called before that, without ``patches``,
    it imports :mod:`.jit`."""
    if _STATUS:
        return _STATUS
    if patches is None:
        importlib.import_module(f"{__package__}.jit")
        return _STATUS
    version = numba.__version__
    switch = os.environ.get(ENV, "").strip()
    _STATUS.update(version=version, active=frozenset(), skipped={}, reason=None)
    if switch == "0":
        _STATUS["reason"] = f"{ENV}=0"
    elif ".".join(version.split(".")[:2]) not in TESTED:
        _STATUS["reason"] = f"numba {version} is not one of the versions stickslip is tested with " \
                            f"({TESTED[0]}-{TESTED[-1]}); install numba>={TESTED[0]},<{_next_minor(TESTED[-1])}"
    else:
        applied, skipped = [], {}
        with remembered_checks(checks_file()):
            for patch in patches:
                try:
                    problem = patch.check()
                except Exception as exc:  # noqa: BLE001 - a check that fails is a patch that does not fit
                    problem = f"{type(exc).__name__}: {exc}"
                if problem is None:
                    patch.apply()
                    applied.append(patch.name)
                else:
                    skipped[patch.name] = problem
        _STATUS.update(active=frozenset(applied), skipped=skipped)
    _say_status()
    return _STATUS


def _next_minor(minor: str) -> str:
    major, number = minor.split(".")
    return f"{major}.{int(number) + 1}"


def _say_status() -> None:
    if _STATUS["reason"] is not None:
        notice("numba-patches", f"{_STATUS['reason']}: numba runs without stickslip's changes to it, so kernels "
                                "compile more slowly and again in each process (not cached on disk); the results "
                                "are the same")
    elif _STATUS["skipped"]:
        missing = "; ".join(f"{name} ({problem})" for name, problem in _STATUS["skipped"].items())
        notice("numba-patches", f"numba {_STATUS['version']} lacks what some of stickslip's changes to it need, "
                                f"which are off: {missing}; kernels compile more slowly, the results are the same")


def active(name: str) -> bool:
    """Whether the patch ``name`` is installed in this process."""
    return name in install()["active"]


def status() -> dict:
    """``version`` (numba's), ``active`` (names of the installed patches), ``skipped`` (name → what
    its check found missing) and ``reason`` (why none was installed, or None)."""
    return install()


# ----------------------------------------------------------------------------- checks

def has(owner, name: str, params: tuple | None = None) -> str | None:
    """None where ``owner.<name>`` exists (with exactly the parameter names ``params``, where given),
    else what differs."""
    label = f"{getattr(owner, '__name__', owner)}.{name}"
    if not hasattr(owner, name):
        return f"no {label}"
    if params is None:
        return None
    try:
        found = tuple(inspect.signature(getattr(owner, name)).parameters)
    except (TypeError, ValueError):
        return f"{label} has no readable signature"
    return None if found == params else f"{label}{_signature_text(found)} is not {label}{_signature_text(params)}"


def _signature_text(params: tuple) -> str:
    return f"({', '.join(params)})"


def source_has(function, *snippets: str) -> str | None:
    """None where the source text of ``function`` holds every one of ``snippets``, else what is not there.

    Inside :func:`remembered_checks` a check that passed once for the same code (:func:`code_key`)
    passes without reading the source again."""
    key = code_key(function, snippets) if _PASSED is not None else None
    if key is not None and key in _PASSED:
        return None
    try:
        text = inspect.getsource(function)
    except (OSError, TypeError):
        return f"no source of {getattr(function, '__qualname__', function)}"
    missing = [snippet for snippet in snippets if snippet not in text]
    if missing:
        return f"{function.__qualname__} does not read {missing[0]!r}"
    if key is not None:
        _PASSED.add(key)
    return None


# ----------------------------------------------------------------------------- checks remembered

#: Keys (:func:`code_key`) of the source checks that passed, while :func:`remembered_checks` runs; else None.
_PASSED: set | None = None

#: Most keys a file of remembered checks keeps (the package makes some twenty source checks).
MAX_REMEMBERED = 500


def code_key(function, snippets: tuple) -> str | None:
    """A digest of what :func:`source_has` reads, for one check: the compiled code of ``function``
    (that of the function ``inspect.getsource`` reads, behind ``functools.wraps``; its bytecode,
    the names, constants and nested code it holds, its file and first line) and the ``snippets``.
    The same code compiled from the same place gives the same key in every process; a function of
    numba replaced or edited (a wrapper, another release in the same place) gives another. None
    for an object without Python code."""
    code = getattr(inspect.unwrap(function), "__code__", None)
    if code is None:
        return None
    digest = hashlib.sha256(repr(snippets).encode())
    _feed_code(digest, code)
    return digest.hexdigest()


def _feed_code(digest, code) -> None:
    digest.update(code.co_code)
    digest.update(repr((code.co_filename, code.co_firstlineno, code.co_name, code.co_names, code.co_varnames,
                        code.co_freevars, code.co_cellvars)).encode())
    for const in code.co_consts:
        if hasattr(const, "co_code"):
            _feed_code(digest, const)
        else:
            digest.update(repr(sorted(map(repr, const)) if isinstance(const, frozenset) else const).encode())


def checks_file() -> Path:
    """Where the source checks that passed are remembered, per numba version: beside the
    package's cached kernels (numba's ``NUMBA_CACHE_DIR`` where set, else this folder's
    ``__pycache__``)."""
    folder = os.environ.get("NUMBA_CACHE_DIR", "").strip() or Path(__file__).resolve().parent / "__pycache__"
    return Path(folder) / f"stickslip-numba-checks-{numba.__version__}.json"


@contextlib.contextmanager
def remembered_checks(path: Path):
    """Remember the source checks that pass in this block in ``path`` (read at its start, written
    when checks were added): the source text of numba's functions is read once per numba
    install, not at every start (some 10 ms of CPU). A file that cannot be read is an empty memory, one
    that cannot be written leaves the checks unremembered; neither is an error."""
    global _PASSED
    try:
        known = set(json.loads(Path(path).read_text()))
    except (OSError, ValueError, TypeError):
        known = set()
    _PASSED = set(known)
    try:
        yield
    finally:
        passed, _PASSED = _PASSED, None
        if passed - known:
            _write_atomically(Path(path), json.dumps(sorted(passed)[:MAX_REMEMBERED]))


def _write_atomically(path: Path, text: str) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=path.parent, prefix=path.name, suffix=".tmp", delete=False) as f:
            f.write(text)
        os.replace(f.name, path)
    except OSError:
        with contextlib.suppress(OSError, NameError):
            os.unlink(f.name)


def first_problem(*checks) -> str | None:
    """The first problem that ``checks`` find, in order (each a phrase or None, or a function
    returning one, called only where the checks before it found nothing), or None."""
    for check in checks:
        problem = check() if callable(check) else check
        if problem is not None:
            return problem
    return None


# ----------------------------------------------------------------------------- notices

_SAID: set = set()


def _run_id() -> str:
    """This run's id: inherited from the process that started this one, else made here."""
    run = os.environ.get(RUN_ENV)
    if not run:
        run = os.environ[RUN_ENV] = f"{os.getpid()}-{secrets.token_hex(4)}"
    return run


def _marker(key: str) -> Path:
    uid = os.getuid() if hasattr(os, "getuid") else 0
    return Path(tempfile.gettempdir()) / f"stickslip-{uid}-{_run_id()}-{key}"


def notice(key: str, line: str, say: Callable[[str], None] | None = None) -> bool:
    """Say ``line`` (on stderr, prefixed ``stickslip:``; or by ``say(line)``) once per run: not
    again in this process, nor in the processes of the same run (the workers of a sweep or a
    basin study, a cold start's helper) once one of them has said the notice ``key``. Returns
    whether it was said here."""
    if key in _SAID:
        return False
    _SAID.add(key)
    try:
        os.close(os.open(_marker(key), os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600))
    except FileExistsError:
        return False
    except OSError:  # no temporary folder to mark it in: said once in this process
        pass
    if say is None:
        print(f"stickslip: {line}", file=sys.stderr, flush=True)
    else:
        say(line)
    return True


def _forget_markers(run: str, root: int) -> None:
    if os.getpid() != root:  # a forked child that runs exit handlers
        return
    uid = os.getuid() if hasattr(os, "getuid") else 0
    for path in Path(tempfile.gettempdir()).glob(f"stickslip-{uid}-{run}-*"):
        with contextlib.suppress(OSError):
            path.unlink()


#: The run this process is the root of (its id and process id), where it is one.
_ROOT: dict[str, object] = {}


def _start_run() -> None:
    """Make this process the root of a run where it was started by none (its markers removed at exit)."""
    if not os.environ.get(RUN_ENV):
        _ROOT.update(run=_run_id(), pid=os.getpid())
        atexit.register(end_run)


def end_run() -> None:
    """Remove the markers of the run this process is the root of: at exit, or before a process ends
    without running its exit handlers (``os._exit``)."""
    if _ROOT:
        _forget_markers(_ROOT["run"], _ROOT["pid"])


_start_run()
