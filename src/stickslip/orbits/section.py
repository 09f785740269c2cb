"""Poincaré sections and the exact flow map used by the shooting method, for any model.

A section is one state coordinate at a fixed value crossed in one direction:

* ``"max"``: a maximum of the model's observed dof (its velocity down-crossing 0); ``"<dof>_max"``
  the same for a named dof (``"phi_max"`` for the plates' φ, the default there);
* ``(dof, level)``: an up-crossing of a dof through ``level`` (its velocity > 0).

The flow map Φ(s, T) is :func:`stickslip.simulate` with the ``event`` integrator from s over
exactly T seconds: the run is asked for samples at the rate 1/T' with T' = 1/(1/T) (T to one
ulp), so that its last sample is the integration end itself and ``final_state`` is Φ(s, T'),
not a dense-output sample before it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..analysis.signal import hermite_crossings
from ..errors import OrbitError
from ..integrate.driver import simulate
from ..model import physics as P
from ..model.bundle import CST, contact_state
from ..analysis.modes import sample_flags

__all__ = ["Section", "resolve_section", "OrbitError", "flow", "vector_field", "section_crossings"]


@dataclasses.dataclass(frozen=True)
class Section:
    """A Poincaré section g(s) = direction · (s[index] − value) = 0, crossed with dg/dt > 0.

    Attributes
    ----------
    index : int
        State index (the model's ``state_names`` order) fixed on the section.
    value : float
        Its value on the section [the state's unit].
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
        """Section function of one state (2n,); zero on the section, increasing through it."""
        return self.direction * (float(s[self.index]) - self.value)


def resolve_section(section, system) -> Section:
    """Turn ``"max"``, ``"<dof>_max"``, ``(dof, level)`` or a :class:`Section` into a :class:`Section`
    of ``system`` (a FrictionModel)."""
    if isinstance(section, Section):
        return section
    dofs = system.dofs
    if isinstance(section, str) and (section == "max" or (section.endswith("_max") and section[:-4] in dofs)):
        dof = dofs[system.observed_index] if section == "max" else section[:-4]
        return Section(index=system.n + dofs.index(dof), value=0.0, direction=-1, name=f"{dof}_max")
    if isinstance(section, tuple) and len(section) == 2 and section[0] in dofs:
        level = float(section[1])
        return Section(index=dofs.index(section[0]), value=level, direction=1, name=f"{section[0]}={level:g} up")
    raise OrbitError(
        f"unknown section {section!r}; use 'max' (maximum of {dofs[system.observed_index]}), '<dof>_max', "
        f"(dof, level) (up-crossing of a level) with a dof of {', '.join(dofs)}, or a stickslip.orbits.Section"
    )


def modes_at(system, s: np.ndarray, stick_flags: int | None = None) -> np.ndarray:
    """Contact states at ``s``: the contacts whose bit c is set in ``stick_flags`` stick, those
    whose bit n_contacts + c is set are open, the others slip with the exact direction
    v_c/|v_c| (a Trajectory's ``mode`` gives the flags). Without flags every contact slips but
    the unilateral ones whose gap is positive at ``s``, which are open."""
    md = system.data
    nc = system.n_contacts
    cst = contact_state(md.m)
    if stick_flags is None:
        y = np.ascontiguousarray(s[:2 * system.n], dtype=float)
        stick_flags = sum(1 << (nc + c) for c, contact in enumerate(system.contacts)
                          if contact.unilateral and P.gap(y, c, md)[0] > 0.0)
    for c in range(nc):
        if (int(stick_flags) >> (nc + c)) & 1:
            cst[CST * c] = P.MODE_OPEN
            continue
        if (int(stick_flags) >> c) & 1:
            cst[CST * c] = P.MODE_STICK
            continue
        v0, v1 = P.slip_velocity(np.ascontiguousarray(s[:2 * system.n], dtype=float), c, md)
        speed = float(np.hypot(v0, v1))
        cst[CST * c] = P.MODE_SLIP_EXACT
        if speed > 0.0:
            cst[CST * c + 1] = v0 / speed
            cst[CST * c + 2] = v1 / speed
    return cst


def vector_field(system, s: np.ndarray, stick_flags: int | None = None) -> np.ndarray:
    """ds/dt (2n,) at state ``s`` (:func:`modes_at`: slip with the exact direction, unilateral
    contacts open where their gap is positive, by default)."""
    y = np.ascontiguousarray(s[:2 * system.n], dtype=float)
    ds = np.zeros(2 * system.n)
    P.rhs(y, modes_at(system, y, stick_flags), system.data, ds)
    return ds


def flow(system, s0: np.ndarray, T: float, *, rtol: float, atol: float, max_steps: int | None = None):
    """Φ(s0, T): the state after exactly T seconds, and the run's transitions.

    ``max_steps`` caps the integrator's steps (None: the driver's default): a stalled integration
    then fails fast instead of running for minutes.

    Returns
    -------
    state : ndarray (2n,)
    transitions : stickslip.integrate.result.Transitions

    Raises
    ------
    OrbitError
        If T ≤ 0 or the run did not finish.
    """
    if not np.isfinite(T) or T <= 0.0:
        raise OrbitError(f"return time T = {T} s is not positive; the Newton iteration left the orbit: choose another "
                         "Poincaré section (section=, --section on the command line), one the cycle crosses once "
                         "per period in a smooth phase, e.g. the highest point of a flight ('y_max' for a gap y)")
    rate = 1.0 / T
    T_exact = 1.0 / rate  # the last sample time the driver will compute, so it lands on t_end
    cap = {} if max_steps is None else {"max_steps": int(max_steps)}
    traj = simulate(system, T_exact, ic=s0, rtol=rtol, atol=atol, sample_rate=rate, **cap)
    if traj.status != "success" or traj.t[-1] != T_exact:
        raise OrbitError(f"the flow map over T = {T} s failed: {traj.status}")
    return traj.final_state, traj.transitions


def _state_rates(system, states: np.ndarray, mode: np.ndarray, index: int, where: np.ndarray) -> np.ndarray:
    """d s[index]/dt at the samples ``where`` (k,; NaN elsewhere): a velocity for positions, the
    vector field for velocities."""
    if index < system.n:
        return states[:, index + system.n].copy()
    out = np.full(states.shape[0], np.nan)
    for i in where:
        out[i] = vector_field(system, states[i], sample_flags(mode[i]))[index]
    return out


def section_crossings(system, section: Section, t, states, mode):
    """Crossings of the section in uniformly sampled data, on the cubic Hermite interpolant.

    Parameters
    ----------
    system : FrictionModel
    section : Section
    t : ndarray (k,)
        Sample times [s].
    states : ndarray (k, 2n)
    mode : ndarray (k,) int8
        Stick flags of the samples (bit c: contact c sticks).

    Returns
    -------
    times : ndarray (m,)
        Crossing instants [s], fourth-order accurate in the sample interval.
    index : ndarray (m,) int
        Sample interval [t[i], t[i+1]] of each crossing.
    """
    g = section.direction * (states[:, section.index] - section.value)
    up = np.flatnonzero((g[:-1] < 0.0) & (g[1:] >= 0.0))  # the intervals whose ends need the rate
    dg = section.direction * _state_rates(system, states, mode, section.index, np.union1d(up, up + 1))
    return hermite_crossings(np.asarray(t, dtype=float), g, dg, 0.0)


#: Newton corrections of the crossing time when landing exactly on the section: the Hermite
#: guess is fourth-order accurate in the sample interval, so two corrections reach round-off.
LANDING_ITERATIONS = 4


def land_on_section(system, section: Section, s_before: np.ndarray, dt: float, *, rtol: float, atol: float):
    """Integrate from ``s_before`` exactly onto the section, starting from the guess ``dt`` [s].

    Newton on the crossing time with dg/dt from the vector field; each iterate re-simulates from
    ``s_before``. Returns (state on the section (2n,), time from ``s_before`` [s], |g| before the
    coordinate is set to the section value [unit of the coordinate]).
    """
    s = s_before
    for _ in range(LANDING_ITERATIONS):
        s, _tr = flow(system, s_before, dt, rtol=rtol, atol=atol)
        g = section.g(s)
        dg = section.direction * vector_field(system, s)[section.index]
        if dg <= 0.0:
            raise OrbitError(f"the flow does not cross section {section.name} transversally at t = {dt} s")
        dt = dt - g / dg
    s, _tr = flow(system, s_before, dt, rtol=rtol, atol=atol)
    miss = abs(section.g(s))
    s = s.copy()
    s[section.index] = section.value
    return s, dt, miss
