"""Periodic orbits by shooting on a Poincaré section, with finite-difference Floquet multipliers.

Unknowns: the free states on the section except the one the section fixes (so the phase along
the flow is fixed by the section), and the return time T. Equations: Φ(s0, T) − s0 = 0 on the
free states, Φ the exact flow map of the ``event`` integrator (:func:`.section.flow`). This is
a square system (2 n_free equations, 2 n_free − 1 + 1 unknowns), solved by Newton with a
central finite-difference Jacobian of Φ (perturbed shooting: each column is two simulations,
so the jumps of the variational equations at stick↔slip transitions — the saltation matrices —
are contained in it implicitly) and the exact column ∂Φ/∂T = f(Φ) from the vector field.

At the converged orbit the full-state monodromy matrix ∂Φ/∂s0 (2 n_free × 2 n_free) is
computed from the variational equations with saltation matrices (:mod:`.variational`; default)
or differenced once more (``monodromy="finite-difference"``); its eigenvalues are the Floquet
multipliers. One of them is 1 (a shift along the orbit); stick phases collapse the directions
that violate v_r = 0, which gives multipliers 0.
"""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np

from .. import __version__
from ..integrate.driver import SimulationError, initial_state, simulate
from ..integrate.result import Trajectory
from ..model.kernels import DEFAULT_SLIP_BAND
from ..model.parameters import Parameters, parameter_attrs
from ..model.system import assemble
from ..model.variants import STATE_NAMES
from . import variational as _var
from .section import OrbitError, Section, flow, land_on_section, resolve_section, section_crossings, vector_field

__all__ = ["PeriodicOrbit", "periodic_orbit"]

_STATE_UNITS = ("m", "m", "m", "m", "rad", "rad", "m/s", "m/s", "m/s", "m/s", "rad/s", "rad/s")

#: Default convergence tolerance of Newton: max over free states of |Φ(s0, T) − s0| / σ, σ the
#: peak-to-peak range of each state over the guessed period. With rtol = 1e-10 the flow map
#: repeats to ~1e-10 σ (measured residuals at convergence 1e-11 … 1e-9), so 1e-8 is reachable
#: and still 1e-5 below the return-map resolution of :mod:`stickslip.analysis.classify`.
DEFAULT_TOL = 1e-8

#: Default relative finite-difference step (of σ). Central differences: truncation error
#: ~ step² (1e-10) and round-off/integration noise ~ rtol / step (1e-5 at rtol 1e-10), so the
#: Jacobian entries are good to ~1e-5, enough for Newton and for multipliers to ~1e-5 (docs/orbits.md).
DEFAULT_FD_STEP = 1e-5

#: Floor of the state scales σ, relative to the largest σ of the same kind (positions or
#: velocities): keeps a DOF that barely moves on the orbit from getting a perturbation below
#: the integration noise.
SCALE_FLOOR = 1e-4

#: Halvings of a Newton step that increases the residual, before giving up.
MAX_HALVINGS = 6

#: Samples per second of the search run that finds the first section crossings (≥ 100 per
#: period of the fastest free mode of Table 1, 0.36 s), and its length [s] when none is given.
SEARCH_RATE = 2000.0
SEARCH_TIME = 30.0


