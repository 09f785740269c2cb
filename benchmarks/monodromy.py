"""Benchmark: monodromy matrices of stick-slip orbits — saltation against finite differences, and
the working tree against a baseline revision.

For each plates case a periodic orbit is shot by both the working tree's ``stickslip`` and the
package at ``--rev`` (imported as ``stickslip_baseline`` beside it, as benchmarks/ab.py does; not
timed). Then, alternately in each of ``--pairs`` pairs so that both see the same machine load,
the saltation monodromy is timed with each; the finite-difference monodromy of the working tree
is timed too. The model-file cases (``belt``, ``popp-stelter``) have no baseline (the orbit tools
served the plates only before) and are timed on the working tree alone.

Printed per case: best times, the median ratio new/baseline of the saltation monodromy, the
FD/saltation time ratio, the largest distance between the multiplier sets of the two codes and
between saltation and FD, and |μ_trivial − 1|.

    python benchmarks/monodromy.py [--rev main] [--pairs 10]

Writes benchmarks/results/monodromy.json.
"""

import os

# one core: set before numpy/numba load their thread pools
for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[var] = "1"
# compile in this process: a cold start's helper process names kernels by the import name
# ``stickslip.…``, the working tree's, not the baseline's imported beside it
os.environ["STICKSLIP_COMPILE_PROCESSES"] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from scipy.optimize import linear_sum_assignment  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ab import baseline_package  # noqa: E402


def belt_ic(Omega):
    ic = np.zeros(12)
    ic[10] = Omega
    return ic


#: (label, parameters, guess, variant, search time [s]) of the plates' cases.
PLATES = [
    ("Model 1, N = 50 N, Ω = 0.5 rad/s", dict(N=50.0, Omega=0.5), "equilibrium", "full", 30.0),
    ("Model 1, N = 40 N, Ω = 0.5 rad/s", dict(N=40.0, Omega=0.5), "equilibrium", "full", 30.0),
    ("Model 1, N = 30 N, Ω = 0.5 rad/s", dict(N=30.0, Omega=0.5), "equilibrium", "full", 60.0),
    ("belt phi, Coulomb, c = 0", dict(c_pphi=0.0, Omega=0.5, friction_law="coulomb"), belt_ic(0.5), "phi", 3.0),
    ("belt phi, exponential law", dict(Omega=0.5), belt_ic(0.5), "phi", 10.0),
]

#: (label, model, guess, section, search time [s]) of the model-file cases.
MODELS = [
    ("belt (library, exponential)", "belt", {"x": 0.0, "dx": 1.5}, "max", 60.0),
    ("popp-stelter (two 1-D contacts)", "popp-stelter", {"x1": 0.5, "x2": -0.5}, "x2_max", 200.0),
]


