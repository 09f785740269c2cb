"""A model's contact frame compiled apart and called through its address: an edit recompiles it alone.

A kinematics class registered with ``inline=True`` (:func:`~stickslip.model.kinematics.register_kinematics`;
the package's own classes) has its frame compiled into every kernel that calls it, and every
kernel of the class compiles again when the frame's code changes (half a minute and more). A class
registered with ``inline=False`` (the default for classes defined outside the package) has its
frame, bias and gap functions compiled on their own, each for a float and a complex state, and the
kernels call them through their machine-code addresses. The kernels themselves are compiled for a
*pointer class* (:class:`FramePointerFields`, :func:`~stickslip.model.kinematics.pointer_class`), whose instances hold the addresses and the
model's kinematics values as a plain tuple: the kernels depend on the number types of those values,
on the sizes the user's class fixes (n, nc, diagonal, dim: loops unrolled as for an inlined frame)
and on the kinds of contacts the model has, never on the user's class or code. So they are
compiled once per machine for every such model, and editing a frame recompiles the frame alone.

The call passes the frame's arguments in numba's own calling convention (each array as its
fields, the values tuple as its members; a NamedTuple and a plain tuple of the same member types
pass alike), to a function compiled for arrays of any layout, so that every caller's arrays fit.
Addresses belong to one process: a pointer instance pickles as the user's kinematics object and is
rebuilt, with this process's addresses, where it is unpickled (forked workers inherit them).
"""

from __future__ import annotations

import logging
import time
from typing import Any, NamedTuple

from llvmlite import ir
from numba import typeof, types
from numba.core import cgutils
from numba.core.callconv import excinfo_t
from numba.core.errors import TypingError
from numba.extending import intrinsic, overload

from .jit import KERNEL_OPTIONS, KernelDispatcher, inlined_kernel, kernel

__all__ = ["FramePointerFields", "is_pointer_class", "compiled_addresses", "forget", "origin_class", "call_native",
           "frame_address", "bias_address", "gap_address", "pointer_frame", "pointer_bias", "pointer_gap"]


class FramePointerFields(NamedTuple):
    """Kinematics data of a model whose frame is compiled apart: the addresses of the compiled
    frame, bias and gap functions for a float and a complex state (0 where none was registered) and
    the model's kinematics values (the fields of the user's kinematics object, a plain tuple).
    The kernels take an instance of one of its subclasses, made on demand for what they are
    specialised on (:func:`stickslip.model.kinematics.pointer_class`)."""

    frame: int
    frame_complex: int
    bias: int
    bias_complex: int
    gap: int
    gap_complex: int
    values: tuple


def is_pointer_class(cls) -> bool:
    """Whether ``cls`` is a pointer class (a frame compiled apart, called through its address)."""
    return isinstance(cls, type) and issubclass(cls, FramePointerFields)


_log = logging.getLogger("stickslip")

#: The user's kinematics class behind each frame address of this process (for pickling).
_ORIGIN: dict[int, type] = {}
#: Per user class: its numba type and the addresses of its functions compiled for it (this process's).
_ADDRESSES: dict[type, tuple] = {}


def origin_class(pointers) -> type:
    """The user's kinematics class whose functions' addresses ``pointers`` holds."""
    return _ORIGIN[pointers.frame]


def _signature(kin_type, function: str, dtype):
    """Argument types the kernels call ``function`` ("frame", "bias", "gap") with: arrays of any layout."""
    vector = types.Array(dtype, 1, "A")
    data = types.Array(types.float64, 1, "A")
    if function == "gap":
        return (kin_type, vector, types.int64, data, vector)
    if function == "bias":
        return (kin_type, vector, types.int64, data, types.Array(dtype, 2, "A"), vector, vector)
    return (kin_type, vector, types.int64, data, types.Array(dtype, 2, "A"), vector)


def _address(dispatcher, signature) -> int:
    """The machine-code address of ``dispatcher`` compiled (or loaded from the cache) for ``signature``;
    a compilation is logged (``stickslip`` logger, INFO): the frame is new or its code changed."""
    misses = dispatcher._cache_misses[signature]
    start = time.perf_counter()
    dispatcher.compile(signature)
    if dispatcher._cache_misses[signature] > misses:
        _log.info("compiled %s for %s states in %.1f s (compiled apart: the kernels it plugs into are shared and "
                  "cached)", dispatcher.py_func.__qualname__, signature[1].dtype, time.perf_counter() - start)
    result = dispatcher.overloads[signature]
    return result.library.get_pointer_to_function(result.fndesc.llvm_func_name)


def compiled_addresses(kin: Any, functions: tuple) -> tuple:
    """The addresses (frame, frame_complex, bias, bias_complex, gap, gap_complex) of ``functions``
    (frame, bias or None, gap or None; 0 for None) compiled, or loaded from numba's cache, for
    ``kin``'s type and a float and a complex state; compiled once per class and process (again
    when the functions are registered anew: :func:`forget`)."""
    cls = type(kin)
    kin_type = typeof(kin)
    known = _ADDRESSES.get(cls)
    if known is None or known[0] != kin_type:
        addresses = []
        for name, function in zip(("frame", "bias", "gap"), functions):
            if function is None:
                addresses += [0, 0]
                continue
            dispatcher = _dispatcher(function)
            addresses += [_address(dispatcher, _signature(kin_type, name, dtype))
                          for dtype in (types.float64, types.complex128)]
        known = (kin_type, tuple(addresses))
        _ADDRESSES[cls] = known
        _ORIGIN[addresses[0]] = cls
    return known[1]


