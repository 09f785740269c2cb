"""Six exact speed-ups of numba's compiler front end, where a cold compile spends its time.

Each is a patch of :mod:`.numba_patches` (:data:`PATCHES`), installed there after its check; none
changes the code numba emits. Their measured gains are in CHANGELOG.md, and
``docs/numba-upstream.md`` offers them to numba.

**One copy of a callee's variable scope per inlined call, instead of one per block**
(``inline-scope-copy``). numba inlines a function's IR (``inline="always"`` kernels, and overloads
that inline) by deep-copying the callee's blocks one at a time, each with a fresh memo. Every
variable of a block refers to the function's one :class:`numba.core.ir.Scope`, which holds every
variable of the function, so each block's copy copies the whole scope again: O(blocks ×
variables) per inlined call site. The per-block copies of one inlined call get a memo that holds
the scope's copy already, so the blocks of a copied callee share one scope, as the blocks of any
numba IR share theirs (the inliner reads the callee's scope once and then moves every block into
the caller's scope). numba before 0.59 copies each statement again, after its block: those
copies take the same memo, so their variables refer to that one scope copy too (as the block's
copy of them does). Outside an inlined call ``copy.deepcopy`` behaves as before.

**The hash of compiler flags without reading them** (``flags-hash``). Every typing request of an
overload looks up its implementation by a key that holds the compiler flags (a
``TargetConfig``), and ``TargetConfig.__hash__`` builds the dict of every option's value and
hashes its sorted *keys*: the option names, the same for every instance of a class. The hash is
now that of the class's sorted option names, computed once per class: the same number, so every
dict keyed by flags behaves as before. Equality, which such a lookup then tests, built both dicts
of values; it now answers at once where the two are one object or of one class with the same
options set to the same values (equal then, as before), and compares the values as before
otherwise.

**A callee's untyped IR made once per function, not once per inlined call** (``inline-ir-once``).
To inline a call, numba's ``InlineWorker.inline_function`` runs the untyped pipeline (bytecode →
IR, the untyped passes, and the inlining of the callee's own inlined callees) on the callee's
Python function, then copies that IR into the caller (``inline_ir`` copies it first thing, and
mutates only the copy). The IR depends on the function and on the compiler setup, not on the call
site or the argument types, so each callee is translated once per process and compiler setup (the
typing context, the target context's class, the pipeline's class, the caller's ``locals`` and its
flags apart from ``enable_ssa``, which the pipeline sets itself, and ``no_cpython_wrapper``, which
only lowering reads), and every call site gets its copy as before. As with numba's own cache of
inlined overloads, a global that a callee reads is taken when the callee is first inlined in the
process.

**A builtin function's call typed once per argument types, not once per call site**
(``call-type-once``). numba types each call of a builtin function or operator (``a * b``,
``x[i]``, ``math.sqrt``, an ``@overload``) by trying the function's typing templates in order
until one accepts the argument types, at every call site; the templates tried first for scalars
are numpy's array operators, which search the ufunc loops each time. A template's answer depends
on the typing context, the function type (its templates, part of its key: a registration that
adds templates makes a new type) and the argument types only, so :func:`_call_type_once` keeps
each accepted signature per function type, context and argument types and answers a repeated
call from it, recording the implementation key for the signature's arguments as numba does at
every call (the last call's template decides which implementation lowering takes, as before). A
call the templates reject is tried again each time, as before, so its error is numba's own.

**The definitions that reach each block in one pass** (``live-map-once``). numba's dead-code
elimination, its SSA reconstruction and its deletion of dead variables ask for the variables live
at each block's entry (``analysis.compute_live_map``), which first finds the variables defined or
used in any block from which a block can be reached: a fix point that unions each block's set
into its successors' until no set grows, a pass over every block and edge with sets of up to
every variable of the function, repeated (a loop body is one cycle, and the last pass only finds
that nothing changed). For the event loop after inlining this was the front end's largest single
cost. The same sets come from the graph's strongly connected components in one pass: every
block of a component reaches every other, so they share one set, the union of their own
variables and of the sets of the components with an edge into it, taken in topological order.
The liveness that follows is numba's fix point unchanged, so the live maps are numba's.

**An inlined overload's implementation typed, not compiled** (``inline-overload-typed``). To
inline a call of an ``@overload(..., inline="always")`` (the heap and dense flavours of
:mod:`.model_data`, :func:`~stickslip.model.linalg.solve_stick_system`, the complex-step
functions of :mod:`.csmath`), numba types the implementation's IR for the call's argument types
and copies that typed IR into the caller; but first it asks the implementation's dispatcher for its
call template, which compiles the implementation as a function of its own (typing, lowering, LLVM
and a CPython wrapper) that nothing calls, since every call of it is inlined. For the package's
own overloads that dispatcher is now made with compilation disabled (``_can_compile``, what
numba's ``disable_compile`` sets), so asking for the template folds the argument types only: the typed IR
that is inlined is numba's as before, and the code emitted is the same. For the plates' cold
``simulate`` this was ~1.1 s of CPU, more for models with a full mass matrix. Overloads of other
packages (numba's own) are left as they are: one that calls ``literally`` relies on that compile
to ask for its literal arguments.
"""

