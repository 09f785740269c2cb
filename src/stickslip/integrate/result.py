"""Typed, self-describing simulation results with NetCDF round trip, for any friction model."""

from __future__ import annotations

import dataclasses
import json
import operator
from collections.abc import Sequence
from functools import cached_property
from pathlib import Path
from typing import NamedTuple

import numpy as np
from numba import njit

from .._version import __version__
from ..analysis.modes import MODE_WORD_BITS, contact_index_dtype, flag_bits, mode_shape
from ..analysis.steady import SteadyState, summarize
from ..errors import FileFormatError
from ..files import format_name, open_ours, save_netcdf
from ..model import physics
from ..model.bundle import CST
from ..model.library import describe_system, system_from_description, two_plates
from ..model.library.two_plates import is_plates, plates_parameters
from ..model.matrices import dense_array
from ..model.parameters import Parameters, parameter_attrs
from ..model.system_model import FrictionModel
from ..results import Plottable
from .contacts import TRANSITION_IMPACT
from .status import Status

__all__ = ["Stats", "Transitions", "Trajectory", "load_trajectory", "FileFormatError", "mode_dtype", "mode_array",
           "Impact", "Impacts", "find_impacts",
           "ImpactTally", "impact_speeds"]

FORMAT = format_name("trajectory", 2)
#: Format versions :func:`load_trajectory` reads (1: the two plates only, before models as data).
READ_VERSIONS = (1, 2)


@dataclasses.dataclass(frozen=True)
class Stats:
    """Integrator statistics.

    ``wall_time_s`` is the integration alone; ``compile_time_s`` the one-off JIT compilation
    (or cache load) of the kernels when this run was the first in the process, else 0.
    """

    accepted_steps: int = 0
    rejected_steps: int = 0
    rhs_calls: int = 0
    retaken_steps: int = 0
    slip_to_stick: int = 0
    stick_to_slip: int = 0
    wall_time_s: float = 0.0
    compile_time_s: float = 0.0

    @property
    def steps(self) -> int:
        """Accepted plus rejected steps."""
        return self.accepted_steps + self.rejected_steps


@dataclasses.dataclass(frozen=True)
class Transitions:
    """Exact stick↔slip transition instants.

    Attributes
    ----------
    time : ndarray (k,)
        Instants [s].
    kind : ndarray (k,) int8
        +1 slip → stick, −1 stick → slip.
    state : ndarray (k, 2n)
        States at the transitions (after projection when entering stick).
    contact : ndarray (k,) int8
        The contact that changed (0 for a one-contact model).
    dropped : int
        Earlier transitions of the run that were not kept (very long runs keep the most recent
        10^6, and the states of the most recent 10^5; older states are NaN).
    """

    time: np.ndarray
    kind: np.ndarray
    state: np.ndarray
    contact: np.ndarray | None = None
    dropped: int = 0

    def __post_init__(self) -> None:
        if self.contact is None:
            object.__setattr__(self, "contact", np.zeros(self.time.size, dtype=np.int8))

    def __len__(self) -> int:
        return int(self.time.size)


def mode_dtype(n_contacts: int, unilateral: bool = False):
    """Integer type of the sampled mode (bit c set: contact c sticks; with unilateral contacts bit
    nc + c set: contact c is open): the narrowest of int8, int16, int32 with a bit for each flag,
    or int64 words for more flags (:func:`stickslip.analysis.modes.mode_shape`)."""
    return mode_shape(0, n_contacts, unilateral)[1]


def mode_array(k: int, n_contacts: int, unilateral: bool = False) -> np.ndarray:
    """An uninitialised mode array of k samples: (k,), or (k, words) for a model of more than 32 flags."""
    shape, dtype = mode_shape(k, n_contacts, unilateral)
    return np.empty(shape, dtype=dtype)


@njit(cache=True)
def _slip_velocities(states, md, nc):
    """Slip velocity of every contact (k, 2 nc) at each sample [m/s]."""
    k = states.shape[0]
    out = np.empty((k, 2 * nc))
    for i in range(k):
        for c in range(nc):
            v0, v1 = physics.slip_velocity(states[i], c, md)
            out[i, 2 * c] = v0
            out[i, 2 * c + 1] = v1
    return out


