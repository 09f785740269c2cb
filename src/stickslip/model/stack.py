"""Work arrays on the stack of a compiled kernel, sized from the model's kinematics class.

The physics kernels need small work arrays (each contact's G and w, the generalised force, the
stick system). Passed in from outside they are ordinary memory that the compiler must assume may
alias the state, so every value makes a round trip through memory; allocated on the kernel's own
stack (an ``alloca`` in its entry block) they cannot alias anything, and when their size is a
compile-time constant the compiler keeps them in registers. :func:`work_matrix` creates such an
array of shape (rows, cols), where the sizes are codes resolved *at compile time* from the
kinematics class of the model (:func:`stickslip.model.kinematics.register_kinematics`):

``DOFS`` n, ``STATES`` 2n, ``CONTACTS`` nc, ``ROWS`` 2 nc (the tangent rows of all contacts),
``ONE``, ``TWO``, ``VECTORS`` (a few scratch vectors).

Models whose kinematics does not fix n and nc get arrays for :data:`MAX_DOFS` and
:data:`MAX_CONTACTS` (checked when a model is built). The arrays are uninitialised, live until
the kernel returns, and must not be returned (they die with the frame).
"""

from __future__ import annotations

from numba.core import cgutils, types
from numba.extending import intrinsic
from numba.np.arrayobj import populate_array

__all__ = ["work_matrix", "static_sizes", "MAX_DOFS", "MAX_CONTACTS", "DOFS", "STATES", "CONTACTS", "ROWS",
           "ONE", "TWO", "VECTORS"]

#: Largest model (DOFs, contacts) whose kinematics class does not fix its size; a larger one is
#: refused when it is built (the stack frames of the kernels hold arrays of this size).
MAX_DOFS = 64
MAX_CONTACTS = 16

DOFS, STATES, CONTACTS, ROWS, ONE, TWO, VECTORS = range(7)

#: Scratch vectors of length ≥ max(n, 2 nc) in one VECTORS block.
N_VECTORS = 8

#: Sizes fixed by kinematics classes: class → (n, nc); filled by register_kinematics.
_STATIC: dict[type, tuple[int, int]] = {}


def static_sizes(cls) -> tuple[int, int] | None:
    """(n, nc) fixed by a kinematics class, or None."""
    return _STATIC.get(cls)


def _extent(code: int, n: int, nc: int) -> int:
    return {DOFS: n, STATES: 2 * n, CONTACTS: nc, ROWS: 2 * nc, ONE: 1, TWO: 2,
            VECTORS: N_VECTORS}[code]


@intrinsic(prefer_literal=True)
def work_matrix(typingctx, kin, rows, cols, like):
    """A C-contiguous (rows, cols) array of the number type of ``like`` (an array or a scalar) on the
    caller's stack.

    ``rows`` and ``cols`` are literal size codes (module docstring); ``kin`` the model's
    kinematics data (its class fixes n and nc, or the maxima apply). With VECTORS as ``rows`` the
    columns are max(n, 2 nc) whatever ``cols`` says.
    """
    sizes = _STATIC.get(getattr(kin, "instance_class", None), (MAX_DOFS, MAX_CONTACTS))
    n, nc = sizes
    r = _extent(rows.literal_value, n, nc)
    c = max(n, 2 * nc) if rows.literal_value == VECTORS else _extent(cols.literal_value, n, nc)
    dtype = like.dtype if isinstance(like, types.Array) else like
    arrty = types.Array(dtype, 2, "C")

    def codegen(context, builder, signature, args):
        llty = context.get_value_type(dtype)
        ptr = cgutils.alloca_once(builder, llty, size=context.get_constant(types.intp, r * c))
        ary = context.make_array(arrty)(context, builder)
        itemsize = context.get_abi_sizeof(llty)
        intp = lambda value: context.get_constant(types.intp, value)  # noqa: E731
        populate_array(ary, data=ptr, shape=[intp(r), intp(c)], strides=[intp(itemsize * c), intp(itemsize)],
                       itemsize=intp(itemsize), meminfo=None)
        return ary._getvalue()

    return arrty(kin, rows, cols, like), codegen
