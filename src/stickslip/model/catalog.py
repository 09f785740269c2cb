"""The model library's table of contents: its models' names and one-line descriptions, read
without building a model.

``stickslip models`` lists the library from here: a model file's ``description`` is read from its
TOML and the plates' from :data:`TWO_PLATES_DESCRIPTION`, so that the list needs neither numpy
nor numba nor the compiled kernels that building a model loads (:mod:`.library` builds them).
"""

from __future__ import annotations

import sys
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised only on Python 3.10
    import tomli as tomllib

__all__ = ["TWO_PLATES", "TWO_PLATES_DESCRIPTION", "LIBRARY_FOLDER", "library_files", "library_names", "library"]

#: Name of the default model, the paper's two plates (:mod:`.library.two_plates`).
TWO_PLATES = "two-plates"

#: The plates' one-line description.
TWO_PLATES_DESCRIPTION = "two rigid plates in point contact, 2-D friction (Liu & Ouyang; the paper)"

#: The folder of the library's model files (``NAME.toml``, the name with ``_`` for ``-``).
LIBRARY_FOLDER = Path(__file__).resolve().parent / "library"


def library_files() -> list[Path]:
    """The library's model files, in the order of their names."""
    return sorted(LIBRARY_FOLDER.glob("*.toml"))


def library_names() -> list[str]:
    """Library model names, the default first (without reading the files)."""
    return [TWO_PLATES] + [path.stem.replace("_", "-") for path in library_files()]


def library() -> dict[str, str]:
    """Library model names → one-line descriptions, the default first (each file's ``description``)."""
    out = {TWO_PLATES: TWO_PLATES_DESCRIPTION}
    for path in library_files():
        with open(path, "rb") as fh:
            out[path.stem.replace("_", "-")] = tomllib.load(fh).get("description", "")
    return out
