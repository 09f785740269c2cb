"""The evidence tables of docs/fe.md: dense against sparse CEA on one ~2,000-DOF model, and modal
CEA converging to the full sparse result as modes are added.

The model: tests/fe/brake_models.pad_on_strip_2d (a plane-stress pad of 30 × 8 elements pressed
on a strip of 120 × 5 elements clamped at its ends; 31 node pairs on compliant contacts with
Coulomb friction μ = 0.3; light stiffness damping β = 1e-6 s): 1,955 DOFs.

1. Every eigenvalue of the linearisation by LAPACK (dense B⁻¹A, 3,910 states), kept in the band
   (|Im λ| ≤ ω_max inside the disc |λ| ≤ R that the sparse path searches), against the sparse
   direct CEA of the band (shift-invert Arnoldi): the same count, and the largest relative
   distance from each sparse eigenvalue to the nearest dense one and back.
2. Modal CEA with cutoffs of 1.5, 2 and 4 ω_max: the projection's eigenvalues on the first m
   real modes against the full sparse ones (each full eigenvalue from its nearest approximation).

    python benchmarks/fe_cea_evidence.py      (a few minutes: the dense eigenvalues of 3,910 states)

Writes benchmarks/results/fe_cea_evidence.json and prints the tables as Markdown.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from fe.brake_models import pad_on_strip_2d  # noqa: E402

from stickslip.stability.band import band_stability  # noqa: E402
from stickslip.stability.cea import REAL_MARGIN, dense_eigen  # noqa: E402
from stickslip.stability.sparse_sliding import sparse_steady_sliding  # noqa: E402

OMEGA = 2 * math.pi * 60e3  # the band's top [rad/s]


def nearest(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a_i − nearest b| / |a_i|."""
    return float(max(np.min(np.abs(b - x)) / abs(x) for x in a))


def main() -> None:
    model = pad_on_strip_2d(mu=0.3, beta=1e-6)
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
           "max_real_part": direct.max_real_part, "max_backward_error": float(direct.backward_error.max()),
           "modal": []}
    print(f"| DOFs | eigenvalues in the band (dense / sparse) | max rel. distance sparse→dense | dense→sparse | "
          f"dense s | sparse s |\n|---|---|---|---|---|---|\n| {state.n} | {reference.size} / "
          f"{direct.eigenvalues.size} | {out['sparse_to_dense']:.1e} | {out['dense_to_sparse']:.1e} | {dense_s:.0f} | "
          f"{direct_s:.1f} |\n")
    print("| cutoff / ω_max | modes | highest mode / ω_max | max relative error | within 1e-2 |\n|---|---|---|---|---|")
    for factor in (1.5, 2.0, 4.0):
        result = band_stability(model, OMEGA, method="modal", cutoff=factor * OMEGA)
        assert nearest(result.eigenvalues, direct.eigenvalues) < 1e-8  # the refined eigenvalues are the full ones
        for row in result.modal.convergence:
            print(f"| {factor:g} | {row['modes']} | {row['highest_mode'] / OMEGA:.2f} | "
                  f"{row['max_relative_error']:.2e} | {row['found']} / {direct.eigenvalues.size} |")
        out["modal"].append({"cutoff_factor": factor, "convergence": result.modal.convergence})
    folder = ROOT / "benchmarks" / "results"
    folder.mkdir(exist_ok=True)
    (folder / "fe_cea_evidence.json").write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