def _sample_normal_forces(states, mode, md, nc, rigid=None):
    """Normal force of every contact (k, nc) at each sample [N], a unilateral contact's in its
    sampled state (0 while open: bit nc + c of ``mode``; a closed rigid contact's multiplier with
    the sampled stick set, bit c). With ``rigid``, the (nc,) bool mask of a model's rigid contacts, NaN for the closed
    rigid contacts at a sample where their normal forces have no consistent value (Painlevé: the
    multiplier solved there is no force of the motion)."""
    codes = np.where(flag_bits(mode, nc, nc), physics.MODE_OPEN,
                     np.where(flag_bits(mode, 0, nc), physics.MODE_STICK, physics.MODE_SLIP)).astype(np.int8)
    out = _normal_forces(states, codes, md, nc)
    if rigid is not None and rigid.any():
        undefined = ~_consistent_normal_forces(states, codes, md, nc)
        out[undefined[:, None] & rigid[None, :] & (codes != physics.MODE_OPEN)] = np.nan
    return out


@njit(cache=True)
def _consistent_normal_forces(states, codes, md, nc):
    """Whether the closed rigid contacts' normal forces have a consistent value at each sample
    (k,) bool: the relative pivot of their normal-force system is positive (true where none is closed)."""
    k = states.shape[0]
    out = np.ones(k, dtype=np.bool_)
    cst = np.zeros(CST * nc)
    for i in range(k):
        for c in range(nc):
            cst[CST * c] = codes[i, c]
            cst[CST * c + 1] = 1.0
        out[i] = physics.rigid_pivot(states[i], cst, md) > 0.0
    return out


@njit(cache=True)
def _normal_forces(states, codes, md, nc):
    """:func:`_sample_normal_forces` from each contact's mode code (k, nc) int8 (``physics.MODE_*``)."""
    k = states.shape[0]
    out = np.empty((k, nc))
    cst = np.zeros(CST * nc)
    for i in range(k):
        for c in range(nc):
            cst[CST * c] = codes[i, c]
            cst[CST * c + 1] = 1.0
        for c in range(nc):
            out[i, c] = physics.normal_force_of(states[i], cst, c, md)
    return out


@njit(cache=True)
def _gaps(states, md, nc):
    """Gap g of every unilateral contact (k, nc) at each sample [m] (NaN for pressed contacts)."""
    k = states.shape[0]
    out = np.full((k, nc), np.nan)
    for c in range(nc):
        if physics.unilateral(c, md):
            for i in range(k):
                out[i, c] = physics.gap(states[i], c, md)[0]
    return out


class Impact(NamedTuple):
    """One impact of a rigid contact (an item of :class:`Impacts`).

    Attributes
    ----------
    time : float
        Instant [s].
    contact : int
        The contact that closed.
    speed_before, speed_after : float
        Its normal speed ġ = W·q̇ just before and after [m/s].
    impulse : float
        The normal impulse P_N [N s].
    """

    time: float
    contact: int
    speed_before: float
    speed_after: float
    impulse: float


@njit(cache=True)
def _impact_speeds(states, contacts, md):
    """Normal speed ġ⁻ = W·q̇ of contact ``contacts[i]`` at each state (k, ≥ 2n) before an impact [m/s]."""
    out = np.empty(states.shape[0])
    for i in range(states.shape[0]):
        out[i] = physics.gap(states[i], np.int64(contacts[i]), md)[1]
    return out


def impact_speeds(system: FrictionModel, kinds: np.ndarray, contacts: np.ndarray, states: np.ndarray):
    """(instants' indices, |ġ⁻| [m/s]) of the impacts among transitions of ``kinds`` (k,) with the
    ``contacts`` (k,) and ``states`` (k, ≥ 2n) there (the state before each impact)."""
    rows = np.flatnonzero(kinds == TRANSITION_IMPACT)
    if rows.size == 0:
        return rows, np.empty(0)
    speeds = _impact_speeds(np.ascontiguousarray(states[rows]), contacts[rows].astype(np.int64), system.data)
    return rows, np.abs(speeds)


