"""Memory: what a computation will need, what this process can have, and the one check.

Every computation whose arrays grow with what the user asks for estimates its peak memory here,
from the model's sizes, *before* it allocates, and refuses with one line
(:class:`~stickslip.errors.MemoryLimitError`) that gives the estimate, the memory available and
a setting that fits, computed from them. The library functions check (``simulate``,
``basin_stability`` and the states of a study, ``sweep``, ``stability_map``, the Lyapunov
functions), so a caller, the command line included, checks nothing again.

The estimates are per item: a kept sample of a run, a state and a parameter value of a basin
study (these three measured as the growth of the peak resident memory between two sizes of the
same computation; the numbers are beside each constant), a grid point of a sweep or a stability
map and a running estimate of a Lyapunov average (counted from the arrays that hold them, with
the copies the measured ones showed). They cover the arrays that grow; the process's fixed
memory (libraries, compiled kernels) is already resident when the check runs and so is not
counted in what is available.

Available memory is ``MemAvailable`` of ``/proc/meminfo`` (what the kernel can give without
swapping), capped by the memory limit of this process's control group where one is set, else
the physical memory (``os.sysconf``); where none can be read the check lets everything through.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Callable

from .errors import MemoryLimitError

__all__ = ["available_memory", "check_memory", "largest_count", "sample_bytes", "state_bytes", "param_bytes",
           "grid_point_bytes", "map_point_bytes", "average_bytes", "format_bytes", "model_data_bytes",
           "largest_dense_dofs", "matrix_file_bytes", "compiled_model_bytes", "work_array_bytes", "pattern_bytes",
           "contact_rows_bytes", "delassus_bytes", "fits_in_memory"]

#: Control-group memory limits (v2, then v1) that cap what the kernel gives this process.
_CGROUP_LIMITS = (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                  ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes"))


def _meminfo_available() -> float | None:
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0  # the file gives kB
    except (OSError, ValueError, IndexError):
        pass
    return None


def _cgroup_room() -> float | None:
    """Room left under this process's control-group memory limit [bytes], None without one."""
    for limit_file, usage_file in _CGROUP_LIMITS:
        try:
            limit = Path(limit_file).read_text().strip()
            usage = float(Path(usage_file).read_text().strip())
        except (OSError, ValueError):
            continue
        if limit.isdigit() and float(limit) < 2.0**60:  # "max" (v2) or 2^63 rounded to pages (v1): no limit
            return max(float(limit) - usage, 0.0)
    return None


def available_memory() -> float | None:
    """Memory this process can allocate now [bytes]: ``MemAvailable`` (else the physical memory)
    capped by its control group's limit; None when nothing can be read."""
    memory = _meminfo_available()
    if memory is None:
        try:
            memory = float(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
        except (ValueError, OSError, AttributeError):
            memory = None
    room = _cgroup_room()
    if room is not None:
        memory = room if memory is None else min(memory, room)
    return memory


def format_bytes(n: float) -> str:
    """``1.23 GB``, ``456 MB``, ``7.8 kB`` (decimal units, 3 significant digits)."""
    if not math.isfinite(n):
        return "an unbounded amount"
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} B"


def check_memory(need: float, what: str, fix: Callable[[float], str] | str) -> None:
    """Refuse work that needs ``need`` bytes when less memory is available.

    Parameters
    ----------
    need : float
        Estimated peak memory of the arrays the work allocates [bytes] (may be inf).
    what : str
        What needs it, for the message (``"a run of 2e+07 samples of model 'dof60'"``).
    fix : callable or str
        The settings that fit: a function of the memory available [bytes] that computes them
        (``lambda memory: f"lower the sample rate to at most {...} Hz"``), or a fixed text.

    Raises
    ------
    MemoryLimitError
        When ``need`` exceeds the memory available (never when that cannot be read).
    """
    memory = available_memory()
    if memory is None or need <= memory:
        return
    advice = fix(memory) if callable(fix) else fix
    raise MemoryLimitError(f"{what} needs ≈ {format_bytes(need)}, more than the {format_bytes(memory)} of memory "
                           f"available; {advice}")