@dataclasses.dataclass(frozen=True, eq=False)
class PeriodicOrbit:
    """A periodic orbit found by :func:`periodic_orbit`.

    Attributes
    ----------
    state : ndarray (12,)
        State on the section, s = [q, q̇] [m, rad, m/s, rad/s].
    period : float
        Period T [s] (of ``multiplicity`` section returns).
    multiplicity : int
        Section crossings per period.
    stick_phases : int
        Slip → stick transitions per period (0: a pure-slip orbit).
    residual : float
        max |Φ(s0, T) − s0| / σ over the free states at the solution [-].
    iterations : int
        Newton iterations taken.
    residual_history : ndarray (iterations + 1,)
        Scaled residual before each iteration and at the end [-].
    multipliers : ndarray (2 n_free,) complex
        Floquet multipliers (eigenvalues of :attr:`monodromy`), by decreasing modulus [-].
    monodromy : ndarray (2 n_free, 2 n_free)
        ∂Φ(s0, T)/∂s0 on the free states, in SI units, by ``options["monodromy"]``
        (``"saltation"``: variational equations with jump matrices; ``"finite-difference"``).
    free_states : tuple of str
        Names of the free states (rows/columns of :attr:`monodromy`).
    scale : ndarray (2 n_free,)
        State scales σ used for residual and differences [SI units].
    params : Parameters
    model : str
    section : Section
    options : dict
        rtol, atol, tol, fd_step, slip_band, max_iter, monodromy (the method used).
    """

    state: np.ndarray
    period: float
    multiplicity: int
    stick_phases: int
    residual: float
    iterations: int
    residual_history: np.ndarray
    multipliers: np.ndarray
    monodromy: np.ndarray
    free_states: tuple
    scale: np.ndarray
    params: Parameters
    model: str
    section: Section
    options: dict

    @property
    def frequency(self) -> float:
        """Fundamental frequency 1/T [Hz]."""
        return 1.0 / self.period

    @property
    def trivial_multiplier(self) -> complex:
        """The multiplier closest to 1 (the shift along the orbit) [-]."""
        return complex(self.multipliers[np.argmin(np.abs(self.multipliers - 1.0))])

    @property
    def nontrivial_multipliers(self) -> np.ndarray:
        """All multipliers except :attr:`trivial_multiplier`, by decreasing modulus [-]."""
        k = int(np.argmin(np.abs(self.multipliers - 1.0)))
        return np.delete(self.multipliers, k)

    @property
    def stable(self) -> bool:
        """True if every non-trivial multiplier lies inside the unit circle."""
        return bool(np.all(np.abs(self.nontrivial_multipliers) < 1.0))

    def trajectory(self, periods: float = 1.0, sample_rate: float = 1000.0) -> Trajectory:
        """Simulate the orbit from its section state over ``periods`` periods (for plots)."""
        opt = self.options
        return simulate(self.params, periods * self.period, model=self.model, ic=self.state,
                        rtol=opt["rtol"], atol=opt["atol"], sample_rate=sample_rate, slip_band=opt["slip_band"])

    def to_xarray(self):
        """``xarray.Dataset``: section state, multipliers, monodromy; period etc. as attributes."""
        import xarray as xr

        data = {
            "state_on_section": ("state", self.state, {"long_name": "state on the Poincaré section",
                                                       "units": " ".join(_STATE_UNITS)}),
            "multiplier_real": ("multiplier", self.multipliers.real, {"long_name": "Floquet multiplier, real part", "units": "1"}),
            "multiplier_imag": ("multiplier", self.multipliers.imag, {"long_name": "Floquet multiplier, imaginary part", "units": "1"}),
            "multiplier_abs": ("multiplier", np.abs(self.multipliers), {"long_name": "Floquet multiplier modulus", "units": "1"}),
            "monodromy": (("free_state", "free_state_0"), self.monodromy,
                          {"long_name": f"monodromy matrix d s(T) / d s(0) on the free states ({self.options.get('monodromy', 'finite-difference')})",
                           "units": "SI"}),
            "scale": ("free_state", self.scale, {"long_name": "state scale sigma of residual and differences", "units": "SI"}),
            "residual_history": ("iteration", self.residual_history, {"long_name": "scaled Newton residual", "units": "1"}),
        }
        coords = {"state": list(STATE_NAMES), "free_state": list(self.free_states),
                  "free_state_0": list(self.free_states)}
        attrs = {
            "title": "stickslip periodic orbit (shooting on a Poincaré section)",
            "stickslip_version": __version__,
            "model": self.model,
            "section": self.section.name,
            "period": self.period, "period_units": "s",
            "frequency": self.frequency, "frequency_units": "Hz",
            "multiplicity": self.multiplicity,
            "stick_phases": self.stick_phases,
            "residual": self.residual,
            "iterations": self.iterations,
            "stable": int(self.stable),
            "options": json.dumps(self.options),
            "parameters": json.dumps(self.params.to_dict()),
        }
        attrs.update(parameter_attrs(self.params.to_dict()))
        return xr.Dataset(data, coords=coords, attrs=attrs)


