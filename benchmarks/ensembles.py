"""Basin ensembles: CPU time per state of a basin study, this tree against a revision, in one run.

The peers' friction case (bSTAB, pyBasin): the belt at v_d = 1.5, at most 500 time units a
state, ``--states`` states drawn uniformly from x ∈ [−2, 2], x' ∈ [0, 2] (the same seed for
both). Each package runs the study in a process of its own (the revision's extracted by ``git
archive`` as ``stickslip_baseline``, as benchmarks/ab.py does, with a numba cache of its own),
first a small study that compiles or loads the kernels (not timed), then the whole study,
alternately ``--pairs`` times. Measured: the CPU time of the study's processes (the process
itself and its waited-for children: the pool's workers, the forked writer) per state, in
ms·core, and the wall time; the machine's load average before and after each. The labels are
compared state by state, and the fractions and their standard errors.

    python benchmarks/ensembles.py [--rev main] [--states 20000] [--workers 2] [--pairs 1]
Writes benchmarks/results/ensembles.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ab import ROOT, baseline_package  # noqa: E402

CHILD = r"""
import json, os, resource, sys, tempfile, time
from collections import Counter
from pathlib import Path
import numpy as np
pkg = __import__(sys.argv[1])
from importlib import import_module
basins = import_module(sys.argv[1] + ".basins")
library = import_module(sys.argv[1] + ".model.library")
n, workers, executor, labels_out = int(sys.argv[2]), int(sys.argv[3]), sys.argv[4], sys.argv[5]
belt = library.load_model("belt")
box = {"x": (-2.0, 2.0), "dx": (0.0, 2.0)}
with tempfile.TemporaryDirectory() as tmp:
    basins.basin_stability(belt, basins.box(belt, box, n=64, seed=99), out=Path(tmp) / "warm.nc", executor=executor,
                           workers=workers)
    def cpu():
        s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime
    load = [round(x, 2) for x in os.getloadavg()]
    c0, t0 = cpu(), time.perf_counter()
    res = basins.basin_stability(belt, basins.box(belt, box, n=n, seed=0), out=Path(tmp) / "b.nc", executor=executor,
                                 workers=workers)
    wall, used = time.perf_counter() - t0, cpu() - c0
    ds = res.to_xarray()
names = ds["decided_by"].attrs["flag_meanings"].split()
np.save(labels_out, np.stack([ds["label"].values.astype(float), ds["steps"].values.astype(float),
                              ds["t_decided"].values, ds["decided_by"].values.astype(float)]))
np.save(labels_out.replace(".npy", "_states.npy"), ds["initial_state"].values)
print(json.dumps({"wall_s": wall, "cpu_s": used, "ms_core_per_state": 1e3 * used / n, "load_before": load,
                  "load_after": [round(x, 2) for x in os.getloadavg()], "fractions": res.fractions,
                  "standard_errors": res.standard_errors,
                  "decided_by": dict(Counter(names[int(c)] for c in ds["decided_by"].values)),
                  "mean_steps": float(ds["steps"].mean()), "mean_t_decided": float(ds["t_decided"].mean()),
                  "batch_size": res.timings.get("batch_size")}))
"""


def run(package: str, path: Path, cache: Path, args, labels: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": str(path), "NUMBA_CACHE_DIR": str(cache)}
    out = subprocess.run([sys.executable, "-c", CHILD, package, str(args.states), str(args.workers), args.executor,
                          str(labels)], env=env, capture_output=True, text=True)
    if out.returncode:
        raise SystemExit(f"{package} failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default="main")
    ap.add_argument("--states", type=int, default=20000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--executor", default="processes", choices=["serial", "processes"])
    ap.add_argument("--pairs", type=int, default=1)
    args = ap.parse_args()
    rev = subprocess.run(["git", "-C", str(ROOT), "rev-parse", args.rev], check=True, capture_output=True,
                         text=True).stdout.strip()
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], check=True, capture_output=True,
                          text=True).stdout.strip()
    runs: dict = {"baseline": [], "tree": []}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        baseline_package(rev, tmp)
        sides = {"baseline": ("stickslip_baseline", tmp, tmp / "cache-baseline"),
                 "tree": ("stickslip", ROOT / "src", tmp / "cache-tree")}
        for _ in range(args.pairs):
            for side, (package, path, cache) in sides.items():
                runs[side].append(run(package, path, cache, args, tmp / f"{side}.npy"))
                print(f"{side:8s} {runs[side][-1]['ms_core_per_state']:.3f} ms·core/state, wall "
                      f"{runs[side][-1]['wall_s']:.1f} s (load {runs[side][-1]['load_before']} -> "
                      f"{runs[side][-1]['load_after']})", flush=True)
        base, tree = np.load(tmp / "baseline.npy"), np.load(tmp / "tree.npy")
        same_states = bool(np.array_equal(np.load(tmp / "baseline_states.npy"), np.load(tmp / "tree_states.npy")))
    b, t = runs["baseline"][-1], runs["tree"][-1]
    cost = {side: min(r["ms_core_per_state"] for r in rs) for side, rs in runs.items()}
    result = {
        "case": {"model": "belt", "v_d": 1.5, "t_end": 500.0, "box": {"x": [-2, 2], "dx": [0, 2]}, "seed": 0,
                 "states": args.states, "workers": args.workers, "executor": args.executor},
        "rev": args.rev, "rev_commit": rev, "tree_commit": head, "machine": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(), "runs": runs, "ms_core_per_state": cost,
        "speedup": cost["baseline"] / cost["tree"], "goal_ms_core_per_state": 0.5,
        "same_states": same_states, "labels_equal": int(np.sum(base[0] == tree[0])),
        "steps_equal": int(np.sum(base[1] == tree[1])), "t_decided_equal": int(np.sum(base[2] == tree[2])),
        "decided_by_equal": int(np.sum(base[3] == tree[3])),
        "fractions_equal": b["fractions"] == t["fractions"], "standard_errors_equal": b["standard_errors"] == t["standard_errors"]}
    print(f"belt, {args.states} states x 500, {args.executor} on {args.workers}: {args.rev} {cost['baseline']:.3f}, "
          f"tree {cost['tree']:.3f} ms·core/state (x{result['speedup']:.2f}; goal <= 0.5)")
    print(f"  labels equal {result['labels_equal']}/{args.states}, steps equal {result['steps_equal']}, t_decided "
          f"equal {result['t_decided_equal']}, decided_by equal {result['decided_by_equal']}; fractions "
          f"{t['fractions']} +- {t['standard_errors']} (equal: {result['fractions_equal']}, "
          f"{result['standard_errors_equal']})")
    path = ROOT / "benchmarks" / "results" / "ensembles.json"
    path.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
