"""Linear stability of steady sliding (paper Sect. 4.1, Eq. 15): eigen analysis of the Jacobian."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np

from .._version import __version__
from ..errors import EquilibriumError
from ..model.bundle import CST, contact_state
from ..model.derivatives import state_jacobian_from_python
from ..model.library.two_plates import plates_parameters
from ..model.matrices import dense_array
from ..model.parameters import Parameters, parameter_attrs
from ..model.physics import MODE_OPEN, MODE_SLIP_EXACT
from ..model.sparse_form import SparseForm
from ..model.variants import DOF_NAMES
from .band import BandError, band_stability
from .equilibrium import model_of, point_text, rigid_constraint, solve_steady_modes
from .sparse_input import is_sparse_model
from .verdict import MARGINAL_RTOL, stability_verdict

__all__ = ["StabilityResult", "stability", "linearization", "model_stability"]


@dataclasses.dataclass(frozen=True, eq=False)
class StabilityResult:
    """Linear stability of the steady-sliding equilibrium (paper Sect. 4.1).

    Parameters
    ----------
    params : Parameters or None
        The plates' parameters (None for other models: see ``system.parameters``).
    model : str
        The plates' variant (``full``, ``x``, ``y``, ``rotation`` or ``custom:...``) or the model's name.
    dofs : tuple of str
        The free DOFs, in q order; the reduced state is [dofs, d(dofs)/dt].
    equilibrium : ndarray (n,)
        q_e of every dof (for the plates [x1, y1, x2, y2, φ, ψ] [m, rad]); locked DOFs are 0.
    residual : float
        Relative residual of Eq. (14) at ``equilibrium`` (simulator kernel).
    jacobian : ndarray (2k, 2k)
        ∂(ds/dt)/∂s of the slip equations at (q_e, q̇ = 0), reduced to the k free DOFs [1/s, 1/s²].
    stiffness, damping : ndarray (k, k)
        K_L and C_L of Eq. (15) on the free DOFs (M_L is diagonal: ``mass``).
    mass : ndarray (k,) or (k, k)
        M_L on the free DOFs: its diagonal when M is diagonal (the plates) [kg, kg m²], else the matrix.
    eigenvalues : ndarray (2k,) complex
        Sorted by real part, descending (conjugate pairs: positive imaginary part first) [1/s].
        With m closed rigid contacts 2(k − m): those of the motion that keeps them closed (the
        constrained eigenproblem: ``jacobian`` restricted to W q = 0, W q̇ = 0).
    mode_shapes : ndarray (2k, k) complex
        Displacement part of each eigenvector, scaled so that its largest entry is 1 (real).
    system : FrictionModel, optional
        The model linearised.
    all_dofs : tuple of str
        Every dof of the model, free or locked, in q order (the order of ``equilibrium``).
    open_contacts : tuple of str
        The unilateral contacts that steady sliding leaves open (gap > 0 at ``equilibrium``): they
        carry no force there and contribute nothing to ``jacobian``.
    """

    params: Parameters
    model: str
    dofs: tuple[str, ...]
    equilibrium: np.ndarray
    residual: float
    jacobian: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    mass: np.ndarray
    eigenvalues: np.ndarray
    mode_shapes: np.ndarray
    system: object = None
    all_dofs: tuple[str, ...] = DOF_NAMES
    open_contacts: tuple[str, ...] = ()

    # ------------------------------------------------------------------ derived
    @property
    def growth_rates(self) -> np.ndarray:
        """Real parts of the eigenvalues [1/s] (positive: the mode grows)."""
        return self.eigenvalues.real

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Damped frequencies |Im λ| / 2π [Hz]."""
        return np.abs(self.eigenvalues.imag) / (2.0 * math.pi)

    @property
    def max_real_part(self) -> float:
        """Largest real part of the eigenvalues [1/s]; −inf where there are none (closed rigid
        contacts fix every free dof: no motion is left to grow)."""
        return float(self.eigenvalues.real[0]) if self.eigenvalues.size else -math.inf

    @property
    def tolerance(self) -> float:
        """Real parts within ±tolerance count as 0 [1/s]: :data:`MARGINAL_RTOL` × ‖J‖₂."""
        return MARGINAL_RTOL * float(np.linalg.norm(self.jacobian, 2)) if self.jacobian.size else 0.0

    @property
    def verdict(self) -> str:
        """``stable``, ``marginal`` or ``unstable`` (:func:`stability_verdict`)."""
        return stability_verdict(self.max_real_part, self.tolerance)

    @property
    def stable(self) -> bool:
        """True when every eigenvalue has a real part below −:attr:`tolerance` (asymptotically
        stable sliding); a centre (Re λ = 0 within the tolerance) is marginal, not stable."""
        return self.verdict == "stable"

    @property
    def equilibrium_dict(self) -> dict[str, float]:
        """``{dof name: value}`` of the equilibrium, every dof."""
        return {name: float(v) for name, v in zip(self.all_dofs, self.equilibrium)}

    def modes(self, *, one_per_pair: bool = True) -> list[dict]:
        """One dict per mode: eigenvalue, growth rate [1/s], frequency [Hz], dominant DOF, shape.

        With ``one_per_pair`` only the member with Im λ ≥ 0 of each conjugate pair is listed.
        """
        rows = []
        for j, lam in enumerate(self.eigenvalues):
            if one_per_pair and lam.imag < 0.0:
                continue
            shape = self.mode_shapes[j]
            rows.append({
                "index": j,
                "eigenvalue": complex(lam),
                "growth_rate": float(lam.real),
                "frequency_hz": float(abs(lam.imag) / (2.0 * math.pi)),
                "dominant_dof": self.dofs[int(np.argmax(np.abs(shape)))],
                "shape": {d: complex(c) for d, c in zip(self.dofs, shape)},
            })
        return rows

    def summary(self) -> dict:
        """JSON-ready summary: equilibrium (names → values), the contacts open there, eigenvalues
        [[re, im], ...], max_real_part, stable, verdict (stable | marginal | unstable) and the
        tolerance within which a real part counts as 0 (``marginal_tolerance`` [1/s])."""
        return {
            "model": self.model,
            "equilibrium": self.equilibrium_dict,
            "open_contacts": list(self.open_contacts),
            "eigenvalues": [[float(v.real), float(v.imag)] for v in self.eigenvalues],
            "max_real_part": self.max_real_part,
            "stable": bool(self.stable),
            "verdict": self.verdict,
            "marginal_tolerance": self.tolerance,
            **({} if self.eigenvalues.size else
               {"max_real_part_reason": "no eigenvalues: the closed contacts fix every free dof"}),
        }

    def to_xarray(self):
        """``xarray.Dataset`` with units, long names and the full parameter set in attrs."""
        import xarray as xr

        states = list(self.dofs) + ["d" + d for d in self.dofs]
        data = {
            "equilibrium": ("dof_all", self.equilibrium,
                            {"long_name": "steady-sliding equilibrium q_e (Eq. 14)", "units": "m or rad"}),
            "eigenvalue_real": ("mode", self.eigenvalues.real, {"units": "1/s", "long_name": "growth rate Re(lambda)"}),
            "eigenvalue_imag": ("mode", self.eigenvalues.imag, {"units": "rad/s", "long_name": "Im(lambda)"}),
            "frequency": ("mode", self.frequencies_hz, {"units": "Hz", "long_name": "damped frequency |Im(lambda)|/(2 pi)"}),
            "mode_shape_real": (("mode", "dof"), self.mode_shapes.real, {"long_name": "mode shape (displacements), real part"}),
            "mode_shape_imag": (("mode", "dof"), self.mode_shapes.imag, {"long_name": "mode shape (displacements), imaginary part"}),
            "jacobian": (("state", "state_col"), self.jacobian, {"long_name": "Jacobian of the slip equations at q_e"}),
            "stiffness_L": (("dof", "dof_col"), self.stiffness, {"long_name": "K_L of Eq. (15)"}),
            "damping_L": (("dof", "dof_col"), self.damping, {"long_name": "C_L of Eq. (15)"}),
            "mass_L": (("dof",) if self.mass.ndim == 1 else ("dof", "dof_col"), self.mass, {"long_name": "M_L of Eq. (15)"}),
        }
        coords = {
            "mode": ("mode", np.arange(self.eigenvalues.size)),
            "dof": ("dof", list(self.dofs)),
            "dof_col": ("dof_col", list(self.dofs)),
            "dof_all": ("dof_all", list(self.all_dofs)),
            "state": ("state", states),
            "state_col": ("state_col", states),
        }
        attrs = {
            "title": "stickslip linear stability of steady sliding",
            "stickslip_version": __version__,
            "model": self.model,
            "max_real_part": self.max_real_part,
            "max_real_part_units": "1/s",
            "stable": int(self.stable),
            "verdict": self.verdict,
            "marginal_tolerance": self.tolerance,
            "equilibrium_residual": self.residual,
            "parameters": json.dumps(self.params.to_dict() if self.params is not None else dict(self.system.parameters)),
        }
        if self.params is not None:
            attrs.update(parameter_attrs(self.params.to_dict()))
        return xr.Dataset(data, coords=coords, attrs=attrs)


