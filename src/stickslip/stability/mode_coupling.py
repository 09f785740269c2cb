"""The mode-coupling diagram: the band's eigenvalues against the friction coefficient.

For each μ of a sweep, every contact's kinetic coefficient μk is set to μ and the band's
eigenvalues are computed on the full model (:func:`~stickslip.stability.band.band_stability`).
The eigenvalues with Im λ ≥ 0 are followed from one μ to the next as branches (an assignment that
minimises the total distance, scipy's ``linear_sum_assignment``), so that two frequencies that
approach and merge as μ grows — mode coupling — show as two branches meeting, one of which then
leaves the imaginary axis with Re λ > 0.

The *onset* of each such instability is where a branch's real part crosses 0 upwards: located on
the μ grid and then by Brent's method on μ (each evaluation a CEA of the full model) to
:data:`ONSET_XTOL`; its *partner* is the branch nearest in frequency there (the coalescing pair).
Computing only: the figure is :func:`stickslip.plot.fe.plot_mode_coupling`.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from .._version import __version__
from ..results import Plottable
from .band import band_stability
from .sparse_input import sparse_form

__all__ = ["ModeCoupling", "mode_coupling", "with_friction", "ONSET_XTOL"]

#: Absolute tolerance of an onset's μ (Brent's method).
ONSET_XTOL = 1e-10

#: A real part counts as positive above this fraction of |λ| (round-off of an undamped model's 0).
GROWTH_TOL = 1e-9


def with_friction(form, mu: float):
    """The sparse form with every contact's kinetic coefficient μk set to ``mu``."""
    laws = tuple(dataclasses.replace(law, mu_k=float(mu)) for law in form.friction)
    return dataclasses.replace(form, friction=laws)


@dataclasses.dataclass(frozen=True, eq=False)
class ModeCoupling(Plottable):
    """The band's eigenvalues against μ, in branches, with the instabilities' onsets.

    Attributes
    ----------
    model : str
    mu : ndarray (p,)
        The friction coefficients [-].
    eigenvalues : ndarray (p, b) complex
        Branch j's eigenvalue at mu[i] (Im λ ≥ 0; NaN where the branch is not in the band) [1/s].
    max_frequency : float
        The band's top [rad/s].
    onsets : list of dict
        ``mu``, ``angular_frequency``, ``branch``, ``partner`` of each crossing of Re λ = 0 upwards.
    """

    FIGURE = "mode_coupling"

    model: str
    mu: np.ndarray
    eigenvalues: np.ndarray
    max_frequency: float
    onsets: list

    @property
    def unstable(self) -> np.ndarray:
        """(p, b) bool: Re λ > 0 beyond round-off (:data:`GROWTH_TOL` |λ|)."""
        with np.errstate(invalid="ignore"):
            return self.eigenvalues.real > GROWTH_TOL * np.abs(self.eigenvalues)

    @property
    def critical_mu(self) -> float | None:
        """The lowest onset's μ (None: stable over the sweep)."""
        return min((o["mu"] for o in self.onsets), default=None)

    def to_xarray(self):
        """``xarray.Dataset``: growth rates and angular frequencies (mu, branch), onsets in attrs."""
        import xarray as xr

        data = {"growth_rate": (("mu", "branch"), self.eigenvalues.real, {"units": "1/s", "long_name": "Re(lambda)"}),
                "angular_frequency": (("mu", "branch"), self.eigenvalues.imag,
                                      {"units": "rad/s", "long_name": "Im(lambda)"})}
        attrs = {"title": "stickslip mode-coupling diagram", "stickslip_version": __version__, "model": self.model,
                 "max_frequency": self.max_frequency, "onsets": json.dumps(self.onsets)}
        return xr.Dataset(data, coords={"mu": self.mu, "branch": np.arange(self.eigenvalues.shape[1])}, attrs=attrs)


