"""stickslip's changes to numba: one installer, a check per patch, one line where numba runs as it comes."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import numba

from stickslip.model import numba_patches
from stickslip.model.numba_patches import RUN_ENV

ALL = {"inline-scope-copy", "inline-ir-once", "flags-hash", "call-type-once", "live-map-once", "inline-overload-typed",
       "python-entry", "standalone-linking", "cache-keeping", "cache-load", "fork-helper"}


def _fresh_env(**extra) -> dict:
    """This environment as a new run's (its notices not yet said), with ``extra`` set."""
    env = {key: value for key, value in os.environ.items() if key not in (RUN_ENV, numba_patches.ENV)}
    return {**env, **extra}


def _python(code: str, **env) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          env=_fresh_env(**env), timeout=300)


def _lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip()]


def test_every_patch_installs_on_a_tested_numba():
    """This environment's numba is one of the tested versions, and each patch's check passes on it:
    a check that failed here would silently cost the compile speed it stands for."""
    assert ".".join(numba.__version__.split(".")[:2]) in numba_patches.TESTED
    status = numba_patches.status()
    assert status["reason"] is None and status["skipped"] == {}
    assert status["active"] == ALL


def test_a_check_says_what_differs():
    class Owner:
        def method(self, a, b=1):
            """reads self.thing"""

    assert numba_patches.has(Owner, "method", ("self", "a", "b")) is None
    assert numba_patches.has(Owner, "gone") == "no Owner.gone"
    assert numba_patches.has(Owner, "method", ("self", "a")) == "Owner.method(self, a, b) is not Owner.method(self, a)"
    assert numba_patches.source_has(Owner.method, "self.thing") is None
    assert "does not read 'self.other'" in numba_patches.source_has(Owner.method, "self.thing", "self.other")
    calls = []
    assert numba_patches.first_problem(None, lambda: "first", lambda: calls.append(1)) == "first"
    assert calls == []  # a check after a problem is not made (it may rely on what was missing)


def test_off_on_request_numba_runs_as_it_comes_with_one_line():
    res = _python("""
        from stickslip.model import jit, numba_patches
        from numba.core import caching
        status = numba_patches.status()
        print(sorted(status["active"]), jit._CACHE, type(jit.kernel(lambda x: x)._cache).__name__,
              caching.CacheImpl._locator_classes[0].__name__.lstrip("_"))  # numba 0.57 names it _User...
    """, STICKSLIP_NUMBA_PATCHES="0")
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["[]", "False", "NullCache", "UserProvidedCacheLocator"]
    (line,) = _lines(res.stderr)
    assert line.startswith("stickslip: STICKSLIP_NUMBA_PATCHES=0: numba runs without stickslip's changes")


def test_an_untested_numba_runs_as_it_comes_with_one_line():
    res = _python("""
        import numba
        numba.__version__ = "0.99.0"
        from stickslip.model import numba_patches
        print(sorted(numba_patches.status()["active"]))
    """)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["[]"]
    (line,) = _lines(res.stderr)
    assert "numba 0.99.0 is not one of the versions stickslip is tested with" in line
    assert f"install numba>={numba_patches.TESTED[0]},<" in line


#: Before stickslip is imported: each patch's private name removed from numba or given another
#: shape, in ways numba itself survives (nothing is compiled in this process).
_EVERY_NAME_CHANGED = """
    import copy, types
    from numba.core import caching, compiler_lock, funcdesc, inline_closurecall as icc
    from numba.core.registry import CPUDispatcher
    from numba.core.targetconfig import TargetConfig
    from numba.core.types.functions import BaseFunction

    icc.copy = types.SimpleNamespace(deepcopy=copy.deepcopy, copy=copy.copy)   # inline-scope-copy
    inline_function = icc.InlineWorker.inline_function
    def other_inline_function(self, caller_ir, block, i, function, arg_typs=None):
        return inline_function(self, caller_ir, block, i, function, arg_typs)
    icc.InlineWorker.inline_function = other_inline_function                   # inline-ir-once
    def other_eq(self, other):
        return isinstance(other, TargetConfig) and dict(self.values()) == dict(other.values())
    TargetConfig.__eq__ = other_eq                                            # flags-hash
    get_call_type = BaseFunction.get_call_type
    def other_get_call_type(self, context, args, kws):
        return get_call_type(self, context, args, kws)
    BaseFunction.get_call_type = other_get_call_type                          # call-type-once
    from numba.core import analysis
    compute_live_map = analysis.compute_live_map
    analysis.compute_live_map = lambda cfg, blocks, var_use_map, var_def_map: compute_live_map(
        cfg, blocks, var_use_map, var_def_map)                                # live-map-once
    from numba.core.typing import templates
    build_impl = templates._OverloadFunctionTemplate._build_impl
    def other_build_impl(self, cache_key, args, kws, *more):
        return build_impl(self, cache_key, args, kws)
    templates._OverloadFunctionTemplate._build_impl = other_build_impl        # inline-overload-typed
    add_overload = CPUDispatcher.add_overload
    def other_add_overload(self, cres, *more):
        return add_overload(self, cres)
    CPUDispatcher.add_overload = other_add_overload                           # python-entry
    from_python = funcdesc.FunctionDescriptor._from_python_function.__func__
    funcdesc.FunctionDescriptor._from_python_function = classmethod(
        lambda cls, *args, **kwargs: from_python(cls, *args, **kwargs))       # standalone-linking
    for name in ("InTreeCacheLocator", "_InTreeCacheLocator"):                # cache-keeping
        if hasattr(caching, name):
            delattr(caching, name)
    load_overload = caching.Cache.load_overload
    def other_load_overload(self, sig, target_context):
        return load_overload(self, sig, target_context)
    caching.Cache.load_overload = other_load_overload                         # cache-load
    del compiler_lock.global_compiler_lock                                    # fork-helper
"""


