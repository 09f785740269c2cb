"""A friction-contact model, stated once and served by every solver and analysis.

    M q̈ = f0 − C q̇ − K q + Σ_c G_c(q)ᵀ F_c + Σ_u W_uᵀ λ_u,   v_c = G_c(q) q̇ − w_c(q)

A contact is pressed by a prescribed load N_c = N0 + n·q + n_v·q̇, or it is *unilateral*: it
states a gap g_u = g0 + W_u·q and a normal law (:class:`NormalLaw`), opens and closes, and its
normal force λ_u acts on the coordinates (:mod:`stickslip.model.normal`).

:class:`FrictionModel` holds the ingredients — named coordinates q, the matrices M, C, K, the
force f0, the contacts (each with its slip-velocity dimension, normal force and friction law) and
the kinematics data that selects the contact frame (constant G, w for model files; compiled
functions for nonlinear kinematics such as the two plates) — plus the parameter values that
``--set`` reaches and the rule that rebuilds the model from them. Everything else (equations of
motion, stick multipliers, events, equilibrium, Jacobians, variational equations) is derived from
these by the generic kernels (:mod:`stickslip.model.physics`).
"""

from __future__ import annotations

import dataclasses
import math
import re
import unicodedata
from functools import cached_property
from typing import Any, Callable, Mapping, NamedTuple

import numpy as np

from ..errors import ModelError
from ..memory import check_memory, compiled_model_bytes, largest_dense_dofs
from .bundle import ModelData, pack
from .friction import FrictionLaw, NoUserLaw
from .bundle import NORMAL_LAWS
from .kinematics import (CONSTANT_KINEMATICS, ConstantKinematics, ConstantRigidKinematics, ConstantUnilateralKinematics,
                         allows_rigid, allows_unilateral,
                         LARGE_KINEMATICS, computes_gap, fits_stack, kernel_kinematics, large_kinematics,
                         registered_kinematics)
from .matrices import (DENSE_DOFS, MAX_MASS_CONDITION, check_mass, contact_rows, dense_array, dense_spec, finite,
                       has_nonzero, is_sparse, square_matrix)
from .mass_factor import without_round_off
from .physics import SPEED_FLOOR
from .sparse_form import NodeMap, SparseForm, sparse_form
from .stack import MAX_CONTACTS, MAX_DOFS, static_sizes

__all__ = ["FrictionModel", "Contact", "NormalLaw", "NamedState", "ModelError", "DEFAULT_SLIP_BAND", "MAX_MASS_CONDITION",
           "NAME_RULE", "check_text", "check_name"]

#: Default low-speed band [m/s]: below it the 2-D slip direction is the quasi-static one instead of
#: v/|v|. Near v = 0 the direction of 2-D friction relaxes on the time scale |v| / (λ μ N) → 0 (a
#: stiff mode that forces explicit steps of that size); inside the band the direction sits on its
#: slow manifold, an O(|v|) approximation. Measured on the plates at N = 50 N, Ω = 5 rad/s and
#: Ω = 0.5 rad/s, N = 30/50/70/120 N (100 s, rtol 1e-8, against band 1e-5 at rtol 1e-11): bands
#: 1e-5, 1e-4 and 5e-4 give the same errors (≤ 6e-9 in frequency), 1e-3 and above start to show
#: the band (docs/numerics.md); 5e-4 takes 15–65 % fewer steps than 1e-4 and 1e-5.
DEFAULT_SLIP_BAND = 5e-4

#: The friction law the kernels take for a frictionless contact (:class:`Contact`): zero coefficients.
FRICTIONLESS = FrictionLaw("coulomb", mu_k=0.0, delta_mu=0.0)

#: [m/s] The constant speed at which a frictionless contact's zero tangent row "slides" in the
#: kernels (v = −w): never 0, so it never sticks nor raises a slip event.
FRICTIONLESS_DRIVE = 1.0

#: What a dof name may hold: ``--ic x=1,dx=0`` splits at ``,`` and ``=``, ``--set stiffness.x.y``
#: at ``.``, the shell at whitespace, and a leading digit would read as an index in a path.
NAME_RULE = "ASCII letters, digits and _, not starting with a digit"
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")

#: Unicode categories refused in names and descriptions: control (Cc: newline, tab, escape, so
#: ANSI colour codes), format (Cf: bidirectional overrides that reorder a printed line),
#: surrogates and private use (Cs, Co), unassigned (Cn) and line/paragraph separators (Zl, Zp).
_CONTROL = frozenset({"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"})


