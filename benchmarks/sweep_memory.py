"""Sweep memory benchmark: peak resident memory (RSS) of a whole sweep at several grid sizes.

Each sweep runs in a fresh Python process (so nothing is shared or cached between sizes) over an
(N, Ω) grid and reports

* ``peak_rss_mb``: peak RSS of the driver process (``ru_maxrss``), which journals, assembles the
  NetCDF and, with ``--executor serial``, also evaluates the points;
* ``peak_rss_children_mb``: the largest peak RSS of its worker processes (``processes`` executor;
  with ``serial`` it is a short-lived helper forked by a library at import, whose ``ru_maxrss``
  is the parent's RSS at the fork, and says nothing about the sweep);
* the per-point cost, the NetCDF size, and the baseline of a 16-point sweep (imports, compiled
  kernels, xarray/h5netcdf) so that the growth with the grid is visible apart from it.

Two tasks per point:

``simulate`` (default)  a real :func:`stickslip.simulate` run of ``--t-end`` seconds, reduced;
``trivial``             no simulation: ``stickslip.sweep.spec.evaluate`` is replaced in the child
                        by a function that returns a synthetic row (deterministic in the index),
                        so that 10^5 points take seconds. Everything that can grow with the grid
                        (the journal, the done mask, the NetCDF assembly, the returned dataset)
                        runs exactly as in a real sweep; what a real point adds (one trajectory,
                        freed after its reduction) does not depend on the grid size.

The NetCDF is assembled in slabs of ``SLAB_POINTS`` points from an index-ordered scratch copy of
the journal (``sweep/store.py``), and sweeps above ``LOAD_LIMIT_POINTS`` points are returned
opened lazily, so the peak should not grow with the grid beyond 1 byte per point (the done mask)
and the ≤ 46 MB of a loaded result at the limit.

Run: python benchmarks/sweep_memory.py [--sizes 10000 100000] [--task trivial] [--t-end 1] [--executor serial]
Writes benchmarks/results/sweep_memory[_trivial].json.
"""

import argparse
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

_CHILD = r"""
import json, resource, sys, time
import numpy as np
import importlib
spec_module = importlib.import_module("stickslip.sweep.spec")
from stickslip.sweep import sweep
n_side_a, n_side_b, t_end, executor, workers, out, task = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), sys.argv[4], int(sys.argv[5]), sys.argv[6], sys.argv[7]
if task == "trivial":
    def evaluate(spec, flat_index):  # a synthetic row: no simulation, same width as a real one
        row = np.random.default_rng(int(flat_index)).normal(size=spec.row_width)
        row[0] = 1.0  # outcome code of a periodic orbit (stickslip.OUTCOMES)
        return row
    spec_module.evaluate = evaluate
grid = {"N": np.linspace(10.0, 130.0, n_side_a).tolist(), "Omega": np.linspace(0.5, 15.0, n_side_b).tolist()}
t = time.perf_counter()
res = sweep(grid, out=out, executor=executor, workers=workers, t_end=t_end, t_from=0.5 * t_end, snapshot_interval=1e9)
wall = time.perf_counter() - t
kb = 1024.0  # ru_maxrss is in KiB on Linux
print(json.dumps({
    "points": n_side_a * n_side_b, "wall_s": wall,
    "compute_s": res.timings.get("compute_s"), "first_point_s": res.timings.get("first_point_s"),
    "sum_point_s": float(res.dataset["wall_time"].sum()) if task == "simulate" else wall,
    "failed": int((res.dataset["attractor"] == 7).sum()),  # stickslip.OUTCOMES.index("failed")
    "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / kb,
    "peak_rss_children_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / kb,
}))
"""


def measure(points: int, t_end: float, executor: str, workers: int, task: str = "simulate") -> dict:
    """Run one sweep of about ``points`` points in a fresh process and return its measurements."""
    a = max(1, int(round(math.sqrt(points))))
    b = max(1, int(round(points / a)))
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "mem.nc"
        proc = subprocess.run([sys.executable, "-c", _CHILD, str(a), str(b), str(t_end), executor, str(workers), str(out), task],
                              capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            raise RuntimeError(f"child failed:\n{proc.stderr[-3000:]}")
        result = json.loads(proc.stdout.strip().splitlines()[-1])
        result["netcdf_mb"] = out.stat().st_size / 2**20
    result["grid"] = [a, b]
    return result


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000], help="grid sizes (points)")
    ap.add_argument("--t-end", type=float, default=1.0, help="simulated time per point [s]")
    ap.add_argument("--executor", default="serial", choices=["serial", "processes", "dask"])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--task", default="simulate", choices=["simulate", "trivial"],
                    help="simulate each point, or return a synthetic row (store/journal memory only; serial)")
    args = ap.parse_args()
    if args.task == "trivial" and args.executor != "serial":
        ap.error("--task trivial patches evaluate in the driver process; use --executor serial")
    report = {"machine": platform.processor() or platform.machine(), "cpus": os.cpu_count(), "python": sys.version.split()[0],
              "t_end": args.t_end, "executor": args.executor, "task": args.task, "workers": args.workers, "runs": []}
    t0 = time.perf_counter()
    for points in [16] + list(args.sizes):  # 16 points: the baseline (imports, kernels, I/O libraries)
        r = measure(points, args.t_end, args.executor, args.workers, args.task)
        report["runs"].append(r)
        print(f"{r['points']:>7d} points  wall {r['wall_s']:7.1f} s  ({1e3 * r['sum_point_s'] / r['points']:.2f} ms/point)  "
              f"peak RSS {r['peak_rss_mb']:7.1f} MB (workers {r['peak_rss_children_mb']:6.1f} MB)  "
              f"NetCDF {r['netcdf_mb']:.2f} MB", flush=True)
    base = report["runs"][0]["peak_rss_mb"]
    runs = report["runs"][1:]
    for r in runs:
        r["above_baseline_mb"] = r["peak_rss_mb"] - base
    if len(runs) >= 2:
        lo, hi = runs[0], runs[-1]
        slope = (hi["peak_rss_mb"] - lo["peak_rss_mb"]) / (hi["points"] - lo["points"])  # MB per point
        report["growth_kb_per_point"] = 1024.0 * slope
        print(f"growth {report['growth_kb_per_point']:.3f} kB/point between {lo['points']} and {hi['points']} points")
        if hi["points"] < 1e5:
            report["extrapolated_peak_rss_mb_1e5"] = hi["peak_rss_mb"] + slope * (1e5 - hi["points"])
            report["extrapolation_note"] = "linear in the points from the smallest and largest measured sizes; not measured"
            print(f"10^5 points extrapolated (not measured): {report['extrapolated_peak_rss_mb_1e5']:.0f} MB")
    report["total_s"] = time.perf_counter() - t0
    Path(__file__).parent.joinpath("results").mkdir(exist_ok=True)
    name = "sweep_memory.json" if args.task == "simulate" else f"sweep_memory_{args.task}.json"
    Path(__file__).parent.joinpath("results", name).write_text(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