def test_where_numba_lacks_what_each_patch_needs_each_is_skipped_and_said_in_one_line():
    res = _python(_EVERY_NAME_CHANGED + """
    import stickslip
    from stickslip.model import jit, numba_patches
    status = numba_patches.status()
    print(sorted(status["active"]), sorted(status["skipped"]), jit._CACHE)
    """)
    assert res.returncode == 0, res.stderr
    assert "Traceback" not in res.stderr
    (line,) = _lines(res.stderr)
    assert line.startswith(f"stickslip: numba {numba.__version__} lacks what some of stickslip's changes to it need")
    for name in ALL:
        assert f"{name} (" in line
    assert "no caching.InTreeCacheLocator" in line or "has no InTreeCacheLocator" in line
    active, skipped, cache = res.stdout.strip().split("] ")
    assert active == "[" and cache == "False"


def test_a_notice_is_said_once_per_run_whatever_process_of_it_says_it(tmp_path):
    """The workers of a campaign inherit the run: a notice one of them said is not said again by
    another; a new run says it again."""
    code = """
        import sys
        from stickslip.model.numba_patches import notice
        said = notice("test-notice", "once")
        said_again = notice("test-notice", "once")
        print(int(said), int(said_again))
    """
    run = f"{os.getpid()}-test-{tmp_path.name}"
    first = _python(code, **{RUN_ENV: run})
    second = _python(code, **{RUN_ENV: run})
    other = _python(code)
    assert first.stdout.split() == ["1", "0"] and _lines(first.stderr) == ["stickslip: once"]
    assert second.stdout.split() == ["0", "0"] and second.stderr == ""
    assert other.stdout.split() == ["1", "0"]
    for path in Path(tempfile.gettempdir()).glob(f"stickslip-*-{run}-*"):  # none of them was the run's root
        path.unlink()


def test_a_source_check_that_passed_is_remembered_for_the_same_code_only(tmp_path, monkeypatch):
    """The installer reads numba's source text once per install of numba: a check that passed is
    remembered (in this process and, through the file, the next) for that code; a failed check, a
    function replaced (a wrapper of another source) and a check outside the installer read it."""
    import inspect

    reads = []
    real = inspect.getsource
    monkeypatch.setattr(numba_patches.inspect, "getsource", lambda f: reads.append(f.__qualname__) or real(f))
    path = tmp_path / "checks.json"

    def method(self):
        return self.thing

    with numba_patches.remembered_checks(path):
        assert numba_patches.source_has(method, "self.thing") is None
        assert numba_patches.source_has(method, "self.thing") is None
        assert "does not read 'self.other'" in numba_patches.source_has(method, "self.other")
    assert len(reads) == 2 and path.is_file()
    with numba_patches.remembered_checks(path):  # as a new process: from the file
        assert numba_patches.source_has(method, "self.thing") is None
        assert "does not read 'self.other'" in numba_patches.source_has(method, "self.other")
    assert len(reads) == 3
    namespace = {}
    exec("def method(self):\n    return self.other\n", namespace)  # same name, other code, no source file
    with numba_patches.remembered_checks(path):
        assert numba_patches.source_has(namespace["method"], "self.thing") == "no source of method"
    assert numba_patches.source_has(method, "self.thing") is None  # outside the installer: read
    assert len(reads) == 5


def test_a_remembered_check_is_keyed_alike_in_every_process():
    """The key of a check does not depend on the process (string hashing is salted per process)."""
    code = """
        from numba.core.registry import CPUDispatcher
        from stickslip.model import numba_patches
        print(numba_patches.code_key(CPUDispatcher.__init__, ("self._compiler = ",)))
    """
    keys = {_python(code, PYTHONHASHSEED=seed).stdout.strip() for seed in ("1", "2")}
    assert len(keys) == 1 and len(keys.pop()) == 64


def test_an_unreadable_or_unwritable_memory_of_checks_is_no_error(tmp_path):
    garbled = tmp_path / "garbled.json"
    garbled.write_text("{not json")
    unwritable = tmp_path / "file" / "checks.json"
    (tmp_path / "file").write_text("a file where a folder would be")

    def method(self):
        return self.thing

    for path in (garbled, unwritable):
        with numba_patches.remembered_checks(path):
            assert numba_patches.source_has(method, "self.thing") is None
    assert not unwritable.exists()
