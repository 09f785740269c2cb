"""The one way compiled kernels are declared in stickslip.

``kernel``: numba ``njit`` with an on-disk cache and *without* the numba runtime (NRT). Kernels
only read and write the arrays they are given and never allocate, so they need no reference
counting; compiled without NRT their calls carry no atomic incref/decref per array argument,
which halves the cost of the right-hand side (measured 189 → 84 ns per call, N = 50 N,
Ω = 5 rad/s). Functions that allocate (the orbit tools' segment integrator, steady sliding) use
``loop`` (plain cached ``njit``); they allocate only on entry and never reassign an array variable
inside their main loop, since numba reference-counts loop-carried arrays on every iteration
(``transitions.record_transition``). The simulators' loops are kernels whose arrays their Python
callers allocate (``integrate/bundles.py``).

``inlined_kernel``: a ``kernel`` that numba inlines into its callers (typed IR). For small
kernels on the innermost path (``forces.slip_force``, ``forces.add_contact_force``,
``forces.rotated``) and for the right-hand side's body ``physics.rhs_body`` at exactly one call
site per integrator step,
inside the loop over its stages (a call passes each array as 7 words, ~40 per rhs; inlined:
−1.5…6 % per fixed-step run). Each inlined copy of the rhs costs ~2.3 s of cold compile: three
copies (one per RK4 stage) took it +5…9 s for about the speed of one copy in a loop. Inlining
larger step functions (``fixed_step.rk4_slip_step``) into the loop made runs 1.5× *slower*, and
inlining every kernel took the cold compile from 15 s to 295 s. The small predicates, offsets
and formulas that kernels call at tens of sites (``bundle.offsets``, ``contact_offsets``,
``gap_offset``, ``normal.is_open``, ``is_rigid``, ``is_unilateral``, ``gap_and_rate``,
``gap_with_rate``, ``contact_indicator``, ``model_data.is_stick``, ``static_limit``,
``kinetic_coefficient``, ``frames.frame_velocity``, ``friction.static_coefficient``,
``linalg.solve_psd_2x2``, ``forces.exact_direction``) are plain kernels instead: numba types an
inlined body again at every call site (and at every site of every inlined caller), a kernel
once, and LLVM still inlines the small function into its caller's module. A cold ``simulate`` of
the plates in one process: 25.0–25.5 s against 27.7–34.9 s for the first nine, 21.8–22.5 s
against 22.9–23.6 s for the rest; the same states bit for bit and the same speed
(``benchmarks/ab.py``: event 1000 s 0.983–1.009 and 0.989, AEOM 0.983 and 1.001, the belt 0.983).
``model_data.apply_inverse_mass`` and ``base_force``, loops on the right-hand side's path, stay
inlined: as kernels the plates' event runs took 1.016× as long.

``error_model="numpy"`` everywhere: a float division by zero gives inf/nan as in numpy instead
of raising ZeroDivisionError, so divisions carry no zero test and branch to an exception
(measured −2 % per fixed-step run). Every kernel guards its divisions where zero can occur
(speed floors, rank tests), and the integrators check that the state stays finite.

Compile time (a cold start compiles every kernel a command needs; on two cores that was a
minute): numba gives each kernel that is not inlined a module of its own, into which it links
the code of every kernel it calls, and LLVM optimises and emits all of that code again there.
A thin kernel over a large one therefore costs the large one's optimisation once more: such
kernels are ``inlined_kernel`` (``physics.stick_margin``, ``slip_direction``,
``contacts.event_value``, the steady-sliding Newton (called at one
site; ``inlined_loop``, as it allocates), its residual and Jacobian, the variational right-hand
side's band correction), a compiled wrapper that only allocates is Python instead
(``event_loop.integrate_event``), and the stick solve (``forces.solve_stick_rows``) is one
kernel called from five places rather than inlined into each. The largest kernels are
:func:`standalone` (:mod:`.linking`): their callers call their one compiled copy instead of
linking a copy in. Since they are, a thin kernel over standalone ones costs little more than its
own code, and the event loop's rare branches over them (``event_loop.cut_step``,
``transitions.settle`` and ``break_away``) are kernels: typed once instead of at each of their
sites, and compiled by a cold start's helper process beside the loop
(:mod:`stickslip.model.compile_ahead`). A kernel gets numba's Python entry only when Python calls it
(:class:`KernelDispatcher`), the physics and the starting modes that both the event loop and
the analyses' Python call always (``api_kernel``: one version,
compiled by ``simulate`` and loaded by ``stability`` and ``orbit``), and no kernel a C-callable
wrapper. numba's inliner copies an inlined callee's scope once per
inlined call here, not once per block, and translates an inlined callee once per function, not
once per call site; numba's compiler flags hash and compare without reading every option
(:mod:`.compile_speedups`, installed on import). A slice assignment from an
array inside compiled code (``a[:n] = b[:n]``) makes numba compile its shape-mismatch error
message (string formatting, ~10 s of a cold start); use element loops. Literal arguments
(``f(x, 0)``, ``f(x, True)``) compile a second version of the callee for the literal type; pass
``np.int64(0)`` / ``np.bool_(True)`` or a variable, and start a counter that is passed to a
kernel as ``np.int64(0)`` (numba types the call for the literal first).
"""

