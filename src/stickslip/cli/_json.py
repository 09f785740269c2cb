"""The one writer of every ``--json`` output: strict JSON, one line on stdout.

JSON has no NaN or ±Infinity (``json.dumps`` writes them as bare ``NaN`` and ``Infinity``, which
strict parsers refuse). A value that is undefined is written as ``null`` with a reason beside it:
``"<key>_reason"`` in the same object, the reason its producer gave there (a key already named
so), else what the number was (``not a number``, ``infinite``). A list with such entries gets
``null`` in their places and one ``"<key>_reason"``. The text is then written by ``json.dumps``
with ``allow_nan=False``, so nothing else non-finite can pass.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Mapping

__all__ = ["print_json", "strict_json", "to_strict"]


def _undefined_reason(x: float) -> str:
    """Why a non-finite float has no JSON value."""
    return "not a number (undefined)" if math.isnan(x) else f"{'' if x > 0 else '-'}infinite"


def _value(value):
    """(the JSON value of ``value``, the reason it is null or None): numpy scalars and arrays as
    Python numbers and lists, non-finite floats as None."""
    if isinstance(value, Mapping):
        return to_strict(value), None
    # numpy values exist only where numpy is imported: a command that needs none (the list of
    # models) does not import it for this
    np = sys.modules.get("numpy")
    if np is not None and isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        items = [_value(v) for v in value]
        reasons = sorted({r for _, r in items if r is not None})
        return [v for v, _ in items], (f"null entries: {'; '.join(reasons)}" if reasons else None)
    if np is not None and isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None, _undefined_reason(value)
    return value, None


def to_strict(summary: Mapping) -> dict:
    """``summary`` with every undefined value null and its reason beside it (see the module)."""
    out = {}
    for key, value in summary.items():
        key = str(key)
        clean, reason = _value(value)
        out[key] = clean
        if reason is not None and f"{key}_reason" not in summary:
            out[f"{key}_reason"] = reason
    return out


def strict_json(summary) -> str:
    """One line of strict JSON (no NaN or Infinity) of ``summary``, a mapping (see the module) or
    a list."""
    return json.dumps(_value(summary)[0], allow_nan=False)


def print_json(summary) -> None:
    """Print ``summary`` as one line of strict JSON on stdout: every command's ``--json``."""
    print(strict_json(summary))
