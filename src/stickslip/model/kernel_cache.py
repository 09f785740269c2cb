"""numba's on-disk cache of the package's kernels, kept correct and survivable.

numba caches each kernel in an index (``.nbi``: its compiled signatures, keyed by argument types,
target and bytecode) and one data file per signature (``.nbc``: the object code and what numba
needs to load it). For the package's kernels this module changes four things, together the patch
``cache-keeping`` of :mod:`.numba_patches` (:data:`PATCH`; all or none):

**Stamped with the whole compiled layer.** numba checks a cached kernel against its own file only,
but the kernels here inline and call one another across modules, so a kernel whose file did not
change would be loaded with the old code of another. Each is stamped with
:func:`compiled_layer_digest` as well (a locator of the package's files): a change to any module of
the compiled layer recompiles them all.

**Keyed by what else they depend on.** The index key of a kernel holds the digest of the user
code it inlines (:func:`track_user_code`), whether it was compiled without its Python entry
(:class:`~stickslip.model.jit.KernelDispatcher`), and the patches installed that change what a
cache entry holds (:func:`patch_tag`), so that entries of processes with other patches (or none)
never mix.

**Checksummed.** The index and each data file of a package's kernel are written as a SHA-256 digest and the pickled
payload, and checked when read: a truncated, garbled or bit-flipped file is a miss (its kernel
compiled again and saved anew) with one line on stderr (:func:`_damaged`), never an unpickling
error and never damaged object code handed to the JIT engine. The index's version field carries
the format (:data:`FORMAT`): numba without this patch reads such an index as another numba
version's, and so ignores it, never misreads it.

**Tolerant.** An index that names a kinematics class this process cannot import (one in a user's
script or a test folder) is read with a stand-in for it (:func:`unavailable_class`): its entries
match nothing here, the others load, and all are kept when the index is saved again. A cache
file that cannot be written (a full disk, a file-size limit, a read-only folder) leaves the
kernel uncached, with one warning per run.

Without the patch the package's kernels are not cached on disk (:func:`caching`): numba's own
cache would load a kernel with the old code of a module it inlines.

**Loaded without numba's registries.** A second patch, ``cache-load`` (:data:`LOAD_PATCH`), loads
a cached kernel of the package without the refresh of numba's target context that numba makes
first, which imports every implementation registry of numba (and scipy.linalg): what a warm
command needs of it, numba's runtime, is initialised alone (:func:`_load_without_refresh`).
"""

from __future__ import annotations

import functools
import hashlib
import io
import os
import pickle
import re
import sys
import threading
import warnings
from pathlib import Path

from .numba_patches import Patch, active, first_problem, has, notice, source_has

__all__ = ["PATCH", "LOAD_PATCH", "FORMAT", "caching", "compiled_layer_digest", "track_user_code",
           "defined_in_package", "unavailable_class", "without_entry", "patch_tag"]

#: The cache files' format: numba's version field of an index carries it.
FORMAT = "stickslip-sha256-1"
_MAGIC = b"stickslip-sha256\n"
_DIGEST_SIZE = 32

#: The package's root folder, and what marks a module of the compiled layer.
_PACKAGE = Path(__file__).resolve().parents[1]
_COMPILED = re.compile(rb"@kernel|@inlined_kernel|@unilateral_kernel|@rigid_kernel|@loop|njit|@overload|@intrinsic|register_kinematics")
#: Modules that shape what a cache entry holds (its payload, symbols and keys), in the digest too.
_MACHINERY = ("model/kernel_cache.py", "model/linking.py", "model/numba_patches.py")


@functools.lru_cache(maxsize=1)
def compiled_layer_digest() -> str:
    """SHA-256 of every module of the package that defines or specialises compiled code, and of
    the modules that shape what a cache entry holds (module docstring)."""
    digest = hashlib.sha256()
    for relative in _package_modules():
        text = (_PACKAGE / relative).read_bytes()
        if relative in _MACHINERY or _COMPILED.search(text):
            digest.update(relative.encode())
            digest.update(hashlib.sha256(text).digest())
    return digest.hexdigest()


def _package_modules() -> list[str]:
    """The package's modules as sorted paths relative to it, ``/``-separated. The ``__pycache__``
    folders are not entered: numba's cache files there number in the thousands, and listing
    them took most of the digest's time."""
    found = []
    for folder, dirs, files in os.walk(_PACKAGE):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        base = Path(folder).relative_to(_PACKAGE)
        found += [(base / name).as_posix() for name in files if name.endswith(".py")]
    return sorted(found)


