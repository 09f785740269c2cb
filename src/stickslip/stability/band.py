"""Stability of steady sliding over a frequency band: the CEA of sparse (finite-element) models.

:func:`band_stability` finds steady sliding by one sparse solve (:mod:`.sparse_sliding`) and
every eigenvalue of its linearisation with |Im λ| ≤ ω_max, by one of

``direct``  shift-invert Arnoldi on the full first-order pencil (:func:`~.cea.band_eigen`);
``modal``   the projection on the real modes below a cutoff and the residual vectors of the
            contact rows, refined on the full pencil (:func:`~.modal_cea.modal_cea`), with the
            convergence as modes are added;
``dense``   every eigenvalue by LAPACK (a few thousand DOFs at most: checked against memory).

Every eigenvalue reported is one of the full model (with its backward error on the full pencil);
the result (:class:`BandStability`) writes the unstable modes' shapes to NetCDF and, where the
model gives node coordinates, to VTK for ParaView (:meth:`BandStability.write_vtk`).
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np

from .._version import __version__
from ..errors import StickSlipError
from ..memory import check_memory, format_bytes
from .cea import REAL_MARGIN, BandEigen, backward_errors, band_eigen, dense_eigen, frictionless_count, sorted_eigen
from .modal_cea import ModalReport, modal_cea
from .sparse_sliding import SlidingState, sparse_steady_sliding

__all__ = ["BandStability", "BandError", "band_stability", "METHODS", "dense_bytes"]

METHODS = ("direct", "modal", "dense")


class BandError(StickSlipError, ValueError):
    """A band that cannot be analysed as asked: no eigenvalue in it, a method that does not fit."""


def dense_bytes(n: int) -> float:
    """Peak memory of the dense eigenvalues of n free DOFs [bytes]: the 2n × 2n state matrix, LAPACK's
    copy and its complex eigenvectors (8 + 8 + 16 bytes per entry)."""
    return 32.0 * (2.0 * n) ** 2


@dataclasses.dataclass(frozen=True, eq=False)
class BandStability:
    """Eigenvalues of steady sliding in a frequency band, of a model's full linearisation.

    Attributes
    ----------
    model : str
    dofs : tuple of str
        Every dof, in q order.
    free : ndarray (k,) of int
        The free DOFs.
    equilibrium : ndarray (n,)
        Steady sliding [units of the dofs].
    residual : float
        Relative force residual of the steady state.
    eigenvalues : ndarray (m,) complex
        Every eigenvalue of the band: |Im λ| ≤ ``max_frequency`` inside the disc |λ| ≤ ``radius``
        (heavily damped eigenvalues beyond it are not part of the band), by real part descending,
        then Im descending [1/s].
    mode_shapes : ndarray (m, n) complex
        Displacements of each eigenvector on every dof (0 on locked ones), largest entry 1.
    backward_error : ndarray (m,)
        Relative backward error of each eigenpair on the full pencil.
    max_frequency : float
        ω_max [rad/s].
    radius : float
        The disc |λ| ≤ radius searched completely [rad/s] (:mod:`.cea`).
    method : str
        ``direct``, ``modal`` or ``dense``.
    frictionless_count : int or None
        Real modes of the frictionless structure below ``radius`` (Sylvester's inertia).
    normal_force : ndarray (nc,)
        Normal force of each contact at steady sliding [N].
    contact_names : tuple of str
    modal : ModalReport or None
    form : object
        The model's sparse form (node coordinates for VTK).
    """

    model: str
    dofs: tuple
    free: np.ndarray
    equilibrium: np.ndarray
    residual: float
    eigenvalues: np.ndarray
    mode_shapes: np.ndarray
    backward_error: np.ndarray
    max_frequency: float
    radius: float
    method: str
    frictionless_count: int | None
    normal_force: np.ndarray
    contact_names: tuple
    modal: ModalReport | None = None
    form: object = None

    @property
    def max_real_part(self) -> float:
        """Largest real part in the band [1/s]."""
        return float(self.eigenvalues.real[0])

    @property
    def stable(self) -> bool:
        """True when every eigenvalue of the band has a negative real part."""
        return self.max_real_part < 0.0

    @property
    def frequencies_hz(self) -> np.ndarray:
        """|Im λ| / 2π [Hz] (for a model in seconds)."""
        return np.abs(self.eigenvalues.imag) / (2.0 * math.pi)

    @property
    def unstable(self) -> np.ndarray:
        """Indices of the unstable eigenvalues with Im λ ≥ 0 (one per conjugate pair)."""
        return np.flatnonzero((self.eigenvalues.real > 0.0) & (self.eigenvalues.imag >= 0.0))

    def modes(self) -> list[dict]:
        """One dict per mode (the member with Im λ ≥ 0 of each pair): eigenvalue, growth rate,
        angular frequency, backward error."""
        return [{"index": int(j), "eigenvalue": complex(lam), "growth_rate": float(lam.real),
                 "angular_frequency": float(lam.imag), "backward_error": float(self.backward_error[j])}
                for j, lam in enumerate(self.eigenvalues) if lam.imag >= 0.0]

    def summary(self) -> dict:
        """JSON-ready summary: the dense path's keys (eigenvalues [[re, im], ...], max_real_part,
        stable) and the band's."""
        out = {
            "model": self.model,
            "eigenvalues": [[float(v.real), float(v.imag)] for v in self.eigenvalues],
            "max_real_part": self.max_real_part,
            "stable": bool(self.stable),
            "method": self.method,
            "max_frequency": self.max_frequency,
            "searched_radius": self.radius,
            "dofs": len(self.dofs),
            "contacts": len(self.contact_names),
            "equilibrium_residual": self.residual,
            "max_backward_error": float(np.max(self.backward_error, initial=0.0)),
            "frictionless_modes_in_disc": self.frictionless_count,
        }
        if len(self.dofs) <= 64:
            out["equilibrium"] = {d: float(v) for d, v in zip(self.dofs, self.equilibrium)}
        if self.modal is not None:
            out["modal"] = {"modes": self.modal.modes, "residual_vectors": self.modal.residual_vectors,
                            "cutoff": self.modal.cutoff,
                            "max_approximation_error": float(np.max(self.modal.errors, initial=0.0)),
                            "convergence": self.modal.convergence}
        return out

    def to_xarray(self, shapes: str = "unstable"):
        """``xarray.Dataset`` of the band: eigenvalues, backward errors, normal forces, and the mode
        shapes of the unstable modes (``shapes="all"``: of every mode with Im λ ≥ 0)."""
        import xarray as xr

        keep = self.unstable if shapes == "unstable" else np.flatnonzero(self.eigenvalues.imag >= 0.0)
        data = {
            "eigenvalue_real": ("mode", self.eigenvalues.real, {"units": "1/s", "long_name": "growth rate Re(lambda)"}),
            "eigenvalue_imag": ("mode", self.eigenvalues.imag, {"units": "rad/s", "long_name": "Im(lambda)"}),
            "backward_error": ("mode", self.backward_error, {"long_name": "relative backward error on the full pencil"}),
            "equilibrium": ("dof", self.equilibrium, {"long_name": "steady-sliding coordinates"}),
            "normal_force": ("contact", self.normal_force, {"units": "N", "long_name": "normal force at steady sliding"}),
            "shape_real": (("shape", "dof"), self.mode_shapes[keep].real, {"long_name": "mode shape, real part"}),
            "shape_imag": (("shape", "dof"), self.mode_shapes[keep].imag, {"long_name": "mode shape, imaginary part"}),
            "shape_mode": ("shape", keep, {"long_name": "index of the shape's eigenvalue"}),
        }
        coords = {"mode": np.arange(self.eigenvalues.size), "dof": list(self.dofs), "contact": list(self.contact_names),
                  "shape": np.arange(keep.size)}
        attrs = {"title": "stickslip complex eigenvalue analysis of steady sliding", "stickslip_version": __version__,
                 "model": self.model, "method": self.method, "max_frequency": self.max_frequency,
                 "max_frequency_units": "rad/s", "searched_radius": self.radius, "max_real_part": self.max_real_part,
                 "stable": int(self.stable), "equilibrium_residual": self.residual,
                 "summary": json.dumps(self.summary())}
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def write_vtk(self, path, shapes: str = "unstable", file_format: str | None = None) -> None:
        """The mode shapes as point data on the model's mesh (meshio; the ``fe`` extra), one real
        and one imaginary displacement field per mode, for ParaView (``file_format``: meshio's, e.g.
        ``vtu``; default from the suffix). The cells are the model's elements where its nodes come
        with them (``nodes.elements``, :class:`~stickslip.model.sparse_form.NodeMap`), else one
        vertex per node.

        Raises
        ------
        BandError
            When the model gives no node coordinates, or meshio is not installed.
        """
        nodes = getattr(self.form, "nodes", None)
        if nodes is None:
            raise BandError(f"model {self.model!r} gives no node coordinates; write the shapes to NetCDF instead "
                            "(--out), or give the model its nodes (docs/models.md)")
        try:
            import meshio
        except ImportError:
            raise BandError("writing VTK needs meshio: pip install 'stickslip[fe]'") from None
        points = np.asarray(nodes.coordinates, float)
        keep = self.unstable if shapes == "unstable" else np.flatnonzero(self.eigenvalues.imag >= 0.0)
        fields = {}
        for j in keep:
            u = nodes.displacement(self.mode_shapes[j])
            f = self.eigenvalues[j].imag / (2 * math.pi)
            fields[f"mode{j}_{f:.6g}Hz_real"] = u.real
            fields[f"mode{j}_{f:.6g}Hz_imag"] = u.imag
        cells = list(nodes.cells) or [("vertex", np.arange(points.shape[0]).reshape(-1, 1))]
        meshio.write(str(path), meshio.Mesh(points, cells, point_data=fields), file_format=file_format)


