"""stickslip's changes to numba fail safe, and its cache survives damage (each run a process of its own).

With ``STICKSLIP_NUMBA_PATCHES=0`` numba runs as it comes: the library models give the same
results bit for bit (the patches change how much numba compiles, never the code it emits), with one
line on stderr. A numba that lacks a private name a patch needs runs with that patch off, likewise.
A cache file cut short, bit-flipped or garbled is compiled again, with one line, and the run's
results are those of the undamaged cache.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from stickslip.model.numba_patches import ENV, RUN_ENV

from .helpers import STICKSLIP

SCRIPT = Path(__file__).with_name("numba_results.py")

#: Wall-clock limit of each run [s]: a guard against a hung process, not a speed check. A run
#: without the patches compiles every kernel anew (numba 0.57, pressed group: 13.5 CPU minutes), and on a
#: shared machine a process may get a fifth of a core (20 min was too short for the pressed and
#: rigid groups at numba 0.57 on a 2-core machine at load 10-16).
RUN_TIMEOUT_S = 3600

#: The library models by kinematics class (each class compiles its own kernels, so each group is a
#: test of its own that pytest's workers can share out): the models simulated, and the stability
#: eigenvalues of the belt, and the period and multipliers of popp-stelter's stick-slip cycle from rest.
GROUPS = {
    "plates": ["two-plates"],
    "pressed": ["belt,popp-stelter", "--stability", "belt", "--orbit", "popp-stelter:x2_max"],
    "unilateral": ["hoffmann,slider-belt,sprag-slip"],
    "rigid": ["impact-oscillator"],
}


def _env(**extra) -> dict:
    """This environment as a new run's (its notices not yet said), compiling in one process."""
    env = {key: value for key, value in os.environ.items() if key not in (RUN_ENV, ENV)}
    return {**env, "STICKSLIP_COMPILE_PROCESSES": "1", **extra}


def _results(args: list, env: dict, prelude: str = "") -> tuple[dict, list]:
    """The JSON printed by ``numba_results.py args`` in a new process (after running ``prelude``
    there), and its stderr lines."""
    code = f"{prelude}\nimport runpy, sys\nsys.argv = sys.argv[1:]\nrunpy.run_path(sys.argv[0], run_name='__main__')"
    res = subprocess.run([sys.executable, "-c", code, str(SCRIPT), *args], capture_output=True, text=True, env=env,
                         timeout=RUN_TIMEOUT_S)
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(res.stdout), [line for line in res.stderr.splitlines() if line.strip()]


@pytest.mark.parametrize("group", sorted(GROUPS))
def test_without_the_patches_the_library_models_give_the_same_results_bit_for_bit(group, tmp_path):
    args = GROUPS[group]
    patched, said = _results(args, _env())  # the suite's cache
    assert said == []
    stock, said = _results(args, _env(**{ENV: "0", "NUMBA_CACHE_DIR": str(tmp_path / "stock")}))
    assert stock == patched
    (line,) = said
    assert line.startswith(f"stickslip: {ENV}=0: numba runs without stickslip's changes to it")


#: Before stickslip is imported, numba as a version that lacks what three patches need: a locator
#: class gone (the cache is not kept), and the functions that the standalone kernels and the
#: inliner's translate-once wrap given another shape (numba itself runs on them as before).
_LACKING = """
from numba.core import caching, funcdesc, inline_closurecall as icc
for name in ("InTreeCacheLocator", "_InTreeCacheLocator"):
    if hasattr(caching, name):
        delattr(caching, name)
from_python = funcdesc.FunctionDescriptor._from_python_function.__func__
funcdesc.FunctionDescriptor._from_python_function = classmethod(lambda cls, *a, **k: from_python(cls, *a, **k))
inline_function = icc.InlineWorker.inline_function
icc.InlineWorker.inline_function = lambda self, *a, **k: inline_function(self, *a, **k)
"""


def test_a_numba_without_a_name_a_patch_needs_runs_without_that_patch_with_one_line(tmp_path):
    reference, _ = _results(["belt"], _env())
    result, said = _results(["belt"], _env(NUMBA_CACHE_DIR=str(tmp_path / "cache")), prelude=_LACKING)
    assert result == reference
    (line,) = said
    assert "lacks what some of stickslip's changes to it need" in line
    for name in ("cache-keeping", "standalone-linking", "inline-ir-once"):
        assert f"{name} (" in line
    for name in ("flags-hash", "call-type-once", "python-entry"):
        assert f"{name} (" not in line
    assert not list((tmp_path / "cache").glob("model_*/*.nbi"))  # the package's kernels were not cached


_BELT = ["simulate", "--model", "belt", "--ic", "x=1,dx=1", "--t-end", "5", "--json"]


def _simulate(cache: Path) -> tuple[dict, list]:
    res = subprocess.run([STICKSLIP, *_BELT], capture_output=True, text=True, timeout=RUN_TIMEOUT_S,
                         env=_env(NUMBA_CACHE_DIR=str(cache)))
    assert res.returncode == 0, res.stderr[-3000:]
    result = json.loads(res.stdout)
    for timing in ("wall_time_s", "compile_time_s"):
        result.pop(timing)
    return result, [line for line in res.stderr.splitlines() if line.strip()]


def _data_file(cache: Path, kernel: str) -> Path:
    """The first of the data files of ``kernel`` (one per version compiled)."""
    return sorted(cache.rglob(f"{kernel}-*.nbc"))[0]


def test_a_damaged_cache_is_compiled_again_with_one_line_and_the_same_results(tmp_path):
    """One data file cut short, one with a bit flipped in its object code, one index garbled: the
    next run exits 0 with the same JSON and says so once; the run after it finds the cache whole."""
    cache = tmp_path / "cache"
    first, said = _simulate(cache)
    assert said == []
    truncated = _data_file(cache, "stick.solve_stick_rows")
    truncated.write_bytes(truncated.read_bytes()[:truncated.stat().st_size // 2])
    flipped = _data_file(cache, "forces.general_forces")
    blob = bytearray(flipped.read_bytes())
    blob[len(blob) // 2] ^= 0x10  # the object code is the bulk of the file
    flipped.write_bytes(bytes(blob))
    (garbled,) = cache.rglob("physics.rhs-*.nbi")
    blob = bytearray(garbled.read_bytes())
    blob[-40:-20] = b"garbage, not pickles"
    garbled.write_bytes(bytes(blob))

    again, said = _simulate(cache)
    assert again == first
    (line,) = said
    assert line.startswith("stickslip: a damaged file of numba's cache (") and "compiled again" in line
    whole, said = _simulate(cache)
    assert whole == first and said == []
