"""Benchmark: monodromy matrices of stick-slip orbits, saltation vs finite differences.

For each case a periodic orbit is found by shooting (``periodic_orbit``, FD monodromy, not
timed), then the monodromy matrix is computed twice in the same run, each repeated and the best
time kept:

* ``saltation``: variational equations along the orbit with jump matrices at every transition
  (``stickslip.orbits.variational.monodromy``);
* ``finite-difference``: central differences of the flow map (2 · 2 n_free event runs).

Printed: times, FD/saltation time ratio, largest distance between the two multiplier sets and
|μ_trivial − 1| of each. Run: ``python benchmarks/monodromy.py``; writes
benchmarks/results/monodromy.json.
"""

import os

# one core: set before numpy/numba load their thread pools
for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[var] = "1"

import json  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from scipy.optimize import linear_sum_assignment  # noqa: E402

import stickslip  # noqa: E402
from stickslip import Parameters  # noqa: E402
from stickslip.orbits import periodic_orbit  # noqa: E402
from stickslip.orbits.variational import monodromy  # noqa: E402

REPEATS = 3


def belt_ic(Omega):
    ic = np.zeros(12)
    ic[10] = Omega
    return ic


CASES = [
    ("Model 1, N = 50 N, Ω = 0.5 rad/s", Parameters(N=50.0, Omega=0.5), "equilibrium", "full", 30.0),
    ("Model 1, N = 40 N, Ω = 0.5 rad/s", Parameters(N=40.0, Omega=0.5), "equilibrium", "full", 30.0),
    ("Model 1, N = 30 N, Ω = 0.5 rad/s", Parameters(N=30.0, Omega=0.5), "equilibrium", "full", 60.0),
    ("belt phi, Coulomb, c = 0", Parameters(c_pphi=0.0, Omega=0.5, friction_law="coulomb"), belt_ic(0.5), "phi", 3.0),
    ("belt phi, exponential law", Parameters(Omega=0.5), belt_ic(0.5), "phi", 10.0),
]


def distance(a, b):
    C = np.abs(a[:, None] - b[None, :])
    r, c = linear_sum_assignment(C)
    return float(C[r, c].max())


def best_of(fn):
    best, out = np.inf, None
    for _ in range(REPEATS):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def main():
    rows = []
    for label, P, ic, model, search in CASES:
        orbit = periodic_orbit(P, ic, model=model, search_time=search, monodromy="finite-difference")
        monodromy(orbit, "saltation")  # numba compile / cache load, not timed
        t_s, ms = best_of(lambda: monodromy(orbit, "saltation"))
        t_f, mf = best_of(lambda: monodromy(orbit, "finite-difference"))
        row = {
            "case": label, "model": orbit.model, "period_s": orbit.period, "stick_phases": orbit.stick_phases,
            "time_saltation_s": t_s, "time_fd_s": t_f, "ratio_fd_over_saltation": t_f / t_s,
            "multiplier_distance": distance(ms.multipliers, mf.multipliers),
            "trivial_error_saltation": abs(ms.trivial_multiplier - 1.0),
            "trivial_error_fd": abs(mf.trivial_multiplier - 1.0),
            "multipliers_abs_saltation": [float(x) for x in np.abs(ms.multipliers)],
        }
        rows.append(row)
        print(f"{label:38s} T = {orbit.period:.7f} s  saltation {t_s * 1e3:7.1f} ms  FD {t_f * 1e3:7.1f} ms  "
              f"FD/saltation {t_f / t_s:5.2f}  |Δμ| {row['multiplier_distance']:.1e}  "
              f"|μ1−1| salt {row['trivial_error_saltation']:.1e} FD {row['trivial_error_fd']:.1e}")
    result = {
        "benchmark": "monodromy",
        "stickslip_version": stickslip.__version__,
        "machine": {"platform": platform.platform(), "processor": platform.processor() or platform.machine(),
                    "python": platform.python_version(), "cores_used": 1},
        "repeats": REPEATS,
        "cases": rows,
    }
    out = Path(__file__).parent / "results"
    out.mkdir(exist_ok=True)
    (out / "monodromy.json").write_text(json.dumps(result, indent=2))
    print(f"wrote {out / 'monodromy.json'}")


if __name__ == "__main__":
    main()
