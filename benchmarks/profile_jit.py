"""Where a run's time goes inside the compiled kernels: ``perf`` samples mapped to numba functions.

numba writes no perf map here, so ``perf report`` shows compiled code as bare addresses. This
script compiles the package in a fresh numba cache (so every library is in memory), takes the
address of every compiled function from its library (``get_pointer_to_function``), runs
``perf record`` on itself while it repeats the case, and prints the share of samples per
function (compiled ones prefixed ``JIT:``, library ones such as ``__sincos_fma`` by name).
A function's range is taken up to the next known address, so a share is exact per function but
copies of a callee linked into several libraries are counted apart.

    python benchmarks/profile_jit.py [--method aeom] [--dt 1e-3] [--seconds 10] [--top 25] [--sample-rate 1000]

Needs Linux ``perf`` with permission to record this process.

With ``--compile`` it profiles a cold compile instead: a first ``simulate`` (of the plates, or of
``--model``) in a fresh numba cache, in one process (``STICKSLIP_COMPILE_PROCESSES=1``: the cold
start's helper off, so every kernel compiles here), with numba's compile events recorded. Times
are CPU seconds of that process (a fair measure on a machine that others load). Each kernel's
compile time is printed inclusive (its event's span: its typing, the kernels it calls
compiled inside that, its lowering and LLVM) and by itself (less the spans of the kernels compiled
inside it), summed over its signatures; ``--rev REV`` also runs it with the package at a git
revision (``git archive``, as ``first_call.py`` does), alternating, ``--repeat`` times (medians);
``--llvm`` also gives the part of each kernel's own time spent inside LLVM (optimisation and
machine code), the rest being numba's front end and lowering:

    python benchmarks/profile_jit.py --compile [--model FILE] [--rev REV] [--repeat 3] [--top 40] [--llvm]

Writes benchmarks/results/compile_profile.json. Development tool: not run by CI.
"""

from __future__ import annotations

import argparse
import bisect
import collections
import importlib
import json
import os
import pkgutil
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from first_call import baseline_tree  # noqa: E402

#: Run in a child with a fresh NUMBA_CACHE_DIR: a first simulate with every compile event recorded.
_COMPILE_CHILD = """
import json, sys, time
from numba.core import event
import stickslip
own, stack, llvm = {}, [], []
class Listener(event.Listener):
    def on_start(self, ev):
        stack.append([time.process_time(), 0.0, 0.0])
    def on_end(self, ev):
        start, inner, in_llvm = stack.pop()
        span = time.process_time() - start
        if stack:
            stack[-1][1] += span
        d = ev.data["dispatcher"]
        name = d.py_func.__module__.replace("stickslip.", "") + "." + d.py_func.__qualname__
        row = own.setdefault(name, [0.0, 0.0, 0, 0.0])
        row[0] += span
        row[1] += span - inner
        row[2] += 1
        row[3] += in_llvm
class LLVM(event.Listener):
    def on_start(self, ev):
        llvm.append(time.process_time())
    def on_end(self, ev):
        if llvm and stack:
            stack[-1][2] += time.process_time() - llvm.pop()
        elif llvm:
            llvm.pop()
event.register("numba:compile", Listener())
if sys.argv[2] == "1":
    event.register("numba:llvm_lock", LLVM())
model = sys.argv[1] or None
start = time.process_time()
if model:
    stickslip.simulate(stickslip.load_model(model), 1.0)
else:
    stickslip.simulate(t_end=1.0)
own["(total)"] = [time.process_time() - start, 0.0, 0, 0.0]
print(json.dumps(own))
"""


def function_addresses(package) -> list[tuple[int, str]]:
    """(start address, short name) of every compiled function of every dispatcher in ``package``."""
    from numba.core.registry import CPUDispatcher

    found = {}
    for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
        try:
            module = importlib.import_module(info.name)
        except ImportError:
            continue
        for obj in vars(module).values():
            if not isinstance(obj, CPUDispatcher):
                continue
            for cres in obj.overloads.values():
                library = cres.library
                for fn in library._final_module.functions:
                    if fn.is_declaration:
                        continue
                    address = library.get_pointer_to_function(fn.name)
                    if address:
                        found[address] = readable(fn.name)
    return sorted(found.items())


def readable(symbol: str) -> str:
    """``integrate.fixed_step.rk4_slip_step`` from numba's mangled ``_ZN9stickslip9integrate…B…``
    (the length-prefixed name segments); Python wrappers get a ``wrapper:`` prefix."""
    parts = []
    i = symbol.find("N") + 1 if symbol.startswith("_Z") else 0
    while i < len(symbol) and symbol[i].isdigit():
        j = i
        while symbol[j].isdigit():
            j += 1
        n = int(symbol[i:j])
        parts.append(symbol[j:j + n])
        i = j + n
    if not parts:
        return symbol[:60]
    wrapper = parts[0] == "cpython"
    parts = [q for q in parts if q not in ("cpython", "stickslip")]
    return ("wrapper:" if wrapper else "") + ".".join(parts)