from __future__ import annotations

import copy
import functools
from collections import defaultdict
import threading
import weakref
from collections.abc import Mapping

from .numba_patches import Patch, first_problem, has, source_has

__all__ = ["PATCHES"]

_state = threading.local()


class _SharedScopeCopy:
    """Stands in for the ``copy`` module inside numba's inliner: a block's deep copy, made while
    an inlined call is copied, reuses that call's copy of the block's scope."""

    def __getattr__(self, name):
        return getattr(copy, name)

    @staticmethod
    def deepcopy(x, memo=None):
        scopes = getattr(_state, "scopes", None)
        if memo is None and scopes is not None:
            if isinstance(x, _Block):
                scope = x.scope
                if id(scope) not in scopes:
                    scopes[id(scope)] = (scope, copy.deepcopy(scope))  # the original kept alive: ids stay unique
            # a block's copy, or (numba < 0.59) a statement copied after its block: this call's scope copies
            memo = {key: scope_copy for key, (_, scope_copy) in scopes.items()}
        return copy.deepcopy(x, memo)


_Block = None


def _one_scope_copy_per_call(inline_ir):
    @functools.wraps(inline_ir)
    def wrapper(self, *args, **kwargs):
        outer = getattr(_state, "scopes", None)
        _state.scopes = {}
        try:
            return inline_ir(self, *args, **kwargs)
        finally:
            _state.scopes = outer

    wrapper._stickslip_shared_scope = True
    return wrapper


#: Untyped IR of an inlined callee: function → {compiler setup: numba IR}.
_untyped_ir: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

#: Flags the untyped pipeline does not read (it sets ``enable_ssa`` itself).
_FLAGS_NOT_READ = frozenset({"enable_ssa", "no_cpython_wrapper"})


def _setup_key(worker) -> tuple:
    flags = tuple(sorted((name, repr(value)) for name, value in worker.flags.values().items()
                         if name not in _FLAGS_NOT_READ))
    local_types = tuple(sorted((name, repr(typ)) for name, typ in (worker.locals or {}).items()))
    return id(worker.typingctx), type(worker.targetctx), type(worker.pipeline), local_types, flags


def _untyped_ir_once(inline_function):
    @functools.wraps(inline_function)
    def wrapper(self, caller_ir, block, i, function, arg_typs=None):
        per_setup = _untyped_ir.setdefault(function, {})
        key = _setup_key(self)
        callee_ir = per_setup.get(key)
        if callee_ir is None:
            callee_ir = per_setup[key] = self.run_untyped_passes(function)
        else:
            self.flags.enable_ssa = False  # what run_untyped_passes leaves in the shared flags
        return self.inline_ir(caller_ir, block, i, callee_ir, function.__code__.co_freevars,
                              arg_typs=arg_typs)

    wrapper._stickslip_once = True
    return wrapper


@functools.lru_cache(maxsize=None)
def _option_names_hash(cls) -> int:
    return hash(tuple(sorted(cls.options)))


def _flags_hash(self) -> int:
    """``hash(tuple(sorted(self.values())))`` of numba's ``TargetConfig``: the hash of the sorted
    option names (the dict's keys), once per class."""
    return _option_names_hash(type(self))


