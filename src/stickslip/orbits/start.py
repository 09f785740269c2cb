"""The first orbit of a branch: a run from a named initial condition and the orbit it settled on.

:func:`start_run` simulates from ``far``, ``near``, ``zero`` or ``equilibrium``;
:func:`start_orbit_from_run` shoots the stick-slip orbit that run reached, with one stick onset
per period (:func:`crossings_per_stick` section crossings: at low N the orbit of Model 1 has
several maxima of φ a period). :func:`continue_orbit <stickslip.orbits.branch.continue_orbit>`
keeps of its start what :class:`Start` holds, journaled so that a resumed run needs no shooting.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..integrate.driver import SimulationError, simulate
from ..integrate.result import Trajectory
from ..model.kernels import DEFAULT_SLIP_BAND
from ..model.parameters import Parameters
from ..model.system import assemble
from .arclength import ContinuationError
from .section import OrbitError, Section, resolve_section, section_crossings
from .shooting import PeriodicOrbit, periodic_orbit

__all__ = ["start_run", "crossings_per_stick", "start_orbit_from_run", "Start", "start_orbit", "START_RUN", "START_RATE"]

#: Length [s] and sample rate [Hz] of the run from the ``far`` initial condition that gives the
#: start orbit of each N (the stick-slip oscillation settles within ~20 s at Ω = 5 rad/s).
START_RUN, START_RATE = 60.0, 2000.0


def start_run(params: Parameters, ic: str = "far", *, model: str = "full", t_end: float = START_RUN,
              rtol: float = 1e-10, slip_band: float = DEFAULT_SLIP_BAND) -> Trajectory:
    """A run from a named initial condition, to hand to ``continue_orbit`` as ``start``.

    Parameters
    ----------
    params : Parameters
    ic : str
        ``far``, ``near``, ``zero`` or ``equilibrium`` (:data:`stickslip.sweep.NAMED_ICS`).
    model : str
    t_end : float
        Run length [s]; the orbit guess is taken from its last section crossings.
    rtol : float
        Integration tolerance (``atol`` = 1e-3 rtol).
    slip_band : float
        Low-speed band of the slip direction [m/s] (see :func:`stickslip.simulate`).
    """
    from ..sweep.spec import initial_condition

    state, pert = initial_condition(ic, params, model)
    run = simulate(params, t_end, model=model, ic=state, perturbation=pert, sample_rate=START_RATE,
                   rtol=rtol, atol=1e-3 * rtol, slip_band=slip_band)
    if run.status != "success":
        raise ContinuationError(f"the start run from ic {ic!r} failed: {run.status}")
    return run


def crossings_per_stick(run: Trajectory, section="phi_max") -> int:
    """Section crossings between the last two stick onsets of a run (≥ 1): the period
    multiplicity to shoot with when the orbit has one stick phase per period (at low N the
    stick-slip orbit of Model 1 has several maxima of φ per period)."""
    sec = resolve_section(section)
    onsets = run.transitions.time[run.transitions.kind == 1]
    if onsets.size < 2:
        return 1
    system = assemble(run.params, run.model)
    times, _ = section_crossings(system, sec, run.t, run.states, run.mode)
    return max(int(np.sum((times > onsets[-2]) & (times <= onsets[-1]))), 1)


def start_orbit_from_run(run: Trajectory, *, section="phi_max", rtol: float = 1e-10, atol: float | None = None,
                         slip_band: float = DEFAULT_SLIP_BAND) -> PeriodicOrbit:
    """Shoot the stick-slip orbit a run has settled on, with one stick onset per period.

    The period multiplicity is :func:`crossings_per_stick`. Where some section crossings lie in
    stick, the run is cut back one sample period at a time (up to one orbit period) until the
    first crossing used by :func:`~stickslip.orbits.periodic_orbit` lies in slip.

    Raises
    ------
    OrbitError
        If no cut gives a converged orbit.
    """
    k = crossings_per_stick(run, section)
    onsets = run.transitions.time[run.transitions.kind == 1]
    span = float(onsets[-1] - onsets[-2]) if onsets.size >= 2 else 1.0
    cut_step = max(int(round(span / (run.t[1] - run.t[0]) / (4 * k))), 1)  # a quarter of a crossing interval
    error = None
    for cut in range(0, 4 * k + 1):
        m = run.t.size - cut * cut_step
        part = dataclasses.replace(run, t=run.t[:m], states=run.states[:m], mode=run.mode[:m])
        try:
            return periodic_orbit(run.params, part, section=section, rtol=rtol, atol=atol, period_multiplicity=k,
                                  slip_band=slip_band)
        except OrbitError as exc:
            error = exc
            if "crossed in stick" not in str(exc):
                break
    raise OrbitError(f"no stick-slip orbit from the run ({error})")


@dataclasses.dataclass(frozen=True, eq=False)
class Start:
    """What a branch keeps of its start orbit (journaled, so a resumed run needs no shooting)."""

    state: np.ndarray  # (N_STATES,) on the section [SI]
    period: float  # [s]
    stick_phases: int
    scale: np.ndarray  # σ of the free states [SI]
    params: Parameters
    model: str
    section: Section
    options: dict  # rtol, atol, slip_band

    @classmethod
    def of(cls, orbit: PeriodicOrbit) -> "Start":
        """The start of a periodic orbit."""
        o = orbit.options
        return cls(state=np.asarray(orbit.state, dtype=float), period=float(orbit.period),
                   stick_phases=int(orbit.stick_phases), scale=np.asarray(orbit.scale, dtype=float),
                   params=orbit.params, model=orbit.model, section=orbit.section,
                   options={"rtol": o["rtol"], "atol": o["atol"], "slip_band": o["slip_band"]})


def start_orbit(params, param, start, model, section, rtol, atol, slip_band) -> PeriodicOrbit:
    """The periodic orbit ``start`` is, or that a run ``start`` settled on, or that shooting from
    the state ``start`` finds (the ``start`` argument of ``continue_orbit``).

    Raises
    ------
    ContinuationError
        If no orbit is found (naming the parameter value).
    """
    if isinstance(start, PeriodicOrbit):
        return start
    try:
        if isinstance(start, Trajectory):  # one stick onset per period (several φ maxima at low N)
            run = start if start.params == params else dataclasses.replace(start, params=params)
            return start_orbit_from_run(run, section=section, rtol=rtol, atol=atol, slip_band=slip_band)
        return periodic_orbit(params, start, model=model, section=section, rtol=rtol, atol=atol, slip_band=slip_band)
    except (OrbitError, SimulationError) as exc:
        raise ContinuationError(f"no periodic orbit to start from at {param} = {getattr(params, param):g}: {exc}") from exc
