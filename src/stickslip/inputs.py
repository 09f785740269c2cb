"""Inputs read whole and bounded: model files, matrix files, node tables, ``--config``.

:func:`read_regular_file` reads only a regular file (a folder, a pipe or a device such as
``/dev/zero``, also behind a symbolic link, is refused before a byte is read, and a pipe is
opened without waiting for a writer), and only up to a size limit; :func:`regular_file_size`
asks its size with the same refusals (a reader that hands the path to a library, such as
scipy's Matrix Market reader, checks it first).
"""

from __future__ import annotations

import os
import stat

from .errors import StickSlipError

__all__ = ["read_regular_file", "regular_file_size"]


def _open_regular(path, what: str, error: type[StickSlipError]) -> int:
    """A descriptor of ``path`` opened for reading, refused unless it is a regular file (opened
    non-blocking, so that a pipe without a writer does not hang the open; checked on the opened
    file itself, so that nothing can swap it between the check and the read)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise error(f"{what} {path} does not exist; give the path of an existing file") from None
    except OSError as exc:
        raise error(f"{what} {path} cannot be read ({exc.strerror}); give a readable file") from None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise error(f"{what} {path} is not a regular file (a folder, a pipe or a device); give the path of a file")
    return fd


def regular_file_size(path, what: str, error: type[StickSlipError]) -> int:
    """The size [bytes] of the regular file ``path`` (refused as :func:`read_regular_file` refuses)."""
    fd = _open_regular(path, what, error)
    try:
        return os.fstat(fd).st_size
    finally:
        os.close(fd)


def read_regular_file(path, limit: int, what: str, error: type[StickSlipError],
                      fix: str = "give a smaller file") -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them.

    Raises
    ------
    error
        One line naming ``what`` and ``path``: it does not exist, cannot be read, is not a regular
        file (a folder, a pipe, a device), or holds more than ``limit`` bytes (also when it grows
        past the limit while being read).
    """
    fd = _open_regular(path, what, error)
    too_large = error(f"{what} {path} is larger than {limit:,} bytes, the most such a file may be; {fix}")
    try:
        size = os.fstat(fd).st_size
        if size > limit:
            raise too_large
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(size + 1)  # one byte more than stated: a file that grows is read on
            while 0 < len(data) <= limit:
                more = fh.read(min(2**20, limit + 1 - len(data)))
                if not more:
                    break
                data += more
    except OSError as exc:
        raise error(f"{what} {path} cannot be read ({exc.strerror}); give a readable file") from None
    finally:
        os.close(fd)
    if len(data) > limit:
        raise too_large
    return data
