"""The evidence tables of docs/fe.md: dense against sparse CEA on one ~2,000-DOF model, modal
CEA converging to the full sparse result as modes are added, and Beck's column's flutter onset
against the published one as its elements are refined.

The model: tests/fe/brake_models.pad_on_strip_2d (a plane-stress pad of 30 × 8 elements pressed
on a strip of 120 × 5 elements clamped at its ends; 31 node pairs on compliant contacts with
Coulomb friction μ = 0.3; light stiffness damping β = 1e-6 s): 1,955 DOFs.

1. ``dense``: every eigenvalue of the linearisation by LAPACK (dense B⁻¹A, 3,910 states), kept in
   the band (|Im λ| ≤ ω_max inside the disc |λ| ≤ R that the sparse path searches), against the
   sparse direct CEA of the band (shift-invert Arnoldi): the same count, and the largest relative
   distance from each sparse eigenvalue to the nearest dense one and back.
2. ``modal``: modal CEA with cutoffs of 1.5, 2 and 4 ω_max: the projection's eigenvalues on the
   first m real modes, with the residual vectors of the contact rows and without them, against
   the full sparse ones (each full eigenvalue from its nearest approximation).
3. ``beck``: Beck's column (tests/fe/beck_column.py) of 4 to 1,024 beam elements, its flutter
   onset located by Brent's method on the CEA's eigenvalues, against Beck's published 20.05 EI/L²
   and the continuum's exact onset.

    python benchmarks/fe_cea_evidence.py [--part dense|modal|beck|all] [--write-docs]

(``dense`` takes a few minutes: the dense eigenvalues of 3,910 states.) Writes
benchmarks/results/fe_cea_evidence_<part>.json and prints the tables as Markdown; with
``--write-docs`` it puts them into docs/fe.md between the markers ``<!-- fe_cea_evidence:PART -->``
and ``<!-- /fe_cea_evidence:PART -->`` (the numbers there are this script's, never typed).
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from fe.beck_column import BECK_DIGITS, BECK_LOAD, continuum_onset, flutter_onset  # noqa: E402
from fe.brake_models import pad_on_strip_2d  # noqa: E402

from stickslip.stability.band import band_stability  # noqa: E402
from stickslip.stability.cea import DENSE_STATES, REAL_MARGIN, dense_eigen  # noqa: E402
from stickslip.stability.sparse_sliding import sparse_steady_sliding  # noqa: E402

OMEGA = 2 * math.pi * 60e3  # the band's top [rad/s]
CUTOFFS = (1.5, 2.0, 4.0)  # modal CEA's cutoffs / ω_max
BECK_MESHES = (4, 8, 16, 32, 64, 128, 256, 1024)  # beam elements of Beck's column


def nearest(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a_i − nearest b| / |a_i|."""
    return float(max(np.min(np.abs(b - x)) / abs(x) for x in a))


def dense_part(model) -> tuple[dict, str]:
    """Dense LAPACK against the sparse direct CEA of the band."""
    state = sparse_steady_sliding(model)
    t = time.perf_counter()
    lam = dense_eigen(state)[0]
    dense_s = time.perf_counter() - t
    radius = OMEGA * math.sqrt(1.0 + REAL_MARGIN**2)  # the band: |Im λ| ≤ ω_max inside the disc |λ| ≤ R
    reference = lam[(np.abs(lam.imag) <= OMEGA) & (np.abs(lam) <= radius)]
    t = time.perf_counter()
    direct = band_stability(model, OMEGA)
    direct_s = time.perf_counter() - t
    out = {"dofs": state.n, "contacts": int(model.nc), "max_frequency": OMEGA, "dense_s": dense_s,
           "direct_s": direct_s, "dense_in_band": int(reference.size), "direct_in_band": int(direct.eigenvalues.size),
           "sparse_to_dense": nearest(direct.eigenvalues, reference),
           "dense_to_sparse": nearest(reference, direct.eigenvalues),
           "max_real_part": direct.max_real_part, "max_backward_error": float(direct.backward_error.max())}
    table = ("| DOFs | eigenvalues in the band (dense / sparse) | max rel. distance sparse → dense | dense → sparse "
             "| dense [s] | sparse [s] |\n|---|---|---|---|---|---|\n"
             f"| {state.n} | {reference.size} / {direct.eigenvalues.size} | {out['sparse_to_dense']:.1e} | "
             f"{out['dense_to_sparse']:.1e} | {dense_s:.0f} | {direct_s:.1f} |\n")
    return out, table


