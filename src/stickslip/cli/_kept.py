"""What the running command has on disk, for the one line a Ctrl-C prints.

A command registers each file it writes, before writing it (:func:`keeps`, with what the file
holds); when a Ctrl-C ends the command, :func:`on_disk` names those written (created or replaced)
since, else the command's note (:func:`on_interrupt`: work kept in a journal), else ``nothing
was written``. An existing output that was left as it was is not reported. The application
(:mod:`._app`) clears the registry as each command starts and prints the line.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

__all__ = ["keeps", "keeps_figure", "on_interrupt", "on_disk", "forget_outputs"]

#: The files registered (path, its state when registered, what it holds) and the note.
_kept: dict = {"files": [], "note": None}


def _file_state(path: Path):
    """What tells a file written since apart: (inode, size, modification time), None if absent."""
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_ino, st.st_size, st.st_mtime_ns


def keeps(path, holds: str | Callable[[Path], str]) -> None:
    """Register a file the command writes: if a Ctrl-C ends the command after the file was written
    (created or replaced since this call), the interruption line says what it ``holds`` (a text
    such as ``"the orbit is in orbit.nc"``, or a function of the path that reads it from the file)."""
    path = Path(path)
    _kept["files"].append((path, _file_state(path), holds))


def keeps_figure(out: Path) -> None:
    """:func:`keeps` for the figure a command draws beside its output ``out`` (``OUT.png``)."""
    keeps(out.with_suffix(".png"), f"its figure is in {out.with_suffix('.png')}")


def on_interrupt(text: str, path=None) -> None:
    """Say what an interruption keeps when no registered file was written (printed after
    ``interrupted:``); with ``path``, only if that file or folder exists then (a journal)."""
    _kept["note"] = (text, None if path is None else Path(path))


def forget_outputs() -> None:
    """Clear the registry (a command starting)."""
    _kept.update(files=[], note=None)


def on_disk() -> str:
    """What the command has on disk now (see :func:`keeps`, :func:`on_interrupt`)."""
    written = []
    for path, before, holds in _kept["files"]:
        now = _file_state(path)
        if now is not None and now != before:
            try:
                written.append(holds(path) if callable(holds) else holds)
            except Exception:  # the file is there but cannot be read: say only that  # noqa: BLE001
                written.append(f"{path} was written")
    if written:
        return "; ".join(written)
    note = _kept["note"]
    if note is not None and (note[1] is None or note[1].exists()):
        return note[0]
    return "nothing was written"