def _flags_equal(original):
    @functools.wraps(original)
    def __eq__(self, other):
        """numba's ``TargetConfig.__eq__`` (the values of every option compared), answered at once
        where ``other`` is this object or of its class with the same options set alike."""
        if self is other:
            return True
        if type(self) is type(other) and self._values == other._values:
            return True
        return original(self, other)

    __eq__._stickslip_fast = True
    return __eq__


#: Accepted calls: function type → {(id of the typing context, argument types, keyword types):
#: (signature, implementation key)}; the contexts are kept in :data:`_contexts` so ids stay unique.
_call_types: dict = {}
_contexts: dict = {}


def _call_type_once(get_call_type):
    @functools.wraps(get_call_type)
    def wrapper(self, context, args, kws):
        try:
            key = (id(context), args, tuple(sorted(kws.items())) if kws else ())
            known = _call_types.get(self, {}).get(key)
        except TypeError:  # a type that does not hash: typed as numba does
            return get_call_type(self, context, args, kws)
        if known is not None:
            sig, impl_key = known
            self._impl_keys[sig.args] = impl_key
            return sig
        sig = get_call_type(self, context, args, kws)
        if sig is not None:
            _contexts.setdefault(id(context), context)
            _call_types.setdefault(self, {})[key] = (sig, self._impl_keys[sig.args])
        return sig

    wrapper._stickslip_once = True
    return wrapper


def _inliner():
    from numba.core import inline_closurecall, ir

    return inline_closurecall, ir


def _check_scope_copy() -> str | None:
    icc, ir = _inliner()
    return first_problem(
        has(icc, "InlineWorker"),
        lambda: has(icc.InlineWorker, "inline_ir",
                    ("self", "caller_ir", "block", "i", "callee_ir", "callee_freevars", "arg_typs")),
        lambda: source_has(icc.InlineWorker.inline_ir, "copy.deepcopy(the_ir.blocks[block_label])", "callee_scopes"),
        None if getattr(icc, "copy", None) is copy else "numba.core.inline_closurecall.copy is not the copy module",
        lambda: has(ir.Block, "__init__", ("self", "scope", "loc")))


def _apply_scope_copy() -> None:
    global _Block
    icc, ir = _inliner()
    _Block = ir.Block
    icc.InlineWorker.inline_ir = _one_scope_copy_per_call(icc.InlineWorker.inline_ir)
    icc.copy = _SharedScopeCopy()


def _check_ir_once() -> str | None:
    icc, _ = _inliner()
    from numba.core.targetconfig import TargetConfig

    def worker(name, params):
        return lambda: has(icc.InlineWorker, name, params)

    return first_problem(
        has(icc, "InlineWorker"),
        worker("inline_function", ("self", "caller_ir", "block", "i", "function", "arg_typs")),
        worker("run_untyped_passes", ("self", "func", "enable_ssa")),
        worker("inline_ir", ("self", "caller_ir", "block", "i", "callee_ir", "callee_freevars", "arg_typs")),
        lambda: source_has(icc.InlineWorker.inline_function, "self.run_untyped_passes(function)", "self.inline_ir("),
        lambda: source_has(icc.InlineWorker.__init__, "self.typingctx", "self.targetctx", "self.locals",
                           "self.pipeline", "self.flags"),
        has(TargetConfig, "values"))


def _apply_ir_once() -> None:
    icc, _ = _inliner()
    icc.InlineWorker.inline_function = _untyped_ir_once(icc.InlineWorker.inline_function)


def _check_flags_hash() -> str | None:
    from numba.core.compiler import Flags
    from numba.core.targetconfig import TargetConfig

    problem = first_problem(
        None if isinstance(getattr(TargetConfig, "options", None), Mapping) else "TargetConfig.options is no mapping",
        lambda: source_has(TargetConfig.__hash__, "sorted(self.values())"),
        lambda: source_has(TargetConfig.__eq__, "self.values() == other.values()"),
        lambda: None if isinstance(getattr(Flags(), "_values", None), dict) else "TargetConfig has no _values dict")
    if problem is None and TargetConfig.__hash__(Flags()) != _option_names_hash(Flags):
        problem = "TargetConfig.__hash__ is not the hash of the option names"
    return problem


def _apply_flags_hash() -> None:
    from numba.core.targetconfig import TargetConfig

    TargetConfig.__eq__ = _flags_equal(TargetConfig.__eq__)
    TargetConfig.__hash__ = _flags_hash  # assigning __eq__ in a class body would unset it; here it stays


