"""Jump matrices of the variations at the transitions of any friction-contact model.

Each is built from the one generic definition: the vector fields f⁻, f⁺ are the right-hand side
:func:`stickslip.model.physics.rhs` in the modes before and after, and the event gradients are
complex steps of the contact's slip velocity, friction and normal force
(:func:`.var_kernels.contact_gradients`). With h the event function of the transition,

    S = I + (f⁺ − f⁻) ∇hᵀ / (∇h · f⁻)                                   (saltation matrix)

* **stick → slip** of contact c (:func:`breakaway_jump`): h = μs N_c − |F_c|, F_c the stick
  multiplier solved with the other sticking contacts; f⁺ slips along e = −F_c/|F_c|.
* **leaving the low-speed band** of a 2-D contact (:func:`band_exit_jump`): h = |v_c| − band,
  f⁻ with the quasi-static direction, f⁺ with the exact one.
* **slip → stick of a 1-D contact** (:func:`arrival_jump` with ``dim`` 1): h = e·v_c. Since
  ∇h·f⁺ = dv_c/dt in stick = 0, S maps every variation onto ∇h·δs = 0, the stick manifold; the
  linearised projection :func:`stick_projection` after it only removes round-off.
* **slip → stick of a 2-D contact** (``dim`` 2; the integration stops at |v_c| = ρ_c): the
  friction direction's dynamics remove the variation β = u·δv_c transverse to the arrival
  direction e through a friction impulse B u J, J = −β/(uᵀ A u) (A = G_c M̃⁻¹ G_cᵀ, B = [0; M̃⁻¹ G_cᵀ],
  M̃⁻¹ the inverse mass with the other sticking contacts held); then the rest of the approach to
  first order, I + τ J_reg (τ = ρ_c / (−e·v̇_c), J_reg the Jacobian with the direction frozen);
  then S with h = e·v_c; then the projection onto the stick manifold. docs/orbits.md derives it.
* **velocity reversal** (v_c reaches 0 where stick cannot hold, so slip departs again along the
  breakaway direction, not a recorded transition): the same without projection and with f⁺ the
  departing slip field.
* **a unilateral contact opens or closes** (:func:`gap_jump`): h = φ, the contact's open/closed
  indicator (:mod:`stickslip.model.normal`); the state is continuous and the field jumps (with
  contact damping the normal force jumps to −c ġ at closing); f⁺ open, or sliding. A closed
  rigid contact's indicator is its normal force λ, continuous through 0 at opening.
* **an impact of a rigid contact** (:func:`impact_jump`): the state jumps, s⁺ = Π(s⁻) (Newton's
  restitution, the Coulomb impulse; :mod:`stickslip.model.impact`), so

      S = R + (f⁺ − R f⁻) ∇gᵀ / (∇g · f⁻),    R = ∂Π/∂s

  (Leine & Nijmeijer 2004, ch. 3), with h = g the gap, R by central differences of the compiled
  impact map (linear in the velocities for constant G and W, so exact to round-off there; the
  velocity steps stay under half the one that reverses ġ⁻, where the map has a kink), f⁺ at
  s⁺ in the modes after (bounced off: open; stayed: sliding). The variations enter it at the
  run's recorded impact instant (:mod:`.linear_flow`): S divides by ġ⁻, so the variations and
  the state it is built at must be taken at one instant.
"""

from __future__ import annotations

import numpy as np

from ..errors import OrbitError
from ..integrate import contacts as E
from ..model import physics as P
from ..model.bundle import CST
from ..model.derivatives import state_jacobian_from_python
from ..model.friction import static_coefficient
from ..model.impact import IMPACT_INCONSISTENT, gap_rate, impact, restitution_of
from ..model.matrices import dense_array
from .var_kernels import contact_gradients, indicator_gradient

__all__ = ["saltation_matrix", "field", "ContactState", "contact_at", "stick_projection", "breakaway_jump",
           "band_exit_jump", "arrival_jump", "gap_jump", "impact_jump", "impact_map", "sliding_after_closing",
           "inverse_mass", "sticking", "with_mode"]


