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

A larger model (hundreds of DOFs and contacts, a reduced finite-element model) takes a *heap*
kinematics class (:func:`register_heap`; ``model/kinematics.py``'s ``Large*`` classes, chosen by
``FrictionModel.data``): its data carries n and nc (fields ``ndof``, ``ncontacts``), and each call
site of :func:`work_matrix` or :func:`work_vectors` in its kernels owns one heap buffer, sized
at run time and kept for the next call (grown when a larger model comes; never freed, so a
process holds one buffer per site of the largest model it ran). The kernels compile without
numba's reference counting, so a buffer per site is what lets their arrays have a run-time size
without an allocation and a free per call: a site runs again only after the array it gave last
time is dead (the kernels do not recurse, and hold the GIL, so no two threads run them at once).
The small models' kernels are those of before, stack arrays of compile-time size.
"""

from __future__ import annotations

from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic
from numba.np.arrayobj import populate_array

__all__ = ["work_matrix", "work_vectors", "static_sizes", "register_heap", "on_heap", "MAX_DOFS", "MAX_CONTACTS",
           "DOFS", "STATES", "CONTACTS", "ROWS",
           "ONE", "TWO", "IMPULSE_ROWS"]

#: Largest model (DOFs, contacts) whose kinematics class does not fix its size; a larger one is
#: refused when it is built (the stack frames of the kernels hold arrays of this size).
MAX_DOFS = 64
MAX_CONTACTS = 16

DOFS, STATES, CONTACTS, ROWS, ONE, TWO, IMPULSE_ROWS = range(7)

#: Sizes fixed by kinematics classes: class → (n, nc); filled by register_kinematics.
_STATIC: dict[type, tuple[int, int]] = {}


#: Kinematics classes whose kernels take heap work arrays of run-time size (fields ndof, ncontacts).
_HEAP: set[type] = set()


def static_sizes(cls) -> tuple[int, int] | None:
    """(n, nc) fixed by a kinematics class, or None."""
    return _STATIC.get(cls)


def kinematics_class(md_type):
    """The kinematics class of the model data bundle typed ``md_type`` (the numba type of a
    :class:`~stickslip.model.bundle.ModelData`, as an overload sees it), or None where its
    kinematics type has no class."""
    return getattr(md_type.types[md_type.fields.index("kin")], "instance_class", None)


def one_contact(cls) -> bool:
    """Whether the kinematics class ``cls`` fixes its models' contact count at one: at most two
    stick rows, so code for more (a stick system solved by Jacobi rotations, a breakaway search
    over many contacts) is never reached and need not be compiled."""
    sizes = static_sizes(cls)
    return sizes is not None and sizes[1] == 1


def register_heap(cls: type) -> None:
    """Give the kernels of kinematics class ``cls`` (a NamedTuple with integer fields ``ndof`` and
    ``ncontacts``) heap work arrays sized from those fields at run time (module docstring)."""
    if not {"ndof", "ncontacts"} <= set(getattr(cls, "_fields", ())):
        raise TypeError(f"{cls!r}: a heap kinematics class needs the fields ndof and ncontacts")
    _HEAP.add(cls)


def on_heap(cls) -> bool:
    """Whether the kernels of kinematics class ``cls`` take heap work arrays."""
    return cls in _HEAP


def _extent(code: int, n: int, nc: int) -> int:
    return {DOFS: n, STATES: 2 * n, CONTACTS: nc, ROWS: 2 * nc, ONE: 1, TWO: 2, IMPULSE_ROWS: 3 * nc}[code]


@intrinsic(prefer_literal=True)
def work_matrix(typingctx, kin, rows, cols, like):
    """A C-contiguous (rows, cols) array of the number type of ``like`` (an array or a scalar) on the
    caller's stack (for a heap class: in the call site's heap buffer).

    ``rows`` and ``cols`` are literal size codes (module docstring); ``kin`` the model's
    kinematics data (its class fixes n and nc, or the maxima apply, or a heap class carries them).
    """
    dtype = _number_type(like)
    arrty = types.Array(dtype, 2, "C")
    # Read while typing, so that typing with the sizes as plain integers fails and numba types the
    # call with their literals: numba 0.57's intrinsic ignores prefer_literal and tries plain first
    row_code, col_code = rows.literal_value, cols.literal_value
    if _heap(kin):
        def heap_codegen(context, builder, signature, args):
            n, nc = _run_time_sizes(kin, builder, args[0])
            r = _extent_value(builder, row_code, n, nc)
            c = _extent_value(builder, col_code, n, nc)
            ptr, itemsize, intp = _site_buffer(context, builder, dtype, builder.mul(r, c))
            ary = context.make_array(arrty)(context, builder)
            populate_array(ary, data=ptr, shape=[r, c], strides=[builder.mul(c, intp(itemsize)), intp(itemsize)],
                           itemsize=intp(itemsize), meminfo=None)
            return ary._getvalue()

        return arrty(kin, rows, cols, like), heap_codegen
    n, nc = _sizes(kin)
    r = _extent(row_code, n, nc)
    c = _extent(col_code, n, nc)

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
    of ``like``, on the caller's stack (for a heap class: in the call site's heap buffer): consecutive
    in one block."""
    k = count.literal_value
    dtype = _number_type(like)
    arrty = types.Array(dtype, 1, "C")
    tupty = types.UniTuple(arrty, k)
    heap = _heap(kin)
    if not heap:
        n, nc = _sizes(kin)
        length = _vector_length(n, nc)

    def codegen(context, builder, signature, args):
        if heap:
            n_value, nc_value = _run_time_sizes(kin, builder, args[0])
            two_nc = builder.mul(nc_value, nc_value.type(2))
            size = builder.select(builder.icmp_signed(">", n_value, two_nc), n_value, two_nc)
            ptr, itemsize, intp = _site_buffer(context, builder, dtype, builder.mul(size, intp_of(context)(k)))
            offset = lambda i: builder.mul(size, intp(i))  # noqa: E731
        else:
            ptr, itemsize, intp = _stack_block(context, builder, dtype, k * length)
            size = intp(length)
            offset = lambda i: intp(i * length)  # noqa: E731
        vectors = []
        for i in range(k):
            ary = context.make_array(arrty)(context, builder)
            populate_array(ary, data=builder.gep(ptr, [offset(i)]), shape=[size],
                           strides=[intp(itemsize)], itemsize=intp(itemsize), meminfo=None)
            vectors.append(ary._getvalue())
        return context.make_tuple(builder, tupty, vectors)

    return tupty(kin, count, like), codegen


