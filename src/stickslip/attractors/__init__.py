"""Attractors: what a run settles to, from the evidence, and the claims the dynamics must confirm.

=========================  ==================================================================
``attractor``              the verdict on a trajectory's window (:mod:`.verdict`)
``simulate_until_settled`` a run extended until its verdict is settled (:mod:`.settle`)
``run_summary``            a run's verdict, steady window and cost as one dict (:mod:`.summary`)
``confirm_period``, ...    shooting and Lyapunov confirmations of claims (:mod:`.confirm`)
=========================  ==================================================================
"""

from .. import _startup

#: Public name → the module that defines it, imported on first use (:func:`stickslip._startup.export_on_first_use`).
_EXPORTS = {
    **dict.fromkeys(["confirm_period", "lyapunov_sign", "span_change"], ".confirm"),
    **dict.fromkeys(["DEFAULT_CAP_S", "DEFAULT_STEP_S", "DEFAULT_T_MIN_S", "DEFAULT_WINDOW_S", "SettledRun", "simulate_until_settled"], ".settle"),
    **dict.fromkeys(["run_summary"], ".summary"),
    **dict.fromkeys(["Attractor", "attractor", "jsonable", "stopped_outcome", "undersampled"], ".verdict"),
}

__all__ = ["Attractor", "attractor", "stopped_outcome", "jsonable", "undersampled", "SettledRun",
           "simulate_until_settled", "run_summary", "confirm_period", "lyapunov_sign", "span_change",
           "DEFAULT_CAP_S", "DEFAULT_STEP_S", "DEFAULT_T_MIN_S", "DEFAULT_WINDOW_S"]

_startup.export_on_first_use(__name__, _EXPORTS)
