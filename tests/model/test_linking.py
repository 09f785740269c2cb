"""Standalone kernels (stickslip.model.linking): called by their callers, not copied into them."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from stickslip.model import linking

_MODULE = textwrap.dedent('''
    import numpy as np
    from stickslip.model.jit import kernel, standalone

    @standalone
    @kernel
    def weighted_sum(a, w):
        total = 0.0
        for i in range(a.shape[0]):
            total += w * a[i] * a[i]
        return total

    @kernel
    def caller(a):
        return weighted_sum(a, 2.0) + weighted_sum(a, 0.5)
''')

_RUN = textwrap.dedent('''
    import sys
    import numpy as np
    from numba.core import event
    sys.path.insert(0, sys.argv[1])
    compiles = []

    class Count(event.Listener):
        def on_start(self, e):
            compiles.append(e.data["dispatcher"].py_func.__name__)
        def on_end(self, e):
            pass
    event.register("numba:compile", Count())
    import standalone_kernels as sk
    a = np.linspace(0.1, 1.7, 9)
    print(repr(sk.caller(a)))
    (args,) = sk.weighted_sum.overloads
    print(sk.weighted_sum.overloads[args].fndesc.mangled_name)
    (cargs,) = sk.caller.overloads
    library = sk.caller.overloads[cargs].library
    defined = [f.name for f in library._final_module.functions if not f.is_declaration]
    print(int(any("weighted_sum" in name for name in defined)))
    print(",".join(sorted(set(compiles))) or "-")
''')


@pytest.fixture
def run_in_new_process(tmp_path):
    """Runs ``_RUN`` with ``_MODULE`` as ``standalone_kernels`` in a new process on one numba cache
    under ``tmp_path``; returns its printed lines: the caller's result, the standalone kernel's
    symbol, whether the caller's module defines it (1) and the kernels compiled (``-``: none)."""
    (tmp_path / "standalone_kernels.py").write_text(_MODULE)
    (tmp_path / "run.py").write_text(_RUN)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}

    def run():
        res = subprocess.run([sys.executable, str(tmp_path / "run.py"), str(tmp_path)], capture_output=True, text=True,
                             env=env, timeout=300)
        assert res.returncode == 0, res.stderr
        return res.stdout.split()

    return run


def test_a_caller_calls_the_standalone_kernel_and_loads_from_the_cache_after_it(run_in_new_process):
    a = np.linspace(0.1, 1.7, 9)
    expected = 2.0 * float(np.sum(a * a)) + 0.5 * float(np.sum(a * a))

    result, symbol, defined, compiled = run_in_new_process()
    assert float(result) == pytest.approx(expected, rel=1e-14)
    assert defined == "0"  # the caller's module declares the kernel, it does not carry a copy
    assert compiled == "caller,weighted_sum"

    # a new process loads the caller only after the kernel it calls, under the same symbol
    again = run_in_new_process()
    assert again == [result, symbol, "0", "-"]


def test_a_standalone_kernel_has_the_same_symbol_in_every_process(run_in_new_process, tmp_path):
    first = run_in_new_process()
    # another process compiles it afresh (its cache is gone): numba's per-process numbering would
    # give it another symbol, and the caller cached before would not load beside it
    for path in (tmp_path / "cache").rglob("*weighted_sum*"):
        path.unlink()
    second = run_in_new_process()
    assert second[1] == first[1]
    assert second[3] == "weighted_sum"  # only the kernel compiled again: the cached caller loaded


def test_a_cached_caller_whose_callee_is_not_there_under_its_symbol_is_a_miss():
    """Loading a caller whose standalone callee is defined under another symbol would leave a call
    that the JIT engine cannot resolve (a fatal error); the load refuses it instead, and numba
    compiles the caller afresh."""
    import numba
    from numba.core.registry import cpu_target

    from stickslip.model import linalg

    args = (np.zeros((2, 2)), np.zeros(2), np.zeros(2), np.zeros((2, 2)), np.int64(2))
    types = tuple(numba.typeof(x) for x in args)
    dependencies = {"_ZN_not_the_symbol_of_solve_psd": ("stickslip.model.linalg", "solve_psd", types, False)}
    with pytest.raises(linking.StaleDependency):
        linking._load_dependencies(cpu_target.target_context, dependencies)
    assert types in linalg.solve_psd.overloads  # the kernel itself was loaded or compiled

    class Cache:
        def _load_overload(self, sig, target_context):
            raise linking.StaleDependency("_ZN_not_the_symbol")

    assert linking._stale_is_a_miss(Cache._load_overload)(Cache(), (), None) is None
