"""Every gallery example (``examples/plot_*.py``) runs as a plain script: ``python FILE`` in a
scratch folder with a non-interactive matplotlib backend, exit status 0, nothing written into
the repository or the working folder.

The documentation build runs the same files inside Sphinx; these runs are the scripts a reader
copies. They take a few seconds each once the kernels are compiled and minutes from an empty
numba cache, so they run when ``STICKSLIP_EXAMPLES=1`` is set: CI sets it in its documentation
step, after the tests have filled the cache.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("plot_*.py"))

pytestmark = pytest.mark.skipif(os.environ.get("STICKSLIP_EXAMPLES") != "1",
                                reason="the gallery's scripts run with STICKSLIP_EXAMPLES=1 (CI's docs step)")


def snapshot(folder: Path) -> dict:
    return {p: p.stat().st_mtime_ns for p in folder.rglob("*") if "__pycache__" not in p.parts}


def test_there_are_at_least_twelve_examples():
    assert len(EXAMPLES) >= 12


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs_as_a_script(path, tmp_path):
    before = snapshot(ROOT / "examples")
    env = {**os.environ, "MPLBACKEND": "Agg"}
    run = subprocess.run([sys.executable, str(path)], cwd=tmp_path, env=env, capture_output=True, text=True, check=False,
                         timeout=900)
    assert run.returncode == 0, f"{path.name} failed:\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}"
    assert not list(tmp_path.iterdir()), f"{path.name} wrote into its working folder: {list(tmp_path.iterdir())}"
    assert snapshot(ROOT / "examples") == before, f"{path.name} wrote into examples/"