def _check_call_type_once() -> str | None:
    from numba.core.types.functions import BaseFunction

    return first_problem(
        has(BaseFunction, "get_call_type", ("self", "context", "args", "kws")),
        lambda: source_has(BaseFunction.get_call_type, "self._impl_keys[sig.args] = temp.get_impl_key(sig)"),
        lambda: source_has(BaseFunction.__init__, "self._impl_keys = {}"))


def _apply_call_type_once() -> None:
    from numba.core.types.functions import BaseFunction

    BaseFunction.get_call_type = _call_type_once(BaseFunction.get_call_type)


def _components(cfg, order) -> list[list]:
    """The strongly connected components of the blocks ``order`` and those they lead to under
    ``cfg.successors``, in reverse topological order (Tarjan's algorithm, without recursion)."""
    index, low, on_stack, stack, components = {}, {}, set(), [], []
    for root in order:
        if root in index:
            continue
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        work = [(root, iter(cfg.successors(root)))]
        while work:
            node, successors = work[-1]
            for succ, _ in successors:
                if succ not in index:
                    index[succ] = low[succ] = len(index)
                    stack.append(succ)
                    on_stack.add(succ)
                    work.append((succ, iter(cfg.successors(succ))))
                    break
                if succ in on_stack:
                    low[node] = min(low[node], index[succ])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    components.append(component)
    return components


def _reaching(cfg, blocks, var_use_map, var_def_map) -> defaultdict:
    """For each of ``blocks`` (and the blocks they lead to): the variables defined or used in a
    block of them from which it is reached, itself included (numba's ``def_reach`` fix point); one
    set per strongly connected component, shared by its blocks (module docstring)."""
    components = _components(cfg, blocks)
    member_of = {block: k for k, component in enumerate(components) for block in component}
    reach = defaultdict(set)
    for k in range(len(components) - 1, -1, -1):  # predecessors' components first
        found = set()
        for block in components[k]:
            found |= var_def_map[block]
            found |= var_use_map[block]
            for pred, _ in cfg.predecessors(block):
                if member_of.get(pred, k) != k:
                    found |= reach[pred]
        for block in components[k]:
            reach[block] = found
    return reach


def _live_map(cfg, blocks, var_use_map, var_def_map):
    """numba's ``analysis.compute_live_map`` (the variables live at the entry of each block), with
    the reaching definitions from :func:`_reaching`; the liveness fix point is numba's."""
    # the blocks numba's fix points visit: every block (older numba), or those reachable from the entry
    order = list(var_def_map) if _EVERY_BLOCK else cfg.topo_order()
    def_reach_map = _reaching(cfg, order, var_use_map, var_def_map)
    live_map = {offset: set(var_use_map[offset]) for offset in blocks.keys()}
    backward = list(live_map) if _EVERY_BLOCK else list(reversed(order))
    old_point, new_point = None, tuple(len(v) for v in live_map.values())
    while old_point != new_point:
        for offset in backward:
            live_vars = live_map[offset]
            for inc_blk, _data in cfg.predecessors(offset):
                live_map[inc_blk] |= (live_vars & def_reach_map[inc_blk]) - var_def_map[inc_blk]
        old_point, new_point = new_point, tuple(len(v) for v in live_map.values())
    return live_map


#: Whether numba's ``compute_live_map`` visits every block rather than those reachable from the
#: entry (its topological order), as older numba does: :func:`_live_map` visits the same.
_EVERY_BLOCK = False


def _visits_every_block(compute_live_map) -> bool | None:
    """True where numba's ``compute_live_map`` visits every block (``for offset in var_def_map``,
    ``for offset in dct``), False where it visits the topological order, None otherwise."""
    import inspect

    try:
        text = inspect.getsource(compute_live_map)
    except (OSError, TypeError):
        return None
    if "for offset in var_def_map:" in text and "for offset in dct:" in text:
        return True
    if "for offset in topo_order:" in text and "for offset in reversed(topo_order):" in text:
        return False
    return None


