"""Work arrays on the stack of a compiled kernel, sized from the model's kinematics class.

The physics kernels need small work arrays (each contact's G and w, the generalised force, the
stick system). Passed in from outside they are ordinary memory that the compiler must assume may
alias the state, so every value makes a round trip through memory; allocated on the kernel's own
stack (an ``alloca`` in its entry block) they cannot alias anything, and when their size is a
compile-time constant the compiler keeps them in registers. :func:`work_matrix` creates such an
array of shape (rows, cols), where the sizes are codes resolved *at compile time* from the
kinematics class of the model (:func:`stickslip.model.kinematics.register_kinematics`):

``DOFS`` n, ``STATES`` 2n, ``CONTACTS`` nc, ``ROWS`` 2 nc (the tangent rows of all contacts),
``ONE``, ``TWO``, ``IMPULSE_ROWS`` 3 nc (the normal and tangent rows of all contacts: impacts).

:func:`work_vectors` creates several scratch vectors of length max(n, 2 nc) at once (long enough
for a generalised force and for one entry per tangent row), unpacked by the caller:
``w, v, N, h, F, f = work_vectors(md.kin, 6, s)``.

Models whose kinematics does not fix n and nc get arrays for :data:`MAX_DOFS` and
:data:`MAX_CONTACTS` (checked when a model is built). The arrays are uninitialised, live until
the kernel returns, and must not be returned (they die with the frame).
"""

from __future__ import annotations

from numba.core import cgutils, types
from numba.extending import intrinsic
from numba.np.arrayobj import populate_array

__all__ = ["work_matrix", "work_vectors", "static_sizes", "MAX_DOFS", "MAX_CONTACTS", "DOFS", "STATES", "CONTACTS", "ROWS",
           "ONE", "TWO", "IMPULSE_ROWS"]

#: Largest model (DOFs, contacts) whose kinematics class does not fix its size; a larger one is
#: refused when it is built (the stack frames of the kernels hold arrays of this size).
MAX_DOFS = 64
MAX_CONTACTS = 16

DOFS, STATES, CONTACTS, ROWS, ONE, TWO, IMPULSE_ROWS = range(7)

#: Sizes fixed by kinematics classes: class → (n, nc); filled by register_kinematics.
_STATIC: dict[type, tuple[int, int]] = {}


def static_sizes(cls) -> tuple[int, int] | None:
    """(n, nc) fixed by a kinematics class, or None."""
    return _STATIC.get(cls)


def _extent(code: int, n: int, nc: int) -> int:
    return {DOFS: n, STATES: 2 * n, CONTACTS: nc, ROWS: 2 * nc, ONE: 1, TWO: 2, IMPULSE_ROWS: 3 * nc}[code]


@intrinsic(prefer_literal=True)
def work_matrix(typingctx, kin, rows, cols, like):
    """A C-contiguous (rows, cols) array of the number type of ``like`` (an array or a scalar) on the
    caller's stack.

    ``rows`` and ``cols`` are literal size codes (module docstring); ``kin`` the model's
    kinematics data (its class fixes n and nc, or the maxima apply).
    """
    n, nc = _sizes(kin)
    r = _extent(rows.literal_value, n, nc)
    c = _extent(cols.literal_value, n, nc)
    dtype = _number_type(like)
    arrty = types.Array(dtype, 2, "C")

    def codegen(context, builder, signature, args):
        ptr, itemsize, intp = _stack_block(context, builder, dtype, r * c)
        ary = context.make_array(arrty)(context, builder)
        populate_array(ary, data=ptr, shape=[intp(r), intp(c)], strides=[intp(itemsize * c), intp(itemsize)],
                       itemsize=intp(itemsize), meminfo=None)
        return ary._getvalue()

    return arrty(kin, rows, cols, like), codegen


@intrinsic(prefer_literal=True)
def work_vectors(typingctx, kin, count, like):
    """A tuple of ``count`` (a literal) C-contiguous vectors of length max(n, 2 nc), of the number type
    of ``like``, on the caller's stack: consecutive in one block."""
    n, nc = _sizes(kin)
    length = _vector_length(n, nc)
    k = count.literal_value
    dtype = _number_type(like)
    arrty = types.Array(dtype, 1, "C")
    tupty = types.UniTuple(arrty, k)

    def codegen(context, builder, signature, args):
        ptr, itemsize, intp = _stack_block(context, builder, dtype, k * length)
        vectors = []
        for i in range(k):
            ary = context.make_array(arrty)(context, builder)
            populate_array(ary, data=builder.gep(ptr, [intp(i * length)]), shape=[intp(length)],
                           strides=[intp(itemsize)], itemsize=intp(itemsize), meminfo=None)
            vectors.append(ary._getvalue())
        return context.make_tuple(builder, tupty, vectors)

    return tupty(kin, count, like), codegen


def _sizes(kin) -> tuple[int, int]:
    """(n, nc) of the arrays for the kinematics type ``kin``: its class's, or the maxima."""
    return _STATIC.get(getattr(kin, "instance_class", None), (MAX_DOFS, MAX_CONTACTS))


def _vector_length(n: int, nc: int) -> int:
    return max(n, 2 * nc)


def _number_type(like):
    return like.dtype if isinstance(like, types.Array) else like


def _stack_block(context, builder, dtype, size: int):
    """(pointer to ``size`` uninitialised elements of ``dtype`` in the entry block, item size, a
    maker of intp constants)."""
    llty = context.get_value_type(dtype)
    intp = lambda value: context.get_constant(types.intp, value)  # noqa: E731
    ptr = cgutils.alloca_once(builder, llty, size=intp(size))
    return ptr, context.get_abi_sizeof(llty), intp
