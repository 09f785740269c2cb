"""The arrays that travel together through the compiled loops, bundled.

Kernels are compiled without numba's runtime (:mod:`stickslip.model.jit`), so a bundle is a
``NamedTuple`` of arrays (a structref would need the runtime). A bundle passed to a kernel that is
not inlined travels as its arrays would, one after the other: bundling costs nothing at run time.
The loops' arrays are allocated by their Python callers (:func:`scratch`, :func:`transition_log`,
:class:`Samples` from a :class:`~stickslip.integrate.runner.Record`), so a kernel never allocates.

:class:`Samples`
    Where a run writes its uniform samples.
:class:`TransitionLog`
    Where a chunk records its transitions.
:class:`Scratch`
    Work arrays of the per-contact queries at one state.

A loop's scalar state (its time, step size, counters, status) is a numpy record
(``np.dtype(..., align=True)``) passed in a one-element array; :func:`on_stack` copies it onto the
loop's own stack, where the compiler keeps its fields in registers as it would local variables,
and the loop writes it back when it returns (:func:`store_record`). Both copy the record's bytes
with one ``memcpy``: an aggregate load or store of the record (numba's ``array[0] = record``, or
a zero-fill of the copy) would have LLVM split it into single bytes, each field then reassembled
from them at every use.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba.core import cgutils, types
from numba.extending import intrinsic

__all__ = ["Samples", "TransitionLog", "Scratch", "scratch", "transition_log", "on_stack", "store_record"]


class Samples(NamedTuple):
    """The uniform samples of a run, written in place by the compiled loops.

    Attributes
    ----------
    times : ndarray (k,)
        Sample times [s], absolute.
    states : ndarray (k, ns)
        The state (2n + 2: positions, velocities, the work of friction and of damping [J]).
    modes : ndarray (k,) int
        Bit c set: contact c sticks; bit nc + c set: contact c is open (:func:`.result.mode_dtype`).
    forces : ndarray (k, 2 nc)
        Each contact's friction force [N].
    """

    times: np.ndarray
    states: np.ndarray
    modes: np.ndarray
    forces: np.ndarray


class TransitionLog(NamedTuple):
    """Buffers of the transitions a chunk records (as many as they have room for: the chunk ends
    early where they are nearly full; past them the loop counts on and the chunk is run again with
    room for all, :func:`.runner.transition_room`).

    Attributes
    ----------
    times : ndarray (m,)
        Instants [s], absolute.
    kinds : ndarray (m,) int8
        ``contacts.TRANSITION_*``.
    contacts : ndarray (m,) int8
        The contact.
    states : ndarray (m, ns)
        The state there.
    """

    times: np.ndarray
    kinds: np.ndarray
    contacts: np.ndarray
    states: np.ndarray


class Scratch(NamedTuple):
    """Work arrays of the event functions and contact queries at one state.

    Attributes
    ----------
    state : ndarray (ns,)
        A state (a point of a step's dense output).
    F : ndarray (2 nc,)
        Friction forces [N].
    N : ndarray (nc,)
        Normal forces [N].
    v : ndarray (2 nc,)
        Slip velocities [m/s].
    g : ndarray (2 nc,)
        An event function of every contact at two points of a step: entries c at the point
        sampled last, nc + c at the one before (the breakaway search,
        :func:`~.transitions.first_breakaway`).
    """

    state: np.ndarray
    F: np.ndarray
    N: np.ndarray
    v: np.ndarray
    g: np.ndarray


def scratch(ns: int, nc: int) -> Scratch:
    """:class:`Scratch` for ``ns`` states and ``nc`` contacts."""
    return Scratch(np.empty(ns), np.empty(2 * nc), np.empty(nc), np.empty(2 * nc), np.empty(2 * nc))


def transition_log(capacity: int, ns: int, contact_dtype=np.int8) -> TransitionLog:
    """An empty :class:`TransitionLog` with room for ``capacity`` transitions of ``ns`` states;
    the contacts' indices of ``contact_dtype`` (int8, wider for a model of more than 127 contacts)."""
    return TransitionLog(np.empty(capacity), np.empty(capacity, dtype=np.int8), np.empty(capacity, dtype=contact_dtype),
                         np.empty((capacity, ns)))


@intrinsic
def on_stack(typingctx, record):
    """A copy of the numpy record ``record`` on the caller's stack (a record that the loop's
    inlined steps read and write, kept in registers; module docstring)."""
    if not isinstance(record, types.Record):
        return None

    def codegen(context, builder, signature, args):
        with builder.goto_entry_block():  # not cgutils.alloca_once: its zero-fill, a store of the
            # whole byte array, would have LLVM split the record into bytes
            copy = builder.alloca(context.data_model_manager[record].get_data_type())
        copy.align = 16  # the record's fields are aligned (align=True)
        cgutils.raw_memcpy(builder, copy, args[0], context.get_constant(types.intp, 1), record.size)
        return copy

    return record(record), codegen


@intrinsic
def store_record(typingctx, array, record):
    """Copy the numpy record ``record`` into the first element of the record array ``array`` (one
    ``memcpy``; module docstring)."""
    if not isinstance(record, types.Record) or not isinstance(array, types.Array) or array.dtype != record:
        return None

    def codegen(context, builder, signature, args):
        data = context.make_array(array)(context, builder, args[0]).data
        cgutils.raw_memcpy(builder, data, args[1], context.get_constant(types.intp, 1), record.size)
        return context.get_dummy_value()

    return types.none(array, record), codegen
