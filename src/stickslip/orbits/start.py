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

from ..errors import ContinuationError, OrbitError, SimulationError
from ..integrate.driver import check_samples, simulate
from ..integrate.result import Trajectory
from ..model.system_model import FrictionModel
from .models import ModelResult, parameter_value, resolve
from .section import Section, resolve_section, section_crossings
from .shooting import PeriodicOrbit, periodic_orbit

__all__ = ["start_run", "default_start", "crossings_per_stick", "start_orbit_from_run", "Start", "start_orbit", "START_RUN", "START_RATE"]

#: Length [s] and sample rate [Hz] of the run from the ``far`` initial condition that gives the
#: start orbit of each N (the stick-slip oscillation settles within ~20 s at Ω = 5 rad/s).
START_RUN, START_RATE = 60.0, 2000.0


def default_start(system: FrictionModel) -> str:
    """The start of an orbit search when none is given: the model's own first named start (the
    plates' ``far``), else ``zero``."""
    return next(iter(system.starts), "zero")


def start_run(model, ic=None, *, t_end: float = START_RUN, rtol: float = 1e-10,
              slip_band: float | None = None) -> Trajectory:
    """A run from a named initial condition, to hand to ``continue_orbit`` as ``start``.

    Parameters
    ----------
    model : FrictionModel, Parameters, str
        The model (as :func:`stickslip.simulate` takes it).
    ic : str, array-like (2n,) or mapping, optional
        A named start (``zero``, ``equilibrium``, ``near``, the model's own such as the plates'
        ``far``: :func:`stickslip.integrate.initial.start_names`) or a state as ``simulate``
        takes it; default :func:`default_start`.
    t_end : float
        Run length [s]; the orbit guess is taken from its last section crossings.
    rtol : float
        Integration tolerance (``atol`` = 1e-3 rtol).
    slip_band : float, optional
        Low-speed band of the slip direction [m/s] (default: the model's).
    """
    system = resolve(model, slip_band)
    ic = default_start(system) if ic is None else ic
    if t_end > 0 and t_end < float("inf"):  # its samples: refused by their length, the rate is ours
        check_samples(system, t_end, START_RATE, run="the start run (--search-time)", rate_settable=False)
    try:
        run = simulate(system, t_end, ic=ic, sample_rate=START_RATE, rtol=rtol, atol=1e-3 * rtol)
    except SimulationError as exc:
        raise ContinuationError(f"the start run from ic {ic!r} failed: {exc}") from exc
    if run.status != "success":
        raise ContinuationError(f"the start run from ic {ic!r} failed: {run.status}")
    return run


def crossings_per_stick(run: Trajectory, section="max") -> int:
    """Section crossings between the last two stick onsets of a run (≥ 1): the period
    multiplicity to shoot with when the orbit has one stick phase per period (at low N the
    stick-slip orbit of Model 1 has several maxima of φ per period). With several contacts the
    stick onsets of contact 0 count."""
    sec = resolve_section(section, run.system)
    tr = run.transitions
    onsets = tr.time[(tr.kind == 1) & (tr.contact == 0)]
    if onsets.size < 2:
        return 1
    times, _ = section_crossings(run.system, sec, run.t, run.states, run.mode)
    return max(int(np.sum((times > onsets[-2]) & (times <= onsets[-1]))), 1)


def start_orbit_from_run(run: Trajectory, *, section="max", rtol: float = 1e-10, atol: float | None = None,
                         slip_band: float | None = None) -> PeriodicOrbit:
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
    tr = run.transitions
    onsets = tr.time[(tr.kind == 1) & (tr.contact == 0)]
    span = float(onsets[-1] - onsets[-2]) if onsets.size >= 2 else 1.0
    cut_step = max(int(round(span / (run.t[1] - run.t[0]) / (4 * k))), 1)  # a quarter of a crossing interval
    error = None
    for cut in range(0, 4 * k + 1):
        m = run.t.size - cut * cut_step
        part = dataclasses.replace(run, t=run.t[:m], states=run.states[:m], mode=run.mode[:m])
        try:
            return periodic_orbit(None, part, section=section, rtol=rtol, atol=atol, period_multiplicity=k,
                                  slip_band=slip_band)
        except OrbitError as exc:
            error = exc
            if "crossed in stick" not in str(exc):
                break
    raise OrbitError(f"no stick-slip orbit from the run ({error})")


@dataclasses.dataclass(frozen=True, eq=False)
class Start(ModelResult):
    """What a branch keeps of its start orbit (journaled, so a resumed run needs no shooting)."""

    state: np.ndarray  # (2n,) on the section
    period: float  # [s]
    stick_phases: int
    scale: np.ndarray  # σ of the free states
    system: FrictionModel
    section: Section
    options: dict  # rtol, atol, slip_band

    @classmethod
    def of(cls, orbit: PeriodicOrbit) -> "Start":
        """The start of a periodic orbit."""
        o = orbit.options
        return cls(state=np.asarray(orbit.state, dtype=float), period=float(orbit.period),
                   stick_phases=int(orbit.stick_phases), scale=np.asarray(orbit.scale, dtype=float),
                   system=orbit.system, section=orbit.section,
                   options={"rtol": o["rtol"], "atol": o["atol"], "slip_band": o["slip_band"]})


def start_orbit(system: FrictionModel, param, start, section, rtol, atol) -> PeriodicOrbit:
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
            run = start if start.system is system else dataclasses.replace(start, system=system)
            return start_orbit_from_run(run, section=section, rtol=rtol, atol=atol)
        return periodic_orbit(system, start, section=section, rtol=rtol, atol=atol)
    except (OrbitError, SimulationError) as exc:
        raise ContinuationError(f"no periodic orbit to start from at {param} = {parameter_value(system, param):g}: "
                                f"{exc}") from exc
