"""The kernels' disk cache: stamped with the whole compiled layer, and never fatal to write."""

from __future__ import annotations

import errno
import warnings

import pytest
from numba.core.caching import Cache, CacheImpl

from stickslip.model import jit


def test_every_kernel_of_the_package_is_stamped_with_the_compiled_layer():
    """A cached kernel is checked against every module it may inline, not only its own file."""
    from stickslip.model import physics

    locator = physics.rhs._cache._impl.locator
    stamp = locator.get_source_stamp()
    assert type(locator).__name__.startswith("Stickslip")
    assert isinstance(stamp, tuple) and stamp[1] == jit.compiled_layer_digest()
    assert CacheImpl._locator_classes[0].__name__.startswith("Stickslip")


def test_the_digest_covers_the_modules_that_define_or_specialise_kernels():
    text = (jit._PACKAGE / "model" / "normal.py").read_bytes()
    assert jit._COMPILED.search(text)  # the unilateral contacts' kernels count
    assert not jit._COMPILED.search((jit._PACKAGE / "errors.py").read_bytes())


def test_a_cache_file_that_cannot_be_written_is_one_warning_not_an_error(monkeypatch):
    """A full disk or a file-size limit while numba saves a kernel (seen under ulimit -f with an
    empty cache): the kernel runs uncached; the process warns once."""
    full = OSError(errno.EFBIG, "File too large")

    class Stub:
        _enabled = True

        def _guard_against_spurious_io_errors(self):
            return Cache._guard_against_spurious_io_errors(self)

        def _save_overload(self, sig, data):
            raise full

    stub = Stub()
    saved = Cache.save_overload
    assert saved._stickslip_wrapped
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        saved(stub, None, None)
        saved(stub, None, None)
    messages = [str(w.message) for w in caught]
    assert len(messages) <= 1 and all("could not be cached (File too large)" in m for m in messages)
    with pytest.raises(TypeError):  # anything but an OSError still surfaces
        Stub._save_overload = lambda self, sig, data: (_ for _ in ()).throw(TypeError("bug"))
        saved(stub, None, None)


def test_an_index_naming_a_class_this_process_cannot_import_keeps_its_entries(tmp_path, monkeypatch):
    """A cache index whose keys name a class from a module that is gone (a user's script, a test
    folder) still loads: that entry with a stand-in, the others as they were; saved again, the
    stand-in is written as the original name, so a process that can import it gets it back."""
    import pickle
    import sys
    import types

    from numba.core.caching import IndexDataCacheFile
    from numba.core.serialize import dumps as numba_dumps

    module = types.ModuleType("gone_kinematics")
    exec("class Arm:\n    pass\n", module.__dict__)
    monkeypatch.setitem(sys.modules, "gone_kinematics", module)
    index = {("sig", module.Arm): "kernel-1.nbc", ("sig", int): "kernel-2.nbc"}
    data = pickle.dumps(("stamp", index), protocol=-1)
    monkeypatch.delitem(sys.modules, "gone_kinematics")
    path = tmp_path / "kernel.nbi"
    with open(path, "wb") as f:
        pickle.dump("v1", f, protocol=-1)
        f.write(data)
    fake = types.SimpleNamespace(_index_path=str(path), _version="v1", _source_stamp="stamp")
    loaded = IndexDataCacheFile._load_index(fake)
    assert sorted(loaded.values()) == ["kernel-1.nbc", "kernel-2.nbc"]
    stand_in = next(key[1] for key, value in loaded.items() if value == "kernel-1.nbc")
    assert "gone_kinematics.Arm" in repr(stand_in) and stand_in is not int
    again = numba_dumps(loaded)  # as numba saves it (cloudpickle, which pickles unknown classes by value)
    monkeypatch.setitem(sys.modules, "gone_kinematics", module)
    restored = pickle.loads(again)
    assert ("sig", module.Arm) in restored and restored[("sig", int)] == "kernel-2.nbc"
    fake._source_stamp = "another"  # a stale index is empty, as numba has it
    assert IndexDataCacheFile._load_index(fake) == {}