from __future__ import annotations

import functools
import hashlib
import io
import pickle
import re
import sys
import threading
import warnings
from pathlib import Path

from numba import config as numba_config
from numba import njit
from numba.core import sigutils
from numba.core.registry import CPUDispatcher

from . import compile_speedups, linking
from .linking import standalone

compile_speedups.install()
linking.install()


def _wrap_caching(class_name: str, method: str, make) -> None:
    """Replace ``numba.core.caching.<class_name>.<method>`` by ``make(original)``, once per process
    (a numba whose caching lacks it caches as it does, unchanged)."""
    try:
        from numba.core import caching
        owner = getattr(caching, class_name)
        getattr(owner, method)
    except (ImportError, AttributeError):  # pragma: no cover - a numba that caches differently
        return
    linking.wrap_once(owner, method, make)


class _StandIn:
    """Stands in for a class that a cache index names but this process cannot import
    (:func:`_tolerant_index_loading`). Not a class itself, so that numba's pickler (cloudpickle)
    pickles it by :meth:`__reduce__`, as the original's name, instead of by value."""

    __slots__ = ("module", "name")

    def __init__(self, module: str, name: str):
        self.module = module
        self.name = name

    def __reduce__(self):
        return unavailable_class, (self.module, self.name)

    def __repr__(self) -> str:
        return f"<unavailable class {self.module}.{self.name}>"


def unavailable_class(module: str, name: str):
    """The class ``module.name`` if this process can import it, else its stand-in (one per name):
    an index entry keyed by it then matches nothing here, and keeps its name when the index is
    saved again."""
    try:
        return pickle.Unpickler.find_class(_REAL_FINDER, module, name)
    except (ImportError, AttributeError):
        return _STAND_INS.setdefault((module, name), _StandIn(module, name))


_STAND_INS: dict = {}


class _TolerantUnpickler(pickle.Unpickler):
    """An unpickler that puts a stand-in (:func:`unavailable_class`) where a class cannot be imported."""

    def find_class(self, module, name):
        try:
            return super().find_class(module, name)
        except (ImportError, AttributeError):
            return unavailable_class(module, name)


_REAL_FINDER = _TolerantUnpickler(io.BytesIO(b""))


def _tolerant_index_loading(load):
    """Let numba's on-disk cache survive kinematics classes that this process cannot import.

    A kernel's cache index holds one entry per compiled signature, keyed by its argument types,
    which name the model's kinematics class. A class that lives in a user's script or a test
    folder cannot be imported by other processes, and unpickling the whole index then fails in
    each of them, whatever model it runs. The index is read again with a stand-in for each such
    class: its entries match nothing here, the other entries load, and when this process adds its
    own and saves the index they are all kept (the stand-ins pickled as their original names, so a
    process that can import the class finds its kernels again).
    Without that, every such process recompiled its kernels and rewrote the index with its own
    entries alone, so that the next process recompiled the others again. An index that cannot be
    read at all counts as empty.
    """
    def _load_index(self):
        try:
            return load(self)
        except (ImportError, AttributeError):
            pass
        except (EOFError, pickle.UnpicklingError):
            return {}
        try:
            with open(self._index_path, "rb") as f:
                version = pickle.load(f)
                data = f.read()
            if version != self._version:
                return {}
            stamp, overloads = _TolerantUnpickler(io.BytesIO(data)).load()
        except Exception:  # noqa: BLE001 - an unreadable index is an empty one
            return {}
        return overloads if stamp == self._source_stamp else {}

    return _load_index


