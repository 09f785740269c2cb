"""How far a reduced model's steady-sliding eigenvalues are from the full model's, over a band."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..stability.band import BandStability, band_stability

__all__ = ["ReductionReport", "reduction_report"]


@dataclasses.dataclass(frozen=True, eq=False)
class ReductionReport:
    """The full and the reduced model's eigenvalues of a band, paired.

    Attributes
    ----------
    full, reduced : BandStability
        The two models' band analyses (both on their full pencils).
    errors : ndarray (m,)
        For each eigenvalue of the full model with Im λ ≥ 0: |λ_r − λ| / |λ| to the nearest eigenvalue
        of the reduced model.
    """

    full: BandStability
    reduced: BandStability
    errors: np.ndarray

    @property
    def max_error(self) -> float:
        return float(np.max(self.errors, initial=0.0))

    def rows(self) -> list[dict]:
        """One row per eigenvalue of the full model with Im λ ≥ 0: full, nearest reduced, relative error."""
        full = self.full.eigenvalues[self.full.eigenvalues.imag >= 0.0]
        out = []
        for lam, err in zip(full, self.errors):
            near = self.reduced.eigenvalues[np.argmin(np.abs(self.reduced.eigenvalues - lam))]
            out.append({"full": [float(lam.real), float(lam.imag)], "reduced": [float(near.real), float(near.imag)],
                        "relative_error": float(err)})
        return out

    def summary(self) -> dict:
        return {"max_frequency": self.full.max_frequency, "max_relative_error": self.max_error,
                "full_max_real_part": self.full.max_real_part, "reduced_max_real_part": self.reduced.max_real_part,
                "eigenvalues": self.rows()}


def reduction_report(full_model, reduced_model, max_frequency: float) -> ReductionReport:
    """Every eigenvalue of both models with |Im λ| ≤ ``max_frequency`` [rad/s] (each on its full
    pencil, :func:`~stickslip.stability.band.band_stability`), and the reduced one's relative error."""
    full = band_stability(full_model, max_frequency)
    reduced = band_stability(reduced_model, max_frequency * 1.2)  # its eigenvalues just past the band pair too
    lam = full.eigenvalues[full.eigenvalues.imag >= 0.0]
    errors = np.array([np.min(np.abs(reduced.eigenvalues - x)) / abs(x) for x in lam])
    return ReductionReport(full=full, reduced=reduced, errors=errors)