def check_text(text: str, what: str) -> None:
    """Refuse a name or description that holds control or format characters (printed raw by the
    command line, they would move the cursor, colour the terminal or break the line).

    Raises
    ------
    ModelError
        Naming ``what`` and the first such character.
    """
    text = str(text)
    if text.isprintable():  # False for every character of _CONTROL (and for spaces other than " ")
        return
    for ch in text:
        if unicodedata.category(ch) in _CONTROL:
            raise ModelError(f"{what} contains the control character U+{ord(ch):04X}; give printable text on "
                             "one line (no newlines, tabs or escape sequences)")


def check_name(name: str, what: str) -> None:
    """Refuse a dof name that ``--ic NAME=VALUE,...`` or a ``--set`` path cannot reach (:data:`NAME_RULE`).

    Raises
    ------
    ModelError
        Naming ``what`` and the characters allowed.
    """
    if not isinstance(name, str) or not _NAME.match(name):
        shown = repr(name) if len(repr(name)) <= 40 else repr(name)[:37] + "..."
        raise ModelError(f"{what} = {shown} is not a valid name; give a name of {NAME_RULE}")


#: The dof names last checked by a FrictionModel (the same tuple is not checked again).
_CHECKED_DOFS: list = [None]

#: Normal laws a unilateral contact may state (:class:`NormalLaw`).
UNILATERAL_LAWS = ("compliant", "rigid")


@dataclasses.dataclass(frozen=True)
class NormalLaw:
    """The normal law of a unilateral contact.

    Attributes
    ----------
    law : {"compliant", "rigid"}
        ``compliant``: λ = max(0, −k g − c ġ) while g < 0, else 0 (Kelvin–Voigt, no impulses).
        ``rigid``: g ≥ 0, λ ≥ 0, g λ = 0; closing is an impact (Newton's restitution, a Coulomb
        impulse).
    stiffness : float
        Contact stiffness k > 0 [N/m] (compliant contacts).
    damping : float
        Contact damping c ≥ 0 [N s/m] (compliant contacts).
    restitution : float
        Newton's restitution coefficient e ∈ [0, 1] (rigid contacts): ġ⁺ = −e ġ⁻.
    """

    law: str = "compliant"
    stiffness: float = 0.0
    damping: float = 0.0
    restitution: float = 0.0

    def check(self, where: str) -> None:
        """Refuse an unknown law or a value out of its range, naming ``where``.

        Raises
        ------
        ModelError
        """
        if self.law not in UNILATERAL_LAWS:
            raise ModelError(f"{where}: law = {self.law!r} is not a normal law; choose compliant or rigid")
        if self.law == "rigid":
            if self.stiffness != 0.0 or self.damping != 0.0:
                raise ModelError(f"{where}: a rigid contact has no stiffness or damping; give restitution = e in "
                                 "[0, 1], or law = \"compliant\" for a contact spring")
            if not (math.isfinite(self.restitution) and 0.0 <= self.restitution <= 1.0):
                raise ModelError(f"{where}: restitution = {self.restitution:g} must lie in [0, 1] (Newton's e: "
                                 "0 plastic, 1 elastic)")
            return
        if self.restitution != 0.0:
            raise ModelError(f"{where}: restitution is a rigid contact's; a compliant contact dissipates through "
                             "its damping")
        if not (math.isfinite(self.stiffness) and self.stiffness > 0.0):
            raise ModelError(f"{where}: stiffness = {self.stiffness:g} must be a finite contact stiffness > 0 [N/m]")
        if not (math.isfinite(self.damping) and self.damping >= 0.0):
            raise ModelError(f"{where}: damping = {self.damping:g} must be finite and >= 0 [N s/m]")