_wrap_caching("IndexDataCacheFile", "_load_index", _tolerant_index_loading)


def _tolerant_cache_saving(save):
    """Let a kernel run when its cache file cannot be written (a full disk, a file-size limit, a
    read-only folder): numba raises the OSError from inside the compilation, after the kernel is
    compiled. The kernel is used uncached instead, with one warning; it is compiled again in the
    next process. Likewise, silently, when numba holds no object code to save (a Ctrl-C landed in
    LLVM's callback that hands it over: the interrupt follows at once)."""
    warned = []

    def save_overload(self, sig, data):
        try:
            return save(self, sig, data)
        except RuntimeError as exc:
            # LLVM hands the emitted object code to numba in a callback; a Ctrl-C inside that
            # callback is reported as unraisable (and delivered again by stickslip._startup), and
            # numba then has nothing to save. The kernel runs; it is compiled again next time.
            if "no compiled object" not in str(exc):
                raise
        except OSError as exc:
            if not warned:  # once per process: every kernel after it fails alike
                warned.append(exc)
                warnings.warn(f"compiled kernels could not be cached ({exc.strerror or exc}); they are used uncached "
                              "and compiled again in the next process", RuntimeWarning, stacklevel=2)

    return save_overload


_wrap_caching("Cache", "save_overload", _tolerant_cache_saving)

#: The package's root folder, and what marks a module of the compiled layer.
_PACKAGE = Path(__file__).resolve().parents[1]
_COMPILED = re.compile(rb"@kernel|@inlined_kernel|@unilateral_kernel|@rigid_kernel|@loop|njit|@overload|@intrinsic|register_kinematics")


@functools.lru_cache(maxsize=1)
def compiled_layer_digest() -> str:
    """SHA-256 of every module of the package that defines or specialises compiled code.

    numba checks a cached kernel against its own file only, but the kernels here inline and call
    one another across modules (the physics into the integrators, the orbits, the steady-state
    solver), so a kernel whose file did not change would be loaded with the old code of another.
    Every kernel of the package is therefore stamped with this digest as well
    (:func:`_stamp_with_package`): a change to any module of the compiled layer recompiles them
    all, and nothing stale is ever loaded.
    """
    digest = hashlib.sha256()
    for path in sorted(_PACKAGE.rglob("*.py")):
        text = path.read_bytes()
        if _COMPILED.search(text):
            digest.update(str(path.relative_to(_PACKAGE)).encode())
            digest.update(hashlib.sha256(text).digest())
    return digest.hexdigest()


def _stamp_with_package() -> None:
    """Make numba's cache locators stamp the package's kernels with :func:`compiled_layer_digest`
    beside their own file (the cache in ``__pycache__`` or ``NUMBA_CACHE_DIR`` as before)."""
    try:
        from numba.core.caching import CacheImpl, InTreeCacheLocator, UserProvidedCacheLocator
    except ImportError:  # pragma: no cover - a numba without these classes caches differently
        return
    if getattr(CacheImpl, "_stickslip_stamped", False):
        return

    def locator(base):
        class PackageLocator(base):
            def get_source_stamp(self):
                return super().get_source_stamp(), compiled_layer_digest()

            @classmethod
            def from_function(cls, py_func, py_file):
                try:
                    inside = Path(py_file).resolve().is_relative_to(_PACKAGE)
                except (OSError, ValueError):
                    inside = False
                return super().from_function(py_func, py_file) if inside else None

        PackageLocator.__name__ = f"Stickslip{base.__name__}"
        return PackageLocator

    CacheImpl._locator_classes = [locator(UserProvidedCacheLocator), locator(InTreeCacheLocator),
                                  *CacheImpl._locator_classes]
    CacheImpl._stickslip_stamped = True


_stamp_with_package()

#: Digest of the code behind each kinematics or friction-law class registered from outside the
#: package (:func:`track_user_code`), which the kernels compiled for that class inline.
_USER_CODE: dict[type, str] = {}


