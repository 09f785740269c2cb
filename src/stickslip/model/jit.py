"""The one way compiled kernels are declared in stickslip.

``kernel``: numba ``njit`` with an on-disk cache and *without* the numba runtime (NRT). Kernels
only read and write the arrays they are given and never allocate, so they need no reference
counting; compiled without NRT their calls carry no atomic incref/decref per array argument,
which halves the cost of the right-hand side (measured 189 → 84 ns per call, N = 50 N,
Ω = 5 rad/s; ``benchmarks/kernels.py``). Functions that allocate (the integrator loops) use
``loop`` (plain cached ``njit``).
"""

from __future__ import annotations

from numba import njit

kernel = njit(cache=True, _nrt=False)
inlined_kernel = njit(cache=True, _nrt=False, inline="always")
loop = njit(cache=True)

__all__ = ["kernel", "inlined_kernel", "loop"]
