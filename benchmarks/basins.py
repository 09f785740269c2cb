"""Basin-stability benchmark: the belt (bSTAB's friction case) and the plates' Region II; ratios
measured in one run.

Belt: 5000 uniform states of bSTAB's box (x ∈ [−2, 2], x' ∈ [0, 2]), at most 500 time units each,
on ``--workers`` processes (goal ≤ 10 s on 2 cores after compile). In the same run, on subsets
(serial, one core, so that the ratios do not depend on the load of the second core):

* ``stickslip basins`` serial on ``--subset`` states: the cost per state with early stopping;
* the same states, each one plain ``stickslip.simulate`` of the full 500 time units: what
  early stopping saves (the runs alone, before any classification);
* the peers' approach (bSTAB, pyBasin): scipy ``solve_ivp`` (RK45, rtol 1e-8, atol 1e-6) of the
  belt with the friction's sign smoothed by tanh(50 v), 500 time units, classified by bSTAB's
  feature (max |x'| over the last 100 above 0.2), on ``--peer-subset`` states, **extrapolated**
  to 5000 states; its labels are compared with ours on those states.

The first call (kernels compiled or loaded from the on-disk cache, the model's context) is
timed apart, in a 1-state study before everything else.

Plates: a ``--plates-grid`` × ``--plates-grid`` grid of (φ, φ̇) ∈ [−0.5, 0.5] rad × [−8, 4] rad/s
at N = 50 N, Ω = 8.5 rad/s, the other states at the plates' ``far`` state (q = 0, ẏ1 = Ω r), at
most 600 s each, on ``--workers`` processes (goal ≤ 5 min on 2 cores).

The machine's load average is recorded before and after each part: other jobs on the cores
inflate every wall time.

Run: python benchmarks/basins.py [--workers 2] [--subset 500] [--peer-subset 40] [--plates-grid 50]
Writes benchmarks/results/basins.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import stickslip
from stickslip.basins import basin_stability, box, grid
from stickslip.model.library import load_model

BELT = load_model("belt")
#: bSTAB's friction case (setup_friction.m): x'' + 2ξx' + x = −sign(v) μ(|v|), v = x' − V.
V, XI, MU_K, MU_S, V0 = 1.5, 0.05, 0.5, 1.0, 0.5


def load() -> list[float]:
    return [round(x, 2) for x in os.getloadavg()]


def peer_rhs(t, y, k=50.0):
    """The belt with the sign of the friction smoothed by tanh(k v) (pyBasin's smoothing)."""
    x, dx = y
    v = dx - V
    mu = MU_K + (MU_S - MU_K) * np.exp(-abs(v) / V0)
    return [dx, -x - 2.0 * XI * dx - np.tanh(k * v) * mu]


def peer_label(s0, t_end=500.0) -> str:
    sol = solve_ivp(peer_rhs, (0.0, t_end), s0, rtol=1e-8, atol=1e-6, t_eval=np.linspace(t_end - 100.0, t_end, 1001))
    return "periodic" if np.max(np.abs(sol.y[1])) > 0.2 else "equilibrium"


def belt(workers: int, subset: int, peer_subset: int) -> dict:
    states = box(BELT, {"x": (-2.0, 2.0), "dx": (0.0, 2.0)}, n=5000, seed=0)
    out: dict = {"states": 5000, "t_end": 500.0, "box": {"x": [-2, 2], "dx": [0, 2]}}
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        basin_stability(BELT, box(BELT, {"x": (0.0, 1.0)}, n=1), out=Path(tmp) / "first.nc", executor="serial")
        out["first_call_s"] = time.perf_counter() - t
        out["load_before"] = load()
        t = time.perf_counter()
        res = basin_stability(BELT, states, out=Path(tmp) / "belt.nc", executor="processes", workers=workers)
        out["wall_s"] = time.perf_counter() - t
        out["load_after"] = load()
        ds = res.to_xarray()
        out.update(workers=workers, fractions=res.fractions, standard_errors=res.standard_errors,
                   decided_by=dict(Counter(str(ds["decided_by"].attrs["flag_meanings"].split()[c])
                                           for c in ds["decided_by"].values)),
                   mean_t_decided=float(ds["t_decided"].mean()), timings={k: v for k, v in res.timings.items()
                                                                         if isinstance(v, (int, float, str))})
        sub = box(BELT, {"x": (-2.0, 2.0), "dx": (0.0, 2.0)}, n=subset, seed=1)
        t = time.perf_counter()
        serial = basin_stability(BELT, sub, out=Path(tmp) / "serial.nc", executor="serial")
        out["serial_per_state_s"] = (time.perf_counter() - t) / subset
    s0 = serial.to_xarray()["initial_state"].values
    t = time.perf_counter()
    for s in s0:
        stickslip.simulate(BELT, 500.0, ic=s, sample_rate=10.0)
    out["full_run_per_state_s"] = (time.perf_counter() - t) / subset
    out["early_stop_saving"] = out["full_run_per_state_s"] / out["serial_per_state_s"]
    ours = serial.labels()[:peer_subset]
    t = time.perf_counter()
    peers = np.array([peer_label(s) for s in s0[:peer_subset]])
    out["peer_per_state_s"] = (time.perf_counter() - t) / peer_subset
    out["peer_5000_serial_s_extrapolated"] = out["peer_per_state_s"] * 5000
    out["peer_agreement"] = float(np.mean(peers == ours))
    out["speedup_vs_peer_serial"] = out["peer_per_state_s"] / out["serial_per_state_s"]
    out["goal_s"] = 10.0
    print(f"belt, 5000 states x 500: {out['wall_s']:.2f} s on {workers} workers (goal <= 10 s; load "
          f"{out['load_before']} -> {out['load_after']}); first call {out['first_call_s']:.2f} s")
    print(f"  fractions {res.fractions} +- {res.standard_errors}; decided by {out['decided_by']}; mean t_decided "
          f"{out['mean_t_decided']:.1f} of 500")
    print(f"  per state, serial: basins {1e3 * out['serial_per_state_s']:.2f} ms; full 500-unit simulate "
          f"{1e3 * out['full_run_per_state_s']:.2f} ms (early stop saves x{out['early_stop_saving']:.1f}); peers' "
          f"solve_ivp+tanh {1e3 * out['peer_per_state_s']:.1f} ms (x{out['speedup_vs_peer_serial']:.0f} slower; 5000 "
          f"states ~{out['peer_5000_serial_s_extrapolated']:.0f} s serial, EXTRAPOLATED from {peer_subset}); peers' "
          f"labels agree on {100 * out['peer_agreement']:.1f} % of those states")
    return out


def plates(workers: int, k: int) -> dict:
    model = load_model("two-plates").replace(N=50.0, Omega=8.5)
    states = grid(model, {"phi": (-0.5, 0.5), "dphi": (-8.0, 4.0)}, k, base="zero", fixed={"dy1": 8.5 * 0.2})
    out: dict = {"grid": [k, k], "t_end": 600.0, "box": {"phi": [-0.5, 0.5], "dphi": [-8, 4]},
                 "fixed": {"dy1": 1.7}, "goal_s": 300.0, "load_before": load()}
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        res = basin_stability(model, states, out=Path(tmp) / "plates.nc", t_end=600.0, executor="processes",
                              workers=workers)
        out["wall_s"] = time.perf_counter() - t
    out["load_after"] = load()
    ds = res.to_xarray()
    names = ds["decided_by"].attrs["flag_meanings"].split()
    out.update(workers=workers, fractions=res.fractions, standard_errors=res.standard_errors,
               decided_by=dict(Counter(names[c] for c in ds["decided_by"].values)),
               mean_t_decided=float(ds["t_decided"].mean()), sum_state_wall_s=float(ds["wall_time"].sum()),
               attractors=res.attractors())
    print(f"plates {k}x{k} (phi, dphi), N = 50, Omega = 8.5, <= 600 s: {out['wall_s']:.1f} s on {workers} workers "
          f"(goal <= 300 s; load {out['load_before']} -> {out['load_after']})")
    print(f"  fractions {res.fractions}; decided by {out['decided_by']}; mean t_decided {out['mean_t_decided']:.0f} s")
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--subset", type=int, default=500)
    ap.add_argument("--peer-subset", type=int, default=40)
    ap.add_argument("--plates-grid", type=int, default=50)
    ap.add_argument("--skip-plates", action="store_true")
    args = ap.parse_args()
    result = {"machine": platform.processor() or platform.machine(), "cpus": os.cpu_count(),
              "belt": belt(args.workers, args.subset, args.peer_subset)}
    if not args.skip_plates:
        result["plates"] = plates(args.workers, args.plates_grid)
    path = Path(__file__).parent / "results" / "basins.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(stickslip.attractors.jsonable(result), indent=1))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