@dataclasses.dataclass(frozen=True)
class ImpactTally:
    """The impacts of a run's steady window counted as the run went, from every impact's state
    (those of the transition log beyond its kept states included), so that their number and
    largest speed are exact however many impacts the run had.

    Attributes
    ----------
    t_from, t_to : float
        The window (t_from, t_to] [s]: the steady window the run was started with and its last sample.
    count : int
        Impacts in the window.
    max_speed : float
        Largest normal speed |ġ⁻| among them [m/s] (0 without impacts).
    """

    t_from: float
    t_to: float
    count: int = 0
    max_speed: float = 0.0

    def add(self, times: np.ndarray, speeds: np.ndarray) -> "ImpactTally":
        """This tally with the impacts at ``times`` [s] of normal speeds |ġ⁻| ``speeds`` [m/s] added."""
        inside = (times > self.t_from) & (times <= self.t_to)
        if not inside.any():
            return self
        return dataclasses.replace(self, count=self.count + int(inside.sum()),
                                   max_speed=max(self.max_speed, float(speeds[inside].max())))

    def covers(self, t_from: float, t_to: float) -> bool:
        """Whether this tally is of the window (t_from, t_to]."""
        return self.t_from == t_from and self.t_to == t_to


@dataclasses.dataclass(frozen=True, eq=False)
class Impacts(Sequence):
    """Impacts of the rigid contacts in a run, in order: a sequence of :class:`Impact` records
    (``impacts[0]``, ``impacts[-3:]``, ``for impact in impacts``) with the columns as arrays.

    Attributes
    ----------
    time : ndarray (k,)
        Instants [s].
    contact : ndarray (k,) int
        The contact that closed.
    speed_before, speed_after : ndarray (k,)
        Its normal speed ġ = W·q̇ just before (< 0) and after (−e ġ⁻, or 0 where it stays closed
        or its bounces accumulated) [m/s].
    impulse : ndarray (k,)
        The normal impulse P_N [N s]: the W-component of the momentum change M Δq̇ written in the
        contacts' normal and tangent directions (least squares, exact where they are independent).
    """

    time: np.ndarray
    contact: np.ndarray
    speed_before: np.ndarray
    speed_after: np.ndarray
    impulse: np.ndarray

    def __len__(self) -> int:
        return int(self.time.size)

    def __getitem__(self, index):
        """Impact ``index`` as an :class:`Impact`; a slice as :class:`Impacts`."""
        if isinstance(index, slice):
            return Impacts(self.time[index], self.contact[index], self.speed_before[index],
                           self.speed_after[index], self.impulse[index])
        i = operator.index(index)
        if not -len(self) <= i < len(self):
            raise IndexError(f"impact {i} of a run with {len(self)} impacts")
        return Impact(float(self.time[i]), int(self.contact[i]), float(self.speed_before[i]),
                      float(self.speed_after[i]), float(self.impulse[i]))

    def __iter__(self):
        return (self[i] for i in range(len(self)))


def find_impacts(system: FrictionModel, transitions: Transitions) -> Impacts:
    """The impacts of a run from its transitions: each ``impact`` record holds the state before,
    the record after it (``open`` or ``close`` of the same contact at the same instant) the state
    after (:func:`stickslip.integrate.transitions.switch_gap`)."""
    n = system.n
    kinds = transitions.kind
    rows = [i for i in np.flatnonzero(kinds == TRANSITION_IMPACT) if i + 1 < kinds.size]
    directions = [dense_array(c.gap_gradient).reshape(-1) for c in system.contacts if c.gap_gradient is not None]
    directions += [row for c in system.contacts if c.tangent is not None
                   for row in np.atleast_2d(dense_array(c.tangent))]
    out = {key: np.empty(len(rows)) for key in ("time", "before", "after", "impulse")}
    contact = np.empty(len(rows), dtype=int)
    for j, i in enumerate(rows):
        c = int(transitions.contact[i])
        W = dense_array(system.contacts[c].gap_gradient).reshape(-1)
        before, after = transitions.state[i], transitions.state[i + 1]
        change = dense_array(system.mass) @ (after[n:2 * n] - before[n:2 * n])
        basis = np.array([W] + [d for d in directions if d is not W and not np.array_equal(d, W)]).T
        coef = np.linalg.lstsq(basis, change, rcond=None)[0]
        out["time"][j] = transitions.time[i]
        out["before"][j] = W @ before[n:2 * n]
        out["after"][j] = W @ after[n:2 * n]
        out["impulse"][j] = coef[0]
        contact[j] = c
    return Impacts(out["time"], contact, out["before"], out["after"], out["impulse"])