def _check_live_map() -> str | None:
    from numba.core import analysis, controlflow, ir_utils

    return first_problem(
        has(analysis, "compute_live_map", ("cfg", "blocks", "var_use_map", "var_def_map")),
        lambda: source_has(analysis.compute_live_map, "def def_reach(dct):", "def liveness(dct):",
                           "dct[out_blk] |= dct[offset]", "reachable = live_vars & def_reach_map[inc_blk]",
                           "dct[inc_blk] |= reachable - var_def_map[inc_blk]"),
        lambda: None if _visits_every_block(analysis.compute_live_map) is not None
        else "analysis.compute_live_map visits neither every block nor the topological order",
        lambda: None if getattr(ir_utils, "compute_live_map", None) is analysis.compute_live_map
        else "numba.core.ir_utils.compute_live_map is not analysis.compute_live_map",
        has(controlflow.CFGraph, "topo_order"), has(controlflow.CFGraph, "successors"),
        has(controlflow.CFGraph, "predecessors"))


#: numba's own ``compute_live_map``, kept when :func:`_live_map` replaces it (the tests compare the two).
numba_live_map = None


def _apply_live_map() -> None:
    global numba_live_map, _EVERY_BLOCK
    from numba.core import analysis, ir_utils

    numba_live_map = analysis.compute_live_map
    _EVERY_BLOCK = _visits_every_block(numba_live_map)
    analysis.compute_live_map = _live_map
    ir_utils.compute_live_map = _live_map


def _package_overload(template) -> bool:
    """Whether an overload template is one of this package's (its typing function defined here)."""
    module = getattr(getattr(template, "_overload_func", None), "__module__", "") or ""
    return module == "stickslip" or module.startswith("stickslip.")


def _typed_not_compiled(get_jit_decorator):
    """numba's ``_get_jit_decorator``, whose decorator makes an always-inlined overload's
    implementation dispatcher of this package with compilation disabled (module docstring)."""
    @functools.wraps(get_jit_decorator)
    def wrapper(self):
        jitter = get_jit_decorator(self)
        if not (self._inline.is_always_inline and _package_overload(self)) or isinstance(self, _method_template()):
            return jitter

        def typed_only(**options):
            decorate = jitter(**options)

            def make(pyfunc):
                disp = decorate(pyfunc)
                disp._can_compile = False  # its call template then folds the arguments without compiling
                return disp
            return make
        return typed_only

    wrapper._stickslip_typed_only = True
    return wrapper


def _overload_template():
    from numba.core.typing import templates

    return templates._OverloadFunctionTemplate


def _method_template():
    from numba.core.typing import templates

    return templates._OverloadMethodTemplate


def _check_inline_overload() -> str | None:
    from numba.core.dispatcher import Dispatcher
    from numba.core.typing import templates

    template = _overload_template()
    return first_problem(
        has(templates, "_OverloadMethodTemplate"),
        has(template, "_get_jit_decorator", ("self",)),
        has(template, "_build_impl", ("self", "cache_key", "args", "kws")),
        has(template, "generic", ("self", "args", "kws")),
        lambda: source_has(template._build_impl, "jitter = self._get_jit_decorator()", "disp = jitdecor(pyfunc)",
                           "disp_type.get_call_type(self.context, args, kws)"),
        lambda: source_has(template.generic, "disp, new_args = self._get_impl(args, kws)",
                           "resolve = disp_type.dispatcher.get_call_template",
                           "template, pysig, folded_args, kws = resolve(new_args, kws)",
                           "if not self._inline.is_always_inline:"),
        has(Dispatcher, "disable_compile", ("self", "val")),
        lambda: source_has(Dispatcher.disable_compile, "self._can_compile = not val"),
        lambda: source_has(Dispatcher.get_call_template, "if self._can_compile:", "self.compile(tuple(args))"))


def _apply_inline_overload() -> None:
    template = _overload_template()
    template._get_jit_decorator = _typed_not_compiled(template._get_jit_decorator)


#: The six speed-ups as patches of :mod:`.numba_patches`: each independent of the others.
PATCHES = [Patch("inline-scope-copy", _check_scope_copy, _apply_scope_copy),
           Patch("inline-ir-once", _check_ir_once, _apply_ir_once),
           Patch("flags-hash", _check_flags_hash, _apply_flags_hash),
           Patch("call-type-once", _check_call_type_once, _apply_call_type_once),
           Patch("live-map-once", _check_live_map, _apply_live_map),
           Patch("inline-overload-typed", _check_inline_overload, _apply_inline_overload)]
