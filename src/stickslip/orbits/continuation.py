"""Pseudo-arclength continuation of periodic stick-slip orbits in one parameter: the public names.

A periodic orbit (:func:`~stickslip.orbits.periodic_orbit`) is followed as one parameter λ — any
numeric field of :class:`~stickslip.Parameters` (``N``, ``Omega``, ``delta_mu``, ...) — changes,
with its Floquet multipliers and stick phases, and the points where it changes stability or ends
are located. The work is split by responsibility:

=============================  ================================================================
:mod:`.problem`                the shooting problem (return map, monodromy, Newton), shared with
                               ``periodic_orbit`` and the Lyapunov tools
:mod:`.arclength`              the corrector: λ as an unknown, Jacobian, tangent, Newton–Broyden
:mod:`.branch`                 :func:`continue_orbit` (steps, step control, stops) and :class:`Branch`
:mod:`.special_points`         folds, period doubling, Neimark–Sacker (by what crosses the unit
                               circle), stick phases appearing or vanishing, grazing (a flight
                               phase of a unilateral contact appearing or vanishing), Hopf
                               points, steady sliding: detection and location
:mod:`.start`                  the first orbit: :func:`start_run`, :func:`start_orbit_from_run`
:mod:`.branch_store`           journals (resume), JSON records, NetCDF of branches and fold curves
:mod:`.region_edge`            the Region II edge over N (:func:`fold_curve`), :func:`unstable_cycle`
=============================  ================================================================

This module re-exports their public names. The shooting residual and Jacobian of the corrector
(``_residual``, ``_jacobian``) and the per-N task of :func:`fold_curve` (``_edge_at``) can be
replaced through it (``monkeypatch.setattr(continuation, "_residual", f)``: an algebraic problem
with a known fold, a stand-in for one N): setting them here sets them in the module that calls them.
"""

# ruff: noqa: F401 (tuning constants and the replaceable callables are re-exported for tests and studies)
from __future__ import annotations

from .arclength import (DEFAULT_FD_STEP, DEFAULT_TOL, MAX_CORRECTOR, MAX_STEPS_PER_SECOND, MIN_TANGENT_COS,
                        ContinuationError, SteadySlidingError, _jacobian, _residual)
from .branch import (AMPLITUDE_SAMPLES, EASY_ITERATIONS, GROW, HARD_ITERATIONS, SHRINK, Branch, continue_orbit,
                     load_branch)
from .problem import nontrivial, unstable_count
from .region_edge import (EDGE_BISECTIONS, EDGE_PROBE, EDGE_SEPARATION, EDGE_WINDOW, FOLD_JACOBIAN_EVERY, FOLD_RTOL,
                          FOLD_TOL, START_FALLBACK, FoldCurve, _edge_at, branch_edge, fold_curve, load_fold_curve,
                          unstable_cycle)
from .section import OrbitError
from .special_points import (HOPF_RATIO, LOCATE_RTOL, MAX_LOCATE, MIN_STICK_FRACTION, ORBIT_MIN_SIZE, REAL_RTOL,
                             SPECIAL_KINDS, VANISH_FIT_POINTS, VANISH_FIT_RTOL, SpecialPoint, circle_crossings,
                             is_orbit)
from .start import START_RATE, START_RUN, crossings_per_stick, start_orbit_from_run, start_run

__all__ = ["Branch", "SpecialPoint", "FoldCurve", "continue_orbit", "fold_curve", "branch_edge", "start_run",
           "crossings_per_stick", "start_orbit_from_run", "unstable_cycle", "load_branch", "load_fold_curve",
           "ContinuationError", "SteadySlidingError", "SPECIAL_KINDS", "circle_crossings"]