@dataclasses.dataclass(frozen=True, eq=False)
class Trajectory(Plottable):
    """Result of :func:`stickslip.simulate`.

    Parameters
    ----------
    t : ndarray (k,)
        Uniform sample times [s].
    states : ndarray (k, 2n)
        s = [q, q̇] in the order of ``system.state_names``.
    mode : ndarray (k,) int8 (wider beyond 8 flags, :func:`mode_dtype`)
        Bit c set when contact c sticks (a one-contact model: 1 in stick, 0 in slip); for a model
        with unilateral contacts bit nc + c set when contact c is open.
    friction : ndarray (k, 2 nc)
        Friction force of contact c at columns 2c, 2c+1 [N] (for the plates: (Fx, Fy) on the
        upper plate; for a 1-D contact the second column is 0).
    work : ndarray (k, 2)
        Work done since t0 by friction and by the dampers [J].
    transitions : Transitions
        The exact transition instants of the run, with the states there (:class:`Transitions`;
        the impacts of rigid contacts: :attr:`impacts`).
    stats : Stats
        Integrator statistics: steps, right-hand-side calls, transition counts, wall and compile
        times (:class:`Stats`).
    status : str
        ``"success"`` or the reason the run stopped early (:attr:`status_code` as an enum).
    system : FrictionModel
        The model simulated, with its parameters.
    method : str
        The integration method: ``event`` (adaptive, exact transitions), ``aeom`` or ``naeom``
        (the paper's fixed-step methods, two plates only).
    options : dict
        rtol, atol, dt, sample_rate, ic, perturbation, t0, t_end, slip_band.
    steady_from : float
        Start of the steady-state window used by :attr:`steady` [s].
    status_code : Status
        How the run ended, as an enum (``Status.SUCCESS``, ``Status.INCONSISTENT``, ...);
        :attr:`status` is its message.
    impact_tally : ImpactTally, optional
        The impacts of the steady window counted during the run (models with rigid contacts):
        :attr:`steady` takes their number and largest speed from it, exact however many
        transitions the run dropped.
    """

    FIGURE = "trajectory"

    t: np.ndarray
    states: np.ndarray
    mode: np.ndarray
    friction: np.ndarray
    work: np.ndarray
    transitions: Transitions
    stats: Stats
    status: str
    system: FrictionModel
    method: str
    options: dict
    steady_from: float
    status_code: Status = Status.SUCCESS
    impact_tally: ImpactTally | None = None

    # ------------------------------------------------------------- the model
    @property
    def is_plates(self) -> bool:
        """Whether the model is the paper's two plates."""
        return is_plates(self.system)

    @property
    def params(self) -> Parameters | None:
        """The plates' :class:`Parameters` (None for other models: see ``system.parameters``)."""
        return plates_parameters(self.system)

    @property
    def model(self) -> str:
        """How results name the model: the plates' variant (``full``, ``rotation``, ...) or the model's name."""
        return self.system.label or self.system.name

    @property
    def state_names(self) -> tuple[str, ...]:
        return self.system.state_names

    @property
    def observed(self) -> int:
        """Index of the coordinate the summaries follow (the plates' φ, else the first dof)."""
        return self.system.observed_index

    # ------------------------------------------------------------- derived series
    @cached_property
    def slip_velocity(self) -> np.ndarray:
        """Slip velocity of each contact (k, 2 nc) [m/s]; for the plates v_r of Eq. (9); NaN for a
        contact without friction."""
        return self._without_friction(_slip_velocities(np.ascontiguousarray(self.states), self.system.data,
                                                       self.system.n_contacts))

    def _without_friction(self, v: np.ndarray) -> np.ndarray:
        """Slip velocities ``v`` (k, 2 nc) with NaN for contacts without friction, which have none."""
        for c, contact in enumerate(self.system.contacts):
            if contact.frictionless:
                v[:, 2 * c:2 * c + 2] = np.nan
        return v

    @property
    def relative_velocity(self) -> np.ndarray:
        """The plates' v_r (k, 2), Eq. (9) [m/s] (the first contact's slip velocity)."""
        return self.slip_velocity[:, :2]

    @cached_property
    def sliding_angle(self) -> np.ndarray:
        """Angle of each contact's slip velocity v against its steady-sliding direction [deg] (k, nc),
        NaN in stick.

        The steady-sliding direction is that of the slip velocity the contact would have at rest in
        the same position, v0 = −w(q) (q̇ = 0), so the angle is 0 in steady sliding and measures how
        far the motion of the bodies turns the slip. For the plates v0 = Ω R (−e_n2), the direction
        of motion of the lower plate's surface against the upper plate (Eq. 8): the angle of Fig. 11.
        """
        n, nc = self.system.n, self.system.n_contacts
        at_rest = np.ascontiguousarray(self.states).copy()
        at_rest[:, n:] = 0.0
        v0 = self._without_friction(_slip_velocities(at_rest, self.system.data, nc)).reshape(-1, nc, 2)
        v = self.slip_velocity.reshape(-1, nc, 2)
        cross = v0[..., 0] * v[..., 1] - v0[..., 1] * v[..., 0]
        dot = v0[..., 0] * v[..., 0] + v0[..., 1] * v[..., 1]
        angle = np.degrees(np.arctan2(cross, dot))
        return np.where((v[..., 0] == 0.0) & (v[..., 1] == 0.0), np.nan, angle)

    @property
    def sliding_angle_deg(self) -> np.ndarray:
        """:attr:`sliding_angle` of the first contact (k,) [deg] (for the plates, Fig. 11)."""
        return self.sliding_angle[:, 0]

    @cached_property
    def normal_force(self) -> np.ndarray:
        """Normal force of each contact (k, nc) [N]: a prescribed N, or a unilateral contact's λ (0 open;
        NaN for a closed rigid contact at a sample where it has no consistent normal force, Painlevé)."""
        return _sample_normal_forces(np.ascontiguousarray(self.states), self.mode, self.system.data,
                                     self.system.n_contacts,
                                     np.array([c.unilateral and c.normal.law == "rigid" for c in self.system.contacts]))

    @property
    def stick(self) -> np.ndarray:
        """Whether each contact sticks at each sample (k, nc) bool."""
        return flag_bits(self.mode, 0, self.system.n_contacts)

    @property
    def open(self) -> np.ndarray:
        """Whether each contact is open at each sample (k, nc) bool (always False for pressed contacts)."""
        nc = self.system.n_contacts
        if not self.system.unilateral:
            return np.zeros((self.t.size, nc), dtype=bool)
        return flag_bits(self.mode, nc, nc)

    @cached_property
    def gap(self) -> np.ndarray:
        """Gap g of each unilateral contact (k, nc) [m] (g0 + W·q, or the kinematics' gap function); NaN
        for pressed contacts."""
        return _gaps(np.ascontiguousarray(self.states), self.system.data, self.system.n_contacts)

    @cached_property
    def impacts(self) -> Impacts:
        """The impacts of the rigid contacts (:class:`Impacts`; empty for other models)."""
        return find_impacts(self.system, self.transitions)

    @property
    def friction_magnitude(self) -> np.ndarray:
        """|F| of the first contact (k,) [N]."""
        return np.hypot(self.friction[:, 0], self.friction[:, 1])

    @property
    def mechanical_energy(self) -> np.ndarray:
        """½ q̇ᵀ M q̇ + ½ qᵀ K_s q (k,) [J], K_s the symmetric part of K (locked DOFs never move)."""
        n = self.system.n
        q, dq = self.states[:, :n], self.states[:, n:2 * n]
        K = dense_array(self.system.stiffness)
        Ks = 0.5 * (K + K.T)
        return (0.5 * np.einsum("ki,ij,kj->k", dq, dense_array(self.system.mass), dq)
                + 0.5 * np.einsum("ki,ij,kj->k", q, Ks, q))

    @property
    def final_state(self) -> np.ndarray:
        """State at the last sample (2n,)."""
        return self.states[-1].copy()

    @cached_property
    def steady(self) -> SteadyState:
        """Steady-state summary over t ≥ :attr:`steady_from`."""
        return self.steady_state(self.steady_from)

    def steady_state(self, t_from: float) -> SteadyState:
        """Steady-state summary over t ≥ ``t_from`` [s]."""
        i = self.observed
        impacts = (self.impacts.time, self.impacts.speed_before) if self.system.rigid else None
        tally = self.impact_tally
        if impacts is not None and tally is not None and tally.covers(float(t_from), float(self.t[-1])):
            impacts = tally
        return summarize(self.t, self.states, self.mode, self.transitions, t_from, n_contacts=self.system.n_contacts,
                         coordinate=i, rate=i + self.system.n, name=self.system.dofs[i],
                         unilateral=self.system.unilateral, impacts=impacts)

    # ------------------------------------------------------------- pieces and joins
    def joined(self, more: "Trajectory") -> "Trajectory":
        """This run followed by ``more``, a continuation of it that starts at its last sample
        (dropped from ``more``); statistics add up and the work of ``more`` continues this run's."""
        a, b = self, more
        stats = Stats(**{f.name: getattr(a.stats, f.name) + getattr(b.stats, f.name)
                         for f in dataclasses.fields(Stats)})
        tr = Transitions(np.concatenate([a.transitions.time, b.transitions.time]),
                         np.concatenate([a.transitions.kind, b.transitions.kind]),
                         np.concatenate([a.transitions.state, b.transitions.state]),
                         np.concatenate([a.transitions.contact, b.transitions.contact]),
                         a.transitions.dropped + b.transitions.dropped)
        return dataclasses.replace(
            b, t=np.concatenate([a.t, b.t[1:]]), states=np.concatenate([a.states, b.states[1:]]),
            mode=np.concatenate([a.mode, b.mode[1:]]), friction=np.concatenate([a.friction, b.friction[1:]]),
            work=np.concatenate([a.work, b.work[1:] + a.work[-1]]), transitions=tr, stats=stats,
            options=dict(a.options, t_end=b.options["t_end"]), impact_tally=None)

    def tail(self, t_from: float) -> "Trajectory":
        """The part of this run from ``t_from`` [s] on (transitions before it counted as dropped)."""
        sel = self.t >= t_from
        keep = self.transitions.time > t_from
        tr = Transitions(self.transitions.time[keep], self.transitions.kind[keep], self.transitions.state[keep],
                         self.transitions.contact[keep], self.transitions.dropped + int(np.count_nonzero(~keep)))
        return dataclasses.replace(self, t=self.t[sel], states=self.states[sel], mode=self.mode[sel],
                                   friction=self.friction[sel], work=self.work[sel], transitions=tr)


    # ------------------------------------------------------------- xarray / NetCDF
    def to_xarray(self):
        """``xarray.Dataset`` with units, long names, the model and its parameters, and the run options."""
        import xarray as xr

        system = self.system
        coords = {"time": ("time", self.t, {"units": "s", "long_name": "time"}),
                  "state": ("state", list(system.state_names)),
                  "contact": ("contact", list(system.contact_names)),
                  "component": ("component", ["t1", "t2"])}
        data = {}
        for j, (name, unit) in enumerate(zip(system.state_names, system.state_units)):
            dof = system.dofs[j % system.n]
            data[name] = ("time", self.states[:, j], {"units": unit, "long_name": ("" if j < system.n else "rate of ") + dof})
        nc = system.n_contacts
        if system.unilateral:
            mode_attrs = {"long_name": "contact flags (bit c set: contact c sticks; bit nc + c set: contact c is open)",
                          "flag_masks": " ".join(str(1 << b) for b in range(2 * nc))}
        elif nc == 1:
            mode_attrs = {"long_name": "sticking contacts (bit c set: contact c sticks)", "flag_values": "0 1",
                          "flag_meanings": "slip stick"}
        else:
            mode_attrs = {"long_name": "sticking contacts (bit c set: contact c sticks)",
                          "flag_masks": " ".join(str(1 << c) for c in range(nc))}
        if self.mode.ndim == 2:  # words of flags (a large model): flag b is bit b % 63 of word b // 63
            mode_attrs = {"long_name": mode_attrs["long_name"] + f"; flag b is bit b % {MODE_WORD_BITS} of word "
                                                                 f"b // {MODE_WORD_BITS}"}
            data["mode"] = (("time", "mode_word"), self.mode, mode_attrs)
        else:
            data["mode"] = ("time", self.mode, mode_attrs)
        data["stick"] = (("time", "contact"), self.stick.astype(np.int8),
                         {"long_name": "each contact sticks (1) or slips (0)", "flag_values": "0 1",
                          "flag_meanings": "slip stick"})
        if system.unilateral:
            data["open"] = (("time", "contact"), self.open.astype(np.int8),
                            {"long_name": "each unilateral contact is open (1) or closed (0)", "flag_values": "0 1",
                             "flag_meanings": "closed open"})
            data["gap"] = (("time", "contact"), self.gap,
                           {"units": "m", "long_name": "gap g = g0 + W·q of each unilateral contact (NaN: pressed)"})
            data["normal_force"] = (("time", "contact"), self.normal_force,
                                    {"units": "N", "long_name": "normal force of each contact (0 while open)"})
        data["friction"] = (("time", "contact", "component"), self.friction.reshape(-1, nc, 2),
                            {"units": "N", "long_name": "friction force of each contact along its tangent rows"})
        data["slip_velocity"] = (("time", "contact", "component"), self.slip_velocity.reshape(-1, nc, 2),
                                 {"units": "m/s", "long_name": "slip velocity v = G q̇ − w of each contact"})
        angle_attrs = {"units": "degree", "long_name": "angle of the slip velocity against the steady-sliding direction"}
        data["sliding_angle"] = (("time",), self.sliding_angle_deg, angle_attrs) if nc == 1 else \
            (("time", "contact"), self.sliding_angle, angle_attrs)
        data["work_friction"] = ("time", self.work[:, 0], {"units": "J", "long_name": "work of friction since t0"})
        data["work_damping"] = ("time", self.work[:, 1], {"units": "J", "long_name": "work of the dampers since t0"})
        data["transition_time"] = ("transition", self.transitions.time, {"units": "s"})
        data["transition_kind"] = ("transition", self.transitions.kind.astype(np.int8),
                                   {"flag_values": "-1 1" + (" 2 3" if system.unilateral else "") +
                                    (" 4" if system.rigid else ""),
                                    "flag_meanings": "stick_to_slip slip_to_stick" +
                                    (" open close" if system.unilateral else "") + (" impact" if system.rigid else "")})
        data["transition_contact"] = ("transition", self.transitions.contact.astype(contact_index_dtype(nc)))
        data["transition_state"] = (("transition", "state"), self.transitions.state)
        attrs = {
            "format": FORMAT,
            "stickslip_version": __version__,
            "title": f"stickslip trajectory of model {system.name}",
            "model": self.model,
            "model_name": system.name,
            "model_source": system.source,
            "system": json.dumps(describe_system(system)),
            "method": self.method,
            "status": self.status,
            "status_code": int(self.status_code),
            "steady_from": self.steady_from,
            "options": json.dumps(self.options),
            "stats": json.dumps(dataclasses.asdict(self.stats)),
            "parameters": json.dumps(dict(system.parameters)),
            "transitions_dropped": int(self.transitions.dropped),
        }
        if self.impact_tally is not None:
            attrs["impact_tally"] = json.dumps(dataclasses.asdict(self.impact_tally))
        if self.is_plates:
            attrs.update(parameter_attrs(self.params.to_dict()))
        for key, value in self.steady.to_dict().items():
            attrs[f"steady_{key}"] = int(value) if isinstance(value, bool) else \
                np.asarray(value, dtype=float) if isinstance(value, tuple) else value
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def to_netcdf(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Write :meth:`to_xarray` to a NetCDF-4 file (h5netcdf engine), atomically.

        An existing ``path`` is replaced only with ``overwrite=True``
        (:class:`stickslip.errors.OutputError` otherwise).
        """
        return save_netcdf(self.to_xarray(), path, overwrite=overwrite)

    @classmethod
    def from_xarray(cls, ds, model: FrictionModel | None = None) -> "Trajectory":
        """Rebuild a trajectory from :meth:`to_xarray` output (or a format-1 plates file).

        ``model`` overrides the model written in the file (needed for models defined in Python
        without a rule to rebuild them).
        """
        if ds.attrs.get("format") == format_name("trajectory", 1):
            return cls._from_plates_v1(ds)
        if ds.attrs.get("format") != FORMAT:
            raise FileFormatError(f"dataset is not a stickslip trajectory (format attribute {ds.attrs.get('format')!r}, "
                                  f"expected {FORMAT!r}); give a file written by `stickslip simulate`")
        system = model or system_from_description(json.loads(ds.attrs["system"]))
        states = np.stack([ds[name].values for name in system.state_names], axis=1)
        nc = system.n_contacts
        code = Status(int(ds.attrs.get("status_code", 0)))
        return cls(
            t=ds["time"].values, states=states, mode=ds["mode"].values.astype(mode_dtype(nc, system.unilateral)),
            friction=ds["friction"].values.reshape(-1, 2 * nc),
            work=np.stack([ds["work_friction"].values, ds["work_damping"].values], axis=1),
            transitions=Transitions(ds["transition_time"].values, ds["transition_kind"].values.astype(np.int8),
                                    ds["transition_state"].values.reshape(-1, 2 * system.n),
                                    ds["transition_contact"].values.astype(contact_index_dtype(nc)),
                                    int(ds.attrs.get("transitions_dropped", 0))),
            stats=Stats(**json.loads(ds.attrs["stats"])), status=ds.attrs["status"], system=system,
            method=ds.attrs["method"], options=json.loads(ds.attrs["options"]),
            steady_from=float(ds.attrs["steady_from"]), status_code=code,
            impact_tally=ImpactTally(**json.loads(ds.attrs["impact_tally"])) if "impact_tally" in ds.attrs else None,
        )

    @classmethod
    def _from_plates_v1(cls, ds) -> "Trajectory":
        """A run of the two plates written before models were data (format 1)."""
        params = Parameters.from_dict(json.loads(ds.attrs["parameters"]))
        system = two_plates(params, ds.attrs["model"])
        states = np.stack([ds[name].values for name in system.state_names], axis=1)
        return cls(
            t=ds["time"].values, states=states, mode=ds["mode"].values.astype(np.int8),
            friction=np.stack([ds["Fx"].values, ds["Fy"].values], axis=1),
            work=np.stack([ds["work_friction"].values, ds["work_damping"].values], axis=1),
            transitions=Transitions(ds["transition_time"].values, ds["transition_kind"].values.astype(np.int8),
                                    ds["transition_state"].values.reshape(-1, 12)),
            stats=Stats(**json.loads(ds.attrs["stats"])), status=ds.attrs["status"], system=system,
            method=ds.attrs["method"], options=json.loads(ds.attrs["options"]),
            steady_from=float(ds.attrs["steady_from"]),
            status_code=Status.SUCCESS if ds.attrs["status"] == "success" else Status.STEP_UNDERFLOW,
        )


def load_trajectory(path: str | Path, model: FrictionModel | None = None) -> Trajectory:
    """Read a trajectory written by :meth:`Trajectory.to_netcdf`.

    Parameters
    ----------
    path : str or Path
        The NetCDF file (``stickslip simulate --out``).
    model : FrictionModel, optional
        The model, for runs of a model defined in Python (files and library models are rebuilt
        from the file itself).

    Returns
    -------
    Trajectory

    Raises
    ------
    FileFormatError
        If the file does not exist, is not NetCDF, is truncated, was not written by stickslip or is
        of a newer format.
    """
    ds = open_ours(path, "trajectory", what="a run.nc written by `stickslip simulate`", versions=READ_VERSIONS)
    return Trajectory.from_xarray(ds, model)
