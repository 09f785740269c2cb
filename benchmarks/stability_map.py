"""Benchmark: (N, Ω) stability maps (paper Figs. 3, 4).

1. A 200 × 200 (N, Ω) map of the largest real part of the eigenvalues (goal ≤ 10 s, one core).
2. Boundary curves Ω_c(N) by brentq for five family members (goal ≤ 5 s).
3. A baseline in the same run: scipy ``root`` (hybr) on the equilibrium residual, a
   central-difference Jacobian of the simulator's right-hand side and ``numpy.linalg.eigvals``, per
   point on a subset, to give the speed-up ratio of the compiled Newton + complex-step path.
4. With ``--rev REV``: the same maps with the package at git revision REV (imported beside the
   working tree's, as ``benchmarks/ab.py`` does), timed alternately in the same process, with the
   largest differences of max Re λ and of the boundaries of the paper's Figs. 3(a), 3(b) and 4,
   and of all eigenvalues at sample points, old against new.

5. With ``--rev REV``: maps of the other library models, old against new, bit for bit (max Re λ,
   its tolerance, the boundaries, their directions and jumps): ``hoffmann`` (damped) across its
   flutter onset and across N0 = 0 where its contact lifts off, ``hoffmann`` undamped,
   ``clearance-oscillator`` across its stop pressed/open, ``slider-belt`` with P < 0 (no steady
   sliding), ``belt`` and the plates; and 40 × 80 maps of ``hoffmann`` timed alternately, old and
   new, each in a process of its own (wall and CPU time). ``--only models`` runs this part alone.

6. With ``--rev REV --only cold``: ``stickslip stability-map`` of the plates and of ``hoffmann``
   (5 × 5 points) as a new user runs it, each from an empty numba cache, the working tree and REV
   alternately (``benchmarks/first_call.py``'s runner): the first-call cost of the map kernels.

Run: ``python benchmarks/stability_map.py [--rev main] [--pairs 5] [--only models|cold]``; writes
benchmarks/results/stability_map.json (``stability_map_models.json``, ``stability_map_cold.json``).
"""

import os

# one core: set before numpy/numba load their thread pools
for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[var] = "1"
# compile in this process: a cold start's helper process names kernels by the import name
# ``stickslip.…``, the working tree's, not the baseline's imported beside it
os.environ["STICKSLIP_COMPILE_PROCESSES"] = "1"

import argparse  # noqa: E402
import importlib  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from scipy import optimize  # noqa: E402

import stickslip  # noqa: E402
from stickslip import Parameters  # noqa: E402
from stickslip.model import physics  # noqa: E402
from stickslip.model.bundle import contact_state  # noqa: E402
from stickslip.model.library import two_plates  # noqa: E402
from stickslip.stability import stability_map  # noqa: E402
from stickslip.stability.equilibrium import equilibrium_residual  # noqa: E402

GOAL_MAP_S = 10.0
GOAL_BOUNDARY_S = 5.0


def baseline_point(params, variant, N, Omega):
    """max Re λ the straightforward way: scipy root + finite differences + numpy eigvals."""
    sy = two_plates(params.replace(N=N, Omega=Omega), variant)
    free = np.flatnonzero(sy.free)

    def residual(x):
        q = np.zeros(6)
        q[free] = x
        return equilibrium_residual(sy, q)[free]

    sol = optimize.root(residual, np.zeros(free.size), method="hybr", options={"xtol": 1e-14})
    s0 = np.zeros(12)
    s0[free] = sol.x

    md = sy.data
    cst = contact_state(md.m)  # slipping along +x; v_r/|v_r| above the low-speed band
    cst[0] = physics.MODE_SLIP

    def f(s):
        ds = np.zeros(12)
        physics.rhs(s, cst, md, ds)
        return ds

    idx = np.concatenate([free, 6 + free])
    J = np.zeros((idx.size, idx.size))
    for b, j in enumerate(idx):
        e = np.zeros(12)
        e[j] = 1e-6
        J[:, b] = ((f(s0 + e) - f(s0 - e)) / 2e-6)[idx]
    return float(np.max(np.linalg.eigvals(J).real))