def compile_once(model: str | None, tree: Path | None, llvm: bool = False) -> dict:
    """{kernel: [inclusive s, own s, compiles, own s inside LLVM]} of one cold first simulate
    (``_COMPILE_CHILD``; the last 0 unless ``llvm``)."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, STICKSLIP_COMPILE_PROCESSES="1")
        if tree is not None:
            env["PYTHONPATH"] = os.pathsep.join([str(tree), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
        res = subprocess.run([sys.executable, "-c", _COMPILE_CHILD, model or "", "1" if llvm else "0"], env=env, capture_output=True,
                             text=True, cwd=cache)
    if res.returncode:
        sys.exit(f"the cold simulate failed:\n{res.stderr[-2000:]}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def compile_profile(args) -> None:
    """Per-kernel compile times of a cold first simulate, for the working tree and ``--rev``s."""
    if args.model and Path(args.model).exists():  # a file: the children run in their cache folder
        args.model = str(Path(args.model).resolve())
    with tempfile.TemporaryDirectory() as tmp:
        trees = {"working tree": None}
        for i, rev in enumerate(args.rev):
            trees[rev] = baseline_tree(rev, Path(tmp) / f"rev{i}")
        runs = {name: [] for name in trees}
        for _ in range(args.repeat):
            for name, tree in trees.items():
                runs[name].append(compile_once(args.model, tree, args.llvm))
    out = {}
    for name, profiles in runs.items():
        kernels = set().union(*profiles)
        out[name] = {k: [round(statistics.median(p.get(k, [0.0, 0.0, 0, 0.0])[i] for p in profiles), 3)
                         for i in range(4)] for k in kernels}
        print(f"-- {name}: cold simulate {out[name]['(total)'][0]:.2f} s CPU (median of {args.repeat}), "
              f"kernels by own compile time (inclusive in brackets)")
        rows = sorted(((k, v) for k, v in out[name].items() if k != "(total)"), key=lambda kv: -kv[1][1])
        for k, (inclusive, own, count, in_llvm) in rows[:args.top]:
            llvm_part = f"  LLVM {in_llvm:5.2f} s" if args.llvm else ""
            print(f"  {own:6.2f} s  ({inclusive:6.2f} s){llvm_part}  x{count:<3g} {k}")
    path = ROOT / "benchmarks" / "results" / "compile_profile.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps({"model": args.model, "repeat": args.repeat, "profiles": out,
                                "load_average": os.getloadavg()}, indent=2))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--compile", action="store_true", help="profile a cold compile instead (module docstring)")
    ap.add_argument("--model", default=None, help="--compile: a model (name or file) instead of the plates")
    ap.add_argument("--rev", action="append", default=[], help="--compile: also at this git revision")
    ap.add_argument("--repeat", type=int, default=1, help="--compile: runs per tree (medians)")
    ap.add_argument("--llvm", action="store_true",
                    help="--compile: also each kernel's own time inside LLVM (numba's llvm_lock events; slower)")
    ap.add_argument("--method", default="aeom", choices=["event", "aeom", "naeom"])
    ap.add_argument("--dt", type=float, default=1e-3, help="fixed step [s] (aeom, naeom)")
    ap.add_argument("--seconds", type=float, default=10.0, help="recording time [s]")
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--sample-rate", type=float, default=1000.0, help="output samples per second [Hz]")
    args = ap.parse_args()
    if args.compile:
        compile_profile(args)
        return
    if shutil.which("perf") is None:
        sys.exit("perf not found: install linux perf (e.g. apt install linux-perf) to profile")

    cache = tempfile.mkdtemp()
    os.environ["NUMBA_CACHE_DIR"] = cache  # compile afresh: the libraries stay in memory
    import stickslip

    kw = {"sample_rate": args.sample_rate}
    if args.method != "event":
        kw.update(method=args.method, dt=args.dt)
    params = stickslip.Parameters()
    stickslip.simulate(params, 0.01, **kw)  # compile
    starts_names = function_addresses(stickslip)
    starts = [a for a, _ in starts_names]

    data = os.path.join(cache, "perf.data")
    perf = subprocess.Popen(["perf", "record", "-q", "-F", "5000", "-p", str(os.getpid()), "-o", data],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(0.5)
    end = time.perf_counter() + args.seconds
    runs = 0
    while time.perf_counter() < end:
        stickslip.simulate(params, 100.0, **kw)
        runs += 1
    perf.send_signal(2)  # SIGINT: perf writes its data and exits
    perf.wait()

    script = subprocess.run(["perf", "script", "-i", data, "-F", "ip,sym"], capture_output=True, text=True).stdout
    counts = collections.Counter()
    total = 0
    for line in script.splitlines():
        parts = line.split(None, 1)
        if not parts:
            continue
        total += 1
        symbol = parts[1].strip() if len(parts) > 1 else "[unknown]"
        if symbol == "[unknown]":
            ip = int(parts[0], 16)
            k = bisect.bisect_right(starts, ip) - 1
            symbol = "JIT:" + starts_names[k][1] if k >= 0 and ip - starts[k] < 1 << 18 else "[unknown]"
        counts[symbol] += 1
    print(f"{args.method} {'' if args.method == 'event' else f'dt={args.dt:g} '}100 s, {runs} runs, "
          f"{total} samples, {len(starts)} compiled functions mapped")
    for symbol, n in counts.most_common(args.top):
        print(f"{100 * n / max(total, 1):6.2f} %  {symbol}")
    shutil.rmtree(cache, ignore_errors=True)


if __name__ == "__main__":
    main()