@dataclasses.dataclass(frozen=True, eq=False)
class Contact:
    """One point contact.

    Parameters
    ----------
    dim : {1, 2}
        Dimension of the tangential slip velocity (1: along a line; 2: in the contact plane).
    friction : FrictionLaw, optional
        The contact's friction law; None (with no ``tangent`` and ``drive``) for a *frictionless*
        unilateral contact, one that acts along its normal only (:attr:`frictionless`).
    normal_force : float
        N0 [N], the constant part of a prescribed normal force (> 0; 0 for a unilateral contact).
    tangent : ndarray (dim, n) or None
        Constant contact Jacobian G (model files); None when the kinematics computes it.
    drive : ndarray (dim,) or None
        Constant surface velocity w, v = G q̇ − w [m/s]; None with computed kinematics.
    normal_gradient, normal_rate_gradient : ndarray (n,)
        n and n_v of N = N0 + n·q + n_v·q̇ [N/m, N s/m].
    name : str
        Label for output (``contact0`` …).
    normal : NormalLaw, optional
        The normal law of a unilateral contact; None for a prescribed load.
    gap : float
        g0 [m] of the gap g = g0 + W·q of a unilateral contact (closed while g ≤ 0); 0 when the
        kinematics computes the gap (``register_kinematics(..., gap=...)``).
    gap_gradient : ndarray (n,), optional
        W [m per unit of each dof] of a unilateral contact; None when the kinematics computes the gap.

    Notes
    -----
    A frictionless contact has no tangential part: it opens, closes and takes impacts, never
    sticks or slips. The compiled kernels take it as a 1-D contact whose tangent row is zero, whose
    drive is 1 m/s and whose friction coefficients are 0 (:data:`FRICTIONLESS_DRIVE`): its slip
    velocity is the constant −1 m/s, so it never reaches v = 0 (no stick, no slip event) and its
    friction force and impulse are 0; no coordinate is added. Results report its slip velocity
    as NaN and its friction as 0.
    """

    dim: int = 1
    friction: FrictionLaw | None = None
    normal_force: float = 0.0
    tangent: np.ndarray | None = None
    drive: np.ndarray | None = None
    normal_gradient: np.ndarray | None = None
    normal_rate_gradient: np.ndarray | None = None
    name: str = ""
    normal: NormalLaw | None = None
    gap: float = 0.0
    gap_gradient: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.friction is None:  # frictionless: the kernels' zero friction law (class Notes)
            object.__setattr__(self, "friction", FRICTIONLESS)
            object.__setattr__(self, "frictionless_contact", True)

    @property
    def frictionless(self) -> bool:
        """Whether the contact acts along its normal only: no friction, no tangent (class Notes)."""
        return getattr(self, "frictionless_contact", False)

    @property
    def unilateral(self) -> bool:
        """Whether the contact states a gap (opens and closes) instead of a prescribed load."""
        return self.normal is not None

    def spec(self, n: int) -> dict:
        """The contact as :func:`stickslip.model.bundle.pack` takes it."""
        out = {"dim": self.dim, "N0": self.normal_force, "law_row": self.friction.row(),
               "n_q": np.zeros(n) if self.normal_gradient is None else self.normal_gradient,
               "n_v": np.zeros(n) if self.normal_rate_gradient is None else self.normal_rate_gradient}
        if self.frictionless:  # a zero tangent row sliding at a constant speed (class Notes)
            out["G"] = np.zeros((1, n))
            out["w"] = np.array([FRICTIONLESS_DRIVE])
        elif self.tangent is not None:
            out["G"] = self.tangent
            out["w"] = self.drive
        if self.normal is not None:
            k, c = self.normal.stiffness, self.normal.damping
            W = np.zeros(n) if self.gap_gradient is None else dense_array(self.gap_gradient).reshape(-1)
            # closed, the compliant force −k (g0 + W·q) − c W·q̇ is the affine N0 + n·q + n_v·q̇ of the
            # constant kinematics' frame
            # (a rigid contact has k = c = 0: its normal force is a multiplier, not part of the frame)
            out.update(normal_law=NORMAL_LAWS[self.normal.law], gap=self.gap, W=W, k=k, c=c,
                       e=self.normal.restitution, N0=-k * self.gap, n_q=-k * W, n_v=-c * W)
        return out


class NamedState(NamedTuple):
    """A named initial state of a model (``FrictionModel.starts``): the state (2n,) and one line on it."""

    state: np.ndarray
    description: str


