"""Sweep benchmark: Fig. 12(a) (121 values of N, Ω = 0.5 rad/s, 200 s each) on serial,
processes and dask executors with the same number of workers; ratios measured in one run.

Run: python benchmarks/sweep.py [--workers 2] [--points 121] [--t-end 200]
Writes benchmarks/results/sweep.json.
"""

import argparse
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

from stickslip.sweep import sweep
from stickslip.sweep.spec import TIMING_COLUMNS


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--points", type=int, default=121)
    ap.add_argument("--t-end", type=float, default=200.0)
    args = ap.parse_args()
    grid = {"N": np.linspace(10.0, 130.0, args.points).tolist()}
    from stickslip import Parameters

    params = Parameters(Omega=0.5)
    out = {"machine": platform.processor() or platform.machine(), "cpus": os.cpu_count(), "workers": args.workers,
           "points": args.points, "t_end": args.t_end}
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for ex in ("serial", "processes", "dask"):
            t = time.perf_counter()
            res = sweep(grid, params, out=Path(tmp) / f"{ex}.nc", executor=ex, workers=args.workers, t_end=args.t_end)
            wall = time.perf_counter() - t
            results[ex] = res.dataset
            work = float(res.dataset["wall_time"].sum())
            out[ex] = {"wall_s": wall, **{k: v for k, v in res.timings.items() if isinstance(v, (int, float, str))},
                       "sum_point_s": work}
            print(ex, f"{wall:.2f} s", res.timings)
    for ex in ("processes", "dask"):
        out[f"speedup_{ex}"] = out["serial"]["wall_s"] / out[ex]["wall_s"]
        same = all(results["serial"][v].equals(results[ex][v]) for v in results["serial"].data_vars if v not in TIMING_COLUMNS)
        out[f"identical_{ex}"] = bool(same)
    d = out["dask"]
    # scheduler overhead: wall time beyond the ideal share of the work, start-up excluded
    ideal = d["sum_point_s"] / args.workers
    d["overhead_fraction"] = (d["compute_s"] - d.get("cluster_start_s", 0) - d.get("worker_warm_s", 0) - ideal) / ideal
    print(json.dumps({k: v for k, v in out.items() if k.startswith(("speedup", "identical"))}, indent=1))
    Path(__file__).parent.joinpath("results").mkdir(exist_ok=True)
    Path(__file__).parent.joinpath("results", "sweep.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