def _guess_from_samples(params, model, system, section, t, states, mode, multiplicity, *, rtol, atol, slip_band):
    """Section state, period guess and scales from sampled data: the last ``multiplicity + 1``
    crossings; the first of them is landed on exactly by re-simulation."""
    times, idx = section_crossings(system, section, t, states, mode)
    if times.size < multiplicity + 1:
        raise OrbitError(
            f"the guess run crosses section {section.name} {times.size} times; need ≥ {multiplicity + 1} "
            f"for period_multiplicity = {multiplicity}. Give a longer guess run (search_time; `--search-time` "
            "on the command line) or another section"
        )
    c = times.size - 1 - multiplicity
    i = max(int(idx[c]) - 1, 0)  # start one sample early, so the landing time is ≥ one interval
    if mode[i] == 1 or mode[int(idx[c]) + 1] == 1:
        raise OrbitError(f"section {section.name} is crossed in stick; choose a section crossed in slip")
    T0 = float(times[c + multiplicity] - times[c])
    s0, _, miss = land_on_section(params, model, system, section, states[i], float(times[c] - t[i]),
                                  rtol=rtol, atol=atol, slip_band=slip_band)
    window = (t >= times[c]) & (t <= times[c + multiplicity])
    ptp = np.ptp(states[window], axis=0) if window.sum() > 1 else np.ptp(states, axis=0)
    return s0, T0, ptp, miss


def _scales(ptp: np.ndarray, free: np.ndarray) -> np.ndarray:
    """σ of the free states from their peak-to-peak range, floored per kind (see SCALE_FLOOR)."""
    sigma = ptp[free].astype(float).copy()
    n = free.size // 2
    for part in (slice(0, n), slice(n, 2 * n)):
        top = sigma[part].max()
        if top <= 0.0:
            raise OrbitError("the guess does not move: no oscillation to shoot from (is it the equilibrium?)")
        sigma[part] = np.maximum(sigma[part], SCALE_FLOOR * top)
    return sigma


def _monodromy(params, model, s0, T, free, cols, h, *, rtol, atol, slip_band):
    """Central-difference columns ∂Φ(s0, T)/∂s0[j] for j in ``cols`` (free-state rows)."""
    return _var.fd_monodromy(params, model, s0, T, free, h[free], rtol=rtol, atol=atol,
                             slip_band=slip_band, cols=cols)


def _newton_columns(params, model, s0, T, free, cols, h, sigma, method, opts):
    """∂Φ(s0, T)/∂s0 on the free rows and the ``cols`` columns, by ``method`` (saltation with a
    finite-difference fallback)."""
    if method == "saltation":
        try:
            return _var.flow_jacobian(params, model, s0, T, scale=sigma, **opts).matrix[np.ix_(free, cols)]
        except (OrbitError, SimulationError, ArithmeticError, np.linalg.LinAlgError):
            pass  # e.g. an iterate whose event sequence the re-integration does not reproduce
    return _monodromy(params, model, s0, T, free, cols, h, **opts)


