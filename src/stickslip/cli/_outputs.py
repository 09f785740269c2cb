"""Writing a command's outputs: a NetCDF file whole, and the figure beside it.

Each file is registered for Ctrl-C as it is written (:mod:`._kept`), so that the line of an
interruption says what is on disk.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from ..files import write_output
from ..integrate.interrupt import finish_first
from ._kept import keeps, keeps_figure

__all__ = ["draw_figure", "write_result", "prepare_outputs"]


def prepare_outputs(figure: bool) -> None:
    """Import what writes a run's outputs: xarray (with the array types it looks for on its first
    variable), the NetCDF writer and, with ``figure``, matplotlib's figure and Agg canvas. A command
    runs it while a cold start's helper compiles (:func:`stickslip.model.compile_ahead.meanwhile`)."""
    import h5netcdf  # noqa: F401
    import numpy as np
    import xarray

    xarray.Variable("x", np.zeros(1))
    if figure:
        from ..plot._common import agg_figure

        agg_figure((1.0, 1.0))


def draw_figure(out: Path, draw: Callable[[Path], object], *, overwrite: bool, inputs: dict | None = None,
                skip: bool = False) -> Path | None:
    """Draw the figure beside the NetCDF output ``out`` (``OUT.png``).

    Parameters
    ----------
    out : Path
        The command's NetCDF output.
    draw : callable
        ``draw(tmp: Path)`` saves the figure to ``tmp`` (:func:`stickslip.files.write_output`).
    overwrite : bool
        Replace an existing figure.
    inputs : dict of option → Path, optional
        Files the command reads; never replaced.
    skip : bool
        Draw nothing (``--no-plot``, or no output to draw from).

    Returns
    -------
    Path or None
        The figure written; None when skipped.
    """
    if skip:
        return None
    keeps_figure(out)
    return write_output(out.with_suffix(".png"), draw, overwrite=overwrite, inputs=inputs)


def write_result(outputs, writer_of: Callable[[], Callable[[Path], object]], *, holds: str, inputs: dict,
                 draw: Callable[[Path], object]) -> Path | None:
    """Write a one-shot command's result to its ``--out`` whole, then its figure beside it.

    A Ctrl-C while the result is made ready and written lets the file be finished, then stops.

    Parameters
    ----------
    outputs : Outputs
        The command's ``--out``, ``--overwrite`` and ``--no-plot`` (:class:`~._options.Outputs`).
    writer_of : callable
        ``writer_of()``: what writes the file (``netcdf_writer(dataset)``), made as the write starts.
    holds : str
        What the file holds, for the line of a Ctrl-C after it was written.
    inputs : dict of option → Path
        Files the command reads; never replaced.
    draw : callable
        ``draw(tmp: Path)`` saves the figure to ``tmp``.

    Returns
    -------
    Path or None
        The figure written; None with ``--no-plot``.
    """
    keeps(outputs.out, holds)
    with finish_first():
        write_output(outputs.out, writer_of(), overwrite=outputs.overwrite, inputs=inputs)
    return draw_figure(outputs.out, draw, skip=outputs.no_plot, overwrite=outputs.overwrite, inputs=inputs)
