"""Where a run's time goes inside the compiled kernels: ``perf`` samples mapped to numba functions.

numba writes no perf map here, so ``perf report`` shows compiled code as bare addresses. This
script compiles the package in a fresh numba cache (so every library is in memory), takes the
address of every compiled function from its library (``get_pointer_to_function``), runs
``perf record`` on itself while it repeats the case, and prints the share of samples per
function (compiled ones prefixed ``JIT:``, library ones such as ``__sincos_fma`` by name).
A function's range is taken up to the next known address, so a share is exact per function but
copies of a callee linked into several libraries are counted apart.

    python benchmarks/profile_jit.py [--method aeom] [--dt 1e-3] [--seconds 10] [--top 25] [--sample-rate 1000]

Needs Linux ``perf`` with permission to record this process. Development tool: not run by CI.
"""

from __future__ import annotations

import argparse
import bisect
import collections
import importlib
import os
import pkgutil
import shutil
import subprocess
import sys
import tempfile
import time


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--method", default="aeom", choices=["event", "aeom", "naeom"])
    ap.add_argument("--dt", type=float, default=1e-3, help="fixed step [s] (aeom, naeom)")
    ap.add_argument("--seconds", type=float, default=10.0, help="recording time [s]")
    ap.add_argument("--top", type=int, default=25)
    ap.add_argument("--sample-rate", type=float, default=1000.0, help="output samples per second [Hz]")
    args = ap.parse_args()
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