def forget(cls: type) -> None:
    """Drop the addresses compiled for ``cls`` (its functions were registered anew)."""
    _ADDRESSES.pop(cls, None)


#: One dispatcher per user function.
_DISPATCHERS: dict[Any, KernelDispatcher] = {}


def _dispatcher(function) -> KernelDispatcher:
    """The kernel dispatcher of a user function: cached on disk where numba can (a function typed in
    an interactive session has no file to key a cache by, and is compiled in each process)."""
    py_func = getattr(function, "py_func", function)
    found = _DISPATCHERS.get(py_func)
    if found is None:
        try:
            found = kernel(py_func)
        except RuntimeError:  # numba: "cannot cache function ...: no locator available"
            found = KernelDispatcher(py_func=py_func, locals={},
                                     targetoptions={"nopython": True, "boundscheck": None, **KERNEL_OPTIONS})
        _DISPATCHERS[py_func] = found
    return found


@intrinsic
def call_native(typingctx, address, arguments):
    """Call the compiled function at ``address`` (an int64) with the members of the tuple
    ``arguments`` in numba's calling convention; it returns the number type of ``arguments[1]``
    (the state). The callee must have been compiled for argument types with the same data model
    (:func:`_signature`)."""
    if not isinstance(arguments, types.BaseTuple) or len(arguments) < 2:
        raise TypingError("call_native takes an address and a tuple of arguments")
    state = arguments[1]
    if not isinstance(state, types.Array):
        raise TypingError(f"call_native: the state must be an array, got {state}")
    if types.unliteral(arguments[2]) != types.int64:  # the callee takes the contact index as an int64
        raise TypingError(f"call_native: the contact index must be an int64, got {arguments[2]}")
    result = state.dtype
    for ty in arguments[3:]:
        if isinstance(ty, types.Array) and ty.dtype not in (types.float64, result):
            raise TypingError(f"call_native: an array of {ty.dtype} beside a state of {result}")
    argument_types = tuple(arguments)

    def codegen(context, builder, signature, args):
        call_conv = context.call_conv
        fnty = call_conv.get_function_type(result, argument_types)
        fnptr = builder.inttoptr(args[0], fnty.as_pointer())
        return_type = call_conv.get_return_type(result).pointee
        returned = cgutils.alloca_once(builder, return_type)
        builder.store(cgutils.get_null_value(return_type), returned)
        excinfo = cgutils.alloca_once(builder, ir.PointerType(excinfo_t), name="excinfo")
        members = [builder.extract_value(args[1], i) for i in range(len(argument_types))]
        packed = list(call_conv._get_arg_packer(argument_types).as_arguments(builder, members))
        builder.call(fnptr, [returned, excinfo] + packed)  # the kernels' error model: nothing raises
        return context.get_returned_value(builder, result, builder.load(returned))

    return result(address, arguments), codegen


def frame_address(kin, s):  # pragma: no cover - resolved by numba (overload below)
    """The address of the frame compiled for the number type of ``s``."""
    raise NotImplementedError


def bias_address(kin, s):  # pragma: no cover - resolved by numba (overload below)
    """The address of the bias function compiled for the number type of ``s`` (0: none)."""
    raise NotImplementedError


def gap_address(kin, s):  # pragma: no cover - resolved by numba (overload below)
    """The address of the gap function compiled for the number type of ``s`` (0: none)."""
    raise NotImplementedError


def _complex(s) -> bool:
    return isinstance(s.dtype, types.Complex)


@overload(frame_address, jit_options=KERNEL_OPTIONS, inline="always")
def _frame_address(kin, s):
    return (lambda kin, s: kin.frame_complex) if _complex(s) else (lambda kin, s: kin.frame)


@overload(bias_address, jit_options=KERNEL_OPTIONS, inline="always")
def _bias_address(kin, s):
    return (lambda kin, s: kin.bias_complex) if _complex(s) else (lambda kin, s: kin.bias)


@overload(gap_address, jit_options=KERNEL_OPTIONS, inline="always")
def _gap_address(kin, s):
    return (lambda kin, s: kin.gap_complex) if _complex(s) else (lambda kin, s: kin.gap)


@inlined_kernel
def pointer_frame(kin, s, c, m, G, w):
    """Frame of a pointer class's model: its compiled frame called through the address."""
    return call_native(frame_address(kin, s), (kin.values, s, c, m, G, w))


@inlined_kernel
def pointer_bias(kin, s, c, m, G, w, h):
    """Frame and velocity bias of a pointer class's model through the bias function's address."""
    return call_native(bias_address(kin, s), (kin.values, s, c, m, G, w, h))


@inlined_kernel
def pointer_gap(kin, s, c, m, W):
    """Gap of a pointer class's model's contact through the gap function's address."""
    return call_native(gap_address(kin, s), (kin.values, s, c, m, W))