def periodic_orbit(
    params: Parameters | None = None,
    guess=None,
    *,
    model="full",
    section="phi_max",
    period_multiplicity: int = 1,
    rtol: float = 1e-10,
    atol: float | None = None,
    tol: float = DEFAULT_TOL,
    max_iter: int = 20,
    fd_step: float = DEFAULT_FD_STEP,
    search_time: float = SEARCH_TIME,
    slip_band: float = DEFAULT_SLIP_BAND,
    monodromy: str = "saltation",
    newton_jacobian: str = "saltation",
) -> PeriodicOrbit:
    """Find a periodic orbit by Newton shooting on a Poincaré section.

    Parameters
    ----------
    params : Parameters, optional
        Physical parameters (default: those of ``guess`` if it is a Trajectory, else Table 1).
    guess : Trajectory, array-like (12,), or "equilibrium"/"zero"
        A Trajectory near the orbit (its last ``period_multiplicity + 1`` section crossings give
        the starting state and period), or an initial state from which a ``search_time`` run
        is made to find them.
    model : str
        Model variant (ignored when ``guess`` is a Trajectory: its model is used). Only its
        free DOFs are unknowns.
    section : "phi_max", ("phi", level) or Section
        Poincaré section: a maximum of φ (φ̇ = 0, φ̈ < 0; default) or an up-crossing of a level
        [rad] of a coordinate. It must be crossed in slip.
    period_multiplicity : int
        Section crossings per period (k for a period-k orbit of the return map).
    rtol, atol : float
        Integration tolerances of every flow map; ``atol`` defaults to 1e-3 · rtol (states of
        the paper's cases are ≥ 1e-4 in SI units on the orbit, so the absolute floor stays below
        the relative one).
    tol : float
        Convergence: max over free states of |Φ(s0, T) − s0| / σ ≤ tol, σ the peak-to-peak
        range of each state over the guessed period [-].
    max_iter : int
        Newton iteration cap.
    fd_step : float
        Finite-difference step relative to σ [-].
    search_time : float
        Length of the search run from a state guess [s].
    slip_band : float
        Low-speed band of the slip direction [m/s] (see :func:`stickslip.simulate`).
    monodromy : {"saltation", "finite-difference"}
        How the monodromy matrix of the converged orbit is computed: variational equations with
        saltation matrices (:func:`stickslip.orbits.variational.monodromy`; default; falls back
        to finite differences with a warning if the re-integration does not reproduce the
        orbit's event sequence), or central differences of the flow map.
    newton_jacobian : {"saltation", "finite-difference"}
        Jacobian ∂Φ/∂s0 of the Newton iteration: one variational integration (default; an
        iteration where it fails, e.g. because the iterate's event sequence differs from the
        integrator's, uses finite differences) or 2 (2 n_free − 1) flow maps.

    Returns
    -------
    PeriodicOrbit

    Raises
    ------
    OrbitError
        If no crossings are found, the section is crossed in stick, or Newton does not reach
        ``tol`` within ``max_iter`` iterations (the message gives the residual history).
    """
    if isinstance(guess, Trajectory):
        params = guess.params if params is None else params
        model = guess.model
    params = Parameters() if params is None else params
    k = int(period_multiplicity)
    if k < 1:
        raise OrbitError(f"period_multiplicity = {period_multiplicity} must be ≥ 1")
    if monodromy not in _var.METHODS:
        raise OrbitError(f"unknown monodromy method {monodromy!r}; use one of {_var.METHODS}")
    if newton_jacobian not in _var.METHODS:
        raise OrbitError(f"unknown newton_jacobian {newton_jacobian!r}; use one of {_var.METHODS}")
    atol = 1e-3 * rtol if atol is None else float(atol)
    sec = resolve_section(section)
    system = assemble(params, model, slip_band)
    model = system.variant.name
    free_dofs = system.variant.free_indices
    free = np.concatenate([free_dofs, free_dofs + 6])
    if sec.index not in free:
        raise OrbitError(f"section {sec.name} fixes {STATE_NAMES[sec.index]}, which is locked in model {model!r}")
    opts = dict(rtol=rtol, atol=atol, slip_band=slip_band)

    if guess is None:
        raise OrbitError("give a guess: a Trajectory near the orbit or an initial state")
    if not isinstance(guess, Trajectory):
        try:
            s_init = initial_state(system, guess)
        except SimulationError as exc:
            raise OrbitError(f"bad guess: {exc}") from exc
        guess = simulate(params, search_time, model=model, ic=s_init, sample_rate=SEARCH_RATE, **opts)
        if guess.status != "success":
            raise OrbitError(f"the search run failed: {guess.status}")
    s0, T, ptp, _ = _guess_from_samples(params, model, system, sec, guess.t, guess.states, guess.mode, k, **opts)
    sigma = _scales(ptp, free)
    h = np.zeros(12)
    h[free] = fd_step * sigma
    cols = [j for j in free if j != sec.index]

    def residual(s, T):
        end, tr = flow(params, model, s, T, **opts)
        return (end[free] - s[free]) / sigma, end, tr

    R, end, tr = residual(s0, T)
    history = [float(np.max(np.abs(R)))]
    it = 0
    while history[-1] > tol:
        if it >= max_iter:
            raise OrbitError(
                f"Newton did not converge in {max_iter} iterations (scaled residuals "
                f"{', '.join(f'{r:.2e}' for r in history)}; tol {tol:.1e}). The orbit may be "
                "non-periodic, or the guess too far: give a guess closer to the orbit or raise max_iter"
            )
        A = np.empty((free.size, free.size))
        A[:, :-1] = _newton_columns(params, model, s0, T, free, cols, h, sigma, newton_jacobian, opts)
        A[:, :-1] -= np.eye(free.size)[:, [list(free).index(j) for j in cols]]
        A[:, :-1] *= sigma[[list(free).index(j) for j in cols]][None, :]  # unknowns in σ units
        A[:, :-1] /= sigma[:, None]
        A[:, -1] = vector_field(system, end)[free] / sigma
        step = np.linalg.lstsq(A, -R, rcond=None)[0]
        lam = 1.0
        for _ in range(MAX_HALVINGS + 1):
            s_new = s0.copy()
            for c_i, j in enumerate(cols):
                s_new[j] += lam * step[c_i] * sigma[list(free).index(j)]
            T_new = T + lam * step[-1]
            try:
                R_new, end_new, tr_new = residual(s_new, T_new)
            except (OrbitError, SimulationError):
                lam *= 0.5
                continue
            if np.max(np.abs(R_new)) < history[-1]:
                break
            lam *= 0.5
        else:
            raise OrbitError(
                f"Newton step {it + 1} does not reduce the residual (history "
                f"{', '.join(f'{r:.2e}' for r in history)}); the guess is too far or the orbit is not isolated"
            )
        s0, T, R, end, tr = s_new, T_new, R_new, end_new, tr_new
        history.append(float(np.max(np.abs(R))))
        it += 1

    method = monodromy
    if method == "saltation":
        try:
            M = _var.flow_jacobian(params, model, s0, T, scale=sigma, **opts).matrix[np.ix_(free, free)]
        except (OrbitError, SimulationError, ArithmeticError, np.linalg.LinAlgError) as exc:
            warnings.warn(f"saltation monodromy failed ({exc}); using finite differences", RuntimeWarning,
                          stacklevel=2)
            method = "finite-difference"
    if method == "finite-difference":
        M = _monodromy(params, model, s0, T, free, list(free), h, **opts)
    mult = _var.sorted_eigenvalues(M)
    sticks = int(np.sum(tr.kind == 1))
    return PeriodicOrbit(
        state=s0, period=float(T), multiplicity=k, stick_phases=sticks, residual=history[-1],
        iterations=it, residual_history=np.array(history), multipliers=mult, monodromy=M,
        free_states=tuple(STATE_NAMES[j] for j in free), scale=sigma, params=params, model=model,
        section=sec, options=dict(opts, tol=tol, fd_step=fd_step, max_iter=max_iter, monodromy=method,
                                  newton_jacobian=newton_jacobian),
    )