def modal_part(model) -> tuple[dict, str]:
    """Modal CEA's convergence with and without the residual vectors, at each cutoff."""
    direct = band_stability(model, OMEGA)
    size = direct.eigenvalues.size
    out = {"dofs": len(model.dofs), "max_frequency": OMEGA, "in_band": int(size), "modal": []}
    lines = ["| cutoff / ω_max | modes | highest mode / ω_max | residual vectors | max relative error | within 1e-2 "
             "| modes alone: max relative error | within 1e-2 |", "|---|---|---|---|---|---|---|---|"]
    for factor in CUTOFFS:
        t = time.perf_counter()
        result = band_stability(model, OMEGA, method="modal", cutoff=factor * OMEGA)
        seconds = time.perf_counter() - t
        assert nearest(result.eigenvalues, direct.eigenvalues) < 1e-8  # the refined eigenvalues are the full ones
        for row in result.modal.convergence:
            lines.append(f"| {factor:g} | {row['modes']} | {row['highest_mode'] / OMEGA:.2f} | "
                         f"{row['residual_vectors']} | {row['max_relative_error']:.2e} | {row['found']} / {size} | "
                         f"{row['modes_only_error']:.2e} | {row['modes_only_found']} / {size} |")
        out["modal"].append({"cutoff_factor": factor, "seconds": seconds, "convergence": result.modal.convergence})
    return out, "\n".join(lines) + "\n"


def beck_part(_model) -> tuple[dict, str]:
    """Beck's column's onset load and frequency per mesh against Beck's 20.05 and the continuum."""
    exact_load, exact_frequency = continuum_onset()
    lines = ["| elements | DOFs | eigenvalues | P_c L²/EI | to Beck's digits | P_c − exact | Ω_c L² √(m/EI) | "
             "Ω_c − exact | [s] |", "|---|---|---|---|---|---|---|---|---|"]
    out = {"beck_load": BECK_LOAD, "exact_load": exact_load, "exact_frequency": exact_frequency, "meshes": []}
    for elements in BECK_MESHES:
        start = time.perf_counter()
        load, frequency, _ = flutter_onset(elements)
        seconds = time.perf_counter() - start
        path = "dense" if 4 * elements <= DENSE_STATES else "Arnoldi"
        within = "20.05" if abs(load - BECK_LOAD) <= BECK_DIGITS else f"{load:.2f}"
        lines.append(f"| {elements} | {2 * elements} | {path} | {load:.9f} | {within} | {load - exact_load:.2e} | "
                     f"{frequency:.7f} | {frequency - exact_frequency:.2e} | {seconds:.1f} |")
        out["meshes"].append({"elements": elements, "load": load, "frequency": frequency, "seconds": seconds})
    lines.append(f"| continuum (exact) | | | {exact_load:.9f} | 20.05 | | {exact_frequency:.7f} | | |")
    return out, "\n".join(lines) + "\n"


def write_docs(part: str, table: str) -> None:
    """Replace the table between ``<!-- fe_cea_evidence:PART -->`` and its closing marker in docs/fe.md."""
    path = ROOT / "docs" / "fe.md"
    text = path.read_text()
    pattern = re.compile(rf"(<!-- fe_cea_evidence:{part} -->\n).*?(<!-- /fe_cea_evidence:{part} -->)", re.DOTALL)
    if not pattern.search(text):
        raise SystemExit(f"docs/fe.md has no markers <!-- fe_cea_evidence:{part} --> … "
                         f"<!-- /fe_cea_evidence:{part} -->")
    path.write_text(pattern.sub(lambda m: m.group(1) + table + m.group(2), text))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", choices=("dense", "modal", "beck", "all"), default="all")
    parser.add_argument("--write-docs", action="store_true", help="put the tables into docs/fe.md")
    args = parser.parse_args()
    model = pad_on_strip_2d(mu=0.3, beta=1e-6)
    folder = ROOT / "benchmarks" / "results"
    folder.mkdir(exist_ok=True)
    for part, run in (("dense", dense_part), ("modal", modal_part), ("beck", beck_part)):
        if args.part not in (part, "all"):
            continue
        out, table = run(model)
        print(table)
        (folder / f"fe_cea_evidence_{part}.json").write_text(json.dumps(out, indent=2))
        if args.write_docs:
            write_docs(part, table)


if __name__ == "__main__":
    main()
