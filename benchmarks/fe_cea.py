"""Complex eigenvalue analysis at finite-element scale: time and peak memory against the goals.

A 3-D brake model (tests/fe/brake_models.pad_on_disc_3d: an annular disc of trilinear hexahedra
clamped at its hub, two elements through its thickness, a pad covering about 30° of its rim,
10 × 50 contact nodes at 100k DOFs, 7 × 16 at 25k, each node pair a compliant contact with 2-D
friction, the disc's surface speed in the drive, Coulomb friction (μ = 0.45 at 25k, past the
onset of two unstable pairs; 0.3 at 100k, whose longer pad lifts its trailing edge off the disc
at 0.4), light stiffness damping) is built at ~25,000 and ~100,000 DOFs; each case runs in a fresh
process (its own peak memory) and times, apart, the model's assembly (not the analysis), steady
sliding with its linearisation, and the band's eigenvalues (``band_stability``, method direct:
every eigenvalue with |Im λ| ≤ ω_max). Goals: 100k DOFs, 500 contacts in ≤ 120 s and ≤ 8 GB;
25k DOFs in ≤ 60 s. Printed as the ratio time / goal (< 1 meets it).

    python benchmarks/fe_cea.py [--only 25k,100k] [--max-frequency-hz 6000] [--method direct|modal]

``--method modal`` times the modal CEA instead (the real modes below 2 ω_max and the residual
vectors of the contact rows, refined on the full model; its largest approximation error is
reported). Writes benchmarks/results/fe_cea[_modal].json. Run on the shared 2-core machine: say so with the numbers.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: name → (disc elements (radial, circumferential, thickness), pad elements, friction coefficient, goal seconds).
CASES = {"25k": ((14, 180, 2), (6, 15, 2), 0.45, 60.0), "100k": ((19, 560, 2), (9, 49, 2), 0.3, 120.0)}
MEMORY_GOAL = 8e9

CHILD = r"""
import json, math, resource, sys, time
sys.path.insert(0, {tests!r})
from fe.brake_models import pad_on_disc_3d
from stickslip.stability.band import band_stability
from stickslip.stability.sparse_sliding import sparse_steady_sliding
t0 = time.perf_counter()
form = pad_on_disc_3d(disc={disc}, pad={pad}, beta=1e-7, mu={mu})
t1 = time.perf_counter()
state = sparse_steady_sliding(form)
t2 = time.perf_counter()
result = band_stability(form, 2 * math.pi * {hz}, method={method!r})
t3 = time.perf_counter()
lam = result.eigenvalues
print(json.dumps({{"dofs": form.n, "contacts": form.nc, "assembly_s": t1 - t0, "steady_s": t2 - t1,
                  "analysis_s": t3 - t1, "eigenvalues": int(lam.size), "unstable": int((lam.real > 0).sum() // 2),
                  "max_real_part": result.max_real_part, "max_backward_error": float(result.backward_error.max()),
                  "frictionless_modes_in_disc": result.frictionless_count,
                  "modal": None if result.modal is None else {{"modes": result.modal.modes,
                            "residual_vectors": result.modal.residual_vectors,
                            "max_relative_error": result.modal.convergence[-1]["max_relative_error"],
                            "modes_only_error": result.modal.convergence[-1]["modes_only_error"]}},
                  "peak_rss_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024.0}}))
"""


def run_case(name: str, hz: float, method: str = "direct") -> dict:
    disc, pad, mu, goal = CASES[name]
    code = CHILD.format(tests=str(ROOT / "tests"), disc=disc, pad=pad, mu=mu, hz=hz, method=method)
    env = {**os.environ, "OMP_NUM_THREADS": "2", "OPENBLAS_NUM_THREADS": "2"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    if out.returncode:
        raise SystemExit(f"case {name} failed:\n{out.stderr}")
    row = json.loads(out.stdout.strip().splitlines()[-1])
    row.update(case=name, mu=mu, goal_s=goal, time_ratio=row["analysis_s"] / goal,
               memory_ratio=row["peak_rss_bytes"] / MEMORY_GOAL, max_frequency_hz=hz)
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default="25k,100k")
    parser.add_argument("--max-frequency-hz", type=float, default=6000.0)
    parser.add_argument("--method", choices=("direct", "modal"), default="direct")
    args = parser.parse_args()
    rows = [run_case(name, args.max_frequency_hz, args.method) for name in args.only.split(",")]
    print(f"{'case':>6} {'dofs':>7} {'contacts':>8} {'steady s':>9} {'analysis s':>10} {'/goal':>6} "
          f"{'peak GB':>8} {'/8 GB':>6} {'eigs':>5} {'unstable':>8} {'max η':>8}")
    for r in rows:
        print(f"{r['case']:>6} {r['dofs']:>7} {r['contacts']:>8} {r['steady_s']:>9.1f} {r['analysis_s']:>10.1f} "
              f"{r['time_ratio']:>6.2f} {r['peak_rss_bytes'] / 1e9:>8.2f} {r['memory_ratio']:>6.2f} "
              f"{r['eigenvalues']:>5} {r['unstable']:>8} {r['max_backward_error']:>8.1e}"
              + ("" if r["modal"] is None else f"  modal: {r['modal']}"))
    folder = ROOT / "benchmarks" / "results"
    folder.mkdir(exist_ok=True)
    suffix = "" if args.method == "direct" else f"_{args.method}"
    (folder / f"fe_cea{suffix}.json").write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
