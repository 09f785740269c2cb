"""Transients of reduced finite-element models: cost against DOFs and contacts (the kernels' heap flavour).

    python benchmarks/fe_transient.py            # every row
    python benchmarks/fe_transient.py --only dofs,contacts,target,cold

The models are Craig–Bampton reductions (``stickslip.reduction``) of the pad on a belt of
``tests/fe/fe_models.py`` (a soft plane-stress pad, compliant contact nodes on its bottom face,
Coulomb friction; the parameters of ``tests/fe/test_fe_transient.py``): the contact nodes' two
DOFs each and m fixed-interface modes, so M and K are dense.

Rows:

* ``dofs``: 10 contact nodes, n = 100 … 800 DOFs: the seconds of one right-hand side with every
  contact sliding, of one with every contact sticking (the stick system of all contacts solved),
  and of a step of a short run (wall time / accepted steps; its accepted and rejected steps and
  right-hand sides counted); the log-log slope of each against n;
* ``contacts``: n = 400 DOFs, 10 … 80 contact nodes: the same against the contacts (the log-log
  slope of each against nc);
* ``target``: 900 DOFs with 40 compliant contact nodes, 20 periods (``--periods``) of its first
  mode (``natural_frequencies()[0]``) from rest at rtol 1e-8: wall and CPU time (the process's,
  which a shared machine inflates less) and per period, steps (accepted, rejected, re-taken at
  slip roots), right-hand sides, stick/slip transitions and how many contacts stuck and opened;
* ``cold``: the first run of a heap-flavour model in a fresh process with an empty
  ``NUMBA_CACHE_DIR`` (the default two compile processes): its compile time as the run reports it.

Each row's models are built and reduced before the clock starts (the reduction is not timed).
Writes benchmarks/results/fe_transient.json. Run on the shared 2-core machine: say so with the numbers.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

from fe.fe_models import pad_on_belt  # noqa: E402

PAD = dict(mu_k=0.3, delta_mu=0.2, preload=3e-5, E=1e7, contact_stiffness=1e6, rayleigh=(0.0, 2e-6), speed=0.05)


def reduced_pad(contacts: int, dofs: int, folder: Path):
    """A Craig–Bampton model of ``dofs`` DOFs of a pad with ``contacts`` contact nodes."""
    from stickslip.model.library import load_model
    from stickslip.reduction import reduce_model, write_model_file

    path = folder / f"cb_{contacts}_{dofs}.toml"
    if path.exists():  # made for an earlier row
        return load_model(str(path))
    modes = dofs - 2 * contacts
    ny = max(2, -(-(modes + 2 * contacts + 10) // (2 * contacts)))  # interior DOFs beyond the modes kept
    fe = pad_on_belt(contacts - 1, ny, **PAD)
    full = load_model(str(fe.write(folder / f"pad_{contacts}_{dofs}")))
    red = reduce_model(full, method="craig-bampton", modes=modes)
    write_model_file(red.form, path)
    model = load_model(str(path))
    assert model.n == dofs and model.n_contacts == contacts, (model.n, model.n_contacts)
    return model


def rhs_seconds(model, stick: bool, repeat: int = 50) -> float:
    """Seconds of one right-hand side at rest (every contact closed), sliding or sticking."""
    from stickslip.model import physics as P
    from stickslip.model.bundle import CST, contact_state

    md = model.data
    s = np.zeros(2 * model.n + 2)
    cst = contact_state(md.m)
    cst[0::CST] = P.MODE_STICK if stick else P.MODE_SLIP_EXACT
    ds = np.zeros_like(s)
    P.rhs(s, cst, md, ds)  # compile or load
    best = np.inf
    for _ in range(3):
        t = time.perf_counter()
        for _ in range(repeat):
            P.rhs(s, cst, md, ds)
        best = min(best, (time.perf_counter() - t) / repeat)
    return best


def step_seconds(model, periods: float = 1.0) -> dict:
    """A short run from rest: wall time per accepted step."""
    from stickslip import simulate

    f1 = float(model.natural_frequencies()[0])
    cpu = time.process_time()
    run = simulate(model, periods / f1, sample_rate=50 * f1, rtol=1e-8, atol=1e-12)
    cpu = time.process_time() - cpu
    steps = run.stats.accepted_steps
    return {"run_s": run.stats.wall_time_s, "cpu_s": cpu, "steps": int(steps), "rejected": int(run.stats.rejected_steps),
            "rhs_calls": int(run.stats.rhs_calls), "step_s": run.stats.wall_time_s / max(steps, 1)}


def slope(x, y) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def sweep(cases, folder: Path) -> dict:
    rows = []
    for contacts, dofs in cases:
        model = reduced_pad(contacts, dofs, folder)
        row = {"dofs": dofs, "contacts": contacts, "rhs_slide_s": rhs_seconds(model, False),
               "rhs_stick_s": rhs_seconds(model, True), **step_seconds(model)}
        print(json.dumps(row), flush=True)
        rows.append(row)
    return {"rows": rows}


def with_slopes(result: dict, key: str) -> dict:
    x = [r[key] for r in result["rows"]]
    result["slopes"] = {k: slope(x, [r[k] for r in result["rows"]]) for k in ("rhs_slide_s", "rhs_stick_s", "step_s")}
    print(f"log-log slopes against {key}: " + ", ".join(f"{k} {v:.2f}" for k, v in result["slopes"].items()))
    return result


def target(folder: Path, periods: float = 20.0) -> dict:
    from stickslip import simulate

    model = reduced_pad(40, 900, folder)
    f1 = float(model.natural_frequencies()[0])
    simulate(model, 1e-6, sample_rate=1e6)  # compile or load the kernels before the clock
    t = time.perf_counter()
    cpu = time.process_time()
    run = simulate(model, periods / f1, sample_rate=50 * f1, rtol=1e-8, atol=1e-12)
    wall = time.perf_counter() - t
    cpu = time.process_time() - cpu
    row = {"dofs": model.n, "contacts": model.n_contacts, "first_mode_hz": f1, "periods": periods, "wall_s": wall,
           "cpu_s": cpu, "wall_per_period_s": wall / periods, "goal_s_for_20_periods": 60.0, "status": run.status,
           "t_reached_periods": float(run.t[-1] * f1), "steps": run.stats.accepted_steps,
           "rejected": run.stats.rejected_steps, "rhs_calls": run.stats.rhs_calls,
           "retaken": run.stats.retaken_steps, "slip_to_stick": run.stats.slip_to_stick,
           "stick_to_slip": run.stats.stick_to_slip, "cpu_per_period_s": cpu / periods,
           "contacts_that_stuck": int(run.stick.any(axis=0).sum()),
           "contacts_that_opened": int(run.open.any(axis=0).sum())}
    print(json.dumps(row), flush=True)
    return row


COLD = """
import json, sys, time
sys.path.insert(0, {tests!r})
from stickslip import simulate
from stickslip.model.library import load_model
model = load_model({path!r})
t = time.perf_counter()
run = simulate(model, 1e-5, sample_rate=1e6)
print(json.dumps({{"first_run_s": time.perf_counter() - t, "compile_time_s": run.stats.compile_time_s,
                   "kinematics": type(model.data.kin).__name__}}))
