"""Contact kinematics: the one place where a model's geometry enters the compiled physics.

Every contact c of a model has a slip velocity v_c = G_c(q) q̇ − w_c(q) (1 or 2 rows) and a
normal force N_c(q, q̇). A model supplies these through a *frame function*

    frame(kin, s, c, m, G, w) -> N

that fills ``G`` (2, n) (rows beyond the contact's dimension are ignored) and ``w`` (2,) for
contact ``c`` at state ``s`` = [q, q̇] and returns N_c. ``kin`` is the model's kinematics data, a
``typing.NamedTuple`` of numbers (e.g. a radius and a drive speed); ``m`` is the model's data array
(:mod:`stickslip.model.bundle`), for frames that read constant matrices from it.

The frame function is chosen *at compile time* by the type of ``kin``: each kinematics class is
registered once with :func:`register_kinematics`, and the generic kernels
(:mod:`stickslip.model.physics`) call :func:`contact_frame`, which numba resolves to the
registered function for that type. So a model's kernels are specialised and inlined like
hand-written code, one compiled version per kinematics class (not per parameter value), and
cached on disk because the class is found by its import path.

A kinematics class may also register a *bias function*

    frame_bias(kin, s, c, m, G, w, h) -> N

that fills the frame as above and the velocity bias ``h`` (2,) = Ġ q̇ − ẇ (the rate of v at q̈ = 0)
in closed form. It is optional: without it the bias is a complex step of the frame (exact to
round-off, :mod:`stickslip.model.frames`), which costs one complex evaluation of the frame per
stick multiplier and event; the closed form is the fast path for a model whose frame is dear
(the plates' trigonometry), and a test checks it against the complex step.

Frames must work on ``float64`` and ``complex128`` states alike (the Jacobians and the
acceleration bias Ġ q̇ are taken by complex step): use ``np.sin``, ``np.cos``, ``np.sqrt``,
``np.exp`` and arithmetic, never ``abs`` or ``math.*`` on the state, and branch on real parts only.
"""

from __future__ import annotations

import inspect
import re
from typing import Any, Callable, NamedTuple

import numpy as np
from numba import njit
from numba.extending import overload

from ..errors import KinematicsError
from . import csmath as csm
from . import stack
from .frame_pointers import (FramePointerFields, compiled_addresses, forget, is_pointer_class, origin_class, pointer_frame,
                             pointer_gap)
from .bundle import C_DIM, C_G, C_N0, H_DIAGONAL, H_N, H_NC, H_UNILATERAL, contact_offsets, offsets
from .jit import KERNEL_OPTIONS, defined_in_package, inlined_kernel, kernel, track_user_code
from ..memory import delassus_bytes, fits_in_memory
from .mass_factor import contact_rows, delassus, mass_factor, row_pattern

__all__ = ["ConstantKinematics", "ConstantUnilateralKinematics", "CONSTANT_KINEMATICS", "register_kinematics",
           "registered_kinematics", "registered_frame_bias", "contact_frame", "constant_frame", "KinematicsError",
           "model_sizes", "contact_dim", "has_unilateral", "allows_unilateral", "pressed_only", "unilateral_kernel",
           "contact_gap", "computes_gap", "gap_computed", "ConstantRigidKinematics", "rigid_kernel", "rigid_free", "allows_rigid",
           "sparse_constant_frame", "heap_normal_and_drive", "frame_for_sums",
           "kernel_kinematics", "bias_at_run_time", "pointer_class", "LargeConstantKinematics",
           "LargeConstantUnilateralKinematics", "LargeConstantRigidKinematics", "LARGE_KINEMATICS", "fits_stack",
           "force_pattern",
           "large_kinematics"]


