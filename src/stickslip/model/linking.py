"""Standalone kernels: compiled once, called by their callers instead of copied into them.

numba gives each compiled kernel an LLVM module of its own and, when the kernel calls another,
links a copy of the callee's whole module into the caller's, callees of the callee included; LLVM
then optimises and emits all of that code again in the caller. Where a chain of kernels calls a
large one (the friction forces, the stick solve, the right-hand side), every level above it
optimises it once more: on a cold start most of LLVM's time went into code it had already
optimised. A *standalone* kernel (:func:`standalone`) is not copied: its callers declare it and
call the one compiled copy, which the JIT engine resolves by its symbol when it loads a caller.
Only kernels that LLVM would not inline are made standalone (those that a caller's optimised
module kept as a function of their own), so the callers' code is the code they had, less the
copies: the same results bit for bit.

numba's on-disk cache keeps each kernel's object code, which now refers to the standalone
kernels it calls by their symbols. A cached caller is loaded only after each of those kernels is
loaded (from the cache or compiled) under the very symbol the caller refers to: each cache entry
records them (:func:`_record_dependencies`), and an entry whose callee is not there under that
symbol (a version that kept numba's own numbering, :func:`_stable_symbols`) counts as a miss and
is compiled again, never loaded with a dangling reference, which would end the process.

These wrappers of numba are one patch of :mod:`.numba_patches`, ``standalone-linking``
(:data:`PATCH`): all of them or none. Without it, :func:`standalone` marks a kernel that numba
then links into its callers as it does any other.
"""

from __future__ import annotations

import hashlib
import importlib

from .numba_patches import Patch, first_problem, has, source_has

__all__ = ["PATCH", "standalone", "wrap_once"]

#: The marker of a cache entry that records its standalone dependencies.
_FORMAT = "stickslip-standalone-1"


class StaleDependency(Exception):
    """A cached kernel refers to a standalone kernel that is not loaded under the symbol it names."""


def standalone(dispatcher):
    """Make the kernel ``dispatcher`` (a :class:`~stickslip.model.jit.KernelDispatcher`) standalone:
    kernels that call it call its one compiled copy instead of linking it (module docstring).

    For large kernels that LLVM does not inline into their callers; a small one would be called
    where it was inlined and slow its callers down.
    """
    dispatcher.standalone = True
    getattr(dispatcher, "py_func", dispatcher)._stickslip_standalone = True
    return dispatcher


#: The argument types behind each symbol that a standalone kernel got in this process.
_SYMBOLS: dict = {}


def _symbol_taken(fndesc) -> bool:
    """Whether another version (other argument types of the same printed names: a class defined
    again under its old name) holds the symbol of ``fndesc`` in this process; else it is taken now."""
    held = _SYMBOLS.setdefault(fndesc.mangled_name, fndesc.argtypes)
    return held != fndesc.argtypes


def _stable_uid(modname: str, qualname: str) -> int:
    """The number in the symbols of standalone kernel ``modname.qualname``: a digest of its name."""
    return int.from_bytes(hashlib.sha256(f"{modname}.{qualname}".encode()).digest()[:6], "big")


def _stable_symbols(from_python_function):
    """numba's ``FunctionDescriptor._from_python_function``, giving a standalone kernel the same
    symbol in every process: numba numbers each compilation in a process and puts the number in the
    symbol, so that a kernel compiled in two processes (the two of a cold start, or two test
    workers) would get two symbols, and a cached caller of one would not load beside the other. The
    number is a digest of the kernel's name instead; the argument types and compiler flags (the
    Python entry) are in the symbol as before. A version whose symbol another version already holds
    here keeps numba's number."""
    def wrapped(cls, func_ir, *args, **kwargs):
        func_id = func_ir.func_id
        if not getattr(func_id.func, "_stickslip_standalone", False):
            return from_python_function(cls, func_ir, *args, **kwargs)
        counted = func_id.unique_id
        func_id.unique_id = _stable_uid(func_id.modname, func_id.func_qualname)
        try:
            fndesc = from_python_function(cls, func_ir, *args, **kwargs)
        finally:
            func_id.unique_id = counted
        if _symbol_taken(fndesc):
            return from_python_function(cls, func_ir, *args, **kwargs)
        return fndesc

    return wrapped


def mark_library(dispatcher, cres, with_entry: bool) -> None:
    """Mark the code library of the new or loaded version ``cres`` of a standalone kernel: callers
    declare it instead of linking it, and record how to load it (:func:`_record_dependencies`)."""
    func = dispatcher.py_func
    cres.library._stickslip_standalone = (cres.fndesc.llvm_func_name,
                                          (func.__module__, func.__qualname__, tuple(cres.signature.args), with_entry))


def _record_dependencies(finalize):
    """numba's ``CPUCodeLibrary.finalize``, linking no standalone library: each is recorded, by
    symbol, among the library's dependencies, with those of the libraries it does link."""
    def wrapped(self):
        dependencies = {}
        linked = []
        for library in self._linking_libraries:
            own = getattr(library, "_stickslip_standalone", None)
            if own is None:
                linked.append(library)
                dependencies.update(getattr(library, "_stickslip_dependencies", {}))
            else:
                symbol, origin = own
                dependencies[symbol] = origin
                inherited = getattr(self, "_reload_init", None)  # numba >= 0.63: what a caller inherits
                if inherited is not None:
                    inherited.update(getattr(library, "_reload_init", ()))
        self._linking_libraries = linked
        self._stickslip_dependencies = dependencies
        return finalize(self)

    return wrapped


