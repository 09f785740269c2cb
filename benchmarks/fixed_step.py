"""Benchmark: the paper's fixed-step methods AEOM and NAEOM (Sect. 3) against Table 2.

100 s simulated at the Sect. 4.2.1 case (Ω = 5 rad/s, N = 50 N, μk 0.2, Δμ 0.1, α 5), one core,
after compilation. Goals (issue 3): AEOM ≤ 0.05 s at Δt = 1e-3 s and ≤ 0.5 s at 1e-4 s;
NAEOM ≤ 5× AEOM at the same Δt. Prints times, ns per step, ratios to the paper's Table 2 and
NAEOM/AEOM, and the adaptive `event` method in the same run.

Run: ``python benchmarks/fixed_step.py [--with-1e-5]``; writes benchmarks/results/fixed_step.json.
"""

import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[var] = "1"

import json  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import stickslip  # noqa: E402
from stickslip.studies.timestep import PAPER_TABLE2, _cpu_name, sect_421_parameters  # noqa: E402

GOALS_AEOM = {1e-3: 0.05, 1e-4: 0.5}
GOAL_NAEOM_OVER_AEOM = 5.0
REPEATS = 7  # best of seven, taken round-robin over all cases (see main)


def best_runs(cases):
    """Best (least wall time) of REPEATS runs per case, the repeats taken round-robin over the
    cases so that a slow minute of this shared VM (up to 1.7× on single runs) does not catch all
    repeats of one case; only the best trajectory of each case is kept alive."""
    params = sect_421_parameters()
    best = {}
    for _ in range(REPEATS):
        for method, dt in cases:
            traj = stickslip.simulate(params, 100.0, method=method, dt=dt)
            if (method, dt) not in best or traj.stats.wall_time_s < best[(method, dt)].stats.wall_time_s:
                best[(method, dt)] = traj
            del traj
    return best


def main():
    dts = [1e-3, 1e-4] + ([1e-5] if "--with-1e-5" in sys.argv else [])
    params = sect_421_parameters()
    for m in ("aeom", "naeom"):  # compile outside the timing
        stickslip.simulate(params, 0.01, method=m, dt=1e-3)
    stickslip.simulate(params, 0.01)
    runs = best_runs([(m, dt) for dt in dts for m in ("aeom", "naeom")] + [("event", None)])
    rows = []
    for dt in dts:
        res = {}
        for col, m in enumerate(("aeom", "naeom")):
            traj = runs[(m, dt)]
            wall = traj.stats.wall_time_s
            res[m] = {"wall_s": wall, "steps": traj.stats.steps, "ns_per_step": 1e9 * wall / traj.stats.steps,
                      "rhs_calls": traj.stats.rhs_calls, "paper_s": PAPER_TABLE2[dt][col],
                      "speed_up_vs_paper": PAPER_TABLE2[dt][col] / wall}
        ratio = res["naeom"]["wall_s"] / res["aeom"]["wall_s"]
        goal = GOALS_AEOM.get(dt)
        rows.append({"dt": dt, **res, "naeom_over_aeom": ratio, "paper_naeom_over_aeom": PAPER_TABLE2[dt][1] / PAPER_TABLE2[dt][0],
                     "goal_aeom_s": goal, "aeom_goal_met": None if goal is None else res["aeom"]["wall_s"] <= goal,
                     "naeom_goal_met": ratio <= GOAL_NAEOM_OVER_AEOM})
        a, n = res["aeom"], res["naeom"]
        print(f"dt = {dt:g} s: AEOM {a['wall_s']:.3f} s ({a['ns_per_step']:.0f} ns/step, paper {a['paper_s']} s, "
              f"{a['speed_up_vs_paper']:.1f}x; goal {goal} s: {'met' if rows[-1]['aeom_goal_met'] else 'NOT met'}) | "
              f"NAEOM {n['wall_s']:.3f} s ({n['ns_per_step']:.0f} ns/step, paper {n['paper_s']} s, "
              f"{n['speed_up_vs_paper']:.0f}x) | NAEOM/AEOM {ratio:.2f} (paper {rows[-1]['paper_naeom_over_aeom']:.0f}; "
              f"goal <= {GOAL_NAEOM_OVER_AEOM:g}: {'met' if rows[-1]['naeom_goal_met'] else 'NOT met'})")
    ev = runs[("event", None)]
    print(f"event (rtol 1e-8, default): {ev.stats.wall_time_s:.3f} s, {ev.stats.steps} steps, "
          f"{1e9 * ev.stats.wall_time_s / ev.stats.steps:.0f} ns/step")
    # per-rhs cost of the shared kernel, for context
    out = {"machine": {"cpu": _cpu_name(), "python": platform.python_version(), "date": time.strftime("%Y-%m-%d"),
                       "note": f"best of {REPEATS}, one core, after compilation"},
           "rows": rows, "event": {"wall_s": ev.stats.wall_time_s, "steps": ev.stats.steps}}
    path = Path(__file__).parent / "results" / "fixed_step.json"
    path.write_text(json.dumps(out, indent=2))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
