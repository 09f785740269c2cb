"""What a run settles to: the one vocabulary of outcomes of runs, sweeps and basin studies.

=================  ======================================================================
``equilibrium``    steady sliding (or rest): the motion dies out
``periodic``       a periodic orbit
``quasiperiodic``  a torus: stationary, not periodic, largest Lyapunov exponent zero
``chaotic``        stationary, not periodic, largest Lyapunov exponent positive
``unbounded``      the state became non-finite
``unsettled``      none of these shown: a transient, an unconfirmed claim, a cut-short run
``contact-lost``   the normal force of a pressed contact reached 0 (the model no longer holds)
``failed``         the integrator could not finish the run (step size underflow, step cap, ...)
=================  ======================================================================

An outcome's integer code is its index in :data:`OUTCOMES`, the same in every file (a sweep's
``attractor`` variable, a basin study's ``verdict``). Whether the motion sticks is not a kind
of its own but an attribute beside the outcome: the fraction of the window in stick
(``stick_fraction``); a motion with stick is a stick-slip oscillation (:func:`is_stick_slip`),
one without a pure-slip oscillation.
"""

from __future__ import annotations

import numpy as np

__all__ = ["OUTCOMES", "MOTIONS", "STOPPED", "outcome_code", "outcome_names", "outcome_flags", "is_stick_slip"]

#: The outcomes, in code order.
OUTCOMES = ("equilibrium", "periodic", "quasiperiodic", "chaotic", "unbounded", "unsettled", "contact-lost", "failed")

#: Outcomes of a run that moves to the end of its window (an oscillation, settled or not).
MOTIONS = ("periodic", "quasiperiodic", "chaotic", "unsettled")

#: Outcomes of a run that stopped before its end time.
STOPPED = ("unbounded", "contact-lost", "failed")


def outcome_code(name: str) -> int:
    """The integer code of an outcome (its index in :data:`OUTCOMES`).

    Raises
    ------
    ValueError
        For a name that is not an outcome (naming the outcomes).
    """
    if name not in OUTCOMES:
        raise ValueError(f"unknown outcome {name!r}; the outcomes are {', '.join(OUTCOMES)}")
    return OUTCOMES.index(name)


def outcome_names(codes, missing: str = "failed") -> np.ndarray:
    """The outcome names (object array) of integer ``codes`` (any shape); NaN, or a code that is
    not an outcome's, is named ``missing``."""
    codes = np.asarray(codes, dtype=float)
    known = np.isfinite(codes) & (codes >= 0) & (codes < len(OUTCOMES))
    names = np.array(OUTCOMES + (missing,), dtype=object)
    return names[np.where(known, np.nan_to_num(codes), len(OUTCOMES)).astype(int)]


def outcome_flags() -> dict:
    """The NetCDF attributes that name the codes of an outcome variable (CF ``flag_values`` and
    ``flag_meanings``)."""
    return {"flag_values": np.arange(len(OUTCOMES), dtype=np.int8), "flag_meanings": " ".join(OUTCOMES)}


def is_stick_slip(outcome, stick_fraction):
    """Whether a run is a stick-slip oscillation: it moves (:data:`MOTIONS`) and sticks in its
    window (``stick_fraction`` > 0). Names or codes, scalars or arrays (NaN stick fractions: no)."""
    outcome = np.asarray(outcome)
    names = outcome_names(outcome) if outcome.dtype.kind in "fiu" else outcome
    moving = np.isin(names, MOTIONS)
    with np.errstate(invalid="ignore"):
        sticks = np.asarray(stick_fraction, dtype=float) > 0.0
    out = moving & sticks
    return bool(out) if out.ndim == 0 else out