def caching() -> bool:
    """Whether the package's kernels are cached on disk (the patch ``cache-keeping`` is installed)."""
    return active("cache-keeping")


# ----------------------------------------------------------------------------- stand-ins

class _StandIn:
    """Stands in for a class that a cache index names but this process cannot import
    (:func:`unavailable_class`). Not a class itself, so that numba's pickler (cloudpickle) pickles
    it by :meth:`__reduce__`, as the original's name, instead of by value."""

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


# ----------------------------------------------------------------------------- checksummed files

def _sealed(payload: bytes) -> bytes:
    return _MAGIC + hashlib.sha256(payload).digest() + payload


def _opened(blob: bytes) -> bytes | None:
    """The payload of a :func:`_sealed` blob, or None where it is not one or its digest does not match."""
    head = len(_MAGIC)
    if len(blob) < head + _DIGEST_SIZE or not blob.startswith(_MAGIC):
        return None
    digest, payload = blob[head:head + _DIGEST_SIZE], blob[head + _DIGEST_SIZE:]
    return payload if hashlib.sha256(payload).digest() == digest else None


def _damaged(path) -> None:
    notice("damaged-cache", f"a damaged file of numba's cache ({path}) was set aside: its kernels are compiled "
                            "again and saved anew")


def _index_version(self) -> str:
    return f"{self._version}+{FORMAT}"


def _ours(cache_file) -> bool:
    """Whether numba's ``IndexDataCacheFile`` ``cache_file`` holds a kernel of the package (its
    stamp is a package locator's, :func:`_package_locator`); other functions keep numba's format."""
    stamp = getattr(cache_file, "_source_stamp", None)
    return isinstance(stamp, tuple) and len(stamp) == 2 and stamp[1] == compiled_layer_digest()


def _for_package_files(method):
    """``method`` for the cache files of the package's kernels, numba's own for any other."""
    def make(original):
        @functools.wraps(original)
        def wrapper(self, *args):
            return method(self, *args) if _ours(self) else original(self, *args)

        return wrapper

    return make


def _load_index(self) -> dict:
    """numba's ``IndexDataCacheFile._load_index`` for a checksummed index: its overloads, or {} where
    it is missing, of another numba or stamp, or damaged (said once per run)."""
    try:
        with open(self._index_path, "rb") as f:
            version = pickle.load(f)
            blob = f.read()
    except FileNotFoundError:
        return {}
    except (OSError, EOFError, pickle.UnpicklingError, ValueError, TypeError):  # not even numba's version field
        _damaged(self._index_path)
        return {}
    if version != _index_version(self):
        return {}  # another numba, or a numba without this patch: not ours to read
    payload = _opened(blob)
    try:
        stamp, overloads = _TolerantUnpickler(io.BytesIO(payload)).load() if payload is not None else (None, None)
    except Exception:  # noqa: BLE001 - a digest that matches over a payload that does not load: damaged all the same
        payload = None
    if payload is None:
        _damaged(self._index_path)
        return {}
    return overloads if stamp == self._source_stamp else {}


def _save_index(self, overloads) -> None:
    payload = self._dump((self._source_stamp, overloads))
    with self._open_for_write(self._index_path) as f:
        pickle.dump(_index_version(self), f, protocol=-1)
        f.write(_sealed(payload))


def _load_data(self, name):
    """numba's ``IndexDataCacheFile._load_data`` for a checksummed data file; None (a miss) where it
    is damaged (said once per run)."""
    path = self._data_path(name)
    with open(path, "rb") as f:
        payload = _opened(f.read())
    if payload is not None:
        try:
            return pickle.loads(payload)
        except Exception:  # noqa: BLE001 - see _load_index
            pass
    _damaged(path)
    return None


def _save_data(self, name, data) -> None:
    with self._open_for_write(self._data_path(name)) as f:
        f.write(_sealed(self._dump(data)))


# ----------------------------------------------------------------------------- saving

_WARNING = "compiled kernels could not be cached ({}); they are used uncached and compiled again in the next process"


