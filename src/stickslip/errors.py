"""The one exception base of stickslip.

Every error that is the user's to fix (bad input, a file that is not ours, an option out of
range, a computation that cannot be done for the given model) derives from
:class:`StickSlipError`. The command line maps this one base to a single line on stderr and
exit code 2; anything else is a bug and keeps its traceback. Subclasses also derive from the
builtin they refine (``ValueError``, ``RuntimeError``), so ``except ValueError`` keeps working.
"""

from __future__ import annotations

__all__ = ["StickSlipError"]


class StickSlipError(Exception):
    """Base of every stickslip error whose message tells the user what to change."""