def distance(a, b):
    C = np.abs(a[:, None] - b[None, :])
    r, c = linear_sum_assignment(C)
    return float(C[r, c].max())


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return time.perf_counter() - t, out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default="main", help="git revision of the baseline (default main)")
    ap.add_argument("--pairs", type=int, default=10)
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        baseline_package(args.rev, Path(tmp))
        sys.path.insert(0, tmp)
        import stickslip
        import stickslip_baseline as base
        import stickslip_baseline.orbits as base_orbits
        from stickslip.model.library import two_plates
        from stickslip.orbits import monodromy, periodic_orbit
        from stickslip_baseline.model.library import two_plates as base_two_plates

        for label, values, ic, variant, search in PLATES:
            # a model as the first argument: the same call before and after `model` named it alone
            o_new = periodic_orbit(two_plates(stickslip.Parameters(**values), variant), ic, search_time=search)
            o_old = base_orbits.periodic_orbit(base_two_plates(base.Parameters(**values), variant), ic,
                                               search_time=search)
            monodromy(o_new), base_orbits.monodromy(o_old)  # compile / load the caches, not timed
            t_new, t_old, ratios = [], [], []
            for i in range(args.pairs):
                for which in ((0, 1) if i % 2 else (1, 0)):
                    if which:
                        dt, m_new = timed(lambda: monodromy(o_new))
                        t_new.append(dt)
                    else:
                        dt, m_old = timed(lambda: base_orbits.monodromy(o_old))
                        t_old.append(dt)
                ratios.append(t_new[-1] / t_old[-1])
            t_fd, m_fd = min(timed(lambda: monodromy(o_new, "finite-difference")) for _ in range(3))
            ratios.sort()
            row = {"case": label, "period_s": o_new.period, "period_baseline_s": o_old.period,
                   "time_saltation_s": min(t_new), "time_saltation_baseline_s": min(t_old),
                   "ratio_new_over_baseline_median": ratios[len(ratios) // 2],
                   "ratio_quartiles": [ratios[len(ratios) // 4], ratios[(3 * len(ratios)) // 4]],
                   "time_fd_s": t_fd, "ratio_fd_over_saltation": t_fd / min(t_new),
                   "multiplier_distance_new_vs_baseline": distance(m_new.multipliers, m_old.multipliers),
                   "multiplier_distance_saltation_vs_fd": distance(m_new.multipliers, m_fd.multipliers),
                   "trivial_error_new": abs(m_new.trivial_multiplier - 1.0),
                   "trivial_error_baseline": abs(m_old.trivial_multiplier - 1.0),
                   "trivial_error_fd": abs(m_fd.trivial_multiplier - 1.0),
                   "multipliers_abs_new": [float(x) for x in np.abs(m_new.multipliers)],
                   "multipliers_abs_baseline": [float(x) for x in np.abs(m_old.multipliers)]}
            rows.append(row)
            print(f"{label:34s} T = {o_new.period:.7f} s  saltation {min(t_new) * 1e3:6.1f} ms (baseline "
                  f"{min(t_old) * 1e3:6.1f} ms, ratio {row['ratio_new_over_baseline_median']:.2f})  FD {t_fd * 1e3:6.1f} ms  "
                  f"|Δμ| new-old {row['multiplier_distance_new_vs_baseline']:.1e}, salt-FD "
                  f"{row['multiplier_distance_saltation_vs_fd']:.1e}  |μ1−1| {row['trivial_error_new']:.1e} "
                  f"(old {row['trivial_error_baseline']:.1e})")
        for label, model, ic, section, search in MODELS:
            orbit = periodic_orbit(model, ic, section=section, search_time=search)
            monodromy(orbit)
            t_s, m_s = min(timed(lambda: monodromy(orbit)) for _ in range(3))
            t_f, m_f = min(timed(lambda: monodromy(orbit, "finite-difference")) for _ in range(3))
            row = {"case": label, "period_s": orbit.period, "time_saltation_s": t_s, "time_fd_s": t_f,
                   "ratio_fd_over_saltation": t_f / t_s,
                   "multiplier_distance_saltation_vs_fd": distance(m_s.multipliers, m_f.multipliers),
                   "trivial_error_new": abs(m_s.trivial_multiplier - 1.0),
                   "multipliers_abs_new": [float(x) for x in np.abs(m_s.multipliers)]}
            rows.append(row)
            print(f"{label:34s} T = {orbit.period:.7f} s  saltation {t_s * 1e3:6.1f} ms  FD {t_f * 1e3:6.1f} ms  "
                  f"|Δμ| salt-FD {row['multiplier_distance_saltation_vs_fd']:.1e}  |μ1−1| {row['trivial_error_new']:.1e}")
    result = {
        "benchmark": "monodromy", "rev": args.rev, "pairs": args.pairs,
        "stickslip_version": stickslip.__version__,
        "machine": {"platform": platform.platform(), "processor": platform.processor() or platform.machine(),
                    "python": platform.python_version(), "cores_used": 1},
        "cases": rows,
    }
    out = Path(__file__).parent / "results"
    out.mkdir(exist_ok=True)
    (out / "monodromy.json").write_text(json.dumps(result, indent=2))
    print(f"wrote {out / 'monodromy.json'}")


if __name__ == "__main__":
    main()
