"""The kernels' disk cache: stamped with the whole compiled layer, and never fatal to write."""

from __future__ import annotations

import errno
import pickle
import tempfile
import types
import warnings
from pathlib import Path

import pytest
from numba.core.caching import Cache, CacheImpl

from stickslip.model import jit, kernel_cache, numba_patches


def test_every_kernel_of_the_package_is_stamped_with_the_compiled_layer():
    """A cached kernel is checked against every module it may inline, not only its own file."""
    from stickslip.model import physics

    locator = physics.rhs._cache._impl.locator
    stamp = locator.get_source_stamp()
    assert type(locator).__name__.startswith("Stickslip")
    assert isinstance(stamp, tuple) and stamp[1] == jit.compiled_layer_digest()
    assert CacheImpl._locator_classes[0].__name__.startswith("Stickslip")


def test_the_digest_covers_the_modules_that_define_or_specialise_kernels():
    text = (kernel_cache._PACKAGE / "model" / "normal.py").read_bytes()
    assert kernel_cache._COMPILED.search(text)  # the unilateral contacts' kernels count
    assert not kernel_cache._COMPILED.search((kernel_cache._PACKAGE / "errors.py").read_bytes())
    for module in kernel_cache._MACHINERY:  # what shapes a cache entry counts, kernels or not
        assert (kernel_cache._PACKAGE / module).is_file()


def test_a_cache_folder_is_checked_once_per_process_and_a_folder_outside_the_package_never(monkeypatch, tmp_path):
    """numba checks that a kernel's cache folder is writable by writing a file there; the package's
    some 200 kernels share a few folders, checked once each."""
    from stickslip.model import physics

    written = []
    real = tempfile.TemporaryFile
    monkeypatch.setattr(tempfile, "TemporaryFile", lambda *a, **kw: written.append(kw.get("dir")) or real(*a, **kw))
    monkeypatch.setattr(kernel_cache, "_WRITABLE", set())
    in_tree = CacheImpl._locator_classes[1]
    for _ in range(3):
        locator = in_tree.from_function(physics.rhs.py_func, physics.__file__)
        assert locator.get_cache_path() == str(Path(physics.__file__).parent / "__pycache__")
    assert written == [locator.get_cache_path()]
    outside = tmp_path / "user.py"
    outside.write_text("def f():\n    return 1\n")
    assert in_tree.from_function(physics.rhs.py_func, str(outside)) is None  # numba's own locators take it


def test_a_cache_file_that_cannot_be_written_is_one_warning_not_an_error(monkeypatch, tmp_path):
    """A full disk or a file-size limit while numba saves a kernel (seen under ulimit -f with an
    empty cache): the kernel runs uncached; the run warns once."""
    monkeypatch.setenv(numba_patches.RUN_ENV, f"test-{tmp_path.name}")  # a run that has not warned
    monkeypatch.setattr(numba_patches, "_SAID", set())
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
    assert len(messages) == 1 and "could not be cached (File too large)" in messages[0]
    monkeypatch.setattr(numba_patches, "_SAID", set())  # another process of the run: it is not said again
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        saved(stub, None, None)
    assert caught == []
    for marker in Path(tempfile.gettempdir()).glob(f"stickslip-*-test-{tmp_path.name}-*"):
        marker.unlink()
    with pytest.raises(TypeError):  # anything but an OSError still surfaces
        Stub._save_overload = lambda self, sig, data: (_ for _ in ()).throw(TypeError("bug"))
        saved(stub, None, None)


def test_an_index_naming_a_class_this_process_cannot_import_keeps_its_entries(tmp_path, monkeypatch):
    """A cache index whose keys name a class from a module that is gone (a user's script, a test
    folder) still loads: that entry with a stand-in, the others as they were; saved again, the
    stand-in is written as the original name, so a process that can import it gets it back."""
    import sys

    from numba.core.serialize import dumps as numba_dumps

    module = types.ModuleType("gone_kinematics")
    exec("class Arm:\n    pass\n", module.__dict__)
    monkeypatch.setitem(sys.modules, "gone_kinematics", module)
    index = {("sig", module.Arm): "kernel-1.nbc", ("sig", int): "kernel-2.nbc"}
    data = pickle.dumps(("stamp", index), protocol=-1)
    monkeypatch.delitem(sys.modules, "gone_kinematics")
    path = tmp_path / "kernel.nbi"
    with open(path, "wb") as f:
        pickle.dump(f"v1+{kernel_cache.FORMAT}", f, protocol=-1)
        f.write(kernel_cache._sealed(data))
    fake = types.SimpleNamespace(_index_path=str(path), _version="v1", _source_stamp="stamp")
    loaded = kernel_cache._load_index(fake)
    assert sorted(loaded.values()) == ["kernel-1.nbc", "kernel-2.nbc"]
    stand_in = next(key[1] for key, value in loaded.items() if value == "kernel-1.nbc")
    assert "gone_kinematics.Arm" in repr(stand_in) and stand_in is not int
    again = numba_dumps(loaded)  # as numba saves it (cloudpickle, which pickles unknown classes by value)
    monkeypatch.setitem(sys.modules, "gone_kinematics", module)
    restored = pickle.loads(again)
    assert ("sig", module.Arm) in restored and restored[("sig", int)] == "kernel-2.nbc"
    fake._source_stamp = "another"  # a stale index is empty, as numba has it
    assert kernel_cache._load_index(fake) == {}