def _tolerant_saving(save):
    """Let a kernel run when its cache file cannot be written (a full disk, a file-size limit, a
    read-only folder): numba raises the OSError from inside the compilation, after the kernel is
    compiled. The kernel is used uncached instead, with one warning per run (not one per worker of
    a campaign: :func:`~stickslip.model.numba_patches.notice`); it is compiled again in the next
    process. Likewise, silently, when numba holds no object code to save (a Ctrl-C landed in
    LLVM's callback that hands it over: the interrupt follows at once)."""
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
            notice("cache-write", _WARNING.format(exc.strerror or exc),
                   say=lambda line: warnings.warn(line, RuntimeWarning, stacklevel=3))

    return save_overload


# ----------------------------------------------------------------------------- stamps and keys

@functools.lru_cache(maxsize=None)
def _in_package(path: str) -> bool:
    """Whether the file ``path`` lies in the package (asked once per kernel and locator as the
    modules are imported: resolving a path takes a system call per folder of it)."""
    try:
        return Path(path).resolve().is_relative_to(_PACKAGE)
    except (OSError, ValueError):
        return False


#: The cache folders found writable in this process.
_WRITABLE: set = set()


def _package_locator(base):
    """numba's cache locator ``base`` for the package's files only, stamped with :func:`compiled_layer_digest`."""
    class PackageLocator(base):
        def get_source_stamp(self):
            return super().get_source_stamp(), compiled_layer_digest()

        def ensure_cache_path(self):
            """numba's check that the cache folder exists and is writable (it writes and removes a
            temporary file there), once per folder and process rather than once per kernel (some
            200 as the package is imported). A folder that stops being writable later makes the
            saves into it fail, which leave their kernels uncached with a warning
            (:func:`_tolerant_saving`)."""
            path = self.get_cache_path()
            if path not in _WRITABLE:
                super().ensure_cache_path()
                _WRITABLE.add(path)

        @classmethod
        def from_function(cls, py_func, py_file):
            return super().from_function(py_func, py_file) if _in_package(py_file) else None

    PackageLocator.__name__ = f"Stickslip{base.__name__}"
    return PackageLocator


def _locators():
    """numba's user-provided (``NUMBA_CACHE_DIR``) and in-tree (``__pycache__``) locators (named
    with a leading underscore before numba 0.62)."""
    from numba.core import caching

    found = [getattr(caching, name, None) or getattr(caching, f"_{name}", None)
             for name in ("UserProvidedCacheLocator", "InTreeCacheLocator")]
    return found if all(found) else None


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
    return path is not None and _in_package(path)


def _user_code_in(types) -> list:
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


#: The patches that change what a cache entry holds: an entry is keyed by those installed.
_CONTENT_PATCHES = ("python-entry", "standalone-linking")


@functools.lru_cache(maxsize=1)
def patch_tag() -> tuple:
    """The installed patches that change what a cache entry holds, as the index keys carry them."""
    return ("stickslip", *(name for name in _CONTENT_PATCHES if active(name)))


def _key_by_user_code(index_key):
    """Make numba's index key of a cached kernel hold :func:`patch_tag`, whether the kernel was
    compiled without its Python entry (:func:`without_entry`) and the digests of the user code its
    signature refers to (:func:`track_user_code`)."""
    def _index_key(self, sig, codegen):
        key = (*index_key(self, sig, codegen), patch_tag())
        if getattr(_ENTRY, "without", False):
            key = (*key, "without a Python entry")
        if not _USER_CODE:
            return key
        user = _user_code_in(tuple(sig) if isinstance(sig, tuple) else getattr(sig, "args", ()))
        return key if not user else (*key, tuple(sorted(set(user))))

    return _index_key


def _shared_flag(name: str) -> threading.local:
    """A thread-local kept on numba's caching module, so that every copy of this module in one
    process reads and writes the same one (a benchmark may import a baseline revision of the
    package beside the working tree; numba's cache key function is replaced once)."""
    from numba.core import caching as numba_caching

    flag = getattr(numba_caching, name, None)
    if flag is None:
        flag = threading.local()
        setattr(numba_caching, name, flag)
    return flag


#: Whether the compilation under way on this thread makes a kernel without its Python entry.
_ENTRY = _shared_flag("_stickslip_without_entry")


def without_entry() -> threading.local:
    """The thread-local flag ``.without``: the compilation under way makes a kernel without its
    Python entry (set by :class:`~stickslip.model.jit.KernelDispatcher`, read by the index key)."""
    return _ENTRY


# ----------------------------------------------------------------------------- the patch

_FILE_METHODS = {"_load_index": ("self",), "_save_index": ("self", "overloads"), "_load_data": ("self", "name"),
                 "_save_data": ("self", "name", "data"), "_dump": ("self", "obj"), "_data_path": ("self", "name"),
                 "_open_for_write": ("self", "filepath")}


