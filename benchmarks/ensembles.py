"""Basin ensembles: CPU time per state of a basin study, this tree against a revision, in one run.

The peers' friction case (bSTAB, pyBasin): the belt at v_d = 1.5, at most 500 time units a
state, ``--states`` states drawn uniformly from x ∈ [−2, 2], x' ∈ [0, 2] (the same seed for
both). Each package runs the study in a process of its own (the revision's extracted by ``git
archive`` as ``stickslip_baseline``, as benchmarks/ab.py does, with a numba cache of its own),
first a small study in batches large enough for the compiled batch, which compiles or loads the
kernels (not timed), then the whole study,
alternately ``--pairs`` times. Measured: the CPU time of the study's processes (the process
itself and its waited-for children: the pool's workers, the forked writer) per state, in
ms·core, and the wall time; the machine's load average before and after each. The labels are
compared state by state, and the fractions and their standard errors.

With ``--breakdown N`` it measures instead, in this process and serially on N states, where
the Python classifier's time per state goes (building a run, the calls of the compiled loop,
the tests after each chunk, the outcome rows) against the compiled batch on the same states.

    python benchmarks/ensembles.py [--rev main] [--states 20000] [--workers 2] [--pairs 1]
    python benchmarks/ensembles.py --breakdown 2000
Writes benchmarks/results/ensembles.json (ensembles_breakdown.json).
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
    # batches of 48 states: the compiled batch (taken from 32 states on) is compiled or loaded here too
    basins.basin_stability(belt, basins.box(belt, box, n=128, seed=99), out=Path(tmp) / "warm.nc", executor=executor,
                           workers=workers, batch_size=48)
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


def breakdown(n: int) -> dict:
    """Where a state's CPU time goes in the Python classifier, against the compiled batch (module docstring)."""
    import time

    from stickslip.basins import batch, box, early
    from stickslip.basins.context import make_context
    from stickslip.basins.cycles import find_cycle
    from stickslip.integrate import runner
    from stickslip.model.library import load_model

    belt = load_model("belt")
    ctx = make_context(belt)
    states = box(belt, {"x": (-2.0, 2.0), "dx": (0.0, 2.0)}, n=n, seed=0).states(belt, ctx.equilibrium[:1])
    opts = early.Options()
    spent = {"run_setup": 0.0, "loop_calls": 0.0, "tests_after_chunks": 0.0, "outcome_rows": 0.0}
    calls = {"loop_calls": 0, "tests_after_chunks": 0}

    def timed(owner, name, key):
        original = getattr(owner, name)

        def wrapper(*a, **k):
            c = time.process_time()
            try:
                return original(*a, **k)
            finally:
                spent[key] += time.process_time() - c
                calls[key] = calls.get(key, 0) + 1
        setattr(owner, name, wrapper)
        return original

    early.classify_state(ctx, belt, states[0], [], opts)
    batch.classify_batch(ctx, belt, states[:1], [], opts)
    originals = [(runner.EventStepper, "__init__", timed(runner.EventStepper, "__init__", "run_setup")),
                 (runner, "integrate_event", timed(runner, "integrate_event", "loop_calls")),
                 (early.EarlyStop, "_decide", timed(early.EarlyStop, "_decide", "tests_after_chunks")),
                 (early.Outcome, "to_row", timed(early.Outcome, "to_row", "outcome_rows"))]
    cycles, steps = [], 0
    c0 = time.process_time()
    for s0 in states:
        o = early.classify_state(ctx, belt, s0, cycles, opts)
        if o.verdict == "periodic" and find_cycle(cycles, o.cycle, opts.match_rtol) < 0:
            cycles.append(o.cycle)
        o.to_row()
        steps += o.steps
    python_s = time.process_time() - c0
    for owner, name, original in originals:
        setattr(owner, name, original)
    c0 = time.process_time()
    rows, _ = batch.classify_batch(ctx, belt, states, [], opts)
    batch_s = time.process_time() - c0
    # the compiled loop alone: 400 time units in one chunk on the cycle, less the cost of a call
    # (calls that take no step), per step
    stepper = runner.EventStepper(belt, np.array([-1.0, 1.5]), 0.0, 500.0, rtol=opts.rtol, atol=opts.atol,
                                  h_max=ctx.chunk * ctx.dt, max_steps=10**9)
    record = runner.Record(belt, np.arange(int(500.0 / ctx.dt) + 2) * ctx.dt)
    c0 = time.process_time()
    for _ in range(200):
        stepper.advance(0.0, record)
    call_s = (time.process_time() - c0) / 200
    c0 = time.process_time()
    chunk = stepper.advance(400.0, record)
    step_us = 1e6 * (time.process_time() - c0 - call_s) / chunk.steps
    per = {k: 1e3 * v / n for k, v in spent.items()}
    per["loop_calls_of_which_compiled_steps"] = 1e-3 * step_us * steps / n
    per["loop_calls_of_which_calling"] = 1e3 * call_s * calls["loop_calls"] / n
    out = {"states": n, "python_ms_core_per_state": 1e3 * python_s / n, "batch_ms_core_per_state": 1e3 * batch_s / n,
           "ms_per_state": per, "calls_per_state": {k: v / n for k, v in calls.items()}, "steps_per_state": steps / n,
           "us_per_step_in_a_long_chunk": step_us, "ms_per_loop_call": 1e3 * call_s, "load": [round(x, 2) for x in os.getloadavg()]}
    print(json.dumps(out, indent=1))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default="main")
    ap.add_argument("--states", type=int, default=20000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--executor", default="processes", choices=["serial", "processes"])
    ap.add_argument("--pairs", type=int, default=1)
    ap.add_argument("--cache", default=str(Path(tempfile.gettempdir()) / "stickslip-ensembles-cache"),
                    help="numba caches of the two packages, kept between runs")
    ap.add_argument("--breakdown", type=int, default=0, help="states of the breakdown (module docstring)")
    args = ap.parse_args()
    if args.breakdown:
        result = breakdown(args.breakdown)
        path = ROOT / "benchmarks" / "results" / "ensembles_breakdown.json"
        path.parent.mkdir(exist_ok=True)
        path.write_text(json.dumps(result, indent=1) + "\n")
        return
    rev = subprocess.run(["git", "-C", str(ROOT), "rev-parse", args.rev], check=True, capture_output=True,
                         text=True).stdout.strip()
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], check=True, capture_output=True,
                          text=True).stdout.strip()
    runs: dict = {"baseline": [], "tree": []}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        baseline_package(rev, tmp)
        caches = Path(args.cache)  # kept between runs: a cold compile of each package only once
        sides = {"baseline": ("stickslip_baseline", tmp, caches / f"baseline-{rev[:12]}"),
                 "tree": ("stickslip", ROOT / "src", caches / "tree")}
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
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
