"""Sweep benchmark: Fig. 12(a) (121 values of N, Ω = 0.5 rad/s, 200 s each) on serial,
processes and dask executors with the same number of workers; ratios measured in one run.

With ``--fig8``: the Fig. 8 region map at 100 × 100 (N, Ω) × 2 initial conditions, 200 s each
(N 10–130 N, Ω 1–15 rad/s, model ``full``, window from 100 s), on the ``processes`` executor.
By default only a regular sub-grid is run, every ``--fig8-every``-th value along N and along Ω
(10 × 10 × 2 = 200 runs for 10), which samples the cost over the whole plane, and the full
wall time is **extrapolated** as (measured wall of the sub-grid) × (20 000 / runs of the
sub-grid); the JSON and the printout label it so. ``--fig8-every 1`` runs the whole map.

Run: python benchmarks/sweep.py [--workers 2] [--points 121] [--t-end 200]
     python benchmarks/sweep.py --fig8 [--fig8-every 10] [--workers 2] [--t-end 200]
Writes benchmarks/results/sweep.json or benchmarks/results/sweep_fig8.json.
"""

import argparse
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

from stickslip import OUTCOMES
from stickslip.sweep import sweep
from stickslip.sweep.spec import TIMING_COLUMNS


#: Fig. 8 grid of the issue's benchmark: 100 × 100 (N, Ω) × 2 initial conditions.
FIG8_N = np.linspace(10.0, 130.0, 100)
FIG8_OMEGA = np.linspace(1.0, 15.0, 100)


def fig8(workers: int, every: int, t_end: float) -> dict:
    """Time the Fig. 8 map (or its sub-grid) with :func:`stickslip.sweep.regions`; see module doc."""
    from stickslip.sweep import regions

    N, Om = FIG8_N[::every], FIG8_OMEGA[::every]
    runs_full = 2 * FIG8_N.size * FIG8_OMEGA.size
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        rm = regions(N, Om, out=Path(tmp) / "fig8.nc", t_end=t_end, executor="processes", workers=workers)
        wall = time.perf_counter() - t
    ds = rm.dataset
    runs = 2 * N.size * Om.size
    work = float(ds["wall_time"].sum())
    out = {"machine": platform.processor() or platform.machine(), "cpus": os.cpu_count(), "workers": workers,
           "t_end": t_end, "grid_measured": [int(N.size), int(Om.size), 2], "runs_measured": runs,
           "wall_measured_s": wall, "sum_point_s": work, "mean_point_s": work / runs,
           "max_point_s": float(ds["wall_time"].max()), "failed": int((ds["attractor"] == OUTCOMES.index("failed")).sum()),
           "runs_full": runs_full, "timings": {k: v for k, v in rm.timings.items() if isinstance(v, (int, float, str))}}
    if runs == runs_full:
        out["wall_full_s"] = wall
        out["wall_full_note"] = "measured"
    else:
        out["wall_full_s"] = wall * runs_full / runs
        out["wall_full_note"] = (f"EXTRAPOLATED, not measured: wall of the measured {N.size} x {Om.size} x 2 sub-grid "
                                 f"(every {every}th N and Omega) x {runs_full} / {runs}")
    print(f"Fig. 8 sub-grid {N.size} x {Om.size} x 2 = {runs} runs of {t_end:g} s: {wall:.1f} s wall on {workers} workers "
          f"(mean {work / runs:.3f} s per run, max {out['max_point_s']:.2f} s, {out['failed']} failed)")
    print(f"Fig. 8 at 100 x 100 x 2: {out['wall_full_s'] / 60:.1f} min ({out['wall_full_note']}); goal <= 15 min")
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--points", type=int, default=121)
    ap.add_argument("--t-end", type=float, default=200.0)
    ap.add_argument("--fig8", action="store_true", help="time the Fig. 8 map (100 x 100 x 2 ICs) instead")
    ap.add_argument("--fig8-every", type=int, default=10,
                    help="run every k-th N and Omega of the Fig. 8 grid and extrapolate (1: the whole map)")
    args = ap.parse_args()
    if args.fig8:
        result = fig8(args.workers, args.fig8_every, args.t_end)
        Path(__file__).parent.joinpath("results").mkdir(exist_ok=True)
        Path(__file__).parent.joinpath("results", "sweep_fig8.json").write_text(json.dumps(result, indent=1))
        return
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