def _reduce_with_dependencies(reduce):
    """numba's cache payload of a compiled version, with the standalone kernels its code calls (a
    version that calls none keeps numba's own payload)."""
    def wrapped(self, cres):
        payload = reduce(self, cres)
        dependencies = getattr(cres.library, "_stickslip_dependencies", None)
        return (_FORMAT, payload, dict(dependencies)) if dependencies else payload

    return wrapped


def _rebuild_after_dependencies(rebuild):
    """numba's rebuilding of a cached version, after the standalone kernels it calls are loaded;
    a version that would take a symbol held by another here is a miss (:func:`_symbol_taken`)."""
    def wrapped(self, target_context, payload):
        ours = isinstance(payload, tuple) and len(payload) == 3 and payload[0] == _FORMAT
        inner, dependencies = (payload[1], payload[2]) if ours else (payload, {})
        fndesc = inner[1]
        if fndesc.uid == _stable_uid(fndesc.modname, fndesc.qualname) and _symbol_taken(fndesc):
            raise StaleDependency(fndesc.mangled_name)
        _load_dependencies(target_context, dependencies)
        cres = rebuild(self, target_context, inner)
        if dependencies:
            cres.library._stickslip_dependencies = dependencies
        return cres

    return wrapped


def _load_dependencies(target_context, dependencies: dict) -> None:
    """Load (or compile) each standalone kernel that a cached library refers to; raise
    :class:`StaleDependency` where one is not then defined under the symbol recorded."""
    engine = target_context.codegen()._engine
    for symbol, (module, qualname, args, with_entry) in dependencies.items():
        if engine.is_symbol_defined(symbol):
            continue
        try:
            dispatcher = importlib.import_module(module)
            for part in qualname.split("."):
                dispatcher = getattr(dispatcher, part)
        except (ImportError, AttributeError) as exc:
            raise StaleDependency(symbol) from exc
        if with_entry:
            dispatcher._python_entry = True
        try:
            dispatcher.compile(args)
        except Exception as exc:  # the caller compiles afresh and reports what fails
            raise StaleDependency(symbol) from exc
        if not engine.is_symbol_defined(symbol):
            raise StaleDependency(symbol)


def _stale_is_a_miss(load):
    """numba's loading of a cached version, where a :class:`StaleDependency` is a miss."""
    def wrapped(self, sig, target_context):
        try:
            return load(self, sig, target_context)
        except StaleDependency:
            return None

    return wrapped


def wrap_once(owner, name: str, make) -> None:
    """Replace ``owner.<name>`` by ``make(original)``, once per process however many copies of the
    package it imports (a classmethod stays one)."""
    attribute = owner.__dict__.get(name)
    method = isinstance(attribute, classmethod)
    original = attribute.__func__ if method else getattr(owner, name)
    if getattr(original, "_stickslip_wrapped", False):
        return
    wrapped = make(original)
    wrapped._stickslip_wrapped = True
    setattr(owner, name, classmethod(wrapped) if method else wrapped)


def _check() -> str | None:
    from numba.core import caching, codegen, compiler, funcdesc

    library = codegen.CPUCodeLibrary
    cache_impl = caching.CompileResultCacheImpl
    return first_problem(
        has(funcdesc.FunctionDescriptor, "_from_python_function",
            ("func_ir", "typemap", "restype", "calltypes", "native", "mangler", "inline", "noalias", "abi_tags")),
        lambda: source_has(funcdesc.FunctionDescriptor._from_python_function, "uid=func_ir.func_id.unique_id"),
        has(library, "finalize", ("self",)),
        lambda: source_has(library.finalize, "for library in self._linking_libraries:"),
        lambda: source_has(library.__init__, "self._linking_libraries = "),
        lambda: source_has(codegen.JITCodeLibrary.get_pointer_to_function, "self._codegen._engine"),
        has(codegen.JitEngine, "is_symbol_defined", ("self", "name")),
        has(cache_impl, "reduce", ("self", "cres")),
        has(cache_impl, "rebuild", ("self", "target_context", "payload")),
        lambda: source_has(compiler.CompileResult._reduce, "return (libdata, self.fndesc,"),
        has(caching.Cache, "_load_overload", ("self", "sig", "target_context")))


def _apply() -> None:
    """Install the wrappers of numba's linking and caching (:func:`wrap_once`)."""
    from numba.core import caching, codegen, funcdesc

    wrap_once(funcdesc.FunctionDescriptor, "_from_python_function", _stable_symbols)
    wrap_once(codegen.CPUCodeLibrary, "finalize", _record_dependencies)
    wrap_once(caching.CompileResultCacheImpl, "reduce", _reduce_with_dependencies)
    wrap_once(caching.CompileResultCacheImpl, "rebuild", _rebuild_after_dependencies)
    wrap_once(caching.Cache, "_load_overload", _stale_is_a_miss)


#: The standalone kernels as a patch of :mod:`.numba_patches`.
PATCH = Patch("standalone-linking", _check, _apply)
