"""What separation costs: a run whose contact opens and closes against one whose contact never opens.

The same model (``hoffmann``: a mass pressed by a compliant contact spring onto a belt, past the
flutter onset at μ = 1.3 with damping 0.1 on both axes) and the same simulated time, two preloads:

* ``N0 = 1``: the oscillation grows until the contact lifts off, and settles on a cycle with a
  flight phase in each period (open about a third of the time);
* ``N0 = 100``: the oscillation grows until the mass sticks to the belt first; its stick-slip cycle
  keeps the contact closed (the run's open fraction is checked to be 0).

Both runs start on their cycles (a transient of ``--t-transient`` s is run first and its final state
used), and the pair is timed alternately so that both see the same machine. Prints the median
ratio of wall times (opening / closed) with quartiles, the steps and events of each, and the cost
per step, and writes JSON.

    python benchmarks/contact_cost.py [--t-end 1000] [--pairs 15]
Writes benchmarks/results/contact_cost.json.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

import stickslip

ROOT = Path(__file__).resolve().parents[1]
SETTINGS = {"contact.0.friction.mu_k": 1.3, "damping.x.x": 0.1, "damping.y.y": 0.1}


def _case(n0: float, t_transient: float):
    model = stickslip.load_model("hoffmann").replace(**SETTINGS, N0=n0)
    start = stickslip.simulate(model, t_transient, ic={"x": 0.05}, sample_rate=10.0).final_state
    return model, start


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=1000.0, help="simulated time of each timed run [s]")
    ap.add_argument("--t-transient", type=float, default=300.0, help="run first to reach the cycle [s]")
    ap.add_argument("--pairs", type=int, default=15)
    ap.add_argument("--sample-rate", type=float, default=10.0, help="output samples per second [Hz]")
    args = ap.parse_args()
    cases = {"opens": _case(1.0, args.t_transient), "closed": _case(100.0, args.t_transient)}
    walls = {name: [] for name in cases}
    runs = {}
    for i in range(args.pairs):
        for name in (("opens", "closed") if i % 2 else ("closed", "opens")):
            model, start = cases[name]
            run = stickslip.simulate(model, args.t_end, ic=start, sample_rate=args.sample_rate)
            walls[name].append(run.stats.wall_time_s)
            runs[name] = run
    for name, run in runs.items():
        opened = float(np.mean(run.open)) if run.open.size else 0.0
        if (name == "opens") != (opened > 0.0):
            raise SystemExit(f"case {name!r}: open fraction {opened:.3f} — the case does not show what it should")
    ratios = sorted(o / c for o, c in zip(walls["opens"], walls["closed"]))
    q = len(ratios) // 4
    out = {"t_end": args.t_end, "pairs": args.pairs, "settings": SETTINGS, "ratio_median": ratios[len(ratios) // 2],
           "ratio_quartiles": [ratios[q], ratios[-q - 1]]}
    for name, run in runs.items():
        steps = run.stats.accepted_steps + run.stats.rejected_steps
        out[name] = {"wall_min_s": min(walls[name]), "accepted_steps": run.stats.accepted_steps,
                     "rejected_steps": run.stats.rejected_steps, "transitions": int(run.transitions.time.size),
                     "open_fraction": float(np.mean(run.open)), "ns_per_step": 1e9 * min(walls[name]) / steps}
        print(f"{name:>6}: min {min(walls[name]):.4f} s, {run.stats.accepted_steps} + {run.stats.rejected_steps} "
              f"steps, {run.transitions.time.size} transitions, open {out[name]['open_fraction']:.3f} of the "
              f"samples, {out[name]['ns_per_step']:.0f} ns per step")
    print(f"opens/closed wall time, {args.t_end:g} s each: median {out['ratio_median']:.3f} "
          f"(quartiles {ratios[q]:.3f} … {ratios[-q - 1]:.3f}, {args.pairs} pairs)")
    path = ROOT / "benchmarks" / "results" / "contact_cost.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
