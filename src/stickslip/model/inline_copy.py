"""One copy of a callee's variable scope per inlined call, instead of one per block.

numba inlines a function's IR (``inline="always"`` kernels, and overloads that inline) by
deep-copying the callee's blocks one at a time, each with a fresh memo. Every variable of a block
refers to the function's one :class:`numba.core.ir.Scope`, which holds every variable of the
function, so each block's copy copies the whole scope again: O(blocks × variables) per inlined
call site. The kernels here inline large bodies into one another (the physics into the event
loop and its steps), and this copying was a quarter of a cold compile (``simulate`` of the
plates: 43.5 s → 32.5 s on two cores, the same results bit for bit).

:func:`install` keeps numba's inliner as it is and only gives the per-block copies of one
inlined call a memo that holds the scope's copy already, so the blocks of a copied callee share
one scope, as the blocks of any numba IR share theirs (the inliner reads the callee's scope once
and then moves every block into the caller's scope). Outside an inlined call, and for anything
but a block, ``copy.deepcopy`` behaves as before. It is installed when the compiled layer is
imported; with a numba whose inliner is not laid out this way it installs nothing.
"""

from __future__ import annotations

import copy
import functools
import threading

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


def install() -> bool:
    """Make numba's inliner copy a callee's scope once per inlined call; returns :func:`installed`."""
    global _Block
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
