"""The shooting problem: the return map of a Poincaré section, its Jacobian, Newton and monodromy.

One :class:`ShootingProblem` serves every orbit tool. It holds a model at fixed parameters, its
free states, their scales σ, the section and the integration options, and gives

* the flow map Φ(s0, T) (:func:`.section.flow`: the ``event`` integrator over exactly T seconds;
  with an optional cap on the steps per simulated second and a count of the runs);
* the shooting residual F = (Φ(s0, T) − s0)[free] / σ;
* ∂Φ/∂s0 on the free states from the variational equations with saltation matrices
  (:func:`.linear_flow.flow_jacobian`) or from central differences of Φ (two runs a column, the
  saltation then inside the differences);
* the scaled Jacobian of F in the unknowns (the section states but the coordinate the section
  fixes, in units of σ, and T), whose T column is exact, f(Φ) from the vector field;
* Newton's iteration on F with step halving (:meth:`ShootingProblem.newton`).

:func:`~stickslip.orbits.periodic_orbit` solves it, pseudo-arclength continuation adds the
parameter as an unknown (:mod:`.arclength`), the Lyapunov tools use its flow map, scales and
σ-scaled perturbations (:mod:`.lyapunov`), and :func:`monodromy` gives an orbit's monodromy
matrix. A PeriodicOrbit's monodromy and Floquet multipliers (:class:`Monodromy`) are here too.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import time as _time
from typing import NamedTuple

import numpy as np

from .._version import __version__
from ..analysis.modes import sample_flags
from ..analysis.signal import CLOSE, OPEN
from ..analysis.signal import open_time as signal_open_time
from ..analysis.signal import stick_time as signal_stick_time
from ..errors import OrbitError, SimulationError
from ..model.bundle import CST
from ..model.physics import MODE_STICK, gap
from ..model.system_model import FrictionModel
from ..stability.verdict import MARGINAL_RTOL
from . import linear_flow as _lin
from .layout import Constraint, free_states, independent_states, resting_contacts, rigid_admissible, stick_projected
from .models import ModelResult, model_attrs
from .section import Section, flow, vector_field

__all__ = ["ShootingProblem", "NewtonResult", "Monodromy", "monodromy", "central_differences",
           "scales", "sorted_eigenvalues", "nontrivial", "unstable_count", "floquet_verdict", "multiplier_tolerance",
           "stick_count", "stick_time", "stick_summary", "open_count", "open_time",
           "check_method", "check_section", "METHODS", "DEFAULT_TOL", "DEFAULT_FD_STEP"]

#: Ways of computing ∂Φ/∂s0: variational equations with saltation matrices, or central differences.
METHODS = ("saltation", "finite-difference")

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


def check_method(method: str, what: str = "monodromy method") -> None:
    """Refuse a method of computing ∂Φ/∂s0 not in :data:`METHODS` (OrbitError naming ``what``)."""
    if method not in METHODS:
        raise OrbitError(f"unknown {what} {method!r}; use one of {METHODS}")


def check_section(section: Section, system: FrictionModel) -> None:
    """Refuse a section that fixes a state the model locks (OrbitError)."""
    if section.index not in free_states(system):
        raise OrbitError(f"section {section.name} fixes {system.state_names[section.index]}, which is locked in "
                         f"model {ModelResult.label(system)!r}")


def scales(ptp: np.ndarray, free: np.ndarray) -> np.ndarray:
    """σ (2 n_free,) of the free states from their peak-to-peak ranges ``ptp`` (all states),
    floored per kind, positions and velocities (see :data:`SCALE_FLOOR`) [state units]."""
    sigma = ptp[free].astype(float).copy()
    n = free.size // 2
    for part in (slice(0, n), slice(n, 2 * n)):
        top = sigma[part].max()
        if top <= 0.0:
            raise OrbitError("the guess does not move: no oscillation to shoot from (is it the equilibrium?)")
        sigma[part] = np.maximum(sigma[part], SCALE_FLOOR * top)
    return sigma


def central_differences(end_of, s0, free: np.ndarray, h: np.ndarray, cols=None) -> np.ndarray:
    """Columns (Φ(s0 + h_k e_k) − Φ(s0 − h_k e_k))[free] / (2 h_k) of ∂Φ/∂s0, free-state rows.

    Parameters
    ----------
    end_of : callable
        ``end_of(s)`` → Φ(s) (all states).
    s0 : array-like (2n,)
    free : ndarray (2 n_free,)
        State indices of the free states.
    h : ndarray (2 n_free,)
        Steps of the free states [state units].
    cols : sequence of int, optional
        Positions in ``free`` of the columns (default: all).

    Returns
    -------
    ndarray (2 n_free, len(cols))
    """
    s0 = np.asarray(s0, dtype=float)
    cols = range(free.size) if cols is None else cols
    out = np.empty((free.size, len(cols)))
    for c, k in enumerate(cols):
        sp, sm = s0.copy(), s0.copy()
        sp[free[k]] += h[k]
        sm[free[k]] -= h[k]
        out[:, c] = (end_of(sp)[free] - end_of(sm)[free]) / (2.0 * h[k])
    return out


def sorted_eigenvalues(M: np.ndarray) -> np.ndarray:
    """Eigenvalues of M by decreasing modulus (stable order for equal moduli)."""
    mult = np.linalg.eigvals(M)
    return mult[np.argsort(-np.abs(mult), kind="stable")]


def nontrivial(multipliers: np.ndarray) -> np.ndarray:
    """Multipliers without the one closest to 1 (the shift along the orbit)."""
    k = int(np.argmin(np.abs(np.asarray(multipliers) - 1.0)))
    return np.delete(np.asarray(multipliers), k)


def multiplier_tolerance(multipliers: np.ndarray) -> float:
    """Distance from the unit circle within which a multiplier counts as on it [-].

    The trivial multiplier is exactly 1 for the exact monodromy, so its distance from 1 measures
    the error of the computed one (≈ 1e-8 for saltation, 1e-5 for differences, docs/orbits.md); a
    round-off floor :data:`~stickslip.stability.verdict.MARGINAL_RTOL` × max(1, max |μ|) is kept
    below it, as for the eigenvalues of steady sliding.
    """
    mu = np.asarray(multipliers)
    trivial = float(np.min(np.abs(mu - 1.0)))
    return max(trivial, MARGINAL_RTOL * max(1.0, float(np.max(np.abs(mu)))))


def floquet_verdict(multipliers: np.ndarray) -> str:
    """``stable`` (every non-trivial |μ| < 1 − tolerance), ``unstable`` (some > 1 + tolerance) or
    ``marginal`` (the largest on the unit circle within :func:`multiplier_tolerance`: a neutral
    cycle, e.g. of a conservative motion, which the linearisation leaves undecided); ``unknown``
    where the multipliers are not computed (NaN)."""
    mu = np.asarray(multipliers)
    if mu.size == 0 or not np.all(np.isfinite(mu)):
        return "unknown"
    others = np.abs(nontrivial(mu))
    if others.size == 0:
        return "stable"
    tol = multiplier_tolerance(mu)
    if others.max() > 1.0 + tol:
        return "unstable"
    return "stable" if others.max() < 1.0 - tol else "marginal"


def unstable_count(multipliers: np.ndarray) -> int:
    """Number of non-trivial multipliers outside the unit circle (by more than :func:`multiplier_tolerance`)."""
    return int(np.sum(np.abs(nontrivial(multipliers)) > 1.0 + multiplier_tolerance(multipliers)))


def stick_count(transitions) -> int:
    """Slip → stick transitions of a run (its stick phases)."""
    return int(np.sum(transitions.kind == 1))


def stick_summary(traj, period: float) -> dict:
    """The stick (and flight) of one period of an orbit's run (``PeriodicOrbit.trajectory(1.0)``).

    Returns
    -------
    dict
        ``stick_fraction`` (some contact stuck) and, by contact name, ``contacts`` with each one's
        ``stick_phases`` and ``stick_fraction`` of the period. Where the model has unilateral
        contacts, also ``open_phases`` (openings per period, all contacts) and ``open_fraction``
        (some contact open), and each unilateral contact's own ``open_phases`` and
        ``open_fraction``; a model without them gets none of these keys.
    """
    tr = traj.transitions
    system = traj.system
    nc = system.n_contacts
    mode0 = sample_flags(traj.mode[0])
    total, each = signal_stick_time(0.0, period, mode0, tr.time, tr.kind, tr.contact, nc)
    contacts = {name: {"stick_phases": int(np.sum((tr.kind == 1) & (tr.contact == c))),
                       "stick_fraction": float(each[c] / period)}
                for c, name in enumerate(system.contact_names)}
    out = {"stick_fraction": float(total / period), "contacts": contacts}
    if system.unilateral:
        opened, each_open = signal_open_time(0.0, period, mode0, tr.time, tr.kind, tr.contact, nc)
        for c, name in enumerate(system.contact_names):
            if system.contacts[c].unilateral:
                contacts[name].update(open_phases=int(np.sum((tr.kind == OPEN) & (tr.contact == c))),
                                      open_fraction=float(each_open[c] / period))
        out.update(open_phases=open_count(tr), open_fraction=float(opened / period))
    return out


def open_count(transitions) -> int:
    """Openings of unilateral contacts in a run (its flight phases, all contacts)."""
    return int(np.sum(transitions.kind == OPEN))


def open_time(transitions, period: float, system: FrictionModel, state: np.ndarray) -> float:
    """Time with some unilateral contact open over one period of a periodic orbit [s].

    ``transitions`` are those of the run over one period ``period`` from ``state``. A contact
    whose first opening or closing in the run is a closing was open at the start; one with
    neither is open all period if its gap is positive at ``state``, else closed.
    """
    nc = system.n_contacts
    start = np.ascontiguousarray(state, dtype=float)
    flags = 0
    for c, contact in enumerate(system.contacts):
        if not contact.unilateral:
            continue
        mine = (transitions.contact == c) & ((transitions.kind == OPEN) | (transitions.kind == CLOSE))
        kinds = transitions.kind[mine]
        was_open = kinds[0] == CLOSE if kinds.size else gap(start, c, system.data)[0] > 0.0
        flags |= int(bool(was_open)) << (nc + c)
    total, _ = signal_open_time(0.0, period, flags, transitions.time, transitions.kind, transitions.contact, nc)
    return float(total)


def stick_time(transitions) -> float:
    """Total time in stick over a run that starts in slip [s]."""
    t_in = transitions.time[transitions.kind == 1]
    t_out = transitions.time[transitions.kind == -1]
    n = min(t_in.size, t_out.size)
    return float(np.sum(t_out[:n] - t_in[:n]))


class NewtonResult(NamedTuple):
    """A converged orbit of :meth:`ShootingProblem.newton`."""

    state: np.ndarray  # (2n,) on the section
    period: float  # [s]
    residual: np.ndarray  # F at the solution (2 n_free,) [-]
    end: np.ndarray  # Φ(state, period)
    transitions: object  # of the run over one period
    history: list  # max |F| before each iteration and at the end [-]
    iterations: int


@dataclasses.dataclass(frozen=True, eq=False)
class ShootingProblem:
    """The return map of one model at fixed parameters, on its free states in units of σ.

    Attributes
    ----------
    system : FrictionModel
        The model (its slip band included).
    free : ndarray (2 n_free,)
        State indices of the free states (:func:`.layout.free_states`).
    sigma : ndarray (2 n_free,)
        Their scales [state units]: residuals are in units of σ, differences steps of ``fd_step`` σ.
    rtol, atol : float
        Tolerances of every flow map.
    fd_step : float
        Relative finite-difference step [-].
    section : Section, optional
        The Poincaré section (None: a flow map without a section, as for Lyapunov exponents).
    max_steps_per_second : float, optional
        Cap on the integrator steps per simulated second of a flow map (None: the driver's cap).
    constraint : Constraint, optional
        The rigid contacts closed on the section (:func:`.layout.independent_states`): ``free`` are
        then the independent free states, every state the problem makes is completed onto the
        constraint, and ∂Φ/∂s0 is restricted to it.
    counter : dict
        ``{"simulations": flow maps run}``.
    """

    system: FrictionModel
    free: np.ndarray
    sigma: np.ndarray
    rtol: float
    atol: float
    fd_step: float = DEFAULT_FD_STEP
    section: Section | None = None
    max_steps_per_second: float | None = None
    constraint: Constraint | None = None
    counter: dict = dataclasses.field(default_factory=lambda: {"simulations": 0})

    @classmethod
    def build(cls, system: FrictionModel, *, sigma, rtol: float, atol: float, section: Section | None = None,
              constraint: Constraint | None = None, **options) -> "ShootingProblem":
        """The problem of ``system`` (``options``: fd_step, max_steps_per_second); ``sigma`` the scales
        of its free states, the independent ones of ``constraint`` where given.

        Raises
        ------
        OrbitError
            If ``section`` fixes a state the model locks, or one the constraint makes dependent.
        """
        free = free_states(system) if constraint is None else constraint.free
        if section is not None:
            check_section(section, system)
            if section.index not in free:
                raise OrbitError(f"section {section.name} fixes {system.state_names[section.index]}, which rigid "
                                 f"contact {system.contact_names[constraint.contacts[0]]} holds closed on the "
                                 "section: choose a section of another coordinate")
        return cls(system=system, free=free, sigma=np.asarray(sigma, dtype=float), rtol=rtol, atol=atol,
                   section=section, constraint=constraint, **options)

    def complete(self, s: np.ndarray) -> np.ndarray:
        """``s`` on the constraint (its dependent states solved from the others), or ``s`` itself."""
        return s if self.constraint is None else self.constraint.complete(s)

    @functools.cached_property
    def embedding(self) -> np.ndarray:
        """∂s/∂s_free (2n × 2 n_free) on the constraint: a unit variation of each free state, completed."""
        return self.constraint.embedding()

    def _check_scale(self) -> np.ndarray:
        """σ of every free state of the model (1 on the dependent ones): the scales of the
        variational re-integration's consistency checks."""
        if self.constraint is None:
            return self.sigma
        full = np.ones(2 * self.system.n)
        full[self.free] = self.sigma
        return full[free_states(self.system)]

    @property
    def options(self) -> dict:
        """The integration options of every flow map: rtol, atol, slip_band."""
        return dict(rtol=self.rtol, atol=self.atol, slip_band=self.system.slip_band)

    @functools.cached_property
    def unknown(self) -> np.ndarray:
        """Positions in :attr:`free` of the unknown states: all but the one the section fixes."""
        return np.array([k for k, j in enumerate(self.free) if j != self.section.index])

    # ------------------------------------------------------------------ the return map
    def flow(self, s0: np.ndarray, T: float, system: FrictionModel | None = None):
        """Φ(s0, T) and the run's transitions (:func:`.section.flow`), of ``system`` if given."""
        self.counter["simulations"] += 1
        cap = None if self.max_steps_per_second is None else int(self.max_steps_per_second * max(T, 1.0))
        return flow(self.system if system is None else system, s0, T, rtol=self.rtol, atol=self.atol, max_steps=cap)

    def residual(self, s: np.ndarray, T: float, system: FrictionModel | None = None):
        """F (2 n_free,) [σ], the end state Φ(s, T) and the run's transitions."""
        end, tr = self.flow(s, T, system)
        return (end[self.free] - s[self.free]) / self.sigma, end, tr

    def state(self, z: np.ndarray) -> np.ndarray:
        """The state on the section (2n,) of the unknowns ``z`` [σ]."""
        s = np.zeros(2 * self.system.n)
        k = self.unknown
        s[self.free[k]] = z * self.sigma[k]
        s[self.section.index] = self.section.value
        return self.complete(s)

    def unknowns(self, s: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`state`: the unknown states of ``s`` in units of σ."""
        k = self.unknown
        return s[self.free[k]] / self.sigma[k]

    # ------------------------------------------------------------------ derivatives
    def fd_monodromy(self, s0: np.ndarray, T: float, cols=None, system: FrictionModel | None = None) -> np.ndarray:
        """∂Φ(s0, T)/∂s0 by central differences (steps ``fd_step`` σ), free rows × ``cols``
        (positions in :attr:`free`; default all): two flow maps a column."""
        return central_differences(lambda s: self.flow(self.complete(s), T, system)[0], s0, self.free,
                                   self.fd_step * self.sigma, cols)

    def monodromy(self, s0: np.ndarray, T: float, method: str = "saltation", system: FrictionModel | None = None):
        """∂Φ(s0, T)/∂s0 on the free states (2 n_free × 2 n_free) of ``system`` (default: the
        problem's) and the jumps applied (``saltation``: :func:`.linear_flow.flow_jacobian`, which
        raises where it cannot follow the event sequence; ``finite-difference``: :meth:`fd_monodromy`,
        no jumps)."""
        if method == "saltation":
            self.counter["simulations"] += 1
            fj = _lin.flow_jacobian(self.system if system is None else system, s0, T, scale=self._check_scale(),
                                    rtol=self.rtol, atol=self.atol)
            if self.constraint is None:
                return fj.matrix[np.ix_(self.free, self.free)], fj.events
            return fj.matrix[self.free] @ self.embedding, fj.events
        return self.fd_monodromy(s0, T, system=system), ()

    def monodromy_columns(self, s0: np.ndarray, T: float, method: str, cols=None,
                          system: FrictionModel | None = None) -> np.ndarray:
        """∂Φ(s0, T)/∂s0 on the free rows and the columns ``cols`` (positions in :attr:`free`;
        default all) by ``method``; ``saltation`` falls back to differences where the variational
        re-integration fails (e.g. an iterate whose event sequence differs from the integrator's,
        an impact that ends in stick)."""
        if method == "saltation":
            try:
                M = self.monodromy(s0, T, method, system)[0]
                return M if cols is None else M[:, cols]
            except (OrbitError, SimulationError, ArithmeticError, np.linalg.LinAlgError):
                pass
        return self.fd_monodromy(s0, T, cols, system)

    def newton_columns(self, s0: np.ndarray, T: float, method: str) -> np.ndarray:
        """∂Φ(s0, T)/∂s0 on the free rows and the unknown columns by ``method``
        (:meth:`monodromy_columns`)."""
        return self.monodromy_columns(s0, T, method, self.unknown)

    def jacobian(self, columns: np.ndarray, end: np.ndarray, system: FrictionModel | None = None,
                 T_scale: float = 1.0) -> np.ndarray:
        """∂F/∂(z, T/T_scale) (2 n_free × n_unknown + 1) from ∂Φ/∂s0 on the unknown ``columns``.

        The state columns are (∂Φ/∂s0 − I) in units of σ; the T column is exact, f(Φ) from the
        vector field (of ``system`` if given) times ``T_scale`` [s].
        """
        free, sigma, k = self.free, self.sigma, self.unknown
        A = np.empty((free.size, k.size + 1))
        A[:, :-1] = (columns - np.eye(free.size)[:, k]) * sigma[k][None, :] / sigma[:, None]
        A[:, -1] = vector_field(self.system if system is None else system, end)[free] / sigma * T_scale
        return A

    # ------------------------------------------------------------------ Newton
    def newton(self, s0: np.ndarray, T: float, *, tol: float, max_iter: int, method: str) -> NewtonResult:
        """Solve F(s, T) = 0 from (s0, T): least-squares Newton steps, halved while the residual grows.

        Raises
        ------
        OrbitError
            No convergence to max |F| ≤ ``tol`` in ``max_iter`` iterations, or a step that no
            halving makes reduce the residual (the message gives the residual history).
        """
        sigma, moved = self.sigma, self.free[self.unknown]
        R, end, tr = self.residual(s0, T)
        history = [float(np.max(np.abs(R)))]
        it = 0
        while history[-1] > tol:
            if it >= max_iter:
                raise OrbitError(
                    f"Newton did not converge in {max_iter} iterations (scaled residuals "
                    f"{', '.join(f'{r:.2e}' for r in history)}; tol {tol:.1e}). The orbit may be "
                    "non-periodic, or the guess too far: give a guess closer to the orbit or raise max_iter"
                )
            A = self.jacobian(self.newton_columns(s0, T, method), end)
            step = np.linalg.lstsq(A, -R, rcond=None)[0]
            lam = 1.0
            for _ in range(MAX_HALVINGS + 1):
                s_new = s0.copy()
                s_new[moved] += lam * step[:-1] * sigma[self.unknown]
                s_new = self.complete(s_new)
                T_new = T + lam * step[-1]
                try:
                    R_new, end_new, tr_new = self.residual(s_new, T_new)
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
        return NewtonResult(s0, float(T), R, end, tr, history, it)

    # ------------------------------------------------------------------ perturbations
    def perturbed(self, s: np.ndarray, direction: np.ndarray, d: float) -> np.ndarray:
        """``s`` moved by ``d`` along the σ-scaled ``direction`` (2 n_free,); projected onto v_c = 0
        for the contacts at rest in ``s`` (a perturbed stuck state sticks too, so this is the dynamics' own first
        instant, and the integrator need not resolve a 1e-9 m/s slip against the constraint), and
        kept where the rigid contacts let a motion start (:func:`.layout.rigid_admissible`)."""
        sp = s.copy()
        sp[self.free] += d * direction * self.sigma
        if self.system.rigid:
            sp[:2 * self.system.n] = rigid_admissible(self.system, s[:2 * self.system.n], sp[:2 * self.system.n])
        at_rest = resting_contacts(self.system, s)
        if np.any(at_rest[::CST] == MODE_STICK):
            sp = stick_projected(self.system, sp, at_rest)
        return sp


# ----------------------------------------------------------------------- monodromy of an orbit
class Multipliers:
    """Floquet-multiplier properties of a result with a ``multipliers`` array (decreasing modulus)."""

    multipliers: np.ndarray

    @property
    def trivial_multiplier(self) -> complex:
        """The multiplier closest to 1 (the shift along the orbit) [-]."""
        return complex(self.multipliers[np.argmin(np.abs(self.multipliers - 1.0))])

    @property
    def nontrivial_multipliers(self) -> np.ndarray:
        """All multipliers but the trivial one, by decreasing modulus [-]."""
        return nontrivial(self.multipliers)

    @property
    def verdict(self) -> str:
        """``stable``, ``marginal`` or ``unstable`` (:func:`floquet_verdict`)."""
        return floquet_verdict(self.multipliers)

    @property
    def stable(self) -> bool:
        """True if every non-trivial multiplier lies inside the unit circle (by more than
        :func:`multiplier_tolerance`: a neutral cycle is marginal, not stable)."""
        return self.verdict == "stable"


def multiplier_variables(multipliers: np.ndarray, dims) -> dict:
    """Dataset variables (real part, imaginary part, modulus) of Floquet multipliers over ``dims``."""
    return {
        "multiplier_real": (dims, multipliers.real, {"long_name": "Floquet multiplier, real part", "units": "1"}),
        "multiplier_imag": (dims, multipliers.imag, {"long_name": "Floquet multiplier, imaginary part", "units": "1"}),
        "multiplier_abs": (dims, np.abs(multipliers), {"long_name": "Floquet multiplier modulus", "units": "1"}),
    }


@dataclasses.dataclass(frozen=True, eq=False)
class Monodromy(ModelResult, Multipliers):
    """Monodromy matrix and Floquet multipliers of a periodic orbit.

    Parameters
    ----------
    matrix : ndarray (2 n_free, 2 n_free)
        ∂Φ(s0, T)/∂s0 on the free states [state units].
    multipliers : ndarray (2 n_free,) complex
        Its eigenvalues by decreasing modulus [-].
    method : str
        ``"saltation"`` (variational equations with jump matrices) or ``"finite-difference"``.
    period : float
        T [s].
    free_states : tuple of str
        Names of the free states (rows/columns of :attr:`matrix`).
    events : tuple of (float, str, int)
        Jumps applied (saltation only): (instant [s], kind, contact), kind one of ``"stick"``,
        ``"breakaway"``, ``"band"``, ``"reversal"``, ``"open"``, ``"close"``, ``"impact"``
        (as in :class:`stickslip.FlowJacobian`).
    wall_time : float
        Seconds taken.
    system : FrictionModel
        The model of the orbit.
    """

    matrix: np.ndarray
    multipliers: np.ndarray
    method: str
    period: float
    free_states: tuple
    events: tuple
    wall_time: float
    system: FrictionModel

    def to_xarray(self):
        """``xarray.Dataset``: matrix and multipliers, method and period as attributes."""
        import xarray as xr

        data = {
            "monodromy": (("free_state", "free_state_0"), self.matrix,
                          {"long_name": f"monodromy matrix d s(T) / d s(0) ({self.method})"}),
            **multiplier_variables(self.multipliers, "multiplier"),
        }
        attrs = {"title": "stickslip monodromy matrix", "stickslip_version": __version__,
                 "method": self.method, "period": self.period, "period_units": "s",
                 "wall_time_s": self.wall_time, "events": json.dumps(self.events), **model_attrs(self.system)}
        coords = {"free_state": list(self.free_states), "free_state_0": list(self.free_states)}
        return xr.Dataset(data, coords=coords, attrs=attrs)


def monodromy(orbit, method: str = "saltation", *, fd_step: float | None = None) -> Monodromy:
    """Monodromy matrix of a periodic orbit on its free states.

    Parameters
    ----------
    orbit : PeriodicOrbit
        From :func:`stickslip.orbits.periodic_orbit` (state, period, system, scale and the options
        rtol/atol/fd_step are used).
    method : {"saltation", "finite-difference"}
        ``saltation``: variational equations along the orbit with jump matrices at every
        transition (:func:`~stickslip.orbits.linear_flow.flow_jacobian`).
        ``finite-difference``: central differences of the flow map, two ``event`` runs per column
        (perturbed shooting).
    fd_step : float, optional
        Relative step of the finite differences (default: the orbit's).

    Returns
    -------
    Monodromy
    """
    check_method(method)
    t0 = _time.perf_counter()
    opt = orbit.options
    problem = ShootingProblem.build(orbit.system, sigma=orbit.scale, rtol=opt["rtol"], atol=opt["atol"],
                                    constraint=independent_states(orbit.system, orbit.state)[1],
                                    fd_step=opt.get("fd_step", DEFAULT_FD_STEP) if fd_step is None else fd_step)
    M, events = problem.monodromy(orbit.state, orbit.period, method)
    return Monodromy(matrix=M, multipliers=sorted_eigenvalues(M), method=method, period=float(orbit.period),
                     free_states=tuple(orbit.system.state_names[j] for j in problem.free), events=tuple(events),
                     wall_time=_time.perf_counter() - t0, system=orbit.system)