#: Registered frame functions by kinematics class.
_FRAMES: dict[type, Callable] = {}
#: Sizes fixed by a kinematics class (n, nc, diagonal), known to the compiler for speed.
_SIZES: dict[type, tuple] = {}
#: Contact dimension fixed by a kinematics class (or None).
_DIMS: dict[type, int | None] = {}
#: Closed-form frame-and-bias functions by kinematics class (optional).
_BIASES: dict[type, Callable] = {}
#: Gap functions by kinematics class (optional; without one a unilateral contact's gap is g0 + W·q).
_GAPS: dict[type, Callable] = {}
#: Kinematics classes whose models never have unilateral contacts (their kernels compile without them).
_PRESSED_ONLY: set[type] = set()
#: Kinematics classes whose models never have rigid contacts (their kernels compile without the
#: rigid normal forces and impacts).
_NO_RIGID: set[type] = set()


def register_kinematics(cls: type, frame: Callable, *, ndof: int | None = None, ncontacts: int | None = None,
                        diagonal: bool | None = None, dim: int | None = None,
                        frame_bias: Callable | None = None, unilateral: bool = True,
                        gap: Callable | None = None, rigid: bool = True, inline: bool | None = None) -> None:
    """Make ``frame`` the contact frame of models whose kinematics data is a ``cls`` instance.

    Parameters
    ----------
    cls : NamedTuple class
        The kinematics data type (fields: numbers). Must be importable by its module path for the
        compiled kernels to be cached across processes.
    frame : numba-compilable function
        ``frame(kin, s, c, m, G, w) -> N`` as described in the module docstring. Plain Python
        functions are compiled on first use (they must follow numba's nopython subset).
    ndof, ncontacts : int, optional
        The number of DOFs and of contacts, when every model of this kinematics has the same ones:
        the compiler then unrolls the kernels' loops (the plates: 6 and 1).
    diagonal : bool, optional
        Whether M, C and K are always diagonal for this kinematics (skips the dense products).
    dim : {1, 2}, optional
        The dimension of every contact's slip velocity, when fixed by the kinematics.
    frame_bias : numba-compilable function, optional
        ``frame_bias(kin, s, c, m, G, w, h) -> N``: the frame and the velocity bias h = Ġ q̇ − ẇ
        (2,) [m/s²] in closed form (module docstring); complex-safe like ``frame``. Without it
        the bias is taken by complex step of ``frame``.
    unilateral : bool
        Whether models of this kinematics may have unilateral contacts (a gap g = g0 + W·q instead
        of a prescribed load; :mod:`stickslip.model.normal`). False compiles their kernels without
        the gap's branches (the two plates, always pressed).
    gap : numba-compilable function, optional
        ``gap(kin, s, c, m, W) -> g``: the gap g(q) [m] of unilateral contact ``c`` at state ``s``,
        filling ``W`` (n,) with its gradient ∂g/∂q; complex-safe like ``frame``. The contact's normal
        force λ acts on the coordinates as W(q)ᵀ λ and its gap rate is ġ = W(q)·q̇. Without it the
        gap is the contact's affine g0 + W·q (``Contact.gap``, ``Contact.gap_gradient``).
    rigid : bool
        Whether models of this kinematics may have rigid unilateral contacts (impacts; their normal
        force a multiplier). False compiles their kernels without that code (the model files' class
        for compliant contacts).
    inline : bool, optional
        True: ``frame`` (and ``frame_bias``, ``gap``) is compiled into every kernel that calls it,
        each kernel specialised for ``cls`` (the fastest runs; editing the frame recompiles every
        kernel of the class, half a minute and more). False: they are compiled on their own and the
        kernels call them through their addresses (:mod:`stickslip.model.frame_pointers`); the
        kernels depend on the sizes given here (loops unrolled alike) and the model's kinds of
        contacts, not on ``cls`` or its code, so they are shared by every class registered so and
        compiled once per machine, and an edit recompiles the edited function alone (a second or
        two). The call costs steady runs a little (1.19× on a one-DOF arm whose frame is a large
        part of its step). Default: True for the package's own classes, False for any other.
    """
    if not (isinstance(cls, type) and issubclass(cls, tuple) and hasattr(cls, "_fields")):
        raise KinematicsError(f"kinematics class {cls!r} must be a NamedTuple of numbers")
    _FRAMES[cls] = frame
    track_user_code(cls, frame, *[f for f in (frame_bias, gap) if f is not None])
    _SIZES[cls] = (ndof, ncontacts, diagonal)
    _DIMS[cls] = dim
    if frame_bias is None:
        _BIASES.pop(cls, None)
    else:
        _BIASES[cls] = frame_bias if hasattr(frame_bias, "py_func") else njit(**KERNEL_OPTIONS)(frame_bias)
    if ndof is not None and ncontacts is not None:
        stack._STATIC[cls] = (ndof, ncontacts)
    if gap is None:
        _GAPS.pop(cls, None)
    else:
        if not unilateral:
            raise KinematicsError(f"kinematics class {cls.__name__}: a gap function needs unilateral=True")
        _GAPS[cls] = gap
    if unilateral:
        _PRESSED_ONLY.discard(cls)
    else:
        _PRESSED_ONLY.add(cls)
    if unilateral and rigid:
        _NO_RIGID.discard(cls)
    else:
        _NO_RIGID.add(cls)
    if inline is None:
        inline = defined_in_package(cls)
    forget(cls)
    if inline:
        _APART.pop(cls, None)
    else:
        _APART[cls] = ((frame, frame_bias, gap), (ndof, ncontacts, diagonal, dim))


