"""Poincaré sections and the exact flow map used by the shooting method.

A section is one state coordinate at a fixed value crossed in one direction:

* ``"phi_max"``: φ̇ = 0 with φ̈ < 0 (a maximum of φ, a down-crossing of φ̇ through 0);
* ``("phi", level)``: an up-crossing of φ through ``level`` [rad] (φ̇ > 0).

The flow map Φ(s, T) is :func:`stickslip.simulate` with the ``event`` integrator from s over
exactly T seconds: the run is asked for samples at the rate 1/T' with T' = 1/(1/T) (T to one
ulp), so that its last sample is the integration end itself and ``final_state`` is Φ(s, T'),
not a dense-output sample before it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import StickSlipError
from ..analysis.steady import _hermite_crossings
from ..integrate.driver import simulate
from ..model import kernels as K
from ..model.system import System
from .layout import KERNEL_STATE, N_DOFS, N_STATES, PHI_DOT, STATE_NAMES, velocity_of

__all__ = ["Section", "resolve_section", "OrbitError", "flow", "vector_field", "section_crossings"]


class OrbitError(StickSlipError, RuntimeError):
    """A periodic orbit or Lyapunov exponent could not be computed (the message says why)."""


@dataclasses.dataclass(frozen=True)
class Section:
    """A Poincaré section g(s) = direction · (s[index] − value) = 0, crossed with dg/dt > 0.

    Attributes
    ----------
    index : int
        State index (:data:`stickslip.STATE_NAMES` order) fixed on the section.
    value : float
        Its value on the section [m, rad, m/s or rad/s].
    direction : int
        +1: up-crossing of ``s[index]``; −1: down-crossing.
    name : str
        Human-readable label.
    """

    index: int
    value: float
    direction: int
    name: str

    def g(self, s: np.ndarray) -> float:
        """Section function of one state (N_STATES,); zero on the section, increasing through it."""
        return self.direction * (float(s[self.index]) - self.value)


def resolve_section(section) -> Section:
    """Turn ``"phi_max"``, ``("phi", level)`` or a :class:`Section` into a :class:`Section`."""
    if isinstance(section, Section):
        return section
    if isinstance(section, str) and section == "phi_max":
        return Section(index=PHI_DOT, value=0.0, direction=-1, name="phi_max")
    if isinstance(section, tuple) and len(section) == 2 and section[0] in STATE_NAMES[:N_DOFS]:
        j = STATE_NAMES.index(section[0])
        level = float(section[1])
        return Section(index=j, value=level, direction=1, name=f"{section[0]}={level:g} up")
    raise OrbitError(
        f"unknown section {section!r}; use 'phi_max' (phi maximum), ('phi', level) (up-crossing "
        "of a phi level [rad]) or a stickslip.orbits.Section"
    )


def vector_field(system: System, s: np.ndarray, mode: int = K.MODE_SLIP_EXACT) -> np.ndarray:
    """ds/dt (N_STATES,) at state ``s`` in ``mode`` (slip with the exact direction v_r/|v_r| by default)."""
    y = np.zeros(KERNEL_STATE)  # inline, not kernel_state(): called once per sample by section_crossings
    y[:N_STATES] = s
    ds = np.zeros(KERNEL_STATE)
    vx, vy = K.relative_velocity(y, system.p)
    speed = float(np.hypot(vx, vy))
    ex, ey = (vx / speed, vy / speed) if speed > 0.0 else (1.0, 0.0)
    K.rhs(y, int(mode), ex, ey, system.minv, system.damp, system.stiff, system.p, ds)
    return ds[:N_STATES].copy()


def flow(params, model, s0: np.ndarray, T: float, *, rtol: float, atol: float, slip_band: float,
         max_steps: int | None = None):
    """Φ(s0, T): the state after exactly T seconds, and the run's transitions.

    ``max_steps`` caps the integrator's steps (None: the driver's default): a stalled integration
    then fails fast instead of running for minutes.

    Returns
    -------
    state : ndarray (N_STATES,)
    transitions : stickslip.integrate.result.Transitions

    Raises
    ------
    OrbitError
        If T ≤ 0 or the run did not finish.
    """
    if not np.isfinite(T) or T <= 0.0:
        raise OrbitError(f"return time T = {T} s is not positive; the Newton iteration left the orbit")
    rate = 1.0 / T
    T_exact = 1.0 / rate  # the last sample time the driver will compute, so it lands on t_end
    cap = {} if max_steps is None else {"max_steps": int(max_steps)}
    traj = simulate(params, T_exact, model=model, ic=s0, rtol=rtol, atol=atol, sample_rate=rate,
                    slip_band=slip_band, **cap)
    if traj.status != "success" or traj.t[-1] != T_exact:
        raise OrbitError(f"the flow map over T = {T} s failed: {traj.status}")
    return traj.final_state, traj.transitions


def _state_rates(system: System, states: np.ndarray, mode: np.ndarray, index: int) -> np.ndarray:
    """d s[index]/dt at each sample (n,): a state for positions, the vector field for velocities."""
    if index < N_DOFS:
        return states[:, velocity_of(index)].copy()
    out = np.empty(states.shape[0])
    for i in range(states.shape[0]):
        m = K.MODE_STICK if mode[i] == 1 else K.MODE_SLIP_EXACT
        out[i] = vector_field(system, states[i], m)[index]
    return out


def section_crossings(system: System, section: Section, t, states, mode):
    """Crossings of the section in uniformly sampled data, on the cubic Hermite interpolant.

    Parameters
    ----------
    system : System
    section : Section
    t : ndarray (n,)
        Sample times [s].
    states : ndarray (n, N_STATES)
    mode : ndarray (n,) int8
        1 in stick.

    Returns
    -------
    times : ndarray (k,)
        Crossing instants [s], fourth-order accurate in the sample interval.
    index : ndarray (k,) int
        Sample interval [t[i], t[i+1]] of each crossing.
    """
    g = section.direction * (states[:, section.index] - section.value)
    dg = section.direction * _state_rates(system, states, mode, section.index)
    return _hermite_crossings(np.asarray(t, dtype=float), g, dg, 0.0)


#: Newton corrections of the crossing time when landing exactly on the section: the Hermite
#: guess is fourth-order accurate in the sample interval, so two corrections reach round-off.
LANDING_ITERATIONS = 4


def land_on_section(params, model, system: System, section: Section, s_before: np.ndarray, dt: float,
                    *, rtol: float, atol: float, slip_band: float):
    """Integrate from ``s_before`` exactly onto the section, starting from the guess ``dt`` [s].

    Newton on the crossing time with dg/dt from the vector field; each iterate re-simulates from
    ``s_before``. Returns (state on the section (N_STATES,), time from ``s_before`` [s], |g| before
    the coordinate is set to the section value [unit of the coordinate]).
    """
    s = s_before
    for _ in range(LANDING_ITERATIONS):
        s, _tr = flow(params, model, s_before, dt, rtol=rtol, atol=atol, slip_band=slip_band)
        g = section.g(s)
        dg = section.direction * vector_field(system, s)[section.index]
        if dg <= 0.0:
            raise OrbitError(f"the flow does not cross section {section.name} transversally at t = {dt} s")
        dt = dt - g / dg
    s, _tr = flow(params, model, s_before, dt, rtol=rtol, atol=atol, slip_band=slip_band)
    miss = abs(section.g(s))
    s = s.copy()
    s[section.index] = section.value
    return s, dt, miss