@dataclasses.dataclass(frozen=True, eq=False)
class FrictionModel:
    """A friction-contact system (module docstring).

    Parameters
    ----------
    name : str
        Short name (``belt``, ``two-plates``, the file's ``name``).
    dofs : tuple of str
        Names of q, in order; the states are the dofs then ``"d" + dof`` for each.
    mass, damping, stiffness : ndarray (n, n)
        M (symmetric positive definite on the free DOFs) [kg, kg m²], C, K (K may be non-symmetric).
    force : ndarray (n,)
        Constant generalised force f0.
    contacts : tuple of Contact
        The point contacts, in the order of the results' contact columns (``contact0`` …).
    kinematics : NamedTuple
        Kinematics data; its class selects the compiled contact frame
        (:class:`~stickslip.model.kinematics.ConstantKinematics` for constant G and w).
    free : ndarray (n,) of bool
        Free DOFs; locked ones never move (zero inverse mass).
    parameters : mapping
        Named parameter values (what ``--set`` changes), in the order they are listed. Model files:
        the ``[parameters]`` first, then every entry by its path (a number, the text of an
        expression, or a law name).
    builder : callable
        ``builder(parameters) -> FrictionModel``: the model with other parameter values (it gets
        every parameter, the changed ones included).
    source : str
        Where the model came from: ``library:NAME``, ``file:PATH`` or ``python``.
    units : mapping
        Unit of each DOF (``"m"``, ``"rad"``) and of each parameter, where known.
    slip_band : float
        Low-speed band of the 2-D slip direction [m/s] (:data:`DEFAULT_SLIP_BAND`).
    description : str
        One line for listings.
    spec : mapping, optional
        The model file's content, when it came from one (written into results so that they
        reproduce themselves).
    resolver : callable, optional
        Maps an alias of a parameter name to its name in :attr:`parameters` (model files accept
        dof names as indices and leave out the index of a one-entry vector).
    observed : str, optional
        The dof that summaries follow (frequency, extremes, peaks); default the first free dof.
    starts : mapping of str to NamedState, optional
        Named initial states of this model beside the ones every model has (``zero``,
        ``equilibrium``, ``near``): ``simulate(model, ic=NAME)``, ``--ic NAME``.
    label : str, optional
        How results name the model (default :attr:`name`; the plates: their variant, ``full``).
    headline : tuple of str, optional
        Parameters that messages show to say which point of the model they mean (the plates:
        ``N`` and ``Omega``).
    steady_hint : callable, optional
        ``steady_hint(model, q) -> str``: why steady sliding may not exist near the coordinates
        ``q`` where the search failed, in the model's own terms ("" for no hint).
    nodes : NodeMap, optional
        The mesh nodes' coordinates and each dof's node (a finite-element model's; results draw
        mode shapes with them).

    M, C, K and the contacts' rows may be given dense or as scipy.sparse matrices: a model of at
    most :data:`~stickslip.model.matrices.DENSE_DOFS` dofs keeps them dense arrays, a larger one
    CSR matrices (:mod:`stickslip.model.matrices`; :attr:`dense`), and :meth:`sparse_form` gives
    either as the sparse arrays the sparse numerics take.
    """

    name: str
    dofs: tuple[str, ...]
    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    force: np.ndarray
    contacts: tuple[Contact, ...]
    kinematics: NamedTuple = ConstantKinematics()
    free: np.ndarray | None = None
    parameters: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    builder: Callable[[Mapping[str, Any]], "FrictionModel"] | None = None
    source: str = "python"
    units: Mapping[str, str] = dataclasses.field(default_factory=dict)
    slip_band: float = DEFAULT_SLIP_BAND
    description: str = ""
    spec: Mapping[str, Any] | None = None
    resolver: Callable[[str], str] | None = None
    observed: str | None = None
    starts: Mapping[str, NamedState] = dataclasses.field(default_factory=dict)
    label: str = ""
    headline: tuple[str, ...] = ()
    steady_hint: Callable[["FrictionModel", np.ndarray], str] | None = None
    nodes: NodeMap | None = None

    def __post_init__(self) -> None:
        n = len(self.dofs)
        if n == 0:
            raise ModelError(f"model {self.name!r} has no degrees of freedom; list them in dofs")
        check_text(self.name, "the model's name")
        check_text(self.description, f"model {self.name!r}: description")
        if not (isinstance(self.dofs, tuple) and self.dofs is _CHECKED_DOFS[0]):
            self._check_dofs()
        dense = n <= DENSE_DOFS
        for key in ("mass", "damping", "stiffness"):
            object.__setattr__(self, key, square_matrix(getattr(self, key), n, dense, f"model {self.name!r}: {key}"))
        force = np.zeros(n) if self.force is None else np.array(self.force, dtype=float).reshape(-1)
        if force.shape != (n,) or not np.isfinite(force).all():
            shown = force.tolist() if force.size <= 8 else f"{force.size} numbers"
            raise ModelError(f"model {self.name!r}: force must be {n} finite numbers, got {shown}")
        object.__setattr__(self, "force", force)
        free = np.ones(n, dtype=bool) if self.free is None else np.array(self.free, dtype=bool)
        object.__setattr__(self, "free", free)
        object.__setattr__(self, "contacts", tuple(self.contacts))
        unilateral, rigid = self._contact_kinds()
        if type(self.kinematics) in CONSTANT_KINEMATICS and unilateral:
            # the class compiles what the contacts need: rigid contacts' code only where there are some
            cls = ConstantRigidKinematics if rigid else ConstantUnilateralKinematics
            object.__setattr__(self, "kinematics", cls(*self.kinematics))
        object.__setattr__(self, "dofs", tuple(self.dofs))
        self._check_mass()
        self._check_contacts()
        if not (math.isfinite(self.slip_band) and self.slip_band > SPEED_FLOOR):
            raise ModelError(f"slip_band = {self.slip_band} must be a finite speed > {SPEED_FLOOR} m/s")
        self._check_starts()

    def _check_dofs(self) -> None:
        """Dof names valid, distinct, and none ``d`` + another (remembered for the tuple last checked:
        a model file's rebuilds pass the same tuple, of up to 10^6 names)."""
        n = len(self.dofs)
        for i, dof in enumerate(self.dofs):
            check_name(dof, f"model {self.name!r}: dof {i}")
        names = set(self.dofs)
        if len(names) != n:
            seen: set = set()
            twice = next(d for d in self.dofs if d in seen or seen.add(d))
            raise ModelError(f"model {self.name!r}: dof names must be unique, {twice!r} is given twice; give each dof "
                             "its own name")
        for dof in self.dofs:
            if "d" + dof in names:
                raise ModelError(f"model {self.name!r}: dofs {dof} and d{dof} both have the state name d{dof} (the "
                                 f"states are the dofs, then d + each dof); give one of them another name")
        if isinstance(self.dofs, tuple):
            _CHECKED_DOFS[0] = self.dofs

    def _check_starts(self) -> None:
        locked = ~np.concatenate([self.free, self.free])
        for name, start in self.starts.items():
            state = np.array(start.state, dtype=float)
            if state.shape != (2 * self.n,) or not np.all(np.isfinite(state)) or np.any(state[locked] != 0.0):
                raise ModelError(f"model {self.name!r}: start {name!r} must be {2 * self.n} finite numbers, zero on "
                                 "the locked dofs")

    def _check_mass(self) -> None:
        check_mass(self.mass, self.free, f"model {self.name!r}")

    def _check_contacts(self) -> None:
        n = self.n
        cls = type(self.kinematics)
        if cls not in registered_kinematics():
            raise ModelError(f"model {self.name!r}: kinematics class {cls.__name__} is not registered; "
                             "call stickslip.model.register_kinematics(cls, frame) first")
        constant = cls in CONSTANT_KINEMATICS
        sizes = static_sizes(cls)
        if sizes is not None and sizes != (n, len(self.contacts)):
            raise ModelError(f"model {self.name!r}: kinematics {cls.__name__} is for {sizes[0]} dofs and "
                             f"{sizes[1]} contact(s), the model has {n} and {len(self.contacts)}")
        if not self.contacts:
            raise ModelError(f"model {self.name!r} has no contact; add a [[contact]] table")
        for c, contact in enumerate(self.contacts):
            where = f"model {self.name!r}: contact {c}"
            check_text(contact.name, f"{where}: name")
            if contact.dim not in (1, 2):
                raise ModelError(f"{where}: the slip velocity has 1 or 2 components (tangent rows), got {contact.dim}")
            if contact.unilateral:
                self._check_gap(contact, where)
            elif not (math.isfinite(contact.normal_force) and contact.normal_force > 0.0):
                raise ModelError(f"{where}: normal_force = {contact.normal_force} must be > 0 (the contact must be pressed)")
            for key in ("normal_gradient", "normal_rate_gradient"):
                value = getattr(contact, key)
                if value is not None:
                    object.__setattr__(contact, key, self._vector(value, f"{where}: {key} must be {n} finite numbers"))
            if contact.frictionless:
                self._check_frictionless(contact, where, constant)
            elif constant:
                if contact.tangent is None or contact.drive is None:
                    raise ModelError(f"{where}: give tangent (G) and drive (w) for constant kinematics")
                G = contact_rows(contact.tangent, None, n, self.dense)
                if G.ndim == 1:
                    G = G.reshape(1, -1)
                w = np.array(contact.drive, dtype=float).reshape(-1)
                if G.shape != (contact.dim, n):
                    raise ModelError(f"{where}: tangent must have {contact.dim} row(s) of {n} numbers, got shape {G.shape}")
                if w.shape != (contact.dim,):
                    raise ModelError(f"{where}: drive must have {contact.dim} number(s), one per tangent row")
                if not (finite(G) and np.isfinite(w).all()):
                    raise ModelError(f"{where}: tangent and drive must be finite")
                if not has_nonzero(G, self.free):
                    raise ModelError(f"{where}: tangent is zero on every free dof; the contact cannot slip")
                object.__setattr__(contact, "tangent", G)
                object.__setattr__(contact, "drive", w)

    @staticmethod
    def _check_frictionless(contact: Contact, where: str, constant: bool) -> None:
        """A frictionless contact: unilateral, 1-D, with neither tangent nor drive, constant kinematics."""
        if not contact.unilateral:
            raise ModelError(f"{where}: a contact without friction acts through its gap only; give it a gap with a "
                             "normal law (gap_gradient and [contact.normal]) or a friction law")
        if contact.dim != 1 or contact.tangent is not None or contact.drive is not None:
            raise ModelError(f"{where}: a contact without friction has no tangent or drive; give a friction law "
                             "with them, or leave all three out")
        if not constant:
            raise ModelError(f"{where}: contacts without friction are for models of constant frames (model files); "
                             "give this contact a friction law with zero coefficients")

    def _vector(self, value, refusal: str):
        """A contact's gradient (n, n_v or W) as the model keeps it: (n,) dense, (1, n) sparse."""
        out = contact_rows(value, 1, self.n, self.dense)
        if out.shape != ((self.n,) if self.dense else (1, self.n)) or not finite(out):
            raise ModelError(refusal)
        return out

    def _check_gap(self, contact: Contact, where: str) -> None:
        """A unilateral contact: its normal law, a finite gap with a gradient, no prescribed load."""
        if not allows_unilateral(type(self.kinematics)):
            raise ModelError(f"{where}: kinematics {type(self.kinematics).__name__} was registered for pressed "
                             "contacts only (unilateral=False); give the contact a normal_force")
        if contact.normal_force != 0.0 or contact.normal_gradient is not None \
                or contact.normal_rate_gradient is not None:
            raise ModelError(f"{where}: give either a prescribed load (normal_force) or a gap with a normal law, "
                             "not both; a unilateral contact's normal force comes from its gap")
        contact.normal.check(f"{where}: normal")
        if contact.normal.law == "rigid" and not allows_rigid(type(self.kinematics)):
            raise ModelError(f"{where}: kinematics {type(self.kinematics).__name__} was registered without rigid "
                             "contacts (rigid=False); give the contact law = \"compliant\", or register it with rigid=True")
        if not math.isfinite(contact.gap):
            raise ModelError(f"{where}: gap = {contact.gap} must be finite [m]")
        if computes_gap(type(self.kinematics)):
            if contact.normal.law == "rigid":
                raise ModelError(f"{where}: a rigid contact needs a gap affine in q (gap and gap_gradient); a gap "
                                 "that kinematics compute takes law = \"compliant\"")
            if contact.gap != 0.0 or contact.gap_gradient is not None:
                raise ModelError(f"{where}: kinematics {type(self.kinematics).__name__} computes the gap (its "
                                 "registered gap function); give neither gap nor gap_gradient")
            return
        refusal = f"{where}: gap_gradient must be {self.n} finite numbers (W of g = g0 + W·q)"
        if contact.gap_gradient is None:
            raise ModelError(refusal)
        W = self._vector(contact.gap_gradient, refusal)
        if not has_nonzero(W, self.free):
            raise ModelError(f"{where}: gap_gradient is zero on every free dof; the contact can never open or close")
        object.__setattr__(contact, "gap_gradient", W)

    # ------------------------------------------------------------------ structure
    @property
    def unilateral(self) -> bool:
        """Whether some contact opens and closes (states a gap instead of a prescribed load)."""
        return any(c.unilateral for c in self.contacts)

    @property
    def rigid(self) -> bool:
        """Whether some contact is rigid (closes with impacts; its normal force a multiplier)."""
        return any(c.unilateral and c.normal.law == "rigid" for c in self.contacts)

    @property
    def n(self) -> int:
        """Number of generalised coordinates."""
        return len(self.dofs)

    @property
    def n_contacts(self) -> int:
        return len(self.contacts)

    @property
    def state_names(self) -> tuple[str, ...]:
        """The 2n states: the dofs, then ``d<dof>`` for each."""
        return self.dofs + tuple("d" + d for d in self.dofs)

    @property
    def state_units(self) -> tuple[str, ...]:
        """Units of the 2n states ("" where the model does not say): a dof's unit, then its unit per second."""
        units = tuple(self.units.get(d, "") for d in self.dofs)
        return units + tuple(f"{u}/s" if u and u != "-" else u for u in units)

    @property
    def contact_names(self) -> tuple[str, ...]:
        """Each contact's name, ``contact<c>`` where it has none."""
        return tuple(c.name or f"contact{i}" for i, c in enumerate(self.contacts))

    @property
    def observed_index(self) -> int:
        """Index of :attr:`observed` in q (default: the first free dof)."""
        if self.observed is not None:
            return self.dofs.index(self.observed)
        return int(np.flatnonzero(self.free)[0])

    @property
    def constant_kinematics(self) -> bool:
        """Whether G and w are constant (model files)."""
        return type(self.kinematics) in CONSTANT_KINEMATICS

    @property
    def dense(self) -> bool:
        """Whether M, C, K and the contact rows are dense arrays (models of at most
        :data:`~stickslip.model.matrices.DENSE_DOFS` dofs) rather than scipy.sparse CSR matrices."""
        return not is_sparse(self.mass)

    @cached_property
    def data(self) -> ModelData:
        """The model as the compiled kernels take it (:class:`~stickslip.model.bundle.ModelData`).

        Raises
        ------
        MemoryLimitError
            When its dense arrays and the kernels' work arrays of a model above the stack maxima
            (:func:`~stickslip.memory.compiled_model_bytes`) do not fit in memory.
        ModelError
            For a model above ``MAX_DOFS`` dofs or ``MAX_CONTACTS`` contacts whose contact frame is
            computed from q (only constant frames have a heap flavour,
            :func:`~stickslip.model.kinematics.large_kinematics`); both say to reduce the model.

        A model of at most ``MAX_DOFS`` dofs and ``MAX_CONTACTS`` contacts (or of a kinematics
        class that fixes its sizes) gets kernels with stack work arrays; a larger one of constant
        frames the heap flavour (:mod:`stickslip.model.stack`), its matrices packed dense
        (n² numbers each, for hundreds to a few thousand dofs).
        """
        self._check_compiled_size()
        matrices = [dense_array(a) for a in (self.mass, self.damping, self.stiffness)]
        kin = kernel_kinematics(self.kinematics, *self._contact_kinds())
        if not fits_stack(type(kin), self.n, self.n_contacts):  # the heap flavour: patterns of the mechanics
            matrices = [without_round_off(a) for a in matrices]
        m = pack(*matrices, self.force, self.free, [dense_spec(contact.spec(self.n)) for contact in self.contacts],
                 self.slip_band, self.constant_kinematics)
        kin = large_kinematics(kin, self.n, self.n_contacts, (*matrices, self.free), m)
        return ModelData(m, kin, self.user_law)

    @cached_property
    def _sparse_form(self) -> SparseForm:
        return sparse_form(self)

    def sparse_form(self) -> SparseForm:
        """The model as sparse arrays (:class:`~stickslip.model.sparse_form.SparseForm`), for
        constant contact frames (model files, dense or sparse).

        Raises
        ------
        ModelError
            For contact frames computed from q (the plates).
        """
        return self._sparse_form

    def _check_compiled_size(self) -> None:
        n, nc = self.n, self.n_contacts
        cls = type(self.kinematics)
        if fits_stack(cls, n, nc):
            return
        reduce = ("reduce it to its contact dofs and a few modes with `stickslip reduce` (Craig–Bampton), or "
                  "analyse the full model with the sparse tools (complex eigenvalues of steady sliding)")
        if cls not in LARGE_KINEMATICS:
            raise ModelError(f"model {self.name!r} has {n} dofs and {nc} contacts; the compiled tools take at most "
                             f"{MAX_DOFS} dofs and {MAX_CONTACTS} contacts for a contact frame computed from q "
                             f"(kinematics {cls.__name__}): state its contacts with constant rows (a model file), "
                             "or reduce the model")
        check_memory(compiled_model_bytes(n, nc), f"the compiled form of model {self.name!r} ({n} dofs, {nc} "
                     "contacts; dense M⁻¹, M, C, K and the kernels' work arrays)",
                     lambda memory: f"at most {largest_dense_dofs(memory, nc)} dofs fit; {reduce}")

    def _contact_kinds(self) -> tuple[bool, bool]:
        """Whether the model has unilateral contacts, and a rigid one (the kernels compile their code
        only then)."""
        return (any(c.unilateral for c in self.contacts),
                any(c.unilateral and c.normal.law == "rigid" for c in self.contacts))

    @property
    def user_law(self):
        """The user friction law instance the contacts share (:class:`~stickslip.model.friction.NoUserLaw`
        if none)."""
        laws = {c.friction.user for c in self.contacts if c.friction.law == "user"}
        if len(laws) > 1:
            raise ModelError(f"model {self.name!r}: contacts with a user friction law must share one instance "
                             f"(got {len(laws)}); give them the same FrictionLaw.from_user(...)")
        return laws.pop() if laws else NoUserLaw()

    def state_index(self, name: str) -> int:
        """Index of a state by name (``x``, ``dx``, ...)."""
        try:
            return self.state_names.index(name)
        except ValueError:
            raise ModelError(f"unknown state {name!r} of model {self.name!r}; states are "
                             f"{', '.join(self.state_names)}") from None

    # ------------------------------------------------------------------ parameters
    def replace(self, **changes: Any) -> "FrictionModel":
        """The model with some parameters changed (names as in :attr:`parameters`, or their aliases).

        The builder gets every parameter value, the changed ones included, and builds the new
        model once (one validation, in ``__post_init__``).

        Raises
        ------
        ModelError
            For a model without named parameters, an unknown name or a value that makes the model invalid.
        """
        if not changes:
            return self
        if self.builder is None or not self.parameters:
            raise ModelError(f"model {self.name!r} has no named parameters to change ({', '.join(changes)}); give "
                             "FrictionModel a builder= and parameters= (a function that builds the model from its "
                             "parameters, docs/models.md) or state it as a model file")
        if self.resolver is not None:
            changes = {self.resolver(k): v for k, v in changes.items()}
        unknown = [k for k in changes if k not in self.parameters]
        if unknown:
            names = list(self.parameters)
            shown = ", ".join(names[:24]) + (f", … ({len(names)} in all; 'stickslip models' lists them)"
                                             if len(names) > 24 else "")
            raise ModelError(f"unknown parameter(s) {', '.join(unknown)} of model {self.name!r}; valid names: {shown}")
        values = dict(self.parameters)
        values.update(changes)
        return self.builder(values)

    def point_text(self) -> str:
        """Which model and point, in words for messages: its :attr:`headline` parameters and label
        (``N = 50 N, Omega = 5 rad/s, model 'full'``), or ``model 'belt'``."""
        shown = []
        for key in self.headline:
            unit = self.units.get(key, "")
            shown.append(f"{key} = {self.parameters[key]:g}" + (f" {unit}" if unit and unit != "-" else ""))
        return ", ".join(shown + [f"model {self.label or self.name!r}"])

    def with_slip_band(self, slip_band: float) -> "FrictionModel":
        """The same model with another low-speed band [m/s]."""
        if slip_band == self.slip_band:
            return self
        return dataclasses.replace(self, slip_band=float(slip_band))

    def natural_frequencies(self) -> np.ndarray:
        """Undamped natural frequencies [Hz] of the free DOFs without friction, ascending
        (eigenvalues of M⁻¹ K; complex pairs of a non-symmetric K give their modulus).

        Raises
        ------
        MemoryLimitError, ModelError
            For a sparse model too large for the compiled tools (:attr:`data`): its lowest modes come
            from its sparse form (``scipy.sparse.linalg.eigsh(K, M=M, sigma=0)``).
        """
        if not self.dense:  # as dense as the compiled tools take it, where that fits in memory
            self._check_compiled_size()
        idx = np.flatnonzero(self.free)
        M = dense_array(self.mass)[np.ix_(idx, idx)]
        K = dense_array(self.stiffness)[np.ix_(idx, idx)]
        lam = np.linalg.eigvals(np.linalg.solve(M, K))
        return np.sort(np.sqrt(np.abs(lam)) / (2.0 * np.pi))

    def describe(self) -> dict:
        """JSON-ready description: name, source, dofs, contacts, parameters (written into results)."""
        return {"name": self.name, "source": self.source, "dofs": list(self.dofs),
                "contacts": [{"dim": 0, "law": "none"} if c.frictionless else {"dim": c.dim, **c.friction.to_dict()}
                             for c in self.contacts],
                "parameters": {k: v for k, v in self.parameters.items()}}