def linearization(system, q: np.ndarray, open_contacts=()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jacobian of the slip equations of any model at (q, q̇ = 0), reduced to the free DOFs (for
    the plates: Eq. 15 with K_L and C_L of the Appendix), with the contacts ``open_contacts`` open.

    The complex-step Jacobian of the simulator's own right-hand side.

    Returns
    -------
    jacobian : ndarray (2k, 2k)
        ∂(ds/dt)/∂s on [q_free, q̇_free] [1/s², 1/s].
    K_L, C_L : ndarray (k, k)
        −M ∂q̈/∂q and −M ∂q̈/∂q̇ on the free DOFs.
    """
    n = system.n
    s = np.zeros(2 * n)
    s[:n] = q
    cst = contact_state(system.data.m)
    cst[0::CST] = MODE_SLIP_EXACT
    for c in open_contacts:
        cst[CST * c] = MODE_OPEN
    J_full = state_jacobian_from_python(s, cst, system.data)
    free = np.flatnonzero(system.free)
    k = free.size
    idx = np.concatenate([free, n + free])
    J = J_full[np.ix_(idx, idx)]
    M = dense_array(system.mass)[np.ix_(free, free)]
    return J, -M @ J[k:, :k], -M @ J[k:, k:]


def stability(model=None, *, max_frequency: float | None = None, method: str | None = None,
              cutoff: float | None = None, residual: bool = True):
    """Linear stability of steady sliding (paper Sect. 4.1) of any friction model.

    Finds the steady-sliding equilibrium (Eq. 14 for the plates), linearises the slip equations
    about it (Eq. 15) with the exact Jacobian of the simulator's right-hand side (complex-step
    differentiation), and takes the eigenvalues.

    A model of sparse matrices (finite elements), or a call with ``max_frequency``, takes the
    sparse path instead (:func:`~stickslip.stability.band.band_stability`): steady sliding by one
    sparse solve and every eigenvalue of a band by complex eigenvalue analysis.

    Parameters
    ----------
    model : FrictionModel, Parameters or str, optional
        The model, as :func:`stickslip.simulate` takes it: any model (a FrictionModel, a library
        name or a model file path) or the plates' parameters (default Table 1; in a variant:
        ``two_plates(params, "rotation")``, Model 4). The Jacobian is reduced to the free DOFs.
    max_frequency : float, optional
        The band's top ω_max [rad/s] of the sparse path (required for a sparse model).
    method : {"direct", "modal", "dense"}, optional
        The sparse path's method (default ``direct``).
    cutoff : float, optional
        The real modes' cutoff of ``modal`` [rad/s] (default 2 ω_max).
    residual : bool
        ``modal``: the residual vectors of the contact rows beside the modes (default).

    Returns
    -------
    StabilityResult, or BandStability on the sparse path

    Raises
    ------
    EquilibriumError
        No steady sliding (Ω = 0, Newton failure), a sliding speed at equilibrium inside the
        simulator's low-speed band, where its slip direction is not v/|v|, or a Jacobian that
        overflows (values far outside physical size).
    BandError
        A sparse model without ``max_frequency``, or a band that holds no eigenvalue.
    """
    system = model if isinstance(model, SparseForm) else model_of(model)
    if max_frequency is None and method is None and cutoff is None and not is_sparse_model(system):
        return model_stability(system)
    if max_frequency is None:
        raise BandError(f"model {system.name!r} has {system.n} dofs: give max_frequency (--max-frequency), the top "
                        "of the band whose eigenvalues its sparse analysis computes [rad/s]")
    return band_stability(system, max_frequency, method=method or "direct", cutoff=cutoff, residual=residual)


def model_stability(system) -> StabilityResult:
    """:func:`stability` of a :class:`~stickslip.model.FrictionModel`."""
    q, residual, _, opened = solve_steady_modes(system)
    J, K_L, C_L = linearization(system, q, opened)
    if not np.all(np.isfinite(J)):
        raise EquilibriumError(f"the linearisation at steady sliding is not finite ({point_text(system)}: overflow); "
                               "give values of physical size")
    free = np.flatnonzero(system.free)
    k = free.size
    basis = np.eye(k)
    if system.rigid:
        # the closed rigid contacts hold W q = −g0 and W q̇ = 0, an invariant subspace of the
        # linearised flow (J T = T Tᵀ J T): its eigenvalues are those of Tᵀ J T, T = diag(Z, Z)
        basis = rigid_constraint(system, exclude=opened)[1][free]
    T = np.kron(np.eye(2), basis)
    lam, vec = np.linalg.eig(T.T @ J @ T)
    order = np.lexsort((-lam.imag, -lam.real))  # real part descending, then Im descending
    lam = lam[order]
    vec = T @ vec[:, order]
    shapes = vec[:k, :].T.copy()
    for j in range(shapes.shape[0]):
        m = int(np.argmax(np.abs(shapes[j])))
        if shapes[j, m] != 0:
            shapes[j] /= shapes[j, m]
    M = dense_array(system.mass)[np.ix_(free, free)]
    diagonal = np.count_nonzero(M - np.diag(np.diag(M))) == 0
    return StabilityResult(
        params=plates_parameters(system), model=system.label or system.name,
        dofs=tuple(system.dofs[i] for i in free), equilibrium=q, residual=residual, jacobian=J,
        stiffness=K_L, damping=C_L, mass=np.diag(M).copy() if diagonal else M, eigenvalues=lam,
        mode_shapes=shapes, system=system, all_dofs=tuple(system.dofs),
        open_contacts=tuple(system.contact_names[c] for c in opened),
    )