#: Classes registered with ``inline=False``: their (frame, bias, gap) and the sizes they fix.
_APART: dict[type, tuple] = {}


def kernel_kinematics(kin, unilateral: bool, rigid: bool):
    """The kinematics data the kernels take for a model's ``kin``: ``kin`` itself, or for a class
    registered with ``inline=False`` its functions' addresses (compiled where needed:
    :func:`~stickslip.model.frame_pointers.compiled_addresses`) and its values, in the
    :func:`pointer_class` instance for a model with (``unilateral``) unilateral contacts,
    (``rigid``) a rigid one: a model's kernels compile the code of the contacts it has."""
    apart = _APART.get(type(kin))
    if apart is None:
        return kin
    functions, sizes = apart
    return pointer_class(unilateral, rigid, sizes)(*compiled_addresses(kin, functions), tuple(kin))


#: Which contacts a pointer class's kernels compile code for, by the kind in its name.
_KINDS = {"Pressed": (False, False), "Compliant": (True, False), "Rigid": (True, True)}
_POINTER_NAME = re.compile(r"FramePointers(Pressed|Compliant|Rigid)(?:_n(\d+)_c(\d+))?(?:_(diagonal|dense))?"
                           r"(?:_dim(\d))?$")
_POINTER_CLASSES: dict[str, type] = {}


def pointer_class(unilateral: bool, rigid: bool, sizes: tuple) -> type:
    """The class of the kinematics data of a model whose frame is compiled apart
    (:class:`~stickslip.model.frame_pointers.FramePointerFields`): its kernels compile the code of
    unilateral (``unilateral``) and rigid (``rigid``) contacts where the model has them, for the
    (ndof, ncontacts, diagonal, dim) that the user's class fixed (None where it did not), so they
    are specialised as the user's class would be, and shared by every class with the same ones.

    The class is made on first use and registered as a kinematics class of its own; its name says
    what it stands for, so that a process which reads it from numba's cache index makes it again
    (this module's ``__getattr__``).
    """
    ndof, ncontacts, diagonal, dim = sizes
    name = "FramePointers" + ("Rigid" if rigid else "Compliant" if unilateral else "Pressed")
    if ndof is not None and ncontacts is not None:
        name += f"_n{ndof}_c{ncontacts}"
    if diagonal is not None:
        name += "_diagonal" if diagonal else "_dense"
    if dim is not None:
        name += f"_dim{dim}"
    return _POINTER_CLASSES.get(name) or _make_pointer_class(name)


def _make_pointer_class(name: str) -> type:
    match = _POINTER_NAME.match(name)
    if match is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    kind, ndof, ncontacts, diagonal, dim = match.groups()
    unilateral, rigid = _KINDS[kind]
    cls = type(name, (FramePointerFields,), {"__slots__": (), "__reduce__": _reduce_pointers, "__module__": __name__,
                                              "contact_kinds": (unilateral, rigid),
                                              "__doc__": f"Kinematics data of {name[13:]} models whose frame is "
                                                         "compiled apart."})
    register_kinematics(cls, pointer_frame, ndof=None if ndof is None else int(ndof),
                        ncontacts=None if ncontacts is None else int(ncontacts),
                        diagonal=None if diagonal is None else diagonal == "diagonal",
                        dim=None if dim is None else int(dim), gap=pointer_gap if unilateral else None,
                        unilateral=unilateral, rigid=rigid, inline=True)
    _POINTER_CLASSES[name] = cls
    return cls


