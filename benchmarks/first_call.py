"""First call of each command from an empty numba cache, against the same call cached.

What a new user waits for: each command is run as its own process (as a user runs it), first with
``NUMBA_CACHE_DIR`` a new empty folder, then again with that folder filled. The model-file
commands (``simulate``, ``stability``, ``orbit`` of a two-mass belt written as a model file) run
one after the other on one cache, as a first sitting with one's own model does; ``sweep`` and
``basins`` (of the belt) each start from an empty cache, and so does a ``simulate`` of the library's
impact oscillator, whose rigid contact compiles the impacts' kernels (against the model file's
pressed contacts). The last row is the loop a researcher
lives in: a Python model whose kinematics is defined in a module of its own is simulated once
(filling the cache, its "empty cache" column), its frame function is edited, and the next
``simulate`` is timed (its "after the edit" column, the one compared with ``--rev``).

With ``--rev REV`` every row is also run with the package at a git revision (``git archive`` of
``src/stickslip`` into a temporary folder, put first on ``PYTHONPATH``), one command after the
other alternately, so that both columns see the same machine: the before/after table. With
``--breakdown`` it also compiles the default ``simulate`` in this process with numba's compile
events recorded, and prints the outermost kernels by compile time (what a cold start is made of).

    python benchmarks/first_call.py [--rev REV ...] [--repeat 3] [--only simulate,basins] [--breakdown] [--top 15]
Writes benchmarks/results/first_call.json.
"""

from __future__ import annotations

import argparse
import collections
import io
import json
import os
import resource
import statistics
import subprocess
import sys
import tarfile
import tempfile
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MODEL_FILE = ROOT / "tests" / "orbits" / "two_mass_belt.toml"

#: (label, arguments of ``stickslip``, whether it starts a fresh cache).
COMMANDS = [
    ("simulate (defaults)", ["simulate", "--json"], True),
    ("simulate (model file)", ["simulate", "--model", str(MODEL_FILE), "--t-end", "100", "--json"], True),
    ("stability (model file)", ["stability", "--model", str(MODEL_FILE), "--json"], False),
    ("orbit (model file)", ["orbit", "--model", str(MODEL_FILE), "--search-time", "30", "--json", "--no-plot",
                            "--out", "{tmp}/orbit.nc"], False),
    ("sweep (belt, 4 points)", ["sweep", "--model", "belt", "--grid", "contact.0.drive=0.5:2:4", "--t-end", "50",
                                "--out", "{tmp}/sweep.nc", "--no-plot"], True),
    ("simulate (rigid contact: impact-oscillator)", ["simulate", "--model", "impact-oscillator", "--t-end", "20",
                                                     "--json"], True),
    ("basins (belt, 16 states)", ["basins", "--model", "belt", "--box", "x=-1:1", "--box", "dx=-1:1", "--grid", "4",
                                  "--t-end", "100", "--out", "{tmp}/basins.nc", "--no-plot"], True),
]

#: A Python model whose kinematics lives in a module of its own (the frame's gain is edited).
USER_MODULE = textwrap.dedent('''
    from typing import NamedTuple
    from stickslip.model import Contact, FrictionLaw, FrictionModel, register_kinematics
    from stickslip.model import csmath as csm

    class Arm(NamedTuple):
        H: float
        V: float

    def arm_frame(kin, s, c, m, G, w):
        cos = csm.cos(s[0])
        G[0, 0] = GAIN * kin.H / (cos * cos)
        G[1, 0] = 0.0
        w[0] = kin.V
        w[1] = 0.0
        return 1.0 + csm.zero(s[0])

    register_kinematics(Arm, arm_frame, ndof=1, ncontacts=1, dim=1)

    def model():
        return FrictionModel(name="arm", dofs=("theta",), mass=[[1.0]], damping=[[0.02]], stiffness=[[1.0]],
                             force=[0.0], contacts=(Contact(dim=1, friction=FrictionLaw("coulomb", 0.2, 0.1),
                                                            normal_force=1.0),), kinematics=Arm(1.0, 0.1))
    ''')
USER_RUN = "import user_arm, stickslip; stickslip.simulate(user_arm.model(), 60.0, ic=[0.0, 0.1])"
EDITED = "after editing a Python model's frame"


def baseline_tree(rev: str, into: Path) -> Path:
    """``src/stickslip`` at ``rev`` extracted under ``into``; returns the folder to put on PYTHONPATH."""
    data = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "src/stickslip"], check=True,
                          capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(into, filter="data")
    return into / "src"


