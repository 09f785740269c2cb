"""First call of each command from an empty numba cache, against the same call cached.

What a new user waits for: each command is run as its own process (as a user runs it), first with
``NUMBA_CACHE_DIR`` a new empty folder, then again with that folder filled. The model-file
commands (``simulate``, ``stability``, ``orbit`` of a two-mass belt written as a model file) run
one after the other on one cache, as a first sitting with one's own model does. With
``--breakdown`` it also compiles the default ``simulate`` in this process with numba's compile
events recorded, and prints the outermost kernels by compile time (what a cold start is made of).

    python benchmarks/first_call.py [--breakdown] [--top 15]
Writes benchmarks/results/first_call.json.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MODEL_FILE = ROOT / "tests" / "orbits" / "two_mass_belt.toml"

#: (label, arguments of ``stickslip``, whether it starts a fresh cache).
COMMANDS = [
    ("simulate (defaults)", ["simulate", "--json"], True),
    ("simulate (model file)", ["simulate", "--model", str(MODEL_FILE), "--t-end", "100", "--json"], True),
    ("stability (model file)", ["stability", "--model", str(MODEL_FILE), "--json"], False),
    ("orbit (model file)", ["orbit", "--model", str(MODEL_FILE), "--search-time", "30", "--json", "--no-plot",
                            "--out", "{tmp}/orbit.nc"], False),
]


def _run(args, cache: Path, tmp: Path) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    args = [a.replace("{tmp}", str(tmp)) for a in args]
    start = time.perf_counter()
    res = subprocess.run([sys.executable, "-c", "from stickslip.cli import app; app()", *args], env=env,
                         capture_output=True, text=True, cwd=tmp)
    return {"seconds": time.perf_counter() - start, "exit": res.returncode,
            "stderr_tail": res.stderr.strip().splitlines()[-1:] if res.returncode else []}


def breakdown(top: int) -> list[dict]:
    """Outermost compilations of a default ``simulate`` in a fresh cache, longest first."""
    code = ("import json, time\n"
            "from numba.core import event\n"
            "import stickslip\n"
            "spans, depth, start = [], [0], [0.0]\n"
            "class L(event.Listener):\n"
            "    def on_start(self, ev):\n"
            "        if depth[0] == 0: start[0] = time.perf_counter()\n"
            "        depth[0] += 1\n"
            "    def on_end(self, ev):\n"
            "        depth[0] -= 1\n"
            "        if depth[0] == 0:\n"
            "            d = ev.data['dispatcher']\n"
            "            spans.append({'kernel': d.py_func.__module__ + '.' + d.py_func.__qualname__,\n"
            "                          'seconds': time.perf_counter() - start[0]})\n"
            "event.register('numba:compile', L())\n"
            "stickslip.simulate(t_end=1.0)\n"
            "print(json.dumps(spans))\n")
    with tempfile.TemporaryDirectory() as cache:
        res = subprocess.run([sys.executable, "-c", code], env=dict(os.environ, NUMBA_CACHE_DIR=cache),
                             capture_output=True, text=True, check=True)
    totals = collections.defaultdict(float)
    for span in json.loads(res.stdout.strip().splitlines()[-1]):
        totals[span["kernel"]] += span["seconds"]
    return [{"kernel": k, "seconds": round(v, 2)} for k, v in sorted(totals.items(), key=lambda kv: -kv[1])[:top]]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--breakdown", action="store_true", help="also list the kernels a cold simulate compiles")
    ap.add_argument("--top", type=int, default=15)
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp_root:
        cache = Path(tmp_root) / "cache"
        for label, cli_args, fresh in COMMANDS:
            if fresh:
                cache = Path(tempfile.mkdtemp(dir=tmp_root, prefix="cache"))
            work = Path(tempfile.mkdtemp(dir=tmp_root, prefix="work"))
            cold = _run(cli_args, cache, work)
            work = Path(tempfile.mkdtemp(dir=tmp_root, prefix="work"))
            warm = _run(cli_args, cache, work)
            rows.append({"command": label, "empty_cache_s": round(cold["seconds"], 2), "cached_s": round(warm["seconds"], 2),
                         "exit": [cold["exit"], warm["exit"]], "error": cold["stderr_tail"] + warm["stderr_tail"]})
            print(f"{label:<24} empty cache {cold['seconds']:6.1f} s   cached {warm['seconds']:5.1f} s"
                  + (f"   exit {cold['exit']}/{warm['exit']}: {rows[-1]['error']}" if cold["exit"] or warm["exit"] else ""))
    sitting = sum(r["empty_cache_s"] for r in rows[1:])
    print(f"a new model file: simulate, stability, orbit from an empty cache: {sitting:.1f} s together")
    out = {"commands": rows, "model_file_sitting_s": round(sitting, 2)}
    if args.breakdown:
        out["simulate_kernels"] = breakdown(args.top)
        for row in out["simulate_kernels"]:
            print(f"  {row['seconds']:6.1f} s  {row['kernel']}")
    path = ROOT / "benchmarks" / "results" / "first_call.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