def _reduce_pointers(self):
    """Pickle a pointer instance as the user's kinematics object (addresses belong to one process)."""
    return kernel_kinematics, (origin_class(self)(*self.values), *self.contact_kinds)


def __getattr__(name: str) -> type:  # a pointer class named by numba's cache index, made again
    if name.startswith("FramePointers"):
        return _POINTER_CLASSES.get(name) or _make_pointer_class(name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def allows_rigid(cls: type) -> bool:
    """Whether models of kinematics class ``cls`` may have rigid contacts."""
    return cls not in _NO_RIGID


def allows_unilateral(cls: type) -> bool:
    """Whether models of kinematics class ``cls`` may have unilateral contacts."""
    return cls not in _PRESSED_ONLY


def computes_gap(cls: type) -> bool:
    """Whether kinematics class ``cls`` registered a gap function (its contacts' gaps need no W)."""
    return cls in _GAPS


def pressed_only(kin_type) -> bool:
    """At compile time: whether the numba type ``kin_type`` of a kinematics object belongs to a class
    registered without unilateral contacts (the overloads of :mod:`stickslip.model.normal` then
    compile none of their code)."""
    return getattr(kin_type, "instance_class", None) in _PRESSED_ONLY


def rigid_free(kin_type) -> bool:
    """At compile time: whether the numba type ``kin_type`` of a kinematics object belongs to a class
    whose models have no rigid contacts (pressed-only ones included)."""
    return getattr(kin_type, "instance_class", None) in _NO_RIGID


def _kernel_without(lacks: Callable[[Any], bool], what: str) -> Callable:
    """A decorator like :func:`unilateral_kernel` for the kinematics classes where ``lacks(type)``."""
    def decorator(stub: Callable, *, inline: str = "never") -> Callable:
        def register(impl: Callable) -> Callable:
            signature = inspect.signature(impl)
            at = list(signature.parameters).index("md")

            def choose(*args):
                md = args[at]
                return stub if lacks(md.types[md.fields.index("kin")]) else impl

            choose.__signature__ = signature  # numba checks each implementation against it
            overload(impl, jit_options=KERNEL_OPTIONS, inline=inline)(choose)
            return impl
        return register
    decorator.__doc__ = f"""Decorator for a kernel that only kinematics with {what} need.

    Numba resolves each call of the decorated function at compile time by the type of its
    argument ``md``: for a kinematics class registered without {what} it compiles the stub
    instead (the same argument names; a constant, the identity or nothing), so those kernels
    compile none of the decorated code. ``inline`` is numba's overload option (``"always"`` for
    the small ones). Returns the decorated function, the name compiled code calls (it is never
    run by Python).
    """
    return decorator


unilateral_kernel = _kernel_without(pressed_only, "unilateral contacts")
rigid_kernel = _kernel_without(rigid_free, "rigid contacts")


def registered_kinematics() -> tuple[type, ...]:
    """The kinematics classes known to the compiled kernels."""
    return tuple(_FRAMES)


def registered_frame_bias(kin_type) -> Callable | None:
    """The compiled closed-form frame-and-bias function registered for the numba type ``kin_type``
    of a kinematics object, or None (for the pointer classes of frames compiled apart, whether
    there is one is known at run time only: :func:`bias_at_run_time`)."""
    return _BIASES.get(getattr(kin_type, "instance_class", None))


def bias_at_run_time(kin_type) -> bool:
    """At compile time: whether the numba type ``kin_type`` is a pointer class, whose closed-form
    bias is called through its address where one was registered (``kin.bias != 0``)."""
    return is_pointer_class(getattr(kin_type, "instance_class", None))


def contact_frame(kin, s, c, m, G, w):  # pragma: no cover - resolved by numba (overload below)
    """Fill G (2, n), w (2,) of contact ``c`` at state ``s`` and return its normal force [N]."""
    raise NotImplementedError("contact_frame is called from compiled code only")


@overload(contact_frame, jit_options=KERNEL_OPTIONS)
def _contact_frame(kin, s, c, m, G, w):
    frame = _FRAMES.get(getattr(kin, "instance_class", None))
    if frame is None:
        return None
    # the Python source, compiled for each caller's types as an ordinary call (LLVM inlines it): numba's
    # IR-level inlining mis-scoped the accumulator of constant_frame's loop (a 'not in scope' warning)
    return getattr(frame, "py_func", frame)


def contact_gap(kin, s, c, m, W):  # pragma: no cover - resolved by numba (overload below)
    """Fill W (n,) with ∂g/∂q of unilateral contact ``c`` at state ``s`` and return its gap g [m]:
    the gap function registered for the kinematics class (none for the others)."""
    raise NotImplementedError("contact_gap is called from compiled code only")


@overload(contact_gap, jit_options=KERNEL_OPTIONS)
def _contact_gap(kin, s, c, m, W):
    gap = _GAPS.get(getattr(kin, "instance_class", None))
    if gap is None:  # never run: callers take the affine branch (gap_computed is False)
        return lambda kin, s, c, m, W: csm.zero(s[0])
    return getattr(gap, "py_func", gap)


def gap_computed(kin):  # pragma: no cover - resolved by numba (overload below)
    """Whether the kinematics class of ``kin`` registered a gap function: a compile-time constant
    (else its gaps are the data array's affine g0 + W·q)."""
    raise NotImplementedError


@overload(gap_computed, jit_options=KERNEL_OPTIONS)
def _gap_computed(kin):
    if is_pointer_class(getattr(kin, "instance_class", None)):  # whether a gap function was registered
        return lambda kin: kin.gap != 0
    if getattr(kin, "instance_class", None) in _GAPS:
        return lambda kin: True
    return lambda kin: False


def sizes_at_run_time(kin) -> bool:
    """Whether the kinematics object ``kin`` leaves all of a model's sizes (n, nc, diagonal) to its
    data at run time, so that kernels take them as plain integers, not compile-time constants."""
    return _SIZES.get(type(kin), (None, None, None)) == (None, None, None)


def model_sizes(kin, m):  # pragma: no cover - resolved by numba (overload below)
    """(n, nc, diagonal) of a model: compile-time constants where its kinematics fixes them."""
    raise NotImplementedError


@overload(model_sizes, jit_options=KERNEL_OPTIONS)
def _model_sizes(kin, m):
    n, nc, diagonal = _SIZES.get(getattr(kin, "instance_class", None), (None, None, None))
    if n is not None and nc is not None and diagonal is not None:
        def fixed(kin, m):
            return n, nc, diagonal
        return fixed

    def sizes(kin, m):
        return (np.int64(m[H_N]) if n is None else n, np.int64(m[H_NC]) if nc is None else nc,
                (m[H_DIAGONAL] != 0.0) if diagonal is None else diagonal)
    return sizes


def has_unilateral(kin, m):  # pragma: no cover - resolved by numba (overload below)
    """Whether the model has a unilateral contact: False at compile time for kinematics classes
    registered without them, else the header flag."""
    raise NotImplementedError


@overload(has_unilateral, jit_options=KERNEL_OPTIONS)
def _has_unilateral(kin, m):
    if getattr(kin, "instance_class", None) in _PRESSED_ONLY:
        return lambda kin, m: False
    return lambda kin, m: m[H_UNILATERAL] != 0.0


def contact_dim(kin, m, n, c):  # pragma: no cover - resolved by numba (overload below)
    """Dimension (1 or 2) of contact ``c``'s slip velocity: fixed by the kinematics class, or read."""
    raise NotImplementedError


@overload(contact_dim, jit_options=KERNEL_OPTIONS)
def _contact_dim(kin, m, n, c):
    dim = _DIMS.get(getattr(kin, "instance_class", None))
    if dim is not None:
        return lambda kin, m, n, c: dim
    return lambda kin, m, n, c: np.int64(m[contact_offsets(n, c)[0] + C_DIM])


class ConstantKinematics(NamedTuple):
    """Kinematics of a model whose contact Jacobians G and drives w are constant (model files).

    G, w and the affine normal force N = N0 + n·q + n_v·q̇ live in the model's data array. Its
    contacts are all pressed: a model with unilateral contacts takes
    :class:`ConstantUnilateralKinematics` (:class:`~stickslip.model.FrictionModel` swaps it in), so
    that models without them compile none of their code.
    """

    constant: float = 1.0


class ConstantUnilateralKinematics(NamedTuple):
    """:class:`ConstantKinematics` of a model with compliant unilateral contacts: a closed compliant
    contact's force −k (g0 + W·q) − c W·q̇ is affine in the state too, and stands in the data array
    as its N0, n and n_v (:meth:`stickslip.model.system_model.Contact.spec`), so the frame returns it."""

    constant: float = 1.0


class ConstantRigidKinematics(NamedTuple):
    """:class:`ConstantUnilateralKinematics` of a model with a rigid contact: only such models compile
    the rigid normal forces and the impacts."""

    constant: float = 1.0


#: The kinematics classes of constant G and w.
CONSTANT_KINEMATICS = (ConstantKinematics, ConstantUnilateralKinematics, ConstantRigidKinematics)


#: The fields of the heap kinematics classes (below), all three alike.
_HEAP_FIELDS = [("ndof", int), ("ncontacts", int), ("force_rows", np.ndarray), ("force_columns", np.ndarray),
                ("mass_rows", np.ndarray), ("mass_columns", np.ndarray), ("factor_order", np.ndarray),
                ("factor_rows", np.ndarray), ("factor_columns", np.ndarray), ("factor_values", np.ndarray),
                ("factor_diagonal", np.ndarray), ("factor_segment_rows", np.ndarray), ("factor_segments", np.ndarray),
                ("row_starts", np.ndarray), ("row_columns", np.ndarray), ("row_values", np.ndarray),
                ("normal_starts", np.ndarray), ("normal_columns", np.ndarray), ("normal_q", np.ndarray),
                ("normal_v", np.ndarray), ("gap_starts", np.ndarray), ("gap_columns", np.ndarray),
                ("gap_values", np.ndarray), ("delassus", np.ndarray), ("inverse_mass_rows", np.ndarray),
                ("damping_values", np.ndarray), ("stiffness_values", np.ndarray), ("mass_values", np.ndarray)]

LargeConstantKinematics = NamedTuple("LargeConstantKinematics", _HEAP_FIELDS)
LargeConstantKinematics.__doc__ = """The kernels' :class:`ConstantKinematics` of a model larger than the
stack arrays hold (:data:`~stickslip.model.stack.MAX_DOFS`, :data:`~stickslip.model.stack.MAX_CONTACTS`): its work
arrays are heap buffers of run-time size (:func:`~stickslip.model.stack.register_heap`), so it has no fixed
maximum. ``FrictionModel.data`` chooses it; the model keeps its own class.

``force_rows`` (n + 1,) and ``force_columns`` (int64) hold the row-compressed pattern of the entries
of C and K that are not both zero (:func:`force_pattern`), ``damping_values`` and ``stiffness_values``
their entries there: the base force f0 − C q̇ − K q sums over those only
(:func:`~stickslip.model.model_data.base_force_of`), as a reduced or finite-element model's C and K
are mostly zero, reading them in order (gathered from the packed n-by-n matrices, each entry a
cache line of its own, they cost more than the sums); ``mass_rows``, ``mass_columns`` and
``mass_values`` the same for M (the kinetic energy);
``factor_*`` the sparse Cholesky factor of M on its free DOFs
(:func:`~stickslip.model.mass_factor.mass_factor`), with which M⁻¹ f is two triangular solves
(:func:`~stickslip.model.model_data.inverse_mass_of`). ``FrictionModel.data`` packs the matrices of
such a model without their round-off entries (:func:`~stickslip.model.mass_factor.without_round_off`),
so the patterns are those of the model's mechanics, not of its arithmetic.

``row_*``, ``normal_*`` and ``gap_*`` hold the contacts' tangent rows, normal-force gradients and
gap gradients over their nonzero entries (:func:`~stickslip.model.mass_factor.contact_rows`), from
which the frame (:func:`sparse_constant_frame`), the slip velocities and the stick systems' right
sides, the gaps and the normal forces on the coordinates are summed; ``delassus``
(2 nc, 2 nc) is W = G M⁻¹ Gᵀ of all contact rows (:func:`~stickslip.model.mass_factor.delassus`),
whose submatrices are the stick systems, and ``inverse_mass_rows`` (2 nc, n) its rows M⁻¹ g_r (the
right sides of the stick systems and the projections of the velocities read them); both (0, 0)
where they did not fit in memory (the stick systems are then formed row by row)."""
LargeConstantUnilateralKinematics = NamedTuple("LargeConstantUnilateralKinematics", _HEAP_FIELDS)
LargeConstantUnilateralKinematics.__doc__ = (":class:`LargeConstantKinematics` for "
                                             ":class:`ConstantUnilateralKinematics` (compliant contacts).")
LargeConstantRigidKinematics = NamedTuple("LargeConstantRigidKinematics", _HEAP_FIELDS)
LargeConstantRigidKinematics.__doc__ = (":class:`LargeConstantKinematics` for :class:`ConstantRigidKinematics` "
                                        "(a rigid contact).")


#: The heap class the kernels of a large model of each constant-kinematics class take.
LARGE_KINEMATICS = {ConstantKinematics: LargeConstantKinematics,
                    ConstantUnilateralKinematics: LargeConstantUnilateralKinematics,
                    ConstantRigidKinematics: LargeConstantRigidKinematics}


def fits_stack(cls: type, n: int, nc: int) -> bool:
    """Whether a model of n dofs and nc contacts of kinematics class ``cls`` has kernels with stack
    work arrays (its class fixes its sizes, or they are within the maxima)."""
    return stack.static_sizes(cls) is not None or (n <= stack.MAX_DOFS and nc <= stack.MAX_CONTACTS)


def force_pattern(damping: np.ndarray, stiffness: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rows (n + 1,), columns) int64: the row-compressed pattern of the entries (i, j) where the
    dense (n, n) ``damping`` or ``stiffness`` is not zero, columns ascending in each row."""
    return row_pattern((np.asarray(damping) != 0.0) | (np.asarray(stiffness) != 0.0))


def large_kinematics(kin, n: int, nc: int, matrices: tuple[np.ndarray, ...], m: np.ndarray):
    """The kinematics data the kernels take for a model of n dofs and nc contacts: ``kin`` where
    it fits the stack arrays (:func:`fits_stack`), else its heap class with the patterns of the
    dense (n, n) ``matrices`` = (mass, damping, stiffness, free) (:func:`force_pattern`, the mass's
    pattern and its sparse factor, :func:`~stickslip.model.mass_factor.mass_factor`), and the
    contact rows of the packed data ``m`` over their nonzero entries with W = G M⁻¹ Gᵀ and G M⁻¹
    (:func:`~stickslip.model.mass_factor.contact_rows`, :func:`~stickslip.model.mass_factor.delassus`;
    W empty where it does not fit in memory: :func:`~stickslip.memory.delassus_bytes`); None
    where it has no heap class: a frame computed from q, which the stack maxima bound."""
    cls = type(kin)
    if fits_stack(cls, n, nc):
        return kin
    large = LARGE_KINEMATICS.get(cls)
    if large is None:
        return None
    mass, damping, stiffness, free = matrices
    rows = contact_rows(m, n, nc)
    empty = (np.zeros((0, 0)), np.zeros((0, 0)))
    w = delassus(m, n, nc, rows[:3]) if fits_in_memory(delassus_bytes(n, nc)) else empty
    forces = force_pattern(damping, stiffness)
    masses = row_pattern(np.asarray(mass) != 0.0)
    _, o_mass, o_damping, o_stiffness = offsets(n)[:4]
    values = (packed_values(m, o_damping, n, *forces), packed_values(m, o_stiffness, n, *forces),
              packed_values(m, o_mass, n, *masses))
    return large(int(n), int(nc), *forces, *masses, *mass_factor(mass, free), *rows, *w, *values)


def packed_values(m: np.ndarray, offset: int, n: int, rows: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """The entries of the n-by-n matrix packed in ``m`` from ``offset`` (row-major) at the
    row-compressed pattern (``rows`` (n + 1,), ``columns``), in its order."""
    row_of = np.repeat(np.arange(n), np.diff(rows))
    return np.ascontiguousarray(m[offset + row_of * n + columns], dtype=np.float64)


@kernel
def constant_frame(kin, s, c, m, G, w):
    """Frame of :class:`ConstantKinematics`: G and w copied from the data array, N affine in s."""
    n, nc, diagonal = model_sizes(kin, m)
    o, ow, onq, onv = contact_offsets(n, c)
    normal = m[o + C_N0] + csm.zero(s[0])
    for j in range(n):
        G[0, j] = m[o + C_G + j]
        G[1, j] = m[o + C_G + n + j]
        normal += m[onq + j] * s[j] + m[onv + j] * s[n + j]
    w[0] = m[ow]
    w[1] = m[ow + 1]
    return normal


register_kinematics(ConstantKinematics, constant_frame, unilateral=False)
register_kinematics(ConstantUnilateralKinematics, constant_frame, rigid=False)
register_kinematics(ConstantRigidKinematics, constant_frame)


@inlined_kernel
def heap_normal_and_drive(kin, s, c, m, w):
    """The normal force of contact ``c`` of a heap class, summed over the nonzero entries of its
    gradients (``kin.normal_*``), with its drive written to ``w`` (2,): its frame but the rows."""
    o, ow, _, _ = contact_offsets(kin.ndof, c)
    normal = m[o + C_N0] + csm.zero(s[0])
    for p in range(kin.normal_starts[c], kin.normal_starts[c + 1]):
        j = kin.normal_columns[p]
        normal += kin.normal_q[p] * s[j] + kin.normal_v[p] * s[kin.ndof + j]
    w[0] = m[ow]
    w[1] = m[ow + 1]
    return normal


@kernel
def sparse_constant_frame(kin, s, c, m, G, w):
    """:func:`constant_frame` of the heap classes: G's rows set to zero and their nonzero entries
    written (``kin.row_*``), N summed over the nonzero entries of its gradients (``kin.normal_*``)
    in the same order, so a contact costs its entries and two rows of stores instead of 4n reads."""
    for i in range(2):
        for j in range(kin.ndof):
            G[i, j] = 0.0
        for p in range(kin.row_starts[2 * c + i], kin.row_starts[2 * c + i + 1]):
            G[i, kin.row_columns[p]] = kin.row_values[p]
    return heap_normal_and_drive(kin, s, c, m, w)


def frame_for_sums(kin, s, c, m, G, w):  # pragma: no cover - resolved by numba (overload below)
    """:func:`contact_frame` for a caller that reads the rows only through the sums of
    :mod:`stickslip.model.frames` (``contact_velocity``, ``add_force_of``): a heap class's frame
    without the rows (:func:`heap_normal_and_drive`; the sums read ``kin.row_*``), so the 2 n
    stores of each contact's rows are not made."""
    raise NotImplementedError


@overload(frame_for_sums, jit_options=KERNEL_OPTIONS, inline="always")
def _frame_for_sums(kin, s, c, m, G, w):
    if stack.on_heap(getattr(kin, "instance_class", None)):
        return lambda kin, s, c, m, G, w: heap_normal_and_drive(kin, s, c, m, w)
    return lambda kin, s, c, m, G, w: contact_frame(kin, s, c, m, G, w)


for _small, _large in LARGE_KINEMATICS.items():  # each heap class takes the contacts its stack class takes
    register_kinematics(_large, sparse_constant_frame, unilateral=allows_unilateral(_small), rigid=allows_rigid(_small))
    stack.register_heap(_large)