def _max_abs_diff(a, b) -> float:
    """Largest |a − b| where both are finite; inf where only one of them is."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.shape != b.shape:
        return float("inf")
    if not np.array_equal(np.isfinite(a), np.isfinite(b)):
        return float("inf")
    both = np.isfinite(a)
    return float(np.max(np.abs(a[both] - b[both]), initial=0.0))


def baseline(rev: str):
    """The package at git revision ``rev``, imported as ``stickslip_baseline``."""
    sys.path.insert(0, str(Path(__file__).parent))
    from ab import baseline_package

    tmp = tempfile.mkdtemp(prefix="stickslip_baseline_")
    baseline_package(rev, Path(tmp))
    sys.path.insert(0, tmp)
    import stickslip_baseline

    return stickslip_baseline


#: The maps of the library models compared bit for bit (:func:`compare_models`): model, the
#: parameters changed from the library's, the axes and their values.
MODEL_MAPS = {
    "hoffmann_damped": ("hoffmann", {"damping.x.x": 0.1, "damping.y.y": 0.1}, ("N0", "contact.0.friction.mu_k"),
                        np.linspace(-0.5, 2.0, 11), np.linspace(0.3, 2.5, 23)),
    "hoffmann": ("hoffmann", {}, ("contact.0.friction.mu_k", "k3"), np.linspace(0.2, 1.8, 9),
                 np.linspace(0.5, 2.0, 7)),
    "clearance_oscillator": ("clearance-oscillator", {}, ("xs", "contact.0.drive.0"), np.linspace(0.2, 1.2, 6),
                             np.linspace(0.8, 2.5, 8)),
    "slider_belt": ("slider-belt", {}, ("P", "V"), np.linspace(-0.3, 0.8, 8), np.linspace(0.2, 1.0, 9)),
    "belt": ("belt", {}, ("contact.0.normal_force", "contact.0.drive"), np.linspace(0.5, 2.0, 7),
             np.linspace(0.2, 3.0, 15)),
    "plates": ("two-plates", {}, ("N", "Omega"), np.linspace(5.0, 200.0, 12), np.linspace(0.25, 20.0, 20)),
}

_MAP_ARRAYS = ("max_real_part", "marginal_tolerance", "boundary", "boundary_direction", "boundary_jump")


def _same(old_map, new_map, key: str) -> bool:
    """Whether the array ``key`` of two maps is the same bit for bit (NaN where NaN)."""
    x, y = np.asarray(getattr(old_map, key)), np.asarray(getattr(new_map, key))
    return bool(np.array_equal(x, y, equal_nan=x.dtype.kind == "f"))


#: One timed map in a process of its own (:func:`time_hoffmann`): the package's import name, then
#: the map as JSON (model, changes, axes, values); prints the wall and CPU seconds of the map after
#: one small map that compiles or loads the kernels. A process each: two packages in one process
#: slow down each other's calls from Python (numba's dispatch), which these maps make per point.
_TIMED_MAP = """
import json, sys, time
import numpy as np
pkg = __import__(sys.argv[1])
name, changes, axes, a, b = json.loads(sys.argv[2])
model = pkg.load_model(name).replace(**changes)
pkg.stability_map(model, a[:2], b[:2], axes=axes)
wall, cpu = time.perf_counter(), time.process_time()
m = pkg.stability_map(model, np.array(a), np.array(b), axes=axes)
print(json.dumps({"wall": time.perf_counter() - wall, "cpu": time.process_time() - cpu,
                  "grid": m.timings["grid_s"]}))
