"""Exact speed-ups of numba's compiler front end (stickslip.model.compile_speedups)."""

from __future__ import annotations

import copy

import numpy as np
from numba import njit
from numba.core import inline_closurecall as icc
from numba.core import ir

import stickslip.model.jit  # noqa: F401  (installs it)
from stickslip.model import compile_speedups


def test_installed_with_the_compiled_layer():
    from numba.core.targetconfig import TargetConfig
    from numba.core.types.functions import BaseFunction

    from stickslip.model import numba_patches

    assert {patch.name for patch in compile_speedups.PATCHES} <= numba_patches.status()["active"]
    assert numba_patches.install() is numba_patches.status()  # a second install changes nothing
    assert isinstance(icc.copy, compile_speedups._SharedScopeCopy)
    assert getattr(icc.InlineWorker.inline_ir, "_stickslip_shared_scope", False)
    assert getattr(icc.InlineWorker.inline_function, "_stickslip_once", False)
    assert getattr(BaseFunction.get_call_type, "_stickslip_once", False)
    assert TargetConfig.__hash__ is compile_speedups._flags_hash


def _blocks(n_blocks: int):
    scope = ir.Scope(None, ir.Loc("f", 1))
    blocks = []
    for b in range(n_blocks):
        block = ir.Block(scope, ir.Loc("f", b))
        var = scope.redefine(f"v{b}", ir.Loc("f", b))
        block.append(ir.Assign(ir.Const(b, ir.Loc("f", b)), var, ir.Loc("f", b)))
        blocks.append(block)
    return scope, blocks


def test_blocks_copied_for_one_inlined_call_share_one_scope_copy():
    scope, blocks = _blocks(3)
    compile_speedups._state.scopes = {}
    try:
        copies = [icc.copy.deepcopy(b) for b in blocks]
    finally:
        compile_speedups._state.scopes = None
    assert copies[0].scope is copies[1].scope is copies[2].scope
    assert copies[0].scope is not scope and copies[0].scope == scope
    assert copies[2].body[0].target.scope is copies[0].scope
    # outside an inlined call: numba's per-block copies, as before
    plain = [icc.copy.deepcopy(b) for b in blocks]
    assert plain[0].scope is not plain[1].scope
    assert icc.copy.copy is copy.copy


@njit(inline="always")
def _clipped(x, lo, hi):
    if x < lo:
        return lo
    if x > hi:
        return hi
    total = 0.0
    for i in range(3):
        total += x * i
    return total


@njit
def _uses_inlined(a):
    out = np.empty(a.size)
    for i in range(a.size):
        out[i] = _clipped(a[i], -1.0, 1.0) + _clipped(2.0 * a[i], -0.5, 0.5)
    return out


def test_inlined_kernels_compute_what_python_computes():
    a = np.linspace(-2.0, 2.0, 41)
    expected = np.array([_clipped.py_func(x, -1.0, 1.0) + _clipped.py_func(2.0 * x, -0.5, 0.5) for x in a])
    np.testing.assert_array_equal(_uses_inlined(a), expected)


def test_an_inlined_callee_is_translated_once_for_all_its_call_sites(monkeypatch):
    """Three call sites of a fresh callee in two callers: the untyped pipeline runs on it once, and
    each site's copy computes with its own variables (what Python computes)."""
    calls = []
    run = icc.InlineWorker.run_untyped_passes
    monkeypatch.setattr(icc.InlineWorker, "run_untyped_passes",
                        lambda self, func, enable_ssa=False: calls.append(func.__name__) or run(self, func, enable_ssa))

    @njit(inline="always")
    def weighted(x, k):
        acc = 0.0
        for i in range(k):
            acc += x * (i + 1)
        return acc

    @njit
    def first(a):
        return weighted(a[0], 2) + weighted(a[1], 3)

    @njit
    def second(a):
        s = 0.0
        for v in a:
            s += weighted(v, 4)
        return s

    a = np.array([0.5, -1.25, 2.0])
    assert first(a) == weighted.py_func(0.5, 2) + weighted.py_func(-1.25, 3)
    assert second(a) == sum(weighted.py_func(v, 4) for v in a)
    assert calls.count("weighted") == 1


def test_flags_hash_is_numbas_own_number():
    """numba's TargetConfig hashed the sorted keys of its values dict: the same number, once per class."""
    from numba.core.compiler import Flags

    flags = Flags()
    flags.nrt = True
    other = Flags()
    assert hash(flags) == hash(tuple(sorted({k: getattr(flags, k) for k in flags.options})))
    assert hash(flags) == hash(other) and flags != other  # equal hashes, values still compared
    assert {flags: 1}.get(Flags(flags)) == 1


def test_flags_equality_is_numbas():
    """Equal where every option's value is equal, set or defaulted (numba's own comparison)."""
    from numba.core.compiler import Flags

    a, b = Flags(), Flags()
    assert a == a and a == b
    a.nrt = True
    assert a != b
    b.nrt = True
    assert a == b
    c = Flags()
    c.boundscheck = Flags.options["boundscheck"].default  # set to its default: equal to unset
    assert c == Flags() and Flags() == c
    c.boundscheck = not Flags.options["boundscheck"].default if Flags.options["boundscheck"].default is not None else True
    assert c != Flags()


def test_a_builtin_call_is_typed_once_per_argument_types_and_records_its_implementation():
    """The second typing of ``float64 * float64`` is the first's signature, answered without the
    templates, and records the implementation key for lowering again, as numba does at every call."""
    import operator

    from numba.core import types
    from numba.core.registry import cpu_target

    ctx = cpu_target.typing_context
    ctx.refresh()
    fnty = ctx.resolve_value_type(operator.mul)
    args = (types.float64, types.float64)
    first = fnty.get_call_type(ctx, args, {})
    key = fnty._impl_keys[first.args]
    assert compile_speedups._call_types[fnty][(id(ctx), args, ())] == (first, key)
    del fnty._impl_keys[first.args]
    assert fnty.get_call_type(ctx, args, {}) is first
    assert fnty._impl_keys[first.args] == key