def saltation_matrix(f_minus: np.ndarray, f_plus: np.ndarray, grad_h: np.ndarray, jump=None) -> np.ndarray:
    """S = R + (f⁺ − R f⁻) ∇hᵀ / (∇h · f⁻) (2n × 2n) for a transversal crossing of h(s) = 0.

    Parameters
    ----------
    f_minus, f_plus : ndarray (2n,)
        Vector fields before and after the event (f⁺ at the state after a jump) [state units / s].
    grad_h : ndarray (2n,)
        Gradient of the event function [unit of h per state unit].
    jump : ndarray (2n, 2n), optional
        R, the Jacobian of the state's jump at the event (an impact); None: the state is
        continuous, R = I.

    Raises
    ------
    OrbitError
        If the crossing is tangential (∇h · f⁻ = 0): no saltation matrix exists (grazing).
    """
    rate = float(grad_h @ f_minus)
    if rate == 0.0 or not np.isfinite(rate):
        raise OrbitError("tangential event crossing (dh/dt = 0): grazing, no saltation matrix")
    R = np.eye(f_minus.size) if jump is None else jump
    return R + np.outer(f_plus - R @ f_minus, grad_h) / rate


def field(system, s: np.ndarray, cst: np.ndarray) -> np.ndarray:
    """Right-hand side f(s) (2n,) in the modes of ``cst`` [state units / s]."""
    ds = np.zeros(2 * system.n)
    P.rhs(np.ascontiguousarray(s[:2 * system.n], dtype=float), cst, system.data, ds)
    return ds


def with_mode(cst: np.ndarray, c: int, mode: int, e=(1.0, 0.0)) -> np.ndarray:
    """A copy of the contact states with contact ``c`` in ``mode`` along the direction ``e``."""
    out = cst.copy()
    out[CST * c] = mode
    out[CST * c + 1] = e[0]
    out[CST * c + 2] = e[1]
    out[CST * c + 3] = np.inf
    return out