def _env(cache: Path, tree: Path | None, extra: Path | None = None) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    paths = [str(p) for p in (tree, extra) if p is not None]
    if paths:
        env["PYTHONPATH"] = os.pathsep.join(paths + [env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def _children_cpu() -> float:
    """CPU seconds (user + system) of this process's waited-for children so far."""
    use = resource.getrusage(resource.RUSAGE_CHILDREN)
    return use.ru_utime + use.ru_stime


def _timed(command, env, cwd) -> dict:
    """Wall and CPU seconds of ``command``; the CPU time includes its own waited-for children (a
    cold start's helper process), the fair measure on a machine that others load."""
    cpu = _children_cpu()
    start = time.perf_counter()
    res = subprocess.run(command, env=env, capture_output=True, text=True, cwd=cwd)
    return {"seconds": time.perf_counter() - start, "cpu_s": _children_cpu() - cpu, "exit": res.returncode,
            "stderr_tail": res.stderr.strip().splitlines()[-1:] if res.returncode else []}


def edited_model(root: Path, tree: Path | None) -> dict:
    """Seconds of a ``simulate`` of the Python model after its frame was edited (the cache filled
    with the unedited one first); the run before the edit is not timed."""
    folder = Path(tempfile.mkdtemp(dir=root, prefix="user"))
    cache = Path(tempfile.mkdtemp(dir=root, prefix="cache"))
    module = folder / "user_arm.py"
    module.write_text("GAIN = 1.0\n" + USER_MODULE)
    first = _timed([sys.executable, "-c", USER_RUN], _env(cache, tree, folder), folder)
    module.write_text("GAIN = 1.0000001\n" + USER_MODULE)
    edited = _timed([sys.executable, "-c", USER_RUN], _env(cache, tree, folder), folder)
    edited["empty_cache_s"] = first["seconds"]
    return edited


def _run(args, cache: Path, tmp: Path, tree: Path | None = None) -> dict:
    args = [a.replace("{tmp}", str(tmp)) for a in args]
    return _timed([sys.executable, "-c", "from stickslip.cli import app; app()", *args], _env(cache, tree), tmp)


def breakdown(top: int, tree: Path | None = None) -> list[dict]:
    """Outermost compilations of a default ``simulate`` in a fresh cache, longest first (with the
    package of ``tree``, else the working tree's)."""
    code = ("import json, time\n"
            "from numba.core import event\n"
            "import stickslip\n"
            "spans, depth, start = [], [0], [0.0]\n"
            "class L(event.Listener):\n"
            "    def on_start(self, ev):\n"
            "        if depth[0] == 0: start[0] = time.perf_counter()\n"
            "        depth[0] += 1\n"
            "    def on_end(self, ev):\n"
            "        depth[0] -= 1\n"
            "        if depth[0] == 0:\n"
            "            d = ev.data['dispatcher']\n"
            "            spans.append({'kernel': d.py_func.__module__ + '.' + d.py_func.__qualname__,\n"
            "                          'seconds': time.perf_counter() - start[0]})\n"
            "event.register('numba:compile', L())\n"
            "stickslip.simulate(t_end=1.0)\n"
            "print(json.dumps(spans))\n")
    with tempfile.TemporaryDirectory() as cache:
        res = subprocess.run([sys.executable, "-c", code], env=_env(Path(cache), tree),
                             capture_output=True, text=True, check=True)
    totals = collections.defaultdict(float)
    for span in json.loads(res.stdout.strip().splitlines()[-1]):
        totals[span["kernel"]] += span["seconds"]
    return [{"kernel": k, "seconds": round(v, 2)} for k, v in sorted(totals.items(), key=lambda kv: -kv[1])[:top]]


def _row(label: str, runs: list[tuple[dict, dict]]) -> dict:
    """One command's row over its repeats: each repeat's cold and cached wall seconds, the cold
    run's CPU seconds, and their medians."""
    cold = [round(c["seconds"], 2) for c, _ in runs]
    cpu = [round(c["cpu_s"], 2) for c, _ in runs]
    warm = [round(w["seconds"], 2) for _, w in runs]
    errors = [e for c, w in runs for e in c["stderr_tail"] + w["stderr_tail"]]
    return {"command": label, "empty_cache_s": statistics.median(cold), "empty_cache_cpu_s": statistics.median(cpu),
            "cached_s": statistics.median(warm), "runs_empty_cache_s": cold, "runs_empty_cache_cpu_s": cpu,
            "runs_cached_s": warm, "exit": sorted({r["exit"] for pair in runs for r in pair}), "error": errors[-1:]}


def _commands(chosen, trees: dict, tmp_root: Path, repeats: int) -> dict:
    """Each chosen command ``repeats`` times for every tree, the trees alternating command by command."""
    runs = {name: {label: [] for label, _, _ in chosen} for name in trees}
    caches = {name: Path(tmp_root) / f"cache-{i}" for i, name in enumerate(trees)}
    for _ in range(repeats):
        for label, cli_args, fresh in chosen:
            for i, (name, tree) in enumerate(trees.items()):
                if fresh:
                    caches[name] = Path(tempfile.mkdtemp(dir=tmp_root, prefix=f"cache{i}-"))
                cold = _run(cli_args, caches[name], Path(tempfile.mkdtemp(dir=tmp_root, prefix="work")), tree)
                warm = _run(cli_args, caches[name], Path(tempfile.mkdtemp(dir=tmp_root, prefix="work")), tree)
                runs[name][label].append((cold, warm))
    return {name: [_row(label, pairs) for label, pairs in table.items()] for name, table in runs.items()}


def _print(out: dict, revs: list[str]) -> None:
    for name, table in out.items():
        print(f"-- {name}")
        for r in table["commands"]:
            second = "after the edit" if "after_edit_s" in r else "cached"
            cpu = f"  cpu {r['empty_cache_cpu_s']:6.1f} s" if "empty_cache_cpu_s" in r else ""
            print(f"{r['command']:<38} empty cache {r['empty_cache_s']:6.1f} s{cpu}   {second} {r['cached_s']:5.1f} s"
                  + (f"   exit {r['exit']}: {r['error']}" if any(r["exit"]) else ""))
        if table["model_file_sitting_s"]:
            print(f"a new model file: simulate, stability, orbit from an empty cache: "
                  f"{table['model_file_sitting_s']:.1f} s together")
    for rev in revs:
        for new, old in zip(out["working tree"]["commands"], out[rev]["commands"]):
            keys = ["after_edit_s"] if "after_edit_s" in new else ["empty_cache_s", "empty_cache_cpu_s"]
            print(f"{new['command']:<38} " + "; ".join(
                f"{key[:-2].replace('_', ' ')} {new[key]:6.1f} s against {old[key]:6.1f} s at {rev} "
                f"({new[key] / old[key]:.2f})" for key in keys))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--breakdown", action="store_true", help="also list the kernels a cold simulate compiles")
    ap.add_argument("--top", type=int, default=15)
    ap.add_argument("--rev", action="append", default=[],
                    help="also run every row with the package at this git revision (may be repeated)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="runs of each command per tree, alternating (medians reported)")
    ap.add_argument("--only", default=None, help="comma-separated words; the rows whose label has one of them")
    args = ap.parse_args()
    words = None if args.only is None else [w.strip() for w in args.only.split(",") if w.strip()]
    chosen = [c for c in COMMANDS if words is None or any(w in c[0] for w in words)]
    with tempfile.TemporaryDirectory() as tmp_root:
        trees = {"working tree": None}
        for i, rev in enumerate(args.rev):
            trees[rev] = baseline_tree(rev, Path(tmp_root) / f"baseline{i}")
        rows = _commands(chosen, trees, Path(tmp_root), args.repeat)
        if words is None or any(w in EDITED for w in words):
            for name, tree in trees.items():
                edit = edited_model(Path(tmp_root), tree)
                rows[name].append({"command": EDITED, "empty_cache_s": round(edit["empty_cache_s"], 2),
                                   "cached_s": round(edit["seconds"], 2), "after_edit_s": round(edit["seconds"], 2),
                                   "exit": [edit["exit"], edit["exit"]], "error": edit["stderr_tail"]})
        out = {name: {"commands": table, "model_file_sitting_s": round(
            sum(r["empty_cache_s"] for r in table if "model file" in r["command"]), 2)} for name, table in rows.items()}
        _print(out, args.rev)
        if args.breakdown:
            for name, tree in trees.items():
                out[name]["simulate_kernels"] = breakdown(args.top, tree)
                print(f"-- compile of a default simulate, outermost kernels: {name}")
                for row in out[name]["simulate_kernels"]:
                    print(f"  {row['seconds']:6.1f} s  {row['kernel']}")
    out["machine"] = {"load_average": os.getloadavg(), "cpus": os.cpu_count()}
    path = ROOT / "benchmarks" / "results" / "first_call.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
