"""Every library model's results, bit for bit, against those of another revision of the code.

A refactoring of the compiled layer must leave every number the same. ``--save FILE`` runs a fixed
set of computations (``simulate`` of every library model with its states, transitions and step
counts; AEOM and NAEOM on the plates; the eigenvalues of steady sliding and a small stability
map; periodic orbits with Floquet multipliers of the plates, the belt and an impacting model; a
short continuation branch; a Lyapunov spectrum; a basins run of the belt) and writes every array
to an ``.npz`` file; ``--compare FILE`` runs the same with the code at hand and reports each array
that is not ``np.array_equal`` to the saved one (exit 1 if any).

Run ``--save`` with the code before the change (a checkout of the baseline revision on
``PYTHONPATH``), ``--compare`` after it. The saved file is a local check, not a committed
reference: it is produced by the code under test.

    PYTHONPATH=/path/to/baseline/src python benchmarks/bitwise.py --save /tmp/before.npz
    python benchmarks/bitwise.py --compare /tmp/before.npz [--only simulate,orbits]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RIGID_SLIDER = ROOT / "tests" / "contacts" / "rigid_slider.toml"
LIBRARY = ["two-plates", "belt", "hoffmann", "popp-stelter", "impact-oscillator", "slider-belt", "sprag-slip"]


def _trajectory(out: dict, key: str, run) -> None:
    out[f"{key}.t"] = run.t
    out[f"{key}.states"] = run.states
    out[f"{key}.mode"] = run.mode
    out[f"{key}.friction"] = run.friction
    tr = run.transitions
    out[f"{key}.tr.time"] = tr.time
    out[f"{key}.tr.kind"] = tr.kind
    out[f"{key}.tr.state"] = tr.state
    if tr.contact is not None:
        out[f"{key}.tr.contact"] = tr.contact
    st = run.stats
    out[f"{key}.stats"] = np.array([st.accepted_steps, st.rejected_steps, st.rhs_calls, st.retaken_steps,
                                    st.slip_to_stick, st.stick_to_slip])
    out[f"{key}.status"] = np.array(run.status)


def simulate_all(out: dict) -> None:
    import stickslip
    from stickslip.model.library import two_plates

    for name in LIBRARY:
        model = stickslip.load_model(name)
        _trajectory(out, f"simulate.{name}", stickslip.simulate(model, 60.0, sample_rate=50.0))
    rotation = two_plates(stickslip.Parameters(), "rotation")
    _trajectory(out, "simulate.plates-rotation", stickslip.simulate(rotation, 60.0, sample_rate=50.0))
    plates = stickslip.load_model("two-plates").replace(N=50.0, Omega=5.0)
    _trajectory(out, "simulate.plates-dense", stickslip.simulate(plates, 20.0, sample_rate=1000.0))
    slider = stickslip.load_model(RIGID_SLIDER)
    _trajectory(out, "simulate.rigid-slider", stickslip.simulate(slider, 60.0, rtol=1e-11, atol=1e-13,
                                                                 sample_rate=10.0))


def fixed_step(out: dict) -> None:
    import stickslip

    plates = stickslip.load_model("two-plates").replace(N=50.0, Omega=5.0)
    for method in ("aeom", "naeom"):
        _trajectory(out, f"fixed.{method}", stickslip.simulate(plates, 10.0, method=method, dt=1e-4,
                                                                sample_rate=100.0))
        low = stickslip.load_model("two-plates").replace(N=50.0, Omega=0.5)
        _trajectory(out, f"fixed.{method}.stickslip", stickslip.simulate(low, 20.0, method=method, dt=1e-3,
                                                                          sample_rate=100.0))


def stability(out: dict) -> None:
    import stickslip
    from stickslip.stability import stability_map

    for name in ("two-plates", "belt", "hoffmann", "popp-stelter"):
        res = stickslip.stability(stickslip.load_model(name))
        out[f"stability.{name}.eigenvalues"] = np.asarray(res.eigenvalues)
        out[f"stability.{name}.jacobian"] = np.asarray(res.jacobian)
    m = stability_map(stickslip.load_model("belt"), [0.5, 1.0, 2.0], [0.5, 1.5, 2.5],
                      axes=("contact.0.normal_force", "contact.0.drive"), boundary=False)
    out["stability.map.belt"] = np.asarray(m.to_xarray()["max_real_part"].values)


def _orbit(out: dict, key: str, orbit) -> None:
    out[f"{key}.state"] = orbit.state
    out[f"{key}.period"] = np.array(orbit.period)
    out[f"{key}.multipliers"] = np.asarray(orbit.multipliers)
    out[f"{key}.monodromy"] = np.asarray(orbit.monodromy)


def orbits(out: dict) -> None:
    import stickslip
    from stickslip.model.library import two_plates
    from stickslip.model.parameters import Parameters
    from stickslip.orbits import monodromy
    from stickslip.orbits.continuation import continue_orbit

    plates = two_plates(Parameters(N=50.0, Omega=0.5), "full")
    orbit = stickslip.periodic_orbit(plates, "equilibrium", search_time=30.0)
    _orbit(out, "orbit.plates", orbit)
    fd = monodromy(orbit, "finite-difference")
    out["orbit.plates.fd"] = np.asarray(fd.matrix)
    belt = stickslip.load_model("belt")
    _orbit(out, "orbit.belt", stickslip.periodic_orbit(belt, {"x": 0.0, "dx": 1.0}, search_time=60.0))
    popp = stickslip.load_model("popp-stelter")
    _orbit(out, "orbit.popp", stickslip.periodic_orbit(popp, {"x1": 0.5, "x2": -0.5}, search_time=200.0,
                                                        section="x2_max"))
    slider = stickslip.load_model(RIGID_SLIDER)
    _orbit(out, "orbit.rigid-slider", stickslip.periodic_orbit(slider, {"x": 1.0, "y": 0.05}, section="y_max",
                                                               search_time=60.0))
    phi = two_plates(Parameters(c_pphi=0.0, Omega=0.5, friction_law="coulomb"), "phi")
    ic = np.zeros(12)
    ic[10] = 0.5
    start = stickslip.periodic_orbit(phi, ic, search_time=3.0)
    branch = continue_orbit(start=start, param="Omega", step=0.05, max_step=0.2, max_points=5, bounds=(0.5, 2.0),
                            amplitude=False)
    for name in ("values", "periods", "states", "multipliers", "residuals", "iterations", "arclength"):
        out[f"branch.{name}"] = np.asarray(getattr(branch, name))
    spectrum = stickslip.lyapunov_spectrum(plates, ic=orbit.state, t_transient=1.0, t_average=20.0)
    out["lyapunov.exponents"] = np.asarray(spectrum.exponents)
    out["lyapunov.estimate"] = np.asarray(spectrum.to_xarray()["estimate"].values)


def basins(out: dict) -> None:
    from stickslip.basins import basin_stability, box
    from stickslip.model.library import load_model

    belt = load_model("belt")
    res = basin_stability(belt, box(belt, {"x": (-2.0, 2.0), "dx": (0.0, 2.0)}, n=24, seed=3), t_end=200.0,
                          executor="serial")
    ds = res.to_xarray()
    for name in ds.data_vars:
        if "wall_time" in name:  # seconds, not results
            continue
        values = ds[name].values
        if values.dtype.kind in "fiub":
            out[f"basins.{name}"] = values
        elif values.dtype.kind in "OUS":
            out[f"basins.{name}"] = values.astype(str)


GROUPS = {"simulate": simulate_all, "fixed": fixed_step, "stability": stability, "orbits": orbits,
          "basins": basins}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--save", type=Path)
    what.add_argument("--compare", type=Path)
    parser.add_argument("--only", default=",".join(GROUPS), help="comma-separated groups: " + ", ".join(GROUPS))
    args = parser.parse_args()
    out: dict = {}
    for group in args.only.split(","):
        start = time.perf_counter()
        GROUPS[group](out)
        print(f"{group}: {time.perf_counter() - start:.1f} s", file=sys.stderr)
    if args.save:
        np.savez(args.save, **out)
        print(f"saved {len(out)} arrays to {args.save}")
        return 0
    saved = np.load(args.compare)
    differ = []
    for key, value in out.items():
        if key not in saved.files:
            differ.append(f"{key}: not in {args.compare}")
        elif not np.array_equal(saved[key], value, equal_nan=value.dtype.kind in "fc"):
            differ.append(f"{key}: differs")
    for line in differ:
        print(line)
    print(f"{len(out) - len(differ)} of {len(out)} arrays bit for bit the same")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