"""


def cold(folder: Path) -> dict:
    """The first run of a heap-flavour model from an empty numba cache, in a fresh process."""
    model = reduced_pad(20, 100, folder)
    path = folder / "cb_20_100.toml"
    assert model.n == 100
    with tempfile.TemporaryDirectory() as cache:
        env = {k: v for k, v in os.environ.items() if k != "STICKSLIP_COMPILE_PROCESSES"}  # the default: two
        env["NUMBA_CACHE_DIR"] = cache
        out = subprocess.run([sys.executable, "-c", COLD.format(tests=str(HERE.parent / "tests"), path=str(path))],
                             env=env, capture_output=True, text=True, check=True)
    row = json.loads(out.stdout.strip().splitlines()[-1])
    print(json.dumps(row), flush=True)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default="dofs,contacts,target,cold")
    ap.add_argument("--periods", type=float, default=20.0, help="periods of the target run (the goal: 20)")
    ap.add_argument("--folder", default=None, help="keep the reduced models here (reused by a later run)")
    args = ap.parse_args()
    only = set(args.only.split(","))
    out: dict = {"machine": {"cpus": os.cpu_count(), "load_average_at_start": list(os.getloadavg())}}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(args.folder or tmp)
        folder.mkdir(parents=True, exist_ok=True)
        if "dofs" in only:
            out["dofs"] = with_slopes(sweep([(10, n) for n in (100, 200, 400, 800)], folder), "dofs")
        if "contacts" in only:
            out["contacts"] = with_slopes(sweep([(nc, 400) for nc in (10, 20, 40, 80)], folder), "contacts")
        if "target" in only:
            out["target"] = target(folder, args.periods)
        if "cold" in only:
            out["cold"] = cold(folder)
    results = HERE / "results"
    results.mkdir(exist_ok=True)
    name = "fe_transient.json" if only == {"dofs", "contacts", "target", "cold"} else \
        f"fe_transient_{'_'.join(sorted(only))}.json"
    (results / name).write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