class _Files(types.SimpleNamespace):
    """numba's ``IndexDataCacheFile`` as far as the checksummed reads and writes use it."""

    def _dump(self, obj):
        return pickle.dumps(obj, protocol=-1)

    def _data_path(self, name):
        return str(Path(self._cache_path) / name)

    def _open_for_write(self, path):
        return open(path, "wb")


def _said(monkeypatch, tmp_path) -> list:
    monkeypatch.setenv(numba_patches.RUN_ENV, f"test-{tmp_path.name}")
    monkeypatch.setattr(numba_patches, "_SAID", set())
    lines = []
    monkeypatch.setattr(kernel_cache, "notice", lambda key, line, say=None: lines.append((key, line)))
    return lines


@pytest.mark.parametrize("damage", ["truncate", "flip", "garble", "empty"])
def test_a_damaged_index_or_data_file_is_a_miss_said_once(tmp_path, monkeypatch, damage):
    """Whatever happened to a cache file after it was written (cut short by a full disk, a flipped
    bit, garbage), reading it gives a miss, never an unpickling error or damaged object code, and
    one line says so."""
    lines = _said(monkeypatch, tmp_path)
    files = _Files(_cache_path=str(tmp_path), _index_path=str(tmp_path / "k.nbi"), _version="v1",
                   _source_stamp=("stamp", "digest"))
    overloads = {("sig",): "k.1.nbc"}
    data = ("object code " * 200).encode()
    kernel_cache._save_index(files, overloads)
    kernel_cache._save_data(files, "k.1.nbc", data)
    assert kernel_cache._load_index(files) == overloads and kernel_cache._load_data(files, "k.1.nbc") == data
    assert lines == []
    for path in (tmp_path / "k.nbi", tmp_path / "k.1.nbc"):
        blob = bytearray(path.read_bytes())
        if damage == "truncate":
            blob = blob[:len(blob) // 2]
        elif damage == "flip":
            blob[len(blob) * 2 // 3] ^= 0x04
        elif damage == "garble":
            blob[-30:-10] = b"g" * 20
        else:
            blob = b""
        path.write_bytes(bytes(blob))
    assert kernel_cache._load_index(files) == {}
    assert kernel_cache._load_data(files, "k.1.nbc") is None
    assert [key for key, _ in lines] == ["damaged-cache", "damaged-cache"]  # notice() says it once per run
    assert "k.nbi" in lines[0][1] and "compiled again" in lines[0][1]


def test_an_index_of_numba_without_the_patch_is_not_read_as_ours(tmp_path, monkeypatch):
    """numba's own index format (another process, the patch off) is another version's: empty, unsaid."""
    lines = _said(monkeypatch, tmp_path)
    path = tmp_path / "k.nbi"
    with open(path, "wb") as f:
        pickle.dump("v1", f, protocol=-1)
        f.write(pickle.dumps((("stamp", "digest"), {("sig",): "k.1.nbc"})))
    files = _Files(_cache_path=str(tmp_path), _index_path=str(path), _version="v1", _source_stamp=("stamp", "digest"))
    assert kernel_cache._load_index(files) == {} and lines == []


def test_only_the_package_kernels_cache_files_take_the_checksummed_format():
    """A user's own cached numba functions keep numba's format (their caches stay readable by
    numba without stickslip)."""
    from stickslip.model import physics

    assert kernel_cache._ours(physics.rhs._cache._cache_file)
    assert not kernel_cache._ours(types.SimpleNamespace(_source_stamp=(1.0, 2)))


def test_index_keys_carry_the_patches_that_change_what_an_entry_holds():
    """A process with other patches (the standalone kernels off, say) looks its kernels up under
    other keys, so it never loads an entry in a payload format it does not read."""
    from numba.core.registry import cpu_target

    from stickslip.model import physics

    assert kernel_cache.patch_tag() == ("stickslip", "python-entry", "standalone-linking")
    from numba import types as nbtypes

    sig = (nbtypes.float64[::1],)
    key = physics.rhs._cache._index_key(sig, cpu_target.target_context.codegen())
    assert key[0] == sig and kernel_cache.patch_tag() in key


_LOADS_A_KERNEL = """
import sys
from stickslip.model.linalg import solve_psd_2x2
x1, x2, rank = solve_psd_2x2(4.0, 1.0, 3.0, 1.0, 2.0)
print(repr(x1), repr(x2), rank, "numba.np.arraymath" in sys.modules)
"""


def test_a_cached_kernel_loads_without_numbas_registries_and_computes_the_same():
    """A process that only loads the package's kernels from the cache (a warm command) leaves
    numba's implementation registries (and scipy.linalg, which they import) unloaded; the loaded
    kernel computes what it computes in a process that loaded them first, and the exact solution."""
    import subprocess
    import sys

    def run(code):
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr
        return res.stdout.split()

    run(_LOADS_A_KERNEL)  # compiled here if the cache lacked it
    *loaded, registries = run(_LOADS_A_KERNEL)
    *refreshed, registries_first = run("from numba.core.registry import cpu_target\n"
                                       "cpu_target.target_context.refresh()\n" + _LOADS_A_KERNEL)
    assert registries == "False" and registries_first == "True"
    assert loaded == refreshed
    x1, x2 = float(loaded[0]), float(loaded[1])  # [[4, 1], [1, 3]] x = [1, 2]: x = (1/11, 7/11)
    assert loaded[2] == "2" and abs(x1 - 1 / 11) < 1e-15 and abs(x2 - 7 / 11) < 1e-15