def _check() -> str | None:
    from numba.core import caching as numba_caching

    files = numba_caching.IndexDataCacheFile
    return first_problem(
        None if _locators() is not None else "numba.core.caching has no InTreeCacheLocator",
        lambda: has(numba_caching.CacheImpl, "_locator_classes"),
        lambda: has(_locators()[0], "get_source_stamp", ("self",)),
        lambda: has(_locators()[0], "ensure_cache_path", ("self",)),
        lambda: has(_locators()[0], "get_cache_path", ("self",)),
        lambda: has(_locators()[0], "from_function", ("py_func", "py_file")),
        lambda: has(numba_caching.Cache, "_index_key", ("self", "sig", "codegen")),
        lambda: has(numba_caching.Cache, "save_overload", ("self", "sig", "data")),
        *(lambda name=name, params=params: has(files, name, params) for name, params in _FILE_METHODS.items()),
        lambda: source_has(files.__init__, "self._index_path", "self._source_stamp", "self._version"),
        lambda: source_has(files.load, "self._load_data(data_name)", "except OSError"),
        lambda: source_has(files.save, "self._save_data(data_name, data)"))


def _apply() -> None:
    from numba.core import caching as numba_caching

    from .linking import wrap_once

    files = numba_caching.IndexDataCacheFile
    for name, method in (("_load_index", _load_index), ("_save_index", _save_index), ("_load_data", _load_data),
                         ("_save_data", _save_data)):
        wrap_once(files, name, _for_package_files(method))
    wrap_once(numba_caching.Cache, "save_overload", _tolerant_saving)
    wrap_once(numba_caching.Cache, "_index_key", _key_by_user_code)
    cache_impl = numba_caching.CacheImpl
    if not getattr(cache_impl, "_stickslip_stamped", False):
        cache_impl._locator_classes = [*map(_package_locator, _locators()), *cache_impl._locator_classes]
        cache_impl._stickslip_stamped = True


#: Keeping the package's kernels in numba's cache, as a patch of :mod:`.numba_patches`.
PATCH = Patch("cache-keeping", _check, _apply)


# ----------------------------------------------------------------------------- loading without a refresh

def _load_without_refresh(original):
    """numba's ``Cache.load_overload`` that loads a cached kernel of the package without first
    refreshing the target context, which imports and installs every implementation registry of
    numba (its array, linear-algebra, random and datetime libraries, and scipy.linalg for BLAS):
    0.1-0.3 s of a warm command's start, and nothing a loaded kernel uses, as those registries
    serve typing and lowering, that is compiling. A loaded kernel's object code links against
    numba's runtime (NRT), which the refresh initialises: that is done here. Any compilation
    refreshes the context itself first, as before; other functions' caches (a user's njit with
    ``cache=True``, which may link against a third-party extension's symbols) load as numba has it."""
    from numba.core.cpu import CPUContext
    from numba.core.runtime import rtsys

    @functools.wraps(original)
    def load_overload(self, sig, target_context):
        if not isinstance(target_context, CPUContext) or not _ours(getattr(self, "_cache_file", None)):
            return original(self, sig, target_context)
        rtsys.initialize(target_context)
        with self._guard_against_spurious_io_errors():
            return self._load_overload(sig, target_context)

    return load_overload


def _check_load() -> str | None:
    from numba.core import caching as numba_caching
    from numba.core.cpu import CPUContext
    from numba.core.runtime import rtsys

    cache = numba_caching.Cache
    return first_problem(
        has(cache, "load_overload", ("self", "sig", "target_context")),
        lambda: source_has(cache.load_overload, "target_context.refresh()", "self._guard_against_spurious_io_errors()",
                           "self._load_overload(sig, target_context)"),
        has(cache, "_guard_against_spurious_io_errors", ("self",)),
        has(type(rtsys), "initialize", ("self", "ctx")),
        lambda: source_has(CPUContext.load_additional_registries, "rtsys.initialize(self)"))


def _apply_load() -> None:
    from numba.core import caching as numba_caching

    from .linking import wrap_once

    wrap_once(numba_caching.Cache, "load_overload", _load_without_refresh)


#: Loading the package's cached kernels without numba's registries, as a patch of :mod:`.numba_patches`.
LOAD_PATCH = Patch("cache-load", _check_load, _apply_load)