def _heap(kin) -> bool:
    return getattr(kin, "instance_class", None) in _HEAP


def intp_of(context):
    """A maker of intp constants."""
    return lambda value: context.get_constant(types.intp, value)


def _run_time_sizes(kin, builder, value):
    """(n, nc) as intp values read from the fields ``ndof``, ``ncontacts`` of the kinematics data
    ``value`` (of numba type ``kin``)."""
    fields = list(kin.fields)
    return builder.extract_value(value, fields.index("ndof")), builder.extract_value(value, fields.index("ncontacts"))


def _extent_value(builder, code: int, n, nc):
    """:func:`_extent` on run-time sizes (intp values)."""
    one = n.type(1)
    return {DOFS: n, STATES: builder.mul(n, n.type(2)), CONTACTS: nc, ROWS: builder.mul(nc, n.type(2)), ONE: one,
            TWO: n.type(2), IMPULSE_ROWS: builder.mul(nc, n.type(3))}[code]


def _site_buffer(context, builder, dtype, count):
    """(pointer to ``count`` (an intp value) uninitialised elements of ``dtype`` in this call site's
    heap buffer, item size, a maker of intp constants): the buffer is a global of the module, grown
    with ``realloc`` when a call needs more than it holds (module docstring)."""
    llty = context.get_value_type(dtype)
    intp = intp_of(context)
    itemsize = context.get_abi_sizeof(llty)
    module = builder.module
    bytes_t = ir.IntType(8).as_pointer()
    i64 = ir.IntType(64)
    data = ir.GlobalVariable(module, bytes_t, module.get_unique_name("stickslip_work_data"))
    data.linkage = "internal"
    data.initializer = ir.Constant(bytes_t, None)
    room = ir.GlobalVariable(module, i64, module.get_unique_name("stickslip_work_room"))
    room.linkage = "internal"
    room.initializer = ir.Constant(i64, 0)
    need = builder.mul(builder.zext(count, i64) if count.type.width < 64 else count, i64(itemsize))
    with builder.if_then(builder.icmp_unsigned(">", need, builder.load(room)), likely=False):
        realloc = cgutils.get_or_insert_function(module, ir.FunctionType(bytes_t, [bytes_t, i64]), "realloc")
        grown = builder.call(realloc, [builder.load(data), need])
        with builder.if_then(cgutils.is_null(builder, grown), likely=False):
            abort = cgutils.get_or_insert_function(module, ir.FunctionType(ir.VoidType(), []), "abort")
            builder.call(abort, [])  # out of memory after the estimate let the model through
        builder.store(grown, data)
        builder.store(need, room)
    return builder.bitcast(builder.load(data), llty.as_pointer()), itemsize, intp


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
    intp = intp_of(context)
    ptr = cgutils.alloca_once(builder, llty, size=intp(size))
    return ptr, context.get_abi_sizeof(llty), intp
