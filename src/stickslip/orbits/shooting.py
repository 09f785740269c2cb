"""Periodic orbits by shooting on a Poincaré section, with their Floquet multipliers.

Unknowns: the free states on the section except the one the section fixes (so the phase along
the flow is fixed by the section), and the return time T. Equations: Φ(s0, T) − s0 = 0 on the
free states, Φ the exact flow map of the ``event`` integrator (:func:`.section.flow`). This is
a square system (2 n_free equations, 2 n_free − 1 + 1 unknowns): the shooting problem of
:class:`.problem.ShootingProblem`, solved by its Newton iteration with ∂Φ/∂s0 from the
variational equations with saltation matrices (default) or from central differences of Φ
(perturbed shooting: each column is two simulations, so the jumps of the variational equations
at stick↔slip transitions are contained in it implicitly), and the exact column ∂Φ/∂T = f(Φ)
from the vector field. The guess — the section state, the period and the scales σ — comes from
the last section crossings of a run.

At the converged orbit the full-state monodromy matrix ∂Φ/∂s0 (2 n_free × 2 n_free) is
computed from the variational equations with saltation matrices (:mod:`.linear_flow`; default)
or differenced once more (``monodromy="finite-difference"``); its eigenvalues are the Floquet
multipliers. One of them is 1 (a shift along the orbit); stick phases collapse the directions
that violate v_c = 0, which gives multipliers 0. Every model the simulator runs has its orbits:
the states are the model's ``state_names``, the unknowns its free states.
"""
from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np

from .._version import __version__
from ..errors import OrbitError, SimulationError, SteadySlidingOrbitError
from ..integrate.driver import simulate
from ..integrate.initial import initial_state, rigid_gaps
from ..integrate.result import Trajectory
from ..model.library import two_plates
from ..model.parameters import Parameters
from ..model.system_model import DEFAULT_SLIP_BAND, FrictionModel
from .layout import independent_states, is_steady_sliding
from .models import ModelResult, model_attrs, resolve
from .problem import (DEFAULT_FD_STEP, DEFAULT_TOL, MAX_HALVINGS, SCALE_FLOOR, Multipliers, ShootingProblem,
                      check_method, check_section, multiplier_variables, scales, sorted_eigenvalues, stick_count)
from .section import Section, land_on_section, resolve_section, section_crossings

__all__ = ["PeriodicOrbit", "periodic_orbit", "DEFAULT_TOL", "DEFAULT_FD_STEP", "MAX_HALVINGS", "SCALE_FLOOR"]

#: Samples per second of the search run that finds the first section crossings (≥ 100 per
#: period of the fastest free mode of Table 1, 0.36 s), and its length [s] when none is given.
SEARCH_RATE = 2000.0
SEARCH_TIME = 30.0


