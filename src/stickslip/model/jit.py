"""The one way compiled kernels are declared in stickslip.

``kernel``: numba ``njit`` with an on-disk cache and *without* the numba runtime (NRT). Kernels
only read and write the arrays they are given and never allocate, so they need no reference
counting; compiled without NRT their calls carry no atomic incref/decref per array argument.
Functions that allocate (the orbit tools' segment integrator, steady sliding) use ``loop`` (plain
cached ``njit``); they allocate only on entry and never reassign an array variable inside their
main loop, since numba reference-counts loop-carried arrays on every iteration
(``transitions.record_transition``). The simulators' loops are kernels whose arrays their Python
callers allocate (``integrate/bundles.py``).

``inlined_kernel``: a ``kernel`` that numba inlines into its callers (typed IR). For small
kernels on the innermost path (``forces.slip_force``, ``frames.add_contact_force``,
``forces.rotated``), for the right-hand side's body ``physics.rhs_body`` at exactly one call
site per integrator step, inside the loop over its stages (a call passes each array as 7 words),
and for the loops on the right-hand side's path (``model_data.apply_inverse_mass``,
``base_force``). Every inlined copy is typed and compiled again, so larger step functions stay
kernels. The small predicates and formulas that kernels call at tens of sites
(``normal.is_open``, ``is_rigid``, ``is_unilateral``, ``gap_and_rate``, ``gap_with_rate``,
``contact_indicator``, ``model_data.is_stick``, ``static_limit``, ``kinetic_coefficient``,
``frames.frame_velocity``, ``friction.static_coefficient``, ``linalg.solve_psd_2x2``,
``forces.exact_direction``) are plain kernels: numba types an inlined body again at every call
site (and at every site of every inlined caller), a kernel once, and LLVM still inlines the small
function into its caller's module. The data layout's offsets (``bundle.offsets``,
``contact_offsets``, ``gap_offset``, ``contact_width``), which Python calls too and callers pass
constants or variables alike, are :data:`formula`: plain Python for Python, one compiled version
for kernels.

``error_model="numpy"`` everywhere: a float division by zero gives inf/nan as in numpy instead
of raising ZeroDivisionError, so divisions carry no zero test and branch to an exception. Every
kernel guards its divisions where zero can occur (speed floors, rank tests), and the integrators
check that the state stays finite.

Compile time (a cold start compiles every kernel a command needs): numba gives each kernel that
is not inlined a module of its own, into which it links the code of every kernel it calls, and
LLVM optimises and emits all of that code again there. A thin kernel over a large one therefore
costs the large one's optimisation once more: such kernels are ``inlined_kernel``
(``physics.stick_margin``, ``slip_direction``, ``contacts.event_value``, the steady-sliding
Newton (called at one site; ``inlined_loop``, as it allocates), its residual and Jacobian, the
variational right-hand side's band correction), a compiled wrapper that only allocates is Python
instead (``event_loop.integrate_event``), and the stick solve (``stick.solve_stick_rows``) is
one kernel called from five places rather than inlined into each. The largest kernels are
:func:`standalone` (:mod:`.linking`): their callers call their one compiled copy instead of
linking a copy in. So a thin kernel over standalone ones costs little more than its own code,
and the event loop's rare branches over them (``event_loop.cut_step``, ``transitions.settle`` and
``break_away``) are kernels: typed once instead of at each of their sites, and compiled by a
cold start's helper process beside the loop (:mod:`stickslip.model.compile_ahead`). A kernel
gets numba's Python entry only when Python calls it (:class:`KernelDispatcher`), the physics and
the starting modes that both the event loop and the analyses' Python call always
(``api_kernel``: one version, compiled by ``simulate`` and loaded by ``stability`` and
``orbit``), and no kernel a C-callable wrapper. :mod:`.compile_speedups` makes numba's front end
faster where a cold compile spends its time.

Those changes to numba are patches installed by :mod:`.numba_patches` when this module is
imported, each only where numba has what it relies on; :mod:`.kernel_cache` keeps the kernels'
disk cache correct (stamped with the whole compiled layer) and survivable (checksummed). Without
that patch (``STICKSLIP_NUMBA_PATCHES=0``, an untested numba) the kernels are declared uncached.

Pitfalls: a slice assignment from an array inside compiled code (``a[:n] = b[:n]``) makes numba
compile its shape-mismatch error message (string formatting, seconds of a cold start); use
element loops. Literal arguments (``f(x, 0)``, ``f(x, True)``) compile a second version of the
callee for the literal type; pass ``np.int64(0)`` / ``np.bool_(True)`` or a variable, and start
a counter that is passed to a kernel as ``np.int64(0)`` (numba types the call for the literal
first).
"""