"""


def time_hoffmann(old, pairs: int) -> dict:
    """40 × 80 maps of ``hoffmann`` (damped, N0 and μ across its flutter onset), old and new
    alternately, each in a process of its own (:data:`_TIMED_MAP`): every contact pressed (N0 ≥
    0.2), and across N0 = 0 where the contact lifts off (a fifth of the points solved in Python).
    The fastest of ``pairs`` runs each, wall and CPU seconds."""
    import subprocess

    name, changes, axes = MODEL_MAPS["hoffmann_damped"][:3]
    env = dict(os.environ)
    out = {}
    for label, low in (("pressed", 0.2), ("lift_off", -0.5)):
        spec = json.dumps([name, changes, list(axes), list(np.linspace(low, 2.0, 40)), list(np.linspace(0.3, 2.5, 80))])
        times = {"old": [], "new": []}
        for i in range(pairs):
            for which in (("old", "new") if i % 2 else ("new", "old")):
                path = str(Path(old.__file__).parents[1]) if which == "old" else ""
                run_env = {**env, "PYTHONPATH": os.pathsep.join(filter(None, [path, env.get("PYTHONPATH", "")]))}
                res = subprocess.run([sys.executable, "-c", _TIMED_MAP, old.__name__ if which == "old" else "stickslip",
                                      spec], capture_output=True, text=True, check=True, env=run_env)
                times[which].append(json.loads(res.stdout.strip().splitlines()[-1]))
        best = {which: {key: min(t[key] for t in runs) for key in ("wall", "cpu", "grid")} for which, runs in times.items()}
        out[label] = {"N0": [low, 2.0], "points": 3200, **{f"{w}_{k}_min_s": v for w in best for k, v in best[w].items()},
                      "cpu_ratio_new_over_old": best["new"]["cpu"] / best["old"]["cpu"]}
    return {"axes": list(axes), "pairs": pairs, **out}


def compare_models(old, pairs: int) -> dict:
    """The library models' maps of :data:`MODEL_MAPS` old against new bit for bit, and the
    timing of :func:`time_hoffmann`."""
    out = {}
    for label, (name, changes, axes, a, b) in MODEL_MAPS.items():
        maps = [pkg.stability_map(pkg.load_model(name).replace(**changes), a, b, axes=axes) for pkg in (old, stickslip)]
        same = {key: _same(maps[0], maps[1], key) for key in _MAP_ARRAYS}
        out[label] = {"identical": all(same.values()), **same, "points": int(maps[1].max_real_part.size),
                      "no_equilibrium_points": int(np.isnan(maps[1].max_real_part).sum()),
                      "boundary_roots": int(np.isfinite(maps[1].boundary).sum())}
    out["hoffmann_40x80"] = time_hoffmann(old, pairs)
    return out


#: The maps of :func:`cold_start`: label and the arguments of ``stickslip``.
COLD_MAPS = {
    "plates": ["stability-map", "--N-points", "5", "--omega-points", "5", "--no-plot", "--json",
               "--out", "{tmp}/plates.nc"],
    "hoffmann": ["stability-map", "--model", "hoffmann", "--axis", "N0=0.2:2:5",
                 "--axis", "contact.0.friction.mu_k=0.3:2.5:5", "--no-plot", "--json", "--out", "{tmp}/hoffmann.nc"],
}


def cold_start(rev: str, pairs: int) -> dict:
    """Seconds of the :data:`COLD_MAPS` commands from an empty numba cache each, the working tree
    and ``rev`` alternately (the fastest of ``pairs`` each), and of the same command cached."""
    sys.path.insert(0, str(Path(__file__).parent))
    from first_call import _run, baseline_tree

    out = {"rev": rev, "pairs": pairs}
    with tempfile.TemporaryDirectory() as root:
        trees = {"new": None, "old": baseline_tree(rev, Path(root) / "baseline")}
        for label, args in COLD_MAPS.items():
            runs = {"new": [], "old": []}
            for i in range(pairs):
                for which in (("old", "new") if i % 2 else ("new", "old")):
                    cache = Path(tempfile.mkdtemp(dir=root, prefix="cache"))
                    cold = _run(args, cache, Path(tempfile.mkdtemp(dir=root, prefix="work")), trees[which])
                    warm = _run(args, cache, Path(tempfile.mkdtemp(dir=root, prefix="work")), trees[which])
                    if cold["exit"] or warm["exit"]:
                        raise RuntimeError(f"{label} ({which}) failed: {cold['stderr_tail'] + warm['stderr_tail']}")
                    runs[which].append((cold["seconds"], warm["seconds"]))
            best = {w: (min(r[0] for r in runs[w]), min(r[1] for r in runs[w])) for w in runs}
            out[label] = {"new_empty_cache_s": best["new"][0], "old_empty_cache_s": best["old"][0],
                          "new_cached_s": best["new"][1], "old_cached_s": best["old"][1],
                          "empty_cache_ratio_new_over_old": best["new"][0] / best["old"][0]}
    return out


def compare_with(rev: str, pairs: int, only: str = "all") -> dict:
    """Timing ratio and differences of the maps against the package at ``rev`` (same process)."""
    old = baseline(rev)
    if only == "models":
        return {"rev": rev, "models": compare_models(old, pairs)}
    N = np.linspace(2.0, 200.0, 200)
    W = np.linspace(0.2, 20.0, 200)
    old.stability_map(old.Parameters(), N[:3], W[:3])  # compile outside the timing
    t_old, t_new = [], []
    for i in range(pairs):
        for which in ((0, 1) if i % 2 else (1, 0)):
            pkg = old if which == 0 else stickslip
            t = time.perf_counter()
            m = pkg.stability_map(pkg.Parameters(), N, W, boundary=False)
            (t_old if which == 0 else t_new).append(time.perf_counter() - t)
            if which == 0:
                m_old = m
            else:
                m_new = m
    ratios = sorted(n / o for n, o in zip(t_new, t_old))
    out = {"rev": rev, "pairs": pairs, "map_200x200_old_min_s": min(t_old), "map_200x200_new_min_s": min(t_new),
           "map_ratio_new_over_old_median": ratios[len(ratios) // 2],
           "map_max_real_part_max_abs_diff": _max_abs_diff(m_old.max_real_part, m_new.max_real_part),
           "map_nan_points_old": int(np.isnan(m_old.max_real_part).sum()),
           "map_nan_points_new": int(np.isnan(m_new.max_real_part).sum())}
    # boundaries of the paper's maps (100 × 100 as docs/stability.md), old vs new, with timing
    Nf, Wf = np.linspace(2.0, 200.0, 100), np.linspace(0.2, 20.0, 100)
    figures = {"fig3a": ("delta_mu", [0.1, 0.2, 0.3]), "fig3b": ("alpha", [2.0, 5.0, 10.0]),
               "fig4": ("model", ["full", "rotation"])}
    for name, fam in figures.items():
        maps, times = {}, {}
        for label, pkg in (("old", old), ("new", stickslip)):
            t = time.perf_counter()
            maps[label] = pkg.stability_map(pkg.Parameters(), Nf, Wf, family=fam)
            times[label] = time.perf_counter() - t
        out[name] = {"boundary_max_abs_diff_rad_s": _max_abs_diff(maps["old"].boundary, maps["new"].boundary),
                     "boundary_roots": int(np.isfinite(maps["new"].boundary).sum()),
                     "max_real_part_max_abs_diff": _max_abs_diff(maps["old"].max_real_part, maps["new"].max_real_part),
                     "old_s": times["old"], "new_s": times["new"], "ratio_new_over_old": times["new"] / times["old"]}
    # every eigenvalue at sample points of all four models
    old_stability = importlib.import_module(old.__name__ + ".stability.analysis").stability
    new_stability = importlib.import_module("stickslip.stability.analysis").stability
    worst = 0.0
    for model in ("full", "x", "y", "rotation"):
        for Nv, Wv in ((10.0, 0.5), (50.0, 5.0), (100.0, 3.0), (150.0, 12.0), (80.0, -2.0)):
            a = old_stability(old.Parameters(N=Nv, Omega=Wv), model).eigenvalues
            b = new_stability(stickslip.Parameters(N=Nv, Omega=Wv), model).eigenvalues
            worst = max(worst, float(np.max(np.abs(a - b)) / np.max(np.abs(a))))
    out["eigenvalues_max_relative_diff"] = worst
    out["models"] = compare_models(old, pairs)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default=None, help="git revision to compare with (e.g. main)")
    ap.add_argument("--pairs", type=int, default=5, help="alternating timing pairs of the 200 × 200 map")
    ap.add_argument("--only", choices=("all", "models", "cold"), default="all",
                    help="with --rev: 'models' compares the library models' maps alone (item 5), 'cold' times "
                         "the first call (item 6)")
    args = ap.parse_args()
    if args.only != "all":
        if args.rev is None:
            ap.error(f"--only {args.only} compares with a revision: give --rev")
        cmp = compare_with(args.rev, args.pairs, "models") if args.only == "models" else cold_start(args.rev, args.pairs)
        print(json.dumps(cmp, indent=1), flush=True)
        out = Path(__file__).parent / "results" / f"stability_map_{args.only}.json"
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(cmp, indent=2))
        print(f"wrote {out}")
        return
    P = Parameters()
    N = np.linspace(2.0, 200.0, 200)
    W = np.linspace(0.2, 20.0, 200)

    t = time.perf_counter()
    stability_map(P, N[:3], W[:3], family=("delta_mu", [0.1]))  # numba compile / cache load
    compile_s = time.perf_counter() - t

    t = time.perf_counter()
    smap = stability_map(P, N, W, boundary=False)
    map_s = time.perf_counter() - t

    fam = ("delta_mu", [0.05, 0.1, 0.15, 0.2, 0.3])
    Nb = np.linspace(2.0, 200.0, 100)
    Wb = np.linspace(0.2, 20.0, 40)
    t = time.perf_counter()
    bmap = stability_map(P, Nb, Wb, family=fam, boundary=True)
    boundary_s = time.perf_counter() - t
    n_roots = int(np.isfinite(bmap.boundary).sum())

    rng = np.random.default_rng(0)
    picks = [(rng.integers(N.size), rng.integers(W.size)) for _ in range(300)]
    t = time.perf_counter()
    base = [baseline_point(P, "full", N[a], W[b]) for a, b in picks]
    base_per_point = (time.perf_counter() - t) / len(picks)
    ours = np.array([smap.max_real_part[0, a, b] for a, b in picks])
    both = np.isfinite(ours)
    agree = float(np.max(np.abs(np.array(base)[both] - ours[both])))
    ours_per_point = map_s / smap.max_real_part.size

    result = {
        "machine": {"platform": platform.platform(), "processor": platform.processor() or platform.machine(),
                    "python": platform.python_version(), "cores_used": 1},
        "stickslip_version": stickslip.__version__,
        "compile_or_cache_load_s": compile_s,
        "map_200x200": {"seconds": map_s, "goal_s": GOAL_MAP_S, "ratio_to_goal": map_s / GOAL_MAP_S,
                        "points": int(smap.max_real_part.size), "us_per_point": 1e6 * ours_per_point,
                        "no_equilibrium_points": int(np.isnan(smap.max_real_part).sum())},
        "boundary_5_families": {"seconds": boundary_s, "goal_s": GOAL_BOUNDARY_S,
                                "ratio_to_goal": boundary_s / GOAL_BOUNDARY_S, "family": fam[0],
                                "values": fam[1], "N_points": int(Nb.size), "Omega_bracket_points": int(Wb.size),
                                "roots": n_roots, "grid_s": bmap.timings["grid_s"],
                                "brentq_s": bmap.timings["boundary_s"]},
        "baseline": {"method": "scipy root(hybr) on the equilibrium residual + central FD Jacobian + numpy eigvals",
                     "us_per_point": 1e6 * base_per_point, "points_timed": len(picks),
                     "speedup_ours_vs_baseline": base_per_point / ours_per_point,
                     "max_abs_difference_of_max_real_part": agree},
    }
    if args.rev is not None:
        result["against_revision"] = cmp = compare_with(args.rev, args.pairs)
        print(json.dumps(cmp, indent=1), flush=True)
    print(f"compile / cache load           {compile_s:8.2f} s")
    print(f"200 x 200 map                  {map_s:8.2f} s   goal {GOAL_MAP_S:g} s   ratio {map_s / GOAL_MAP_S:.2f}"
          f"   ({1e6 * ours_per_point:.1f} us/point)")
    print(f"boundaries, 5 families         {boundary_s:8.2f} s   goal {GOAL_BOUNDARY_S:g} s   ratio "
          f"{boundary_s / GOAL_BOUNDARY_S:.2f}   ({n_roots} roots; grid {bmap.timings['grid_s']:.2f} s, "
          f"brentq {bmap.timings['boundary_s']:.2f} s)")
    print(f"baseline (scipy root + FD)     {1e6 * base_per_point:8.1f} us/point   speed-up "
          f"{base_per_point / ours_per_point:.1f}x   max |difference| {agree:.2e} 1/s")
    out = Path(__file__).parent / "results"
    out.mkdir(parents=True, exist_ok=True)
    (out / "stability_map.json").write_text(json.dumps(result, indent=2))
    print(f"wrote {out / 'stability_map.json'}")


if __name__ == "__main__":
    main()