@dataclasses.dataclass(frozen=True, eq=False)
class PeriodicOrbit(ModelResult, Multipliers):
    """A periodic orbit found by :func:`periodic_orbit`.

    Parameters
    ----------
    state : ndarray (2n,)
        State on the section, s = [q, q̇] (the model's ``state_names``).
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
        ∂Φ(s0, T)/∂s0 on the free states, in the states' units, by ``options["monodromy"]``
        (``"saltation"``: variational equations with jump matrices; ``"finite-difference"``).
    free_states : tuple of str
        Names of the free states (rows/columns of :attr:`monodromy`).
    scale : ndarray (2 n_free,)
        State scales σ used for residual and differences [state units].
    system : FrictionModel
        The model (``params`` and ``model``: the plates' Parameters and variant, or None and the name).
    section : Section
        The Poincaré section the orbit's state lies on (:class:`stickslip.orbits.section.Section`:
        the state fixed and its value, the direction of crossing).
    options : dict
        rtol, atol, tol, fd_step, slip_band, max_iter, monodromy (the method used),
        newton_jacobian.
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
    system: FrictionModel
    section: Section
    options: dict

    @property
    def frequency(self) -> float:
        """Fundamental frequency 1/T [Hz]."""
        return 1.0 / self.period

    def trajectory(self, periods: float = 1.0, sample_rate: float = 1000.0) -> Trajectory:
        """Simulate the orbit from its section state over ``periods`` periods (for plots)."""
        opt = self.options
        return simulate(self.system, periods * self.period, ic=self.state, rtol=opt["rtol"], atol=opt["atol"],
                        sample_rate=sample_rate)

    def to_xarray(self):
        """``xarray.Dataset``: section state, multipliers, monodromy; period etc. as attributes."""
        import xarray as xr

        data = {
            "state_on_section": ("state", self.state, {"long_name": "state on the Poincaré section",
                                                       "units": " ".join(self.system.state_units)}),
            **multiplier_variables(self.multipliers, "multiplier"),
            "monodromy": (("free_state", "free_state_0"), self.monodromy,
                          {"long_name": f"monodromy matrix d s(T) / d s(0) on the free states ({self.options.get('monodromy', 'finite-difference')})",
                           }),
            "scale": ("free_state", self.scale, {"long_name": "state scale sigma of residual and differences"}),
            "residual_history": ("iteration", self.residual_history, {"long_name": "scaled Newton residual", "units": "1"}),
        }
        coords = {"state": list(self.system.state_names), "free_state": list(self.free_states),
                  "free_state_0": list(self.free_states)}
        attrs = {
            "title": "stickslip periodic orbit (shooting on a Poincaré section)",
            "stickslip_version": __version__,
            "section": self.section.name,
            "period": self.period, "period_units": "s",
            "frequency": self.frequency, "frequency_units": "Hz",
            "multiplicity": self.multiplicity,
            "stick_phases": self.stick_phases,
            "residual": self.residual,
            "iterations": self.iterations,
            "stable": int(self.stable),
            "options": json.dumps(self.options),
            **model_attrs(self.system),
        }
        return xr.Dataset(data, coords=coords, attrs=attrs)


def _guess_from_samples(system, section, t, states, mode, multiplicity, *, rtol, atol):
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
    sticking = (1 << system.n_contacts) - 1  # the stick bits of mode (the others flag open contacts)
    if mode[i] & sticking or mode[int(idx[c]) + 1] & sticking:
        raise OrbitError(f"section {section.name} is crossed in stick; choose a section crossed in slip")
    T0 = float(times[c + multiplicity] - times[c])
    s0, _, miss = land_on_section(system, section, states[i], float(times[c] - t[i]), rtol=rtol, atol=atol)
    window = (t >= times[c]) & (t <= times[c + multiplicity])
    ptp = np.ptp(states[window], axis=0) if window.sum() > 1 else np.ptp(states, axis=0)
    return s0, T0, ptp, miss


def _check_on_constraint(system, constraint, end) -> None:
    """Refuse an orbit whose run leaves the rigid contacts that are closed on its section open at
    its end (the eliminated states then do not return: not a periodic orbit)."""
    if constraint is None:
        return
    opened = [system.contact_names[c] for c, g, _, tol in rigid_gaps(system, end) if c in constraint.contacts
              and g[0] > tol[0]]
    if opened:
        raise OrbitError(f"shooting converged onto a state whose run ends with rigid contact {', '.join(opened)} "
                         "open, closed on the section: not a periodic orbit; choose a section crossed in a flight "
                         "('<dof>_max' of the dof that opens the gap)")


def _orbit_model(model, guess, slip_band) -> FrictionModel:
    """The model of :func:`periodic_orbit`: ``model``, by default a Trajectory ``guess``'s; the
    plates' Parameters with a run of the plates take the run's variant."""
    if isinstance(guess, Trajectory) and model is None:
        return guess.system.with_slip_band(guess.system.slip_band if slip_band is None else slip_band)
    if isinstance(guess, Trajectory) and isinstance(model, Parameters) and "variant" in guess.system.parameters:
        band = DEFAULT_SLIP_BAND if slip_band is None else slip_band
        return two_plates(model, guess.system.parameters["variant"], band).with_slip_band(band)
    return resolve(model, slip_band)


def _orbit_monodromy(problem, orbit, method: str) -> tuple[np.ndarray, str]:
    """(M, method used): the converged orbit's monodromy matrix, by saltation matrices (finite
    differences, with a warning, where that integration fails) or by finite differences."""
    if method == "saltation":
        try:
            M, _ = problem.monodromy(orbit.state, orbit.period, method)
            return M, method
        except (OrbitError, SimulationError, ArithmeticError, np.linalg.LinAlgError) as exc:
            warnings.warn(f"saltation monodromy failed ({exc}); using finite differences", RuntimeWarning,
                          stacklevel=3)
            method = "finite-difference"
    M, _ = problem.monodromy(orbit.state, orbit.period, method)
    return M, method


def periodic_orbit(
    model=None,
    guess=None,
    *,
    section="max",
    period_multiplicity: int = 1,
    rtol: float = 1e-10,
    atol: float | None = None,
    tol: float = DEFAULT_TOL,
    max_iter: int = 20,
    fd_step: float = DEFAULT_FD_STEP,
    search_time: float = SEARCH_TIME,
    slip_band: float | None = None,
    monodromy: str = "saltation",
    newton_jacobian: str = "saltation",
    steady_sliding: str = "refuse",
) -> PeriodicOrbit:
    """Find a periodic orbit by Newton shooting on a Poincaré section.

    Parameters
    ----------
    model : FrictionModel, Parameters, str, optional
        The model, as :func:`stickslip.simulate` takes it: a FrictionModel, a library name or model
        file, or the plates' Parameters. With a Trajectory ``guess`` the default is the run's model,
        and the plates' Parameters take the run's variant (new parameters for the run's plates);
        otherwise the default is the plates with Table 1. Only its free DOFs are unknowns.
    guess : Trajectory, array-like (2n,), mapping, or "equilibrium"/"zero"
        A Trajectory near the orbit (its last ``period_multiplicity + 1`` section crossings give
        the starting state and period), or an initial state (:func:`stickslip.integrate.driver.initial_state`)
        from which a ``search_time`` run is made to find them.
    section : "max", "<dof>_max", (dof, level) or Section
        Poincaré section: a maximum of the model's observed dof (its velocity through 0 downwards;
        the plates' φ, default), of a named dof, or an up-crossing of a level of a dof. It must be
        crossed in slip.
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
    slip_band : float, optional
        Low-speed band of the slip direction [m/s] (default: the model's; see :func:`stickslip.simulate`).
    monodromy : {"saltation", "finite-difference"}
        How the monodromy matrix of the converged orbit is computed: variational equations with
        saltation matrices (:func:`stickslip.orbits.monodromy`; default; falls back
        to finite differences with a warning if the re-integration does not reproduce the
        orbit's event sequence), or central differences of the flow map.
    newton_jacobian : {"saltation", "finite-difference"}
        Jacobian ∂Φ/∂s0 of the Newton iteration: one variational integration (default; an
        iteration where it fails, e.g. because the iterate's event sequence differs from the
        integrator's, uses finite differences) or 2 (2 n_free − 1) flow maps.
    steady_sliding : {"refuse", "keep"}
        What to do where Newton converged onto steady sliding (no stick phase, within the orbit
        size of the equilibrium: a fixed point that any period fits, not a cycle): raise
        :class:`SteadySlidingOrbitError` (default), or return it as found.

    Returns
    -------
    PeriodicOrbit

    Raises
    ------
    OrbitError
        If no crossings are found, the section is crossed in stick, or Newton does not reach
        ``tol`` within ``max_iter`` iterations (the message gives the residual history).
    SteadySlidingOrbitError
        If Newton converged onto steady sliding (an OrbitError), with ``steady_sliding="refuse"``.
    """
    system = _orbit_model(model, guess, slip_band)
    k = int(period_multiplicity)
    if k < 1:
        raise OrbitError(f"period_multiplicity = {period_multiplicity} must be ≥ 1")
    check_method(monodromy)
    check_method(newton_jacobian, "newton_jacobian")
    if steady_sliding not in ("refuse", "keep"):
        raise OrbitError(f"steady_sliding = {steady_sliding!r}: use 'refuse' or 'keep'")
    atol = 1e-3 * rtol if atol is None else float(atol)
    sec = resolve_section(section, system)
    check_section(sec, system)
    opts = dict(rtol=rtol, atol=atol)

    if guess is None:
        raise OrbitError("give a guess: a Trajectory near the orbit or an initial state")
    if not isinstance(guess, Trajectory):
        try:
            s_init = initial_state(system, guess)
        except SimulationError as exc:
            raise OrbitError(f"bad guess: {exc}") from exc
        guess = simulate(system, search_time, ic=s_init, sample_rate=SEARCH_RATE, **opts)
        if guess.status != "success":
            raise OrbitError(f"the search run failed: {guess.status}")
    s0, T, ptp, _ = _guess_from_samples(system, sec, guess.t, guess.states, guess.mode, k, **opts)
    free, constraint = independent_states(system, s0)
    problem = ShootingProblem.build(system, sigma=scales(ptp, free), section=sec, fd_step=fd_step,
                                    constraint=constraint, **opts)
    orbit = problem.newton(problem.complete(s0), T, tol=tol, max_iter=max_iter, method=newton_jacobian)
    _check_on_constraint(system, constraint, orbit.end)
    stick_phases = stick_count(orbit.transitions)
    if steady_sliding == "refuse" and is_steady_sliding(system, orbit.state, problem.free, problem.sigma, stick_phases):
        raise SteadySlidingOrbitError(
            f"shooting converged onto steady sliding (no stick phase, {orbit.period:.6g} s being any period of the "
            "equilibrium), not a cycle: start from a state on the cycle or from a run that has reached it")
    M, method = _orbit_monodromy(problem, orbit, monodromy)
    return PeriodicOrbit(
        state=orbit.state, period=orbit.period, multiplicity=k, stick_phases=stick_phases,
        residual=orbit.history[-1], iterations=orbit.iterations, residual_history=np.array(orbit.history),
        multipliers=sorted_eigenvalues(M), monodromy=M, free_states=tuple(system.state_names[j] for j in problem.free),
        scale=problem.sigma, system=system, section=sec,
        options=dict(opts, slip_band=system.slip_band, tol=tol, fd_step=fd_step, max_iter=max_iter, monodromy=method,
                     newton_jacobian=newton_jacobian),
    )
