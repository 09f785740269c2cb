"""Continuation benchmarks (issue 6): a 200-orbit branch with multipliers on one core, and the
Region II edge (end of the stick-slip branch) over 20 values of N on 2 cores.

Goals: branch ≤ 60 s (one core); edge curve ≤ 300 s (2 cores).

``--ab REV`` instead times a shorter branch (``--points``, default 30) alternately with the working
tree and with the package at git revision REV (imported beside it as ``stickslip_baseline``, as
benchmarks/ab.py does; ``--pairs`` pairs), prints the median ratio new/baseline and how far the two
branches' periods and multipliers are apart, and a belt model-file branch over ``contact.0.drive``
(working tree only: REV may not continue model files).

    python benchmarks/continuation.py [--quick] [--workers 2] [--curve-out /tmp/fold_curve.nc]
    python benchmarks/continuation.py --ab main [--points 30] [--pairs 3]

Prints measured times against the goals and writes benchmarks/results/continuation.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np

from stickslip import Parameters, simulate
from stickslip.model.library import load_model
from stickslip.orbits import periodic_orbit
from stickslip.orbits.continuation import continue_orbit, fold_curve
from stickslip.sweep.spec import initial_condition

BRANCH_GOAL_S, CURVE_GOAL_S = 60.0, 300.0


def start_orbit(N=50.0, Omega=8.0):
    """The stick-slip orbit from the `far` initial condition (not timed)."""
    p = Parameters(N=N, Omega=Omega)
    ic, pert = initial_condition("far", p, "full")
    run = simulate(p, 60.0, ic=ic, perturbation=pert, sample_rate=2000.0, rtol=1e-10, atol=1e-13)
    return periodic_orbit(p, run)


def bench_branch(points: int) -> dict:
    orbit = start_orbit()
    t0 = time.perf_counter()
    # steps of 0.02 in scaled arclength (the adaptive step would reach the end of the branch,
    # Ω ≈ 15.8 rad/s, in ~140 orbits): 200 orbits with multipliers from Ω = 8 rad/s
    b = continue_orbit(start=orbit, param="Omega", step=0.02, max_step=0.02, max_points=points,
                       bounds=(8.0, 40.0), amplitude=False)
    wall = time.perf_counter() - t0
    return {"points": len(b), "wall_s": wall, "goal_s": BRANCH_GOAL_S, "per_point_s": wall / len(b),
            "simulations": b.timings["simulations"], "omega_range": [float(b.values[0]), float(b.values[-1])],
            "stop_reason": b.stop_reason, "all_stable": bool(b.stable.all()),
            "max_abs_trivial_minus_1": float(np.max(np.min(np.abs(b.multipliers - 1.0), axis=1)))}


def bench_curve(n: int, workers: int, out: str | None) -> dict:
    N = np.linspace(10.0, 130.0, n)
    t0 = time.perf_counter()
    fc = fold_curve(N, workers=workers)
    wall = time.perf_counter() - t0
    if out:
        fc.to_xarray().to_netcdf(out, engine="h5netcdf")
    return {"n": n, "workers": workers, "wall_s": wall, "goal_s": CURVE_GOAL_S,
            "N": N.tolist(), "edge": [None if not np.isfinite(e) else float(e) for e in fc.edge],
            "kind": list(fc.kind), "points": fc.points.tolist(), "seconds": fc.seconds.tolist()}


def bench_ab(rev: str, points: int, pairs: int) -> dict:
    """The same Model 1 branch (N = 50 N from Ω = 8 rad/s) with the working tree and with ``rev``."""
    import sys
    import tempfile

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from ab import baseline_package

    with tempfile.TemporaryDirectory() as tmp:
        baseline_package(rev, Path(tmp))
        sys.path.insert(0, tmp)
        import stickslip_baseline as base
        import stickslip_baseline.orbits.continuation as base_cont
        import stickslip_baseline.sweep.spec as base_spec

        def branch(which):
            pkg, cont, spec = (base, base_cont, base_spec) if which == 0 else (None, None, None)
            if which == 0:
                p = pkg.Parameters(N=50.0, Omega=8.0)
                ic, pert = spec.initial_condition("far", p, "full")
                run = pkg.simulate(p, 60.0, ic=ic, perturbation=pert, sample_rate=2000.0, rtol=1e-10, atol=1e-13)
                orbit = pkg.orbits.periodic_orbit(p, run)
                go = cont.continue_orbit
            else:
                orbit, go = start_orbit(), continue_orbit
            t0 = time.perf_counter()
            b = go(start=orbit, param="Omega", step=0.02, max_step=0.02, max_points=points, bounds=(8.0, 40.0),
                   amplitude=False)
            return time.perf_counter() - t0, b

        walls = {0: [], 1: []}
        ratios = []
        for i in range(pairs):
            for which in ((0, 1) if i % 2 else (1, 0)):
                wall, b = branch(which)
                walls[which].append(wall)
                if which == 0:
                    b_old = b
                else:
                    b_new = b
            ratios.append(walls[1][-1] / walls[0][-1])
    ratios.sort()
    n = min(len(b_old), len(b_new))
    belt = load_model("belt")
    t0 = time.perf_counter()
    bb = continue_orbit(belt, "contact.0.drive", start=periodic_orbit(belt, {"x": 0.0, "dx": 1.5}, search_time=60.0),
                        step=0.02, max_step=0.05, max_points=points, bounds=(1.5, 3.0), amplitude=False)
    return {"rev": rev, "points": points, "pairs": pairs, "baseline_min_s": min(walls[0]), "new_min_s": min(walls[1]),
            "ratio_median": ratios[len(ratios) // 2], "ratios": ratios,
            "max_period_rel_difference": float(np.max(np.abs(b_new.periods[:n] / b_old.periods[:n] - 1.0))),
            "max_multiplier_abs_difference": float(np.max(np.abs(np.sort(np.abs(b_new.multipliers[:n]), axis=1)
                                                              - np.sort(np.abs(b_old.multipliers[:n]), axis=1)))),
            "belt_drive_branch": {"points": len(bb), "wall_s": time.perf_counter() - t0,
                                  "drive_range": [float(bb.values[0]), float(bb.values[-1])],
                                  "stop_reason": bb.stop_reason}}


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--ab", default=None, metavar="REV", help="time a branch against git revision REV")
    ap.add_argument("--points", type=int, default=30)
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="50-point branch, 4 values of N")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--curve-out", default=None, help="also write the edge curve as NetCDF")
    ap.add_argument("--only", choices=["branch", "curve"], default=None)
    args = ap.parse_args()
    start_orbit(N=50.0, Omega=8.0)  # compile/load the kernels outside the timings
    if args.ab:
        r = bench_ab(args.ab, args.points, args.pairs)
        print(f"branch of {r['points']} orbits: {r['new_min_s']:.2f} s, {args.ab} {r['baseline_min_s']:.2f} s, median "
              f"ratio {r['ratio_median']:.3f} over {r['pairs']} pairs; periods apart {r['max_period_rel_difference']:.1e} "
              f"(relative), |multipliers| {r['max_multiplier_abs_difference']:.1e}; belt over contact.0.drive: "
              f"{r['belt_drive_branch']['points']} orbits in {r['belt_drive_branch']['wall_s']:.2f} s")
        out = Path(__file__).parent / "results" / "continuation_ab.json"
        out.parent.mkdir(exist_ok=True)
        out.write_text(json.dumps(r, indent=1))
        print(f"wrote {out}")
        return
    res = {"machine": f"{platform.machine()}, {os.cpu_count()} cores (shared), {platform.python_version()}",
           "load_average_start": os.getloadavg()}
    if args.only in (None, "branch"):
        res["branch"] = bench_branch(50 if args.quick else 200)
        b = res["branch"]
        print(f"branch: {b['points']} orbits with multipliers in {b['wall_s']:.1f} s (goal {BRANCH_GOAL_S:.0f} s; "
              f"{b['per_point_s'] * 1e3:.0f} ms/orbit, {b['simulations']} simulations) -> "
              f"{'met' if b['wall_s'] <= BRANCH_GOAL_S else 'MISSED'}")
    if args.only in (None, "curve"):
        res["curve"] = bench_curve(4 if args.quick else 20, args.workers, args.curve_out)
        c = res["curve"]
        print(f"edge curve: {c['n']} values of N on {c['workers']} processes in {c['wall_s']:.1f} s "
              f"(goal {CURVE_GOAL_S:.0f} s) -> {'met' if c['wall_s'] <= CURVE_GOAL_S else 'MISSED'}")
    res["load_average_end"] = os.getloadavg()
    print(f"load average (1, 5, 15 min) at start {res['load_average_start']}, at end {res['load_average_end']} "
          "(other jobs share the 2 cores: times are upper bounds)")
    if not args.quick:
        out = Path(__file__).parent / "results" / "continuation.json"
        out.parent.mkdir(exist_ok=True)
        old = json.loads(out.read_text()) if out.exists() else {}
        old.update(res)
        out.write_text(json.dumps(old, indent=1))
        print(f"wrote {out}")


if __name__ == "__main__":
    main()
