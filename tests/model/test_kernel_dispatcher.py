"""Kernels compiled for other kernels without numba's Python entry (stickslip.model.jit.KernelDispatcher)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np

from stickslip.model.jit import KERNEL_OPTIONS, KernelDispatcher


def uncached(func) -> KernelDispatcher:
    """A kernel as :func:`stickslip.model.jit.kernel` makes it, without the on-disk cache (each test
    compiles afresh, whatever an earlier run left there)."""
    return KernelDispatcher(py_func=func, locals={}, targetoptions={"nopython": True, **KERNEL_OPTIONS})


def test_a_kernel_compiled_for_a_kernel_is_compiled_again_for_python():
    @uncached
    def _weighted(a, w):
        total = 0.0
        for i in range(a.shape[0]):
            total += w * a[i]
        return total

    @uncached
    def _calls_weighted(a):
        return _weighted(a, 2.0) + 1.0

    a = np.arange(5.0)
    assert isinstance(_weighted, KernelDispatcher)
    assert _calls_weighted(a) == 21.0  # compiles _weighted for the call inside, without the Python entry
    args = next(iter(_weighted.overloads))
    assert args not in _weighted._with_entry
    assert _weighted(a, 2.0) == 20.0  # Python's call: compiled again, now with the entry
    assert args in _weighted._with_entry and len(_weighted.overloads) == 1
    assert _weighted(a, 3.0) == 30.0 and _calls_weighted(a + 1.0) == 31.0  # one version for both


def test_a_kernel_called_from_python_first_serves_kernels_too():
    @uncached
    def scaled(a, w):
        return w * a[0]

    @uncached
    def caller(a):
        return scaled(a, 4.0)

    a = np.array([1.5])
    assert scaled(a, 2.0) == 3.0
    assert caller(a) == 6.0
    assert len(scaled.overloads) == 1 and next(iter(scaled.overloads)) in scaled._with_entry


_CACHED = textwrap.dedent('''
    import sys
    import numpy as np
    sys.path.insert(0, sys.argv[1])
    import cached_kernels as ck
    a = np.arange(4.0)
    if sys.argv[2] == "kernel-only":
        print(ck.outer(a), "-")
    else:
        print(ck.inner(a), ck.outer(a))
    print(sum(ck.inner.stats.cache_hits.values()), sum(ck.inner.stats.cache_misses.values()))
''')

_MODULE = textwrap.dedent('''
    from stickslip.model.jit import kernel

    @kernel
    def inner(a):
        return a[0] + a[-1]

    @kernel
    def outer(a):
        return 10.0 * inner(a)
''')


def _cached_runs(tmp_path, module: str):
    """A function that runs ``_CACHED`` with ``module`` as ``cached_kernels`` in a new process on one
    numba cache under ``tmp_path``, in the given order, and returns what it printed (split)."""
    (tmp_path / "cached_kernels.py").write_text(module)
    (tmp_path / "run.py").write_text(_CACHED)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}

    def run(order):
        res = subprocess.run([sys.executable, str(tmp_path / "run.py"), str(tmp_path), order], capture_output=True,
                             text=True, env=env, timeout=300)
        assert res.returncode == 0, res.stderr
        return res.stdout.split()

    return run


def test_the_on_disk_cache_keeps_the_two_versions_apart(tmp_path):
    """A version without the entry, cached by one process, is never what another process's Python
    call loads (it would have no code to enter)."""
    run = _cached_runs(tmp_path, _MODULE)

    assert run("kernel-only")[:2] == ["30.0", "-"]  # inner compiled and cached without its entry
    first = run("python-first")  # its Python call must not load that one (it would crash)
    assert first[:2] == ["3.0", "30.0"] and first[3] == "1"  # compiled with the entry
    again = run("python-first")
    assert again[:2] == ["3.0", "30.0"] and again[2:] == ["1", "0"]  # and now loaded from the cache


def test_an_api_kernel_compiled_for_a_kernel_serves_python_without_a_second_compile():
    def _scaled(a, w):
        return w * a[0]

    scaled = uncached(_scaled)
    scaled.always_entry = True  # as stickslip.model.jit.api_kernel makes it

    @uncached
    def caller(a):
        return scaled(a, 4.0)

    a = np.array([1.5])
    assert caller(a) == 6.0  # compiles scaled for the kernel's call, with its Python entry
    args = next(iter(scaled.overloads))
    assert args in scaled._with_entry
    compiled = scaled.overloads[args]
    assert scaled(a, 2.0) == 3.0  # Python's call enters that version
    assert len(scaled.overloads) == 1 and scaled.overloads[args] is compiled


def test_the_physics_that_analyses_call_from_python_are_api_kernels():
    """The kernels ``stability`` and the orbit tools call from Python, which ``simulate``'s event
    loop calls too: one compiled version serves both (from the cache in a later command)."""
    from stickslip.integrate import contacts
    from stickslip.model import physics as P

    for name in ("rhs", "contact_forces", "stick_forces", "slip_velocity", "project_velocities"):
        assert getattr(P, name).always_entry, name
    assert contacts.initial_modes.always_entry
    assert not P.general_rhs.always_entry  # a kernel only kernels call keeps to no entry


def test_the_cache_gives_an_api_kernel_compiled_for_a_kernel_to_python(tmp_path):
    module = _MODULE.replace("import kernel", "import api_kernel, kernel").replace("@kernel\ndef inner", "@api_kernel\ndef inner")
    assert "@api_kernel" in module
    run = _cached_runs(tmp_path, module)

    assert run("kernel-only")[:2] == ["30.0", "-"]  # inner compiled for outer, with its entry, and cached
    assert run("python-first") == ["3.0", "30.0", "1", "0"]  # Python's call loads it: a hit, no compile