def largest_count(per_item: float, memory: float, fixed: float = 0.0) -> int:
    """The most items of ``per_item`` bytes that fit in ``memory`` beside ``fixed`` bytes (≥ 0)."""
    return max(int((memory - fixed) // per_item), 0)


# ----------------------------------------------------------------------------- per item
#: Bytes per kept sample of a run beyond its recorded arrays: the contiguous copy of the states
#: taken by the derived series, the sample times and a dozen float series of the analysis and
#: the figure. Measured growth of the peak resident memory of `stickslip simulate` (run, NetCDF,
#: figure) per sample: 360 B for the plates (6 DOFs, 1 contact), 1996 B for a 60-DOF model with one
#: contact; :func:`sample_bytes` gives 361 B and 2089 B.
_SAMPLE_SERIES = 14


def sample_bytes(n_dofs: int, n_contacts: int) -> float:
    """Peak bytes per kept sample of a run of a model with ``n_dofs`` coordinates and
    ``n_contacts`` contacts, the run written to NetCDF and drawn: the recorded state (2n + 2
    float64 with the work of friction and damping), mode byte and friction (2 per contact), a
    contiguous copy of the 2n states, slip velocity and normal force (3 per contact), and
    :data:`_SAMPLE_SERIES` float series."""
    n, nc = int(n_dofs), int(n_contacts)
    recorded = 8 * (2 * n + 2) + 1 + 16 * nc
    return float(recorded + 16 * n + 24 * nc + 8 * _SAMPLE_SERIES)


#: Copies of a basin study's outcome row held per state at the peak (the rows read back from the
#: journal or received from the workers, and the dataset assembled from them, where each row is
#: also an :class:`~stickslip.basins.early.Outcome`). Measured growth per state of the peak
#: resident memory of a study with the classification replaced by a constant outcome: 3485 B for
#: a 1-DOF model (a row of 174 numbers), 7241 B for a 60-DOF model (292 numbers);
#: :func:`state_bytes` gives 3504 B and 7280 B.
_ROW_COPIES = 2.5


def state_bytes(n_dofs: int, row_width: int) -> float:
    """Peak bytes per state of a basin study of a model with ``n_dofs`` coordinates whose outcome
    rows hold ``row_width`` numbers: :data:`_ROW_COPIES` rows and 3n float64 for the initial state
    and its copies (the coefficient fitted to the growth with n measured above)."""
    return float(8 * _ROW_COPIES * row_width + 24 * int(n_dofs))


#: Bytes per parameter value of a basin study: the model rebuilt at that value and its context
#: (steady sliding, Jacobian, linear flow and Lyapunov matrix: about 55 float64 per n²), and the
#: Python objects around them. Measured growth per value of the peak resident memory: 22 kB for
#: a 1-DOF model, 1.6 MB for a 60-DOF model.
_PARAM_FIXED, _PARAM_PER_DOF2 = 22_000, 440


def param_bytes(n_dofs: int) -> float:
    """Peak bytes per parameter value of a basin study of a model with ``n_dofs`` coordinates."""
    return float(_PARAM_FIXED + _PARAM_PER_DOF2 * int(n_dofs) ** 2)


#: Copies of a sweep point's row held at the peak (the journal read back, the rows received, the
#: dataset assembled), as :data:`_ROW_COPIES` for basin states, and the point's coordinates,
#: done flag and pending index (32 B).
_GRID_ROW_COPIES, _GRID_INDEX = 3, 32


def grid_point_bytes(row_width: int) -> float:
    """Peak bytes per grid point of a sweep whose points reduce to ``row_width`` numbers."""
    return float(8 * _GRID_ROW_COPIES * row_width + _GRID_INDEX)


#: Bytes per point and member of a stability map: its largest real part, the stacked copy of all
#: members and the flat buffer it is computed in (3 float64).
_MAP_POINT = 24


def map_point_bytes(members: int) -> float:
    """Peak bytes per (first, second) grid point of a stability map of ``members`` family members."""
    return float(_MAP_POINT * max(int(members), 1))


#: Bytes per running estimate of a Lyapunov average, fixed and per exponent: its time (a Python
#: float in a list) and its sums (an array in a list, the stacked copy, the estimate and its
#: ordered copy).
_AVERAGE_FIXED, _AVERAGE_PER_EXPONENT = 160, 32


def average_bytes(exponents: int) -> float:
    """Peak bytes per running estimate of a Lyapunov average of ``exponents`` exponents."""
    return float(_AVERAGE_FIXED + _AVERAGE_PER_EXPONENT * int(exponents))


# ----------------------------------------------------------------------------- per model
#: Dense n × n float64 arrays alive at the peak of packing a model for the compiled kernels
#: (``FrictionModel.data``, ``model/bundle.pack``): M⁻¹, M, C, K in the packed array (4), the
#: dense M, C, K it copies them from (3), and the inverse's result and LAPACK's work copy (2).
_DENSE_COPIES = 9


def model_data_bytes(n_dofs: int, n_contacts: int) -> float:
    """Peak bytes of packing a model of ``n_dofs`` coordinates and ``n_contacts`` contacts for the
    compiled kernels: :data:`_DENSE_COPIES` dense n × n arrays, and per contact its block (the
    tangent rows, drive, three gradients and the law: 5n + 16 numbers)."""
    n, nc = int(n_dofs), int(n_contacts)
    return 8.0 * (_DENSE_COPIES * n * n + nc * (5 * n + 16) + 2 * n + 8)


#: Call sites of work arrays in the compiled kernels (``model/stack.py``), each compiled for
#: float and complex numbers: a model above the stack maxima holds one heap buffer per site
#: reached (the source has about 60 sites; the float and the complex-step kernels reach each at
#: most once, and an inlined kernel's sites once per caller: 120 bounds what a process compiles
#: for one kinematics class, counted generously).
_WORK_SITES = 120


def work_array_bytes(n_dofs: int, n_contacts: int) -> float:
    """Bytes of the kernels' heap work arrays of a model above the stack maxima: per site the
    largest a site takes, complex (16 B): an impact's 3 nc × n rows and 3 nc × 3 nc system, and
    seven vectors of max(n, 2 nc)."""
    n, nc = int(n_dofs), int(n_contacts)
    return 16.0 * _WORK_SITES * (3 * nc * n + 9 * nc * nc + 7 * max(n, 2 * nc))


def pattern_bytes(n_dofs: int) -> float:
    """Bytes of the sparse structure a model above the stack maxima carries beside its packed data
    (``model/kinematics.py``'s heap classes), at most: the row-compressed patterns of C and K and
    of M (int64 row starts and up to n² columns each) with their entries (C's and K's, M's), and
    the Cholesky factor of M (its strict lower triangle's columns and values, its order and
    diagonal, its rows' runs of consecutive columns, three numbers each and at most one per entry)."""
    n = int(n_dofs)
    return 8.0 * (2 * (n * n + n + 1) + 3 * n * n + n * (n - 1) + (n + 1) + 2 * n + (n + 1) + 3 * n * (n - 1) // 2)


def contact_rows_bytes(n_dofs: int, n_contacts: int) -> float:
    """Bytes of the contact rows over their nonzero entries that a model above the stack maxima
    carries (``model/mass_factor.contact_rows``), at most: the 2 nc tangent rows' columns and
    values, the normal-force gradients' columns and two values and the gap gradients' columns and
    values, of n entries each."""
    n, nc = int(n_dofs), int(n_contacts)
    return 8.0 * (2 * 2 * nc * n + 3 * nc * n + 2 * nc * n + 4 * nc + 3)


def delassus_bytes(n_dofs: int, n_contacts: int) -> float:
    """Bytes of the matrix W = G M⁻¹ Gᵀ of all contact rows (2 nc × 2 nc) of a model above the
    stack maxima with the 2 nc × n product G M⁻¹ it is formed from, both kept
    (``model/mass_factor.delassus``). Optional: where they do not fit (:func:`fits_in_memory`),
    the stick systems are formed row by row as without them."""
    n, nc = int(n_dofs), int(n_contacts)
    return 8.0 * (4 * nc * nc + 2 * nc * n)


def fits_in_memory(need: float) -> bool:
    """Whether ``need`` bytes fit in the memory available now (True where none can be read): the
    test of something optional, which is left out where it does not fit."""
    memory = available_memory()
    return memory is None or need <= memory


def compiled_model_bytes(n_dofs: int, n_contacts: int) -> float:
    """Peak bytes of a model in the compiled kernels: its packed data (:func:`model_data_bytes`)
    and, above the stack maxima, the kernels' work arrays (:func:`work_array_bytes`) and its
    sparse structure (:func:`pattern_bytes`, :func:`contact_rows_bytes`)."""
    return (model_data_bytes(n_dofs, n_contacts) + work_array_bytes(n_dofs, n_contacts) + pattern_bytes(n_dofs)
            + contact_rows_bytes(n_dofs, n_contacts))


def largest_dense_dofs(memory: float, n_contacts: int = 0) -> int:
    """The most coordinates whose compiled model (:func:`compiled_model_bytes`) fits in ``memory`` bytes."""
    n = int(math.isqrt(max(int(memory // (8 * _DENSE_COPIES)), 0)))
    while n > 0 and compiled_model_bytes(n, n_contacts) > memory:
        n = min(n - 1, int(n * 0.99))
    return n


#: Bytes held while a matrix file is parsed, per byte of the file: the file's bytes, read once
#: (and hashed), and the parsed triplets and their compressed-row copy, which take about as many
#: bytes as the text they came from (a Matrix Market entry ``i j value`` is 20–30 characters for
#: 16 bytes of index and value, twice while converted).
_MATRIX_FILE_COPIES = 3


def matrix_file_bytes(file_bytes: float, unpacked_bytes: float | None = None) -> float:
    """Peak bytes of reading a matrix file of ``file_bytes`` bytes; ``unpacked_bytes``, where
    known, is what its compressed arrays take unpacked (a ``.npz``'s members)."""
    body = file_bytes if unpacked_bytes is None else max(file_bytes, unpacked_bytes)
    return float(file_bytes + (_MATRIX_FILE_COPIES - 1) * body)