def test_a_rejected_builtin_call_fails_each_time_with_numbas_error():
    import operator

    import pytest
    from numba.core import types
    from numba.core.errors import TypingError
    from numba.core.registry import cpu_target

    ctx = cpu_target.typing_context
    ctx.refresh()
    fnty = ctx.resolve_value_type(operator.truediv)
    for _ in range(2):
        with pytest.raises(TypingError):
            fnty.get_call_type(ctx, (types.unicode_type, types.float64), {})
    assert (id(ctx), (types.unicode_type, types.float64), ()) not in compile_speedups._call_types.get(fnty, {})


@njit
def _repeated_products(x, y):
    a = x * y
    b = (x + 1.0) * y
    c = x * (y - 2.0)
    return a * b * c


def test_a_function_of_repeated_builtin_calls_computes_what_python_computes():
    assert _repeated_products(1.5, -0.25) == _repeated_products.py_func(1.5, -0.25)


def _random_flow(rng, n_blocks: int, n_vars: int):
    """A CFG of ``n_blocks`` blocks (forward edges, back edges that make loops, some blocks
    unreachable) and random sets of variables used and defined in each block."""
    from numba.core.controlflow import CFGraph

    cfg = CFGraph()
    for b in range(n_blocks):
        cfg.add_node(b)
    for b in range(n_blocks - 1):
        for target in rng.choice(n_blocks, size=rng.integers(1, 3), replace=False):
            if target != 0 and (target > b or rng.random() < 0.3):
                cfg.add_edge(b, int(target))
    cfg.set_entry_point(0)
    cfg.process()
    names = [f"v{i}" for i in range(n_vars)]
    uses = {b: set(rng.choice(names, size=rng.integers(0, 6))) for b in range(n_blocks)}
    defs = {b: set(rng.choice(names, size=rng.integers(0, 4))) for b in range(n_blocks)}
    return cfg, {b: None for b in range(n_blocks)}, uses, defs


def test_live_maps_are_numbas_on_random_flow_graphs():
    rng = np.random.default_rng(7)
    for _ in range(300):
        cfg, blocks, uses, defs = _random_flow(rng, int(rng.integers(1, 40)), int(rng.integers(1, 30)))
        assert compile_speedups._live_map(cfg, blocks, uses, defs) == compile_speedups.numba_live_map(
            cfg, blocks, uses, defs)


@njit
def _nested_loops(a, n):
    total = 0.0
    for i in range(n):
        x = a[i]
        while x > 1.0:
            if x > 10.0:
                x = _clipped(x, 0.0, 10.0)
                continue
            x = x / 2.0
        total += x
    return total


def test_live_maps_are_numbas_on_every_function_a_compile_analyses(monkeypatch):
    from numba.core import analysis, ir_utils

    calls = []

    def both(cfg, blocks, var_use_map, var_def_map):
        ours = compile_speedups._live_map(cfg, blocks, var_use_map, var_def_map)
        assert ours == compile_speedups.numba_live_map(cfg, blocks, var_use_map, var_def_map)
        calls.append(len(blocks))
        return ours

    monkeypatch.setattr(analysis, "compute_live_map", both)
    monkeypatch.setattr(ir_utils, "compute_live_map", both)
    a = np.array([0.5, 3.0, 40.0])
    assert _nested_loops(a, 3) == _nested_loops.py_func(a, 3)
    assert calls and max(calls) > 5


def _overload_impls(function) -> list:
    """The implementation dispatchers numba has made so far for the overload ``function``."""
    from numba.core.registry import cpu_target

    fnty = cpu_target.typing_context.resolve_value_type(function)
    return [disp for template in fnty.templates for disp, _ in template._impl_cache.values() if disp is not None]


def test_an_inlined_overload_of_the_package_is_typed_and_inlined_without_compiling_it():
    """A kernel that calls an ``inline="always"`` overload of the package computes what the
    overload's Python implementation computes, and the implementation's dispatcher was never
    compiled (every call of it is inlined); an inlined overload of another module is compiled as
    numba does."""
    from numba.extending import overload

    from stickslip.model.jit import KERNEL_OPTIONS
    from stickslip.model.model_data import _gram_row, gram_row

    @njit(**KERNEL_OPTIONS)
    def rows(g, MG, k, n, A):
        for r in range(2):
            gram_row(0.0, g[r], MG, k, n, A, r, 0.0)

    rng = np.random.default_rng(3)
    g, MG, A = rng.normal(size=(2, 5)), rng.normal(size=(3, 5)), np.zeros((2, 3))
    rows(g, MG, 3, 5, A)
    expected = np.zeros((2, 3))
    _gram_row(None, None, None, None, None, None, None, None)(None, g[0], MG, 3, 5, expected, 0, 0.0)
    _gram_row(None, None, None, None, None, None, None, None)(None, g[1], MG, 3, 5, expected, 1, 0.0)
    np.testing.assert_array_equal(A, expected)
    impls = _overload_impls(gram_row)
    assert impls and all(not disp._can_compile and not disp.overloads for disp in impls)

    def scaled(x):  # pragma: no cover - resolved by numba
        raise NotImplementedError

    @overload(scaled, inline="always")
    def _scaled(x):
        return lambda x: 2.0 * x

    @njit
    def twice(x):
        return scaled(x)

    assert twice(1.5) == 3.0
    (other,) = _overload_impls(scaled)
    assert other._can_compile and other.overloads  # numba's own way outside the package