def track_user_code(cls: type, *functions) -> None:
    """Key the cached kernels compiled for ``cls`` by the code of ``functions`` (a model's frame,
    a user friction law) when they live outside the package.

    The package's kernels inline such a function, but numba keys a cached kernel by the kernel's
    own file and signature only: after the user edits the function, the kernel compiled with the
    old one would be loaded. The digest of each function's whole module file (helpers it calls
    included) joins the index key of every kernel whose signature holds ``cls``, so an edit
    recompiles exactly the kernels of that class; every other kernel keeps its cache.
    """
    digest = hashlib.sha256()
    outside = False
    for function in functions:
        if defined_in_package(function):
            continue
        py_func = getattr(function, "py_func", function)
        path = _module_file(py_func)
        outside = True
        try:
            digest.update(Path(path).read_bytes())
        except (OSError, TypeError):  # no file (an interactive session): the function's own code
            code = py_func.__code__
            digest.update(code.co_code + repr(code.co_consts).encode())
    if outside:
        _USER_CODE[cls] = digest.hexdigest()
    else:
        _USER_CODE.pop(cls, None)


def _module_file(py_func) -> str | None:
    module = sys.modules.get(getattr(py_func, "__module__", None) or "")
    return getattr(module, "__file__", None)


def defined_in_package(obj) -> bool:
    """Whether ``obj`` (a function, a numba dispatcher or a class) is defined in a module of this package."""
    path = _module_file(getattr(obj, "py_func", obj))
    try:
        return path is not None and Path(path).resolve().is_relative_to(_PACKAGE)
    except (OSError, ValueError):
        return False


def _user_code_in(types, seen=None) -> list:
    """The digests of :data:`_USER_CODE` for the classes found in the numba ``types`` (nested)."""
    found = []
    for ty in types:
        cls = getattr(ty, "instance_class", None)
        if cls in _USER_CODE:
            found.append((f"{cls.__module__}.{cls.__qualname__}", _USER_CODE[cls]))
        inner = getattr(ty, "types", None)
        if isinstance(inner, tuple):
            found.extend(_user_code_in(inner))
    return found


def _key_by_user_code(index_key):
    """Make numba's index key of a cached kernel hold the digests of the user code its signature
    refers to (:func:`track_user_code`), and whether it was compiled without its Python entry
    (:class:`KernelDispatcher`); a kernel with neither keeps numba's own key."""
    def _index_key(self, sig, codegen):
        key = index_key(self, sig, codegen)
        if getattr(_ENTRY, "without", False):
            key = (*key, "without a Python entry")
        if not _USER_CODE:
            return key
        user = _user_code_in(tuple(sig) if isinstance(sig, tuple) else getattr(sig, "args", ()))
        return key if not user else (*key, tuple(sorted(set(user))))

    return _index_key


_wrap_caching("Cache", "_index_key", _key_by_user_code)


def _shared_flag(name: str) -> threading.local:
    """A thread-local kept on numba's caching module, so that every copy of this module in one
    process reads and writes the same one: numba's cache key function is replaced once, by the
    first copy (:func:`_wrap_caching`), and reads this flag for the kernels of every copy (a
    benchmark imports a baseline revision of the package beside the working tree)."""
    from numba.core import caching

    flag = getattr(caching, name, None)
    if flag is None:
        flag = threading.local()
        setattr(caching, name, flag)
    return flag


#: Whether the compilation under way on this thread makes a kernel without its Python entry.
_ENTRY = _shared_flag("_stickslip_without_entry")


