"""A/B timing of the working tree against a git revision, side by side.

Timings on a shared VM drift by up to 2× between minutes, so two benchmark runs taken minutes
apart cannot resolve a few per cent. This script extracts the package at a git revision as
``stickslip_baseline`` (``git archive`` of ``src/stickslip`` into a temporary folder; the package
uses relative imports only) and times the same case alternately with it and with the working
tree's ``stickslip``, so each pair sees the same machine. Each package runs in a process of its
own, started alike and asked in turn: with both in one process, the package compiled second ran
its kernels 25 % slower on a small model (hoffmann over 300 s, identical code; the placement of
its machine code, whichever package came second). It prints the minimum of each and the median
and quartiles of the per-pair ratio new/baseline, and writes JSON. Two copies of the same code
give a median ratio within ±1 % with 40 pairs (measured on the 2-core VM).

    python benchmarks/ab.py [--rev HEAD] [--pairs 40] [--method aeom --dt 1e-3] [--t-end 100] [--sample-rate 1000]
                            [--model belt --ic x=1,dx=0 --set contact.0.drive=1.2]
Writes benchmarks/results/ab.json.
"""

from __future__ import annotations

import argparse
import io
import json
import multiprocessing
import os
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def baseline_package(rev: str, into: Path) -> None:
    """Extract ``src/stickslip`` at ``rev`` as ``into/stickslip_baseline``."""
    data = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "src/stickslip"], check=True,
                          capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        try:
            tar.extractall(into, filter="data")
        except TypeError:  # Python < 3.11.4 has no extraction filters (our own repository's archive)
            tar.extractall(into)
    (into / "src" / "stickslip").rename(into / "stickslip_baseline")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default="HEAD", help="git revision of the baseline (default HEAD)")
    ap.add_argument("--pairs", type=int, default=40)
    ap.add_argument("--method", default="aeom")
    ap.add_argument("--dt", type=float, default=None, help="fixed step [s] (default 1e-3 for aeom/naeom); for the event method its largest step (default none)")
    ap.add_argument("--t-end", type=float, default=100.0)
    ap.add_argument("--sample-rate", type=float, default=1000.0, help="output samples per second [Hz]")
    ap.add_argument("--fig12a", action="store_true",
                    help="time the runs of the Fig. 12(a) sweep instead: 13 values of N from 10 to 130 N at "
                         "Omega = 0.5 rad/s, 200 s each, summed per pair")
    ap.add_argument("--model", default=None, help="a library model or model file instead of the plates "
                    "(event method; the same name must mean the same equations at both revisions)")
    ap.add_argument("--ic", default=None, help="initial state of --model, NAME=VALUE,...")
    ap.add_argument("--set", action="append", default=[], help="a parameter of --model, PATH=VALUE (repeatable)")
    args = ap.parse_args()
    dt = args.dt if args.dt is not None or args.method == "event" else 1e-3
    with tempfile.TemporaryDirectory() as tmp:
        baseline_package(args.rev, Path(tmp))
        kw = {"method": args.method, "dt": dt, "sample_rate": args.sample_rate}
        if args.fig12a:  # the points of the Fig. 12(a) sweep, as the sweep runs them (no samples kept)
            loads = [10.0 + 10.0 * i for i in range(13)]
            cases = [(dict(N=N, Omega=0.5), 200.0) for N in loads]
            kw["sample_rate"] = 100.0
        else:
            cases = [({}, args.t_end)]
        if args.model is not None:
            ic = dict(item.split("=") for item in args.ic.split(",")) if args.ic else None
            ic = None if ic is None else {k: float(v) for k, v in ic.items()}
            kw.update(method="event", dt=args.dt)  # dt of the event method: its largest step
            if ic is not None:
                kw["ic"] = ic
            cases = [({}, args.t_end)]
        # each worker compiles in its own process: a cold start's helper names kernels by the
        # package's import name (``stickslip.…``), which is the working tree's, not the baseline's
        os.environ["STICKSLIP_COMPILE_PROCESSES"] = "1"
        context = multiprocessing.get_context("spawn")
        workers = []
        for name in ("stickslip_baseline", "stickslip"):
            mine, theirs = context.Pipe()
            proc = context.Process(target=_serve, args=(theirs, name, tmp, args, kw, cases), daemon=True)
            proc.start()
            workers.append((proc, mine))
        for _, pipe in workers:  # each compiles (or loads) its kernels outside the timing
            try:
                pipe.recv()
            except EOFError:
                raise SystemExit("a worker failed to start (its traceback is above)") from None
        base, new = [], []
        for i in range(args.pairs):
            order = (0, 1) if i % 2 else (1, 0)  # alternate which goes first
            for which in order:
                workers[which][1].send("run")
                (base if which == 0 else new).append(workers[which][1].recv())
        for proc, pipe in workers:
            pipe.send("stop")
            proc.join()
    ratios = sorted(n / b for n, b in zip(new, base))
    q = len(ratios) // 4
    out = {"rev": args.rev, "case": {**kw, "t_end": args.t_end, "fig12a": args.fig12a, "model": args.model,
                                     "set": args.set}, "pairs": args.pairs,
           "baseline_min_s": min(base), "new_min_s": min(new), "ratio_median": ratios[len(ratios) // 2],
           "ratio_quartiles": [ratios[q], ratios[-q - 1]]}
    label = "Fig. 12(a) runs (13 N, 200 s)" if args.fig12a else f"{args.t_end:g} s"
    label += "" if args.model is None else f", model {args.model} {' '.join(args.set)} ic {args.ic}"
    print(f"{kw['method']} dt={kw['dt']} {label}: baseline ({args.rev}) min {min(base):.4f} s, "
          f"working tree min {min(new):.4f} s; new/baseline median {out['ratio_median']:.3f} "
          f"(quartiles {ratios[q]:.3f} … {ratios[-q - 1]:.3f}, {args.pairs} pairs)")
    path = ROOT / "benchmarks" / "results" / "ab.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(out, indent=2))


def _serve(pipe, name: str, tmp: str, args, kw: dict, cases: list) -> None:
    """Worker: import ``name`` (from ``tmp`` for the baseline), run the case once, then answer each
    "run" with the wall time of the case's runs [s] until "stop"."""
    sys.path.insert(0, tmp)
    import importlib
    pkg = importlib.import_module(name)
    pkg.simulate(*_target(pkg, args, {}), 1.0, **kw)
    pipe.send("ready")
    while pipe.recv() == "run":
        pipe.send(sum(pkg.simulate(*_target(pkg, args, values), t_end, **kw).stats.wall_time_s
                      for values, t_end in cases))


def _target(pkg, args, values):
    """The model argument of ``pkg.simulate``: the plates' Parameters, or ``--model`` with ``--set``."""
    if args.model is None:
        return (pkg.Parameters(**values),)
    model = pkg.load_model(args.model)
    changes = {k: float(v) for k, v in (item.split("=") for item in args.set)}
    return (model.replace(**changes) if changes else model,)


if __name__ == "__main__":
    main()
