"""Start-up time of the command line, against a baseline revision measured in the same run.

Each command runs as a process of its own (``python -c "from stickslip.cli import app; app()" ARGS``,
what the ``stickslip`` script runs), ``--runs`` times, alternately with the package of the working
tree and with the package at ``--rev`` (``git archive`` of ``src/stickslip``, put first on
PYTHONPATH), so that both see the same machine. Before timing, both trees are byte-compiled
(``compileall``: a process started with ``PYTHONDONTWRITEBYTECODE`` would otherwise compile every
module from source each time) and each command runs once untimed, which fills numba's cache of
either tree (the baseline's lives beside its extracted copy, kept under the temporary folder by
commit, so a second benchmark run finds it warm). The commands: ``--version``, ``--help``,
``models`` and a default ``simulate --json`` (warm cache: nothing compiled).

It prints, per command, the median wall time and the median CPU time (user + sys, less sensitive
to other load on a shared machine) of each tree and their ratio new/baseline, checks that the
``simulate --json`` output of the two trees is the same apart from its timing fields, and writes
benchmarks/results/startup.json.

    python benchmarks/startup.py [--rev main] [--runs 10] [--only simulate,models]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from first_call import baseline_tree  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

#: Command name → its arguments.
COMMANDS = {"version": ["--version"], "help": ["--help"], "models": ["models"], "simulate": ["simulate", "--json"]}

#: Fields of the ``simulate --json`` summary that are timings, not results.
TIMING_FIELDS = ("wall_time_s", "compile_time_s")


def baseline(rev: str) -> tuple[str, Path]:
    """``src/stickslip`` at ``rev`` extracted once per commit under the temporary folder; returns
    the commit and the folder to put on PYTHONPATH."""
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", rev], check=True, capture_output=True,
                            text=True).stdout.strip()
    into = Path(tempfile.gettempdir()) / f"stickslip-startup-{commit[:12]}"
    if not (into / "src" / "stickslip" / "__init__.py").is_file():
        baseline_tree(commit, into)
    return commit, into / "src"


def run(args: list[str], tree: Path, cwd: Path) -> dict:
    """One process of the command line with the package of ``tree``: wall and CPU seconds, output."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tree), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))
    env.pop("NUMBA_CACHE_DIR", None)  # each tree's kernels in its own __pycache__
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    res = subprocess.run([sys.executable, "-c", "from stickslip.cli import app; app()", *args], env=env, cwd=cwd,
                         capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        raise SystemExit(f"{' '.join(args)} with {tree} exited {res.returncode}: {res.stderr.strip()[-2000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall": wall, "cpu": cpu, "stdout": res.stdout}


def results_of(stdout: str) -> dict:
    """The ``simulate --json`` summary without its timing fields."""
    return {k: v for k, v in json.loads(stdout).items() if k not in TIMING_FIELDS}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default="main", help="git revision of the baseline (default main)")
    ap.add_argument("--runs", type=int, default=10, help="timed runs of each command with each tree")
    ap.add_argument("--only", default=",".join(COMMANDS), help=f"commands to time, of {', '.join(COMMANDS)}")
    args = ap.parse_args()
    names = [n.strip() for n in args.only.split(",") if n.strip()]
    commit, base = baseline(args.rev)
    trees = {"baseline": base, "new": ROOT / "src"}
    for tree in trees.values():
        subprocess.run([sys.executable, "-m", "compileall", "-q", str(tree / "stickslip")], check=True)
    times = {name: {label: {"wall": [], "cpu": []} for label in trees} for name in names}
    with tempfile.TemporaryDirectory() as tmp:
        outputs = {label: {name: run(COMMANDS[name], tree, Path(tmp))["stdout"] for name in names}
                   for label, tree in trees.items()}  # untimed: fills numba's cache of each tree
        for i in range(args.runs):
            order = list(trees.items()) if i % 2 == 0 else list(trees.items())[::-1]
            for name in names:
                for label, tree in order:
                    res = run(COMMANDS[name], tree, Path(tmp))
                    times[name][label]["wall"].append(res["wall"])
                    times[name][label]["cpu"].append(res["cpu"])
    same = None
    if "simulate" in names:
        same = results_of(outputs["baseline"]["simulate"]) == results_of(outputs["new"]["simulate"])
    out = {"rev": args.rev, "commit": commit, "runs": args.runs, "load_average": os.getloadavg(),
           "simulate_output_identical": same, "commands": {}}
    print(f"start-up, median of {args.runs} runs each (baseline {args.rev} = {commit[:10]}; load average "
          f"{os.getloadavg()[0]:.1f})")
    print(f"{'command':>10}  {'baseline wall':>13}  {'new wall':>9}  {'ratio':>6}  {'baseline cpu':>12}  {'new cpu':>8}  "
          f"{'ratio':>6}")
    for name in names:
        row = {label: {kind: statistics.median(v) for kind, v in t.items()} for label, t in times[name].items()}
        row["ratio_wall"] = row["new"]["wall"] / row["baseline"]["wall"]
        row["ratio_cpu"] = row["new"]["cpu"] / row["baseline"]["cpu"]
        row["samples"] = times[name]
        out["commands"][name] = row
        print(f"{name:>10}  {row['baseline']['wall']:>11.3f} s  {row['new']['wall']:>7.3f} s  {row['ratio_wall']:>6.2f}  "
              f"{row['baseline']['cpu']:>10.3f} s  {row['new']['cpu']:>6.3f} s  {row['ratio_cpu']:>6.2f}")
    if same is not None:
        print("simulate --json: " + ("the same results from both trees (timing fields aside)" if same else
                                     "RESULTS DIFFER between the trees"))
    path = ROOT / "benchmarks" / "results" / "startup.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
