"""How an integration ended: one enum instead of free text compared in many places."""

from __future__ import annotations

import enum

__all__ = ["Status", "SUCCESS", "STEP_UNDERFLOW", "NOT_FINITE", "MAX_STEPS", "CONTACT_LOST", "INTERRUPTED",
           "CHUNK_END", "SOLVE_FAILED", "INCONSISTENT"]

# Codes returned by the compiled loops (plain ints there).
SUCCESS = 0
STEP_UNDERFLOW = 1
NOT_FINITE = 2
MAX_STEPS = 3
CONTACT_LOST = 4
INTERRUPTED = 5
SOLVE_FAILED = 6
CHUNK_END = 7  # internal: a chunk of the loop ended; the driver goes on
INCONSISTENT = 8  # a rigid contact without a consistent normal force or impulse (Painlevé)


class Status(enum.IntEnum):
    """Outcome of a run (``Trajectory.status``); ``str(status)`` is its message."""

    SUCCESS = SUCCESS
    STEP_UNDERFLOW = STEP_UNDERFLOW
    NOT_FINITE = NOT_FINITE
    MAX_STEPS = MAX_STEPS
    CONTACT_LOST = CONTACT_LOST
    INTERRUPTED = INTERRUPTED
    SOLVE_FAILED = SOLVE_FAILED
    INCONSISTENT = INCONSISTENT

    @property
    def ok(self) -> bool:
        """Whether the run reached its end time."""
        return self is Status.SUCCESS

    def message(self, t: float, contact: int = -1) -> str:
        """One line saying how the run ended at time ``t`` [s] (``contact``: the lost or inconsistent
        contact)."""
        return {
            Status.SUCCESS: "success",
            Status.STEP_UNDERFLOW: f"step size underflow at t = {t:.6g} s",
            Status.NOT_FINITE: f"state became non-finite at t = {t:.6g} s",
            Status.MAX_STEPS: f"max_steps reached at t = {t:.6g} s",
            Status.CONTACT_LOST: f"contact lost at t = {t:.6g} s (normal force of contact {contact} reached 0)",
            Status.INTERRUPTED: f"interrupted at t = {t:.6g} s (partial run)",
            Status.SOLVE_FAILED: f"stick force iteration failed at t = {t:.6g} s",
            Status.INCONSISTENT: (f"no consistent contact force at t = {t:.6g} s: rigid contact {contact} sliding has "
                                  "no normal force, or two, that keeps it closed, nor an impulse (Painlevé; a smaller "
                                  "friction coefficient, or a compliant contact, has one)"),
        }[self]
