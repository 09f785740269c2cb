"""Results of the library models as exact numbers, for comparing numba runs with and without
stickslip's changes to numba (tests/reliability/test_numba_patches.py runs this as a script).

    python numba_results.py MODEL[,MODEL...] [--stability MODEL] [--orbit MODEL:SECTION]

prints one JSON object: per model its final state and the sums of its sampled states and times, a
stability eigenvalue set, and the period and multipliers of a stick-slip orbit found from rest, every float as ``float.hex``
(bit for bit).
"""

from __future__ import annotations

import argparse
import json

import numpy as np

import stickslip

#: Simulated time of each run [s]: short, the compile is what costs.
T_END = 3.0


def exact(values) -> list:
    """``values`` (real or complex) as hex strings, bit for bit."""
    flat = np.asarray(values).ravel()
    if np.iscomplexobj(flat):
        return [[float(v.real).hex(), float(v.imag).hex()] for v in flat]
    return [float(v).hex() for v in flat]


def simulated(name: str) -> dict:
    run = stickslip.simulate(name, T_END)
    return {"last": exact(run.states[-1]), "sum": exact(run.states.sum(axis=0)), "t": exact([run.t.sum()]),
            "samples": int(run.t.size)}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("models")
    ap.add_argument("--stability", default=None)
    ap.add_argument("--orbit", default=None)
    args = ap.parse_args()
    out = {name: simulated(name) for name in args.models.split(",") if name}
    if args.stability:
        out["stability"] = exact(np.sort_complex(stickslip.stability(args.stability).eigenvalues))
    if args.orbit:
        name, section = args.orbit.split(":")
        orbit = stickslip.periodic_orbit(name, "zero", section=section, search_time=60.0)
        out["orbit"] = {"period": exact([orbit.period]), "multipliers": exact(np.sort_complex(orbit.multipliers))}
    print(json.dumps(out, sort_keys=True))


if __name__ == "__main__":
    main()