def _shapes(state: SlidingState, X: np.ndarray) -> np.ndarray:
    """Displacement shapes (m, n) on every dof, largest entry 1."""
    n = state.q.size
    shapes = np.zeros((X.shape[1], n), complex)
    shapes[:, state.free] = X.T
    for row in shapes:
        big = row[np.argmax(np.abs(row))]
        if big != 0:
            row /= big
    return shapes


def _dense_band(state: SlidingState, max_frequency: float) -> BandEigen:
    """Every eigenvalue densely, kept in the disc the sparse methods search (the same band)."""
    n = state.n
    check_memory(dense_bytes(n), f"the dense eigenvalues of {n} DOFs",
                 lambda memory: f"use --method direct (the sparse path; the dense one fits up to "
                                f"{int(math.sqrt(memory / 32.0) / 2)} DOFs in {format_bytes(memory)})")
    lam, X = dense_eigen(state)
    radius = max_frequency * math.sqrt(1.0 + REAL_MARGIN**2)
    inside = np.abs(lam) <= radius
    lam, X = sorted_eigen(lam[inside], X[:, inside])
    return BandEigen(eigenvalues=lam, vectors=X, radius=radius, backward_error=backward_errors(state, lam, X),
                     method="dense", frictionless_count=frictionless_count(state, radius))