class KernelDispatcher(CPUDispatcher):
    """numba's dispatcher for a :func:`kernel`, whose Python entry is compiled only for Python.

    numba compiles every jitted function with a CPython wrapper, the code that unboxes Python
    arguments and boxes the result (for a kernel with a dozen array and record arguments about
    45 ms of a cold start each, half of what a small kernel costs), although most kernels are only
    called by other kernels, which call the function itself. A kernel here is compiled for
    another kernel's call without the wrapper; a call from Python compiles (or loads) the
    signature with it, once, and from then on kernels and Python share that version. A version
    without the wrapper is never entered from Python: numba's C dispatcher only calls the versions
    this class inserts into its table, those with the wrapper. The on-disk cache keeps the two
    apart (:func:`_key_by_user_code`).
    """

    def _compile_for_args(self, *args, **kws):  # numba's path for a call from Python
        self._python_entry = True
        try:
            return super()._compile_for_args(*args, **kws)
        finally:
            self._python_entry = False

    def available(self, sig) -> bool:
        """Whether the version of ``sig`` that kernels call is compiled in this process or in
        numba's on-disk cache (looked up without compiling)."""
        args = tuple(sigutils.normalize_signature(sig)[0])
        if args in self.overloads:
            return True
        cache = getattr(self, "_cache", None)
        outer = getattr(_ENTRY, "without", False)
        _ENTRY.without = not self.always_entry
        try:
            return cache is not None and cache.load_overload(args, self.targetctx) is not None
        finally:
            _ENTRY.without = outer

    #: Whether every version gets the Python entry (:func:`api_kernel`), kernels' calls included.
    always_entry = False

    def compile(self, sig):
        wanted = self.always_entry or getattr(self, "_python_entry", False)
        self._python_entry = False  # the kernels compiled inside this one are called by kernels
        args = tuple(sigutils.normalize_signature(sig)[0])
        existing = self.overloads.get(args)
        if wanted and existing is not None and args not in self._with_entry:
            del self.overloads[args]  # compile it again, now with the Python entry
        outer = getattr(_ENTRY, "without", False)
        self._compiler.targetoptions = self._options_without_entry if not wanted else self.targetoptions
        _ENTRY.without = not wanted
        try:
            return super().compile(sig)
        except BaseException:
            if args not in self.overloads and existing is not None:
                self.overloads[args] = existing
            raise
        finally:
            _ENTRY.without = outer
            self._compiler.targetoptions = self.targetoptions

    #: Whether callers call this kernel's one compiled copy instead of linking it (:func:`linking.standalone`).
    standalone = False

    def add_overload(self, cres):
        args = tuple(cres.signature.args)
        if self.standalone:
            linking.mark_library(self, cres, with_entry=not getattr(_ENTRY, "without", False))
        if getattr(_ENTRY, "without", False):
            self.overloads[args] = cres  # for kernels only: not in the table that Python calls go through
            return
        self._with_entry.add(args)
        super().add_overload(cres)

    @property
    def _with_entry(self) -> set:
        try:
            return self.__dict__["_with_entry_args"]
        except KeyError:
            return self.__dict__.setdefault("_with_entry_args", set())

    @property
    def _options_without_entry(self) -> dict:
        return {**self.targetoptions, "no_cpython_wrapper": True}


def _kernel_decorator(always_entry: bool = False, **options):
    """A decorator like ``njit(cache=True, **options)`` that makes a :class:`KernelDispatcher`."""
    targetoptions = {"nopython": True, "boundscheck": None, **options}

    def decorate(func):
        if numba_config.DISABLE_JIT:
            return func
        dispatcher = KernelDispatcher(py_func=func, locals={}, targetoptions=dict(targetoptions))
        dispatcher.always_entry = always_entry
        dispatcher.enable_caching()
        return dispatcher

    return decorate


#: Options of every compiled kernel, also given to the overloads whose implementations numba
#: compiles itself (otherwise those get the NRT's reference counting and Python's error model).
#: No kernel is called through a C function pointer, so none needs numba's C-callable wrapper.
KERNEL_OPTIONS = {"_nrt": False, "error_model": "numpy", "no_cfunc_wrapper": True}

kernel = _kernel_decorator(**KERNEL_OPTIONS)
#: A :func:`kernel` that the analyses also call from Python (the right-hand side, the contact and
#: stick forces, the slip velocity, the projection onto the stick constraints, the starting
#: modes): every version is compiled with its Python entry, so that the one a ``simulate``
#: compiled for the event loop is also the one ``stability`` or ``orbit`` calls, loaded from the
#: cache (a Python entry costs ~45 ms; compiling the version again for Python cost a model file's
#: ``orbit`` ~8 s). A kernel only Python calls is one too where a cold start compiles it ahead
#: (``model/compile_ahead.py``): its version then has the entry its first call needs.
api_kernel = _kernel_decorator(always_entry=True, **KERNEL_OPTIONS)
inlined_kernel = njit(cache=True, inline="always", **KERNEL_OPTIONS)
loop = njit(cache=True, error_model="numpy", no_cfunc_wrapper=True)
inlined_loop = njit(cache=True, inline="always", error_model="numpy", no_cfunc_wrapper=True)

__all__ = ["kernel", "api_kernel", "inlined_kernel", "loop", "inlined_loop", "standalone", "KERNEL_OPTIONS", "KernelDispatcher", "track_user_code",
           "defined_in_package"]