def sticking(cst: np.ndarray, exclude: int = -1) -> list[int]:
    """Contacts that stick in ``cst``, without ``exclude``."""
    return [c for c in range(cst.size // CST) if int(cst[CST * c]) == P.MODE_STICK and c != exclude]


class ContactState:
    """One contact at a state: values and complex-step gradients (module docstring).

    Attributes
    ----------
    v, F : ndarray (2,)
        Slip velocity [m/s] and friction force [N] (the stick multiplier if it sticks).
    N : float
        Normal force [N].
    Dv, DF : ndarray (2, 2n)
        ∂v/∂s and ∂F/∂s.
    DN : ndarray (2n,)
        ∂N/∂s.
    """

    def __init__(self, system, s, cst, c):
        n2 = 2 * system.n
        nc = system.n_contacts
        s = np.ascontiguousarray(s[:n2], dtype=float)
        F = np.empty(2 * nc)
        N = np.empty(nc)
        v = np.empty(2 * nc)
        P.contact_forces(s, cst, system.data, F, N, v)
        self.v, self.F, self.N = v[2 * c:2 * c + 2].copy(), F[2 * c:2 * c + 2].copy(), float(N[c])
        self.Dv, self.DF, self.DN = np.empty((2, n2)), np.empty((2, n2)), np.empty(n2)
        contact_gradients(s, cst, c, system.data, n2, self.Dv, self.DF, self.DN, np.empty(n2, complex),
                          np.empty(2 * nc, complex), np.empty(nc, complex), np.empty(2 * nc, complex))
        self.dim = system.contacts[c].dim


def contact_at(system, s, cst, c) -> ContactState:
    """:class:`ContactState` of contact ``c`` at ``s`` in the modes of ``cst``."""
    return ContactState(system, s, cst, c)


def inverse_mass(system) -> np.ndarray:
    """M⁻¹ (n × n) on the free DOFs, zero rows and columns for the locked ones."""
    free = np.flatnonzero(system.free)
    Minv = np.zeros((system.n, system.n))
    Minv[np.ix_(free, free)] = np.linalg.inv(dense_array(system.mass)[np.ix_(free, free)])
    return Minv


def _rows(system, s, cst, contacts) -> np.ndarray:
    """∂v/∂s of the given contacts, stacked (k × 2n; one row per slip direction)."""
    rows = [contact_at(system, s, cst, c).Dv[:system.contacts[c].dim] for c in contacts]
    return np.concatenate(rows) if rows else np.zeros((0, 2 * system.n))


def _held_inverse_mass(system, Minv, Dv_held) -> np.ndarray:
    """M̃⁻¹ = M⁻¹ − M⁻¹ G_Sᵀ (G_S M⁻¹ G_Sᵀ)⁺ G_S M⁻¹: the response to a force with the contacts S held."""
    if Dv_held.shape[0] == 0:
        return Minv
    n = system.n
    G = Dv_held[:, n:]
    A = G @ Minv @ G.T
    return Minv - Minv @ G.T @ np.linalg.pinv(A, rcond=P.RANK_TOL, hermitian=True) @ G @ Minv


def stick_projection(system, s: np.ndarray, cst: np.ndarray) -> np.ndarray:
    """Linearised projection onto the stick manifold of the sticking contacts of ``cst`` (2n × 2n):
    P = I − [0; M⁻¹ G_Sᵀ A⁺ ∂v_S/∂s], the derivative of :func:`stickslip.model.physics.project_velocities`
    on v_S = 0 (A = G_S M⁻¹ G_Sᵀ, minimal-norm inverse where it is rank-deficient)."""
    n = system.n
    Dv = _rows(system, s, cst, sticking(cst))
    out = np.eye(2 * n)
    if Dv.shape[0] == 0:
        return out
    Minv = inverse_mass(system)
    G = Dv[:, n:]
    A = G @ Minv @ G.T
    out[n:] -= Minv @ G.T @ np.linalg.pinv(A, rcond=P.RANK_TOL, hermitian=True) @ Dv
    return out


def breakaway_jump(system, s_b: np.ndarray, cst: np.ndarray, c: int):
    """Saltation matrix (2n × 2n) at stick → slip of contact ``c`` at ``s_b`` (``cst``: c sticks),
    h = μs N_c − |F_c|, after the projection onto the stick manifold (removes constraint drift of
    the stick variations). Returns (S, the contact states after: c slips along −F_c/|F_c|)."""
    k = contact_at(system, s_b, cst, c)
    mu_s = static_coefficient(system.contacts[c].friction.row())
    norm = float(np.hypot(*k.F))
    e = E.breakaway_direction(k.F[0], k.F[1], k.dim)
    grad_h = mu_s * k.DN - (k.F @ k.DF) / norm
    after = with_mode(cst, c, P.MODE_SLIP_QUASI_STATIC, e)
    S = saltation_matrix(field(system, s_b, cst), field(system, s_b, after), grad_h)
    return S @ stick_projection(system, s_b, cst), after


def gap_jump(system, s: np.ndarray, cst: np.ndarray, c: int):
    """Saltation matrix (2n × 2n) where unilateral contact ``c`` opens (closed in ``cst``) or
    closes (open in ``cst``) at ``s``: h = its open/closed indicator. A contact that closes slides
    (a 1-D one along sign(v_c), a 2-D one along v_c/|v_c|); one that opens from stick leaves its
    stick manifold (the projection onto it first). Returns (S, the contact states after).

    Raises
    ------
    OrbitError
        If the contact closes with v_c = 0 (stick at closing has no jump matrix here) or grazes.
    """
    n2 = 2 * system.n
    s = np.ascontiguousarray(s[:n2], dtype=float)
    grad_h = np.empty(n2)
    indicator_gradient(s, cst, c, system.data, n2, grad_h, np.empty(n2, dtype=np.complex128))
    projection = stick_projection(system, s, cst)
    after = sliding_after_closing(system, s, cst, c) if int(cst[CST * c]) == P.MODE_OPEN else \
        with_mode(cst, c, P.MODE_OPEN)
    S = saltation_matrix(field(system, s, cst), field(system, s, after), grad_h)
    return S @ projection, after


def sliding_after_closing(system, s: np.ndarray, cst: np.ndarray, c: int) -> np.ndarray:
    """The contact states after contact ``c`` closes at ``s`` (after an impact: the state after it)
    and slides: a 1-D contact along sign(v_c), a 2-D one along v_c/|v_c|.

    Raises
    ------
    OrbitError
        If it closes with v_c ≈ 0 (into stick: no jump matrix here).
    """
    v = np.array(P.slip_velocity(np.ascontiguousarray(s, dtype=float), c, system.data))
    speed = float(np.hypot(*v))
    if speed <= E.STICK_SPEED_TOL:
        raise OrbitError(f"contact {c} closes with slip velocity {speed:.1e} m/s (v ≈ 0): stick at closing has "
                         "no saltation matrix here; use the finite-difference monodromy")
    if system.contacts[c].dim == 1:
        return with_mode(cst, c, P.MODE_SLIP_QUASI_STATIC, (float(np.sign(v[0])), 0.0))
    return with_mode(cst, c, P.MODE_SLIP_EXACT, tuple(v / speed))


def impact_map(system, s: np.ndarray, cst: np.ndarray, c: int) -> np.ndarray:
    """Π(s): the state (2n,) right after the impact of rigid contact ``c`` (open in ``cst``) at ``s``."""
    out = np.ascontiguousarray(s[:2 * system.n], dtype=float).copy()
    if impact(out, cst, c, system.data, restitution_of(c, system.data))[0] == IMPACT_INCONSISTENT:
        raise OrbitError(f"contact {c}'s impact has no consistent impulse (Painlevé): no saltation matrix")
    return out


def _impact_step(value: float, normal_rate: float, landing: float) -> float:
    """Step of the central difference of the impact map in a state of ``value`` that changes the
    landing speed ``landing`` = |ġ⁻| by ``normal_rate`` per unit: 1e-7 max(1, |value|), at most half
    the step that reverses ġ⁻. Π has a kink at ġ⁻ = 0 (a contact that does not approach gets no
    impulse), and a difference straddling it mixes the two branches: on the rigid slider near its
    flight's vanishing (ġ⁻ = −8.7e-8) a velocity step of 1e-7 gives ∂ẏ⁺/∂ẏ⁻ = 0.07 instead of 0
    (plastic) and a multiplier −98."""
    h = 1e-7 * max(1.0, abs(value))
    return min(h, 0.5 * landing / abs(normal_rate)) if normal_rate != 0.0 else h


def impact_jump(system, s: np.ndarray, cst: np.ndarray, c: int, bounced: bool):
    """Saltation matrix (2n × 2n) of the impact of rigid contact ``c`` (open in ``cst``) at ``s``
    (module docstring); ``bounced``: whether it leaves the stop again (open after), else it stays
    closed and slides. Returns (S, the contact states after).

    Raises
    ------
    OrbitError
        If it stays closed with v_c = 0 (stick at an impact has no jump matrix here) or grazes.
    """
    n2 = 2 * system.n
    s = np.ascontiguousarray(s[:n2], dtype=float)
    after_state = impact_map(system, s, cst, c)
    landing = abs(gap_rate(s, c, system.data))
    if landing == 0.0:
        raise OrbitError(f"contact {c} touches its stop with ġ = 0 (grazing): no saltation matrix")
    normal = np.zeros(n2)  # ∂ġ/∂s: the gap's gradient W_c on the velocities (the gap is affine in q)
    for j in range(system.n, n2):
        unit = np.zeros(n2)
        unit[j] = 1.0
        normal[j] = gap_rate(unit, c, system.data)
    R = np.empty((n2, n2))
    for j in range(n2):
        h = _impact_step(s[j], normal[j], landing)
        up, down = s.copy(), s.copy()
        up[j] += h
        down[j] -= h
        R[:, j] = (impact_map(system, up, cst, c) - impact_map(system, down, cst, c)) / (2.0 * h)
    after = cst.copy() if bounced else sliding_after_closing(system, after_state, cst, c)
    grad_h = np.empty(n2)
    indicator_gradient(s, cst, c, system.data, n2, grad_h, np.empty(n2, dtype=np.complex128))
    S = saltation_matrix(field(system, s, cst), field(system, after_state, after), grad_h, jump=R)
    return S @ stick_projection(system, s, cst), after


def band_exit_jump(system, s: np.ndarray, cst: np.ndarray, c: int):
    """Saltation matrix (2n × 2n) where 2-D contact ``c`` leaves the low-speed band (h = |v_c| − band):
    the slip force switches from the quasi-static to the exact direction. Returns (S, contact states after)."""
    k = contact_at(system, s, cst, c)
    speed = float(np.hypot(*k.v))
    grad_h = (k.v / speed) @ k.Dv
    after = with_mode(cst, c, P.MODE_SLIP_EXACT, tuple(k.v / speed))
    return saltation_matrix(field(system, s, cst), field(system, s, after), grad_h), after


def arrival_jump(system, s_c: np.ndarray, cst: np.ndarray, c: int, s_stick: np.ndarray, departure=None):
    """Jump matrix (2n × 2n) of the variations at slip → stick of contact ``c`` (module docstring).

    Parameters
    ----------
    s_c : ndarray (2n,)
        Where the re-integration stopped: v_c = 0 (1-D contact) or |v_c| = ρ_c (2-D).
    cst : ndarray
        Contact states before (c slipping).
    s_stick : ndarray (2n,)
        The event integrator's state at the onset of stick (on the stick manifold).
    departure : tuple, optional
        For a velocity reversal, the breakaway direction e_b along which slip departs again: f⁺ is
        that slip field and there is no projection.

    Returns
    -------
    jump : ndarray (2n × 2n)
    after : ndarray
        Contact states after (c sticks, or slips along ``departure``).
    """
    n2 = 2 * system.n
    k = contact_at(system, s_c, cst, c)
    after = (with_mode(cst, c, P.MODE_STICK, (0.0, 0.0)) if departure is None
             else with_mode(cst, c, P.MODE_SLIP_QUASI_STATIC, departure))
    f_minus = field(system, s_c, cst)
    f_plus = field(system, s_c, after)
    pre = np.eye(n2)
    if k.dim == 1:
        e = np.array([float(cst[CST * c + 1]), 0.0])
        grad_h = e @ k.Dv
    else:
        speed = float(np.hypot(*k.v))
        e = k.v / speed
        u = np.array([-e[1], e[0]])
        n = system.n
        Minv = _held_inverse_mass(system, inverse_mass(system), _rows(system, s_c, cst, sticking(cst, c)))
        G = k.Dv[:, n:]
        A = G @ Minv @ G.T
        B = np.zeros((n2, 2))
        B[n:] = Minv @ G.T
        grad_h = e @ k.Dv
        auu = float(u @ A @ u)
        if auu > P.RANK_TOL * np.trace(A):  # rank 1: friction cannot act along u, and β ≡ 0
            pre = pre - np.outer(B @ u, u @ k.Dv) / auu
        approach = -float(grad_h @ f_minus)  # −e·dv/dt > 0 on an approach
        if not approach > 0.0:
            raise OrbitError("the slip velocity does not head into zero at the stick arrival (grazing); "
                             "no saltation matrix")
        mu = -float(e @ k.F) / k.N  # the friction coefficient at |v_c|
        J = state_jacobian_from_python(s_c[:n2], cst, system.data)
        # the slip Jacobian without the rotation of the friction direction, −μN (I − e eᵀ)/|v| ∂v/∂s
        J_reg = J + B @ (mu * k.N / speed * (np.eye(2) - np.outer(e, e))) @ k.Dv
        pre = (np.eye(n2) + speed / approach * J_reg) @ pre
    S = saltation_matrix(f_minus, f_plus, grad_h)
    if departure is not None:
        return S @ pre, after
    return stick_projection(system, s_stick, after) @ S @ pre, after