from __future__ import annotations

from numba import config as numba_config
from numba import njit
from numba.core import sigutils
from numba.extending import register_jitable
from numba.core.registry import CPUDispatcher

from . import compile_ahead, compile_speedups, kernel_cache, linking, numba_patches
from .kernel_cache import compiled_layer_digest, defined_in_package, track_user_code
from .linking import standalone
from .numba_patches import Patch, first_problem, has, source_has

#: Whether the compilation under way on this thread makes a kernel without its Python entry.
_ENTRY = kernel_cache.without_entry()


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
    apart (:mod:`.kernel_cache`). This is the patch ``python-entry`` of :mod:`.numba_patches`
    (:func:`python_entry_patch`); without it every version gets its wrapper, as numba has it.
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
        _ENTRY.without = _ENTRY_APART and not self.always_entry
        try:
            return cache is not None and cache.load_overload(args, self.targetctx) is not None
        finally:
            _ENTRY.without = outer

    #: Whether every version gets the Python entry (:func:`api_kernel`), kernels' calls included.
    always_entry = False

    def compile(self, sig):
        wanted = self.always_entry or getattr(self, "_python_entry", False) or not _ENTRY_APART
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


def _check_python_entry() -> str | None:
    from numba.core import dispatcher
    from numba.core.compiler import Flags

    return first_problem(
        has(CPUDispatcher, "_compile_for_args", ("self", "args", "kws")),
        has(CPUDispatcher, "compile", ("self", "sig")),
        has(CPUDispatcher, "add_overload", ("self", "cres")),
        lambda: source_has(CPUDispatcher.__init__, "self._compiler = "),
        lambda: source_has(dispatcher._DispatcherBase.__init__, "self.overloads = "),
        lambda: source_has(dispatcher._FunctionCompiler._compile_core, "self.targetoptions"),
        None if "no_cpython_wrapper" in Flags.options else "numba's Flags have no no_cpython_wrapper")


def _apply_python_entry() -> None:
    global _ENTRY_APART
    _ENTRY_APART = True


def python_entry_patch() -> Patch:
    """:class:`KernelDispatcher`'s versions without their Python entry, as a patch of :mod:`.numba_patches`."""
    return Patch("python-entry", _check_python_entry, _apply_python_entry)


#: Whether kernels compile their versions for other kernels without the Python entry (the patch is installed).
_ENTRY_APART = False

numba_patches.install([*compile_speedups.PATCHES, python_entry_patch(), linking.PATCH, kernel_cache.PATCH,
                       kernel_cache.LOAD_PATCH, compile_ahead.FORK_PATCH])

#: Whether the package's kernels are cached on disk (:func:`.kernel_cache.caching`).
_CACHE = kernel_cache.caching()


def _kernel_decorator(always_entry: bool = False, **options):
    """A decorator like ``njit(cache=True, **options)`` that makes a :class:`KernelDispatcher`."""
    targetoptions = {"nopython": True, "boundscheck": None, **options}

    def decorate(func):
        if numba_config.DISABLE_JIT:
            return func
        dispatcher = KernelDispatcher(py_func=func, locals={}, targetoptions=dict(targetoptions))
        dispatcher.always_entry = always_entry
        if _CACHE:
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
inlined_kernel = njit(cache=_CACHE, inline="always", **KERNEL_OPTIONS)
#: A small integer formula that kernels and Python both call (the data layout's offsets and widths):
#: in Python the function itself (no dispatcher to load from the cache, nothing compiled), for
#: kernels a compiled function that LLVM inlines into its caller. numba types the call of such a
#: function (an overload) with the arguments' plain types first, so a caller that passes a
#: constant (``offsets(6)``) and one that passes a variable share one compiled version, where a
#: kernel would compile one for the literal too.
formula = register_jitable(**KERNEL_OPTIONS)
loop = njit(cache=_CACHE, error_model="numpy", no_cfunc_wrapper=True)
inlined_loop = njit(cache=_CACHE, inline="always", error_model="numpy", no_cfunc_wrapper=True)

__all__ = ["kernel", "api_kernel", "inlined_kernel", "formula", "loop", "inlined_loop", "standalone", "KERNEL_OPTIONS",
           "KernelDispatcher", "track_user_code", "defined_in_package", "compiled_layer_digest"]
