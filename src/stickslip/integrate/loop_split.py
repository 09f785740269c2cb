"""A cold start compiles the event loop's callees in two processes (:mod:`stickslip.model.compile_ahead`).

:data:`EVENT_LOOP`: the stick solve's subtree (:func:`~stickslip.integrate.contacts.try_stick`,
the release of an overloaded stick, the contact forces, the low-speed band's direction and the
starting modes) in the helper, the step's (the right-hand side, the Dormand–Prince step, the
crossings' probe, the samples) here. On two cores, from an empty cache: the plates' ``simulate``
−17 %, a model file's −18 %. The two subtrees share ``general_forces``, which both compile: the
split is as even as the loop's call tree allows, and the loop's own body compiles after both.
The helper also compiles the kernels that a run's results call after the loop (each contact's
slip velocity and normal force at the samples), the release of overloaded sticks after a
transition, a breakaway, the error norm and the slip velocity's rate; this process the cut of a
step at an event and the step's small helpers (the dense-output coefficients, the slip-event
test): what neither side compiles, the loop compiles alone, after both. The run starts the helper
(:func:`start_callees`) before it checks that no contact is open at the start (a refused run ends
it); this process, done with its side, does the command's
:func:`~stickslip.model.compile_ahead.meanwhile` work while the helper finishes.
"""

from __future__ import annotations

from ..model.compile_ahead import ColdStart, Split, start_apart

__all__ = ["EVENT_LOOP", "start_callees"]

#: The event loop's callees: the stick solve's subtree in the helper, the step's here.
EVENT_LOOP = Split(
    helper=("stickslip.integrate.contacts.try_stick", "stickslip.integrate.contacts.release_most_overloaded",
            "stickslip.model.physics.contact_forces", "stickslip.model.physics.band_direction",
            "stickslip.integrate.contacts.initial_modes", "stickslip.integrate.result._slip_velocities",
            "stickslip.integrate.result._normal_forces", "stickslip.integrate.transitions.settle",
            "stickslip.integrate.transitions.break_away", "stickslip.model.physics.slip_velocity_and_rate",
            "stickslip.integrate.event_loop.error_norm"),
    own=("stickslip.model.physics.rhs", "stickslip.integrate.event_loop.dp_step",
         "stickslip.integrate.contacts.probed_crossing", "stickslip.integrate.event_loop.write_samples",
         "stickslip.integrate.event_loop.cut_step", "stickslip.integrate.dormand_prince.dense_coefficients",
         "stickslip.integrate.contacts.slip_event_possible", "stickslip.integrate.contacts.time_to_zero_of",
         "stickslip.integrate.contacts.all_finite", "stickslip.integrate.event_loop.homing_left"),
    caller="stickslip.integrate.event_loop.event_loop",
    signatures={
        "stickslip.integrate.contacts.try_stick": "v v i M f v v",
        "stickslip.integrate.contacts.initial_modes": "v v M f f v v",
        "stickslip.model.physics.contact_forces": "v v M v v v",
        "stickslip.model.physics.band_direction": "v v i M f",
        "stickslip.model.physics.rhs": "v v M v",
        "stickslip.integrate.event_loop.dp_step": "v v f v M m v v",
        "stickslip.integrate.contacts.probed_crossing": "f i i v m f f f v M v v v",
        "stickslip.integrate.contacts.release_most_overloaded": "v v M v v",
        "stickslip.integrate.event_loop.write_samples": "i f v m f f f v M v m b m v v v v",
        "stickslip.integrate.result._slip_velocities": "m M i",
        "stickslip.integrate.result._normal_forces": "m b M i",
        "stickslip.integrate.transitions.settle": "v v M v v f v b b m i I",
        "stickslip.integrate.transitions.break_away": "v v i M v v f v b b m i I",
        "stickslip.integrate.event_loop.error_norm": "v v m f M f f",
        "stickslip.model.physics.slip_velocity_and_rate": "v v i M",
        "stickslip.integrate.dormand_prince.dense_coefficients": "m m",
        "stickslip.integrate.contacts.slip_event_possible": "f f f f",
        "stickslip.integrate.contacts.time_to_zero_of": "f f f f",
        "stickslip.integrate.contacts.all_finite": "v",
        "stickslip.integrate.event_loop.homing_left": "I",
        "stickslip.integrate.event_loop.cut_step": "f i v m f f f v M v m b m v v v v",
    })


def start_callees(md) -> ColdStart | None:
    """:func:`start_apart` of the event loop's callees (:data:`EVENT_LOOP`)."""
    return start_apart(md, EVENT_LOOP, f"{__name__}:EVENT_LOOP")
