"""Two exact speed-ups of numba's compiler front end, where a cold compile spends its time.

**One copy of a callee's variable scope per inlined call, instead of one per block.** numba
inlines a function's IR (``inline="always"`` kernels, and overloads that inline) by deep-copying
the callee's blocks one at a time, each with a fresh memo. Every variable of a block refers to the
function's one :class:`numba.core.ir.Scope`, which holds every variable of the function, so each
block's copy copies the whole scope again: O(blocks × variables) per inlined call site. The
kernels here inline large bodies into one another (the physics into the event loop and its
steps), and this copying was a quarter of a cold compile (``simulate`` of the plates: 43.5 s →
33.2 s on two cores, the same results bit for bit). Numba's inliner is kept as it is; the
per-block copies of one inlined call get a memo that holds the scope's copy already, so the
blocks of a copied callee share one scope, as the blocks of any numba IR share theirs (the
inliner reads the callee's scope once and then moves every block into the caller's scope).
Outside an inlined call, and for anything but a block, ``copy.deepcopy`` behaves as before.

**The hash of compiler flags without reading them.** Every typing request of an overload looks up
its implementation by a key that holds the compiler flags (a ``TargetConfig``), and
``TargetConfig.__hash__`` builds the dict of every option's value and hashes its sorted *keys*:
the option names, the same for every instance of a class. Tens of thousands of failed ``getitem``
overload attempts per cold compile each paid that dict (−5 %: 31.4 s → 29.7 s). The hash is now
that of the class's sorted option names, computed once per class: the same number, so every
dict keyed by flags behaves as before. Equality, which such a lookup then tests, built both
dicts of values; it now answers at once where the two are one object or of one class with the
same options set to the same values (equal then, as before), and compares the values as before
otherwise.

:func:`install` makes both changes when the compiled layer is imported; with a numba laid out
otherwise it leaves that part alone.
"""

from __future__ import annotations

import copy
import functools
import threading
from collections.abc import Mapping

__all__ = ["install", "installed"]

_state = threading.local()


class _SharedScopeCopy:
    """Stands in for the ``copy`` module inside numba's inliner: a block's deep copy, made while
    an inlined call is copied, reuses that call's copy of the block's scope."""

    def __getattr__(self, name):
        return getattr(copy, name)

    @staticmethod
    def deepcopy(x, memo=None):
        scopes = getattr(_state, "scopes", None)
        if memo is None and scopes is not None and isinstance(x, _Block):
            scope = x.scope
            if id(scope) not in scopes:
                scopes[id(scope)] = (scope, copy.deepcopy(scope))  # the original kept alive: ids stay unique
            memo = {id(scope): scopes[id(scope)][1]}
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


def installed() -> bool:
    """Whether numba's inliner copies one scope per inlined call (:func:`install` took effect)."""
    try:
        from numba.core import inline_closurecall as icc
    except ImportError:  # pragma: no cover - numba always has it in the supported versions
        return False
    worker = getattr(icc, "InlineWorker", None)
    return isinstance(getattr(icc, "copy", None), _SharedScopeCopy) and \
        getattr(getattr(worker, "inline_ir", None), "_stickslip_shared_scope", False)


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


def _install_flags_hash() -> None:
    try:
        from numba.core.targetconfig import TargetConfig
    except ImportError:  # pragma: no cover
        return
    if not isinstance(getattr(TargetConfig, "options", None), Mapping):  # pragma: no cover - another layout
        return
    if TargetConfig.__hash__ is not _flags_hash:
        TargetConfig.__hash__ = _flags_hash
    if not getattr(TargetConfig.__eq__, "_stickslip_fast", False) and isinstance(getattr(TargetConfig(), "_values", None), dict):
        TargetConfig.__eq__ = _flags_equal(TargetConfig.__eq__)
        TargetConfig.__hash__ = _flags_hash  # assigning __eq__ in a class body would unset it; here it stays


def install() -> bool:
    """Make numba's inliner copy a callee's scope once per inlined call and numba's flags hash
    once per class; returns :func:`installed` (the inliner's part)."""
    global _Block
    _install_flags_hash()
    try:
        from numba.core import inline_closurecall as icc
        from numba.core import ir
    except ImportError:  # pragma: no cover
        return False
    worker = getattr(icc, "InlineWorker", None)
    if installed() or worker is None or not hasattr(worker, "inline_ir") or getattr(icc, "copy", None) is not copy:
        return installed()
    _Block = ir.Block
    worker.inline_ir = _one_scope_copy_per_call(worker.inline_ir)
    icc.copy = _SharedScopeCopy()
    return True
