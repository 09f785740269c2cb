"""Benchmark of the ``event`` simulator: the paper's Table 2 case (N = 50 N, Ω = 5 rad/s, 100 s).

Measures, in one run on this machine:
  * cold compile: a fresh process with an empty numba cache, import + first call, for the plates
    and for a model file (the library's ``belt``; every model file shares its kernels);
  * cached start-up: a fresh process with the warm cache, import + first call, for both;
  * one 100 s run after compilation (median of repeats), default options (rtol 1e-8,
    1 kHz samples) and with samples off (1 Hz), against the goal 0.05 s and the paper's AEOM
    31.36 s (Δt = 1e-4);
  * work-precision: ``event`` over rtol 1e-3 … 1e-8 and scipy ``solve_ivp`` (LSODA) on the
    smoothed-friction model (v/√(v²+ε²), ε = 1e-2 … 1e-4), each error taken against one tight
    ``event`` reference (steady-state frequency and φ range); the ratio for each LSODA run is
    against the fastest ``event`` run that is at least as accurate (equal accuracy).
  Wall times of the integration (``Stats.wall_time_s``) and, for the main case, the process
  CPU time of the whole call (robust when other jobs share the machine).

Prints ratios and writes benchmarks/results/simulate.json.

    python benchmarks/simulate.py [--quick]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


import stickslip
from stickslip.analysis import fundamental_frequency
from stickslip.integrate.smoothed import simulate_smoothed

HERE = Path(__file__).resolve().parent
#: First calls timed in a fresh process: the plates, and a model file (the library's belt.toml).
STARTUP_CALLS = {"plates": "stickslip.simulate(t_end=1.0)", "model_file": "stickslip.simulate('belt', 1.0)"}


def startup_seconds(cache_dir: str, call: str) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    code = f"import time; t=time.perf_counter(); import stickslip; {call}; print(time.perf_counter()-t)"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.strip().splitlines()[-1])


def steady_metrics(t, states, t_from):
    sel = t >= t_from
    f, _, _ = fundamental_frequency(t[sel], states[sel, 4], states[sel, 10])
    return {"frequency_hz": f, "phi_min": float(states[sel, 4].min()), "phi_max": float(states[sel, 4].max())}


def rel_error(a, ref):
    return max(abs(a[k] - ref[k]) / abs(ref[k]) for k in ref)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats, one smoothed case")
    args = ap.parse_args()
    P = stickslip.Parameters()  # N = 50 N, Ω = 5 rad/s, μk 0.2, Δμ 0.1, α 5
    t_end, t_from = 100.0, 50.0
    result = {"machine": platform.platform(), "processor": platform.processor(), "python": platform.python_version(),
              "case": "N=50 N, Omega=5 rad/s, mu_k=0.2, delta_mu=0.1, alpha=5, 100 s"}

    for name, call in STARTUP_CALLS.items():
        with tempfile.TemporaryDirectory() as cache:
            result.setdefault("cold_compile_s", {})[name] = startup_seconds(cache, call)
            result.setdefault("cached_startup_s", {})[name] = startup_seconds(cache, call)

    stickslip.simulate(P, 1.0)  # compile in this process
    repeats = 3 if args.quick else 7
    runs = {}
    for label, kwargs in {"default (rtol 1e-8, 1 kHz samples)": {}, "no samples (1 Hz)": {"sample_rate": 1.0}}.items():
        walls, cpus = [], []
        for _ in range(repeats):
            c0 = time.process_time()
            traj = stickslip.simulate(P, t_end, **kwargs)
            cpus.append(time.process_time() - c0)
            walls.append(traj.stats.wall_time_s)
        runs[label] = {"median_s": statistics.median(walls), "min_s": min(walls), "cpu_min_s": min(cpus),
                       "accepted_steps": traj.stats.accepted_steps, "rejected_steps": traj.stats.rejected_steps,
                       "rhs_calls": traj.stats.rhs_calls,
                       "ns_per_rhs": 1e9 * min(walls) / traj.stats.rhs_calls}
    result["event"] = runs

    # work-precision: event over rtol, scipy LSODA on the smoothed law over eps, errors against
    # one tight event reference; "equal accuracy" = the fastest event run at least as accurate
    ref_traj = stickslip.simulate(P, t_end, rtol=1e-11, atol=1e-13)
    ref = steady_metrics(ref_traj.t, ref_traj.states, t_from)
    result["reference"] = ref
    event_wp = []
    for rtol in ([1e-4, 1e-6, 1e-8] if args.quick else [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]):
        walls = []
        for _ in range(repeats):
            traj = stickslip.simulate(P, t_end, rtol=rtol, atol=rtol * 1e-2)
            walls.append(traj.stats.wall_time_s)
        err = rel_error(steady_metrics(traj.t, traj.states, t_from), ref)
        event_wp.append({"rtol": rtol, "wall_s": min(walls), "error": err})
    result["event_work_precision"] = event_wp
    smoothed = []
    for eps in ([1e-3] if args.quick else [1e-2, 1e-3, 1e-4]):
        t, y, info = simulate_smoothed(P, t_end, eps=eps, method="LSODA")
        err = rel_error(steady_metrics(t, y, t_from), ref)
        as_good = [e for e in event_wp if e["error"] <= err]
        event_time = min(e["wall_s"] for e in as_good) if as_good else float("nan")
        smoothed.append({"eps": eps, "wall_s": info["wall_time_s"], "nfev": info["nfev"], "error": err,
                         "event_s_at_equal_or_better_accuracy": event_time,
                         "ratio_to_event": info["wall_time_s"] / event_time})
    result["scipy_lsoda_smoothed"] = smoothed
    result["goals"] = {"run_s": 0.05, "cold_compile_s": 20.0, "cached_startup_s": 3.0, "speedup_vs_lsoda": 100.0}

    print(f"machine: {result['machine']}")
    for name in STARTUP_CALLS:
        print(f"{name}: cold compile (fresh process, empty cache) {result['cold_compile_s'][name]:.2f} s (goal ≤ 20 s); "
              f"cached start-up (import + first call) {result['cached_startup_s'][name]:.2f} s (goal ≤ 3 s)")
    for label, r in runs.items():
        print(f"event, 100 s, {label}: median {r['median_s']:.4f} s (min {r['min_s']:.4f}, cpu min "
              f"{r['cpu_min_s']:.4f}), {r['accepted_steps']} steps, {r['rejected_steps']} rejected, "
              f"{r['ns_per_rhs']:.0f} ns per rhs call   (goal ≤ 0.05 s; paper AEOM Δt=1e-4: 31.36 s, "
              f"ratio {31.36 / r['median_s']:.0f}x)")
    for e in event_wp:
        print(f"event rtol {e['rtol']:g}: {e['wall_s']:.4f} s, steady-state error {e['error']:.2e}")
    for s in smoothed:
        print(f"scipy LSODA smoothed eps={s['eps']:g}: {s['wall_s']:.2f} s, error {s['error']:.2e}; event at "
              f"equal or better accuracy {s['event_s_at_equal_or_better_accuracy']:.4f} s -> "
              f"{s['ratio_to_event']:.0f}x   (goal ≥ 100x)")
    out = HERE / "results"
    out.mkdir(exist_ok=True)
    (out / "simulate.json").write_text(json.dumps(result, indent=2, default=float))
    print(f"wrote {out / 'simulate.json'}")


if __name__ == "__main__":
    main()