def band_stability(model, max_frequency: float, *, method: str = "direct", cutoff: float | None = None,
                   residual: bool = True) -> BandStability:
    """Steady sliding and every eigenvalue of its linearisation in the band: |Im λ| ≤ ``max_frequency``
    inside the disc |λ| ≤ ``max_frequency`` √(1 + 0.25²) that the methods search completely
    (:mod:`~stickslip.stability.cea`).

    Parameters
    ----------
    model : FrictionModel or sparse form
        Any model with constant contact kinematics and pressed or compliant contacts.
    max_frequency : float
        ω_max, the band's top, in the model's angular-frequency unit [rad/s].
    method : {"direct", "modal", "dense"}
        Module docstring.
    cutoff : float, optional
        Cutoff of the real modes of ``modal`` [rad/s] (default 2 ω_max).
    residual : bool
        ``modal``: enrich the modes with the residual vectors of the contact rows (the static
        response to the contact forces; without them the projection stalls where stiff contacts
        put motion into high modes: docs/fe.md).

    Raises
    ------
    BandError
        For an unknown method, a band that is not a positive finite frequency, or a band that holds
        no eigenvalue (the message gives the lowest frequency).
    EquilibriumError
        No steady sliding (a contact that would be open or stick).
    MemoryLimitError
        ``dense`` for a model too large for memory.
    """
    if method not in METHODS:
        raise BandError(f"method {method!r}: choose one of {', '.join(METHODS)}")
    if not (math.isfinite(max_frequency) and max_frequency > 0.0):
        raise BandError(f"max_frequency = {max_frequency!r} must be a finite angular frequency > 0 [rad/s]")
    state = sparse_steady_sliding(model)
    report = None
    if method == "dense":
        band = _dense_band(state, max_frequency)
    elif method == "modal":
        band, report = modal_cea(state, max_frequency, cutoff=cutoff, residual=residual)
    else:
        band = band_eigen(state, max_frequency)
    inside = np.abs(band.eigenvalues.imag) <= max_frequency
    if not np.any(inside):
        raise BandError(f"no eigenvalue with frequency below {max_frequency:.6g} rad/s; the lowest lies near "
                        f"{_lowest(state):.6g} rad/s: give a larger --max-frequency")
    form = state.form
    return BandStability(
        model=form.name, dofs=tuple(form.dofs), free=state.free, equilibrium=state.q,
        residual=state.residual, eigenvalues=band.eigenvalues[inside],
        mode_shapes=_shapes(state, band.vectors[:, inside]), backward_error=band.backward_error[inside],
        max_frequency=float(max_frequency), radius=band.radius, method=method,
        frictionless_count=band.frictionless_count,
        normal_force=state.normal_force, contact_names=tuple(form.contact_names), modal=report, form=form,
    )


def _lowest(state: SlidingState) -> float:
    """The lowest natural angular frequency of the frictionless structure [rad/s] (a hint for messages)."""
    from .modal_cea import real_modes

    omega = 1.0
    while frictionless_count(state, omega) == 0 and omega < 1e15:
        omega *= 10.0
    return float(real_modes(state, omega).frequencies[0])