def _track(columns: list[np.ndarray]) -> np.ndarray:
    """Eigenvalue lists per μ → branches (p, b), each step matched by least total distance."""
    from scipy.optimize import linear_sum_assignment

    width = max(c.size for c in columns)
    out = np.full((len(columns), width), np.nan + 1j * np.nan)
    first = np.sort_complex(columns[0])
    out[0, :first.size] = first
    for i in range(1, len(columns)):
        prev, cur = out[i - 1], columns[i]
        known = np.flatnonzero(np.isfinite(prev))
        cost = np.abs(prev[known][:, None] - cur[None, :])
        rows, cols = linear_sum_assignment(cost)
        out[i, known[rows]] = cur[cols]
        rest = np.setdiff1d(np.arange(cur.size), cols)  # eigenvalues new to the band: the free branches
        out[i, np.flatnonzero(~np.isfinite(out[i]))[:rest.size]] = cur[rest]
    return out


def _upper(model, mu: float, max_frequency: float, method: str) -> np.ndarray:
    lam = band_stability(with_friction(model, mu), max_frequency, method=method).eigenvalues
    return lam[lam.imag >= 0.0]


def _onsets(form, mu, branches, max_frequency, method, xtol) -> list[dict]:
    """Each upward crossing of Re λ = 0 by a branch, refined by Brent's method on max Re λ nearby."""
    from scipy.optimize import brentq

    growth = branches.real / np.abs(branches)
    out = []
    for j in range(branches.shape[1]):
        for i in range(mu.size - 1):
            a, b = growth[i, j], growth[i + 1, j]
            if not (np.isfinite(a) and np.isfinite(b) and a <= GROWTH_TOL < b):
                continue
            target = branches[i + 1, j]

            def rate(m, target=target):
                lam = _upper(form, m, max_frequency, method)
                near = lam[np.argmin(np.abs(lam - target))]
                return near.real / abs(near) - GROWTH_TOL

            lo, hi = float(mu[i]), float(mu[i + 1])
            critical = brentq(rate, lo, hi, xtol=xtol) if rate(lo) < 0.0 < rate(hi) else hi
            lam = _upper(form, critical, max_frequency, method)
            at = lam[np.argmin(np.abs(lam - target))]
            others = branches[i + 1].imag.copy()
            others[j] = np.nan
            partner = int(np.nanargmin(np.abs(others - at.imag))) if np.any(np.isfinite(others)) else None
            out.append({"mu": critical, "angular_frequency": float(at.imag), "branch": j, "partner": partner})
    return out


def mode_coupling(model, mu, max_frequency: float, *, method: str = "direct", xtol: float = ONSET_XTOL
                  ) -> ModeCoupling:
    """The band's eigenvalues against the friction coefficient (module docstring).

    Parameters
    ----------
    model : FrictionModel or SparseForm
        A model with constant contact kinematics (every contact's μk is set to each value).
    mu : sequence of float
        Increasing friction coefficients [-].
    max_frequency : float
        The band's top [rad/s].
    method : {"direct", "modal", "dense"}
        The CEA of each point (:func:`~stickslip.stability.band.band_stability`).
    xtol : float
        Absolute tolerance of the onsets' μ (each step of the root finding is one CEA).

    Raises
    ------
    BandError, EquilibriumError
        As :func:`~stickslip.stability.band.band_stability`, at the first μ where it fails.
    ValueError
        For μ values that are not increasing and ≥ 0.
    """
    mu = np.asarray(mu, dtype=float)
    if mu.ndim != 1 or mu.size < 2 or not np.all(np.diff(mu) > 0) or mu[0] < 0:
        raise ValueError("mu must hold at least 2 increasing values >= 0")
    form = sparse_form(model)
    branches = _track([_upper(form, m, max_frequency, method) for m in mu])
    return ModeCoupling(model=form.name, mu=mu, eigenvalues=branches, max_frequency=float(max_frequency),
                        onsets=_onsets(form, mu, branches, max_frequency, method, xtol))
