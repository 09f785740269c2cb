"""How fine and how long the recipes of :mod:`stickslip.studies.reproduce` compute.

:class:`Resolution` holds every grid size, run length, settle cap and worker setting that a
recipe reads, so that the recipes carry no sizes of their own and one name fixes the cost of a
whole ``stickslip reproduce`` run. :data:`RESOLUTIONS` names the three presets: ``full`` (the
paper's grids and run lengths), ``quick`` (coarse grids, minutes) and ``micro`` (a few points and
seconds, for the tests).
"""

from __future__ import annotations

import dataclasses

__all__ = ["Resolution", "RESOLUTIONS"]


@dataclasses.dataclass(frozen=True)
class Resolution:
    """How fine and how long the recipes compute."""

    name: str
    stab_N: int                  # points along N of the stability maps (2–200 N)
    stab_Omega: int              # points along Ω (0.2–20 rad/s)
    timestep_dts: tuple          # Δt of the Table 2 study [s]
    timestep_t_end: float        # simulated time of the study [s] (paper: 100)
    timestep_event_rtols: tuple
    fig7_t_end: float            # run length of the Fig. 7 runs [s]
    fig10_t_end: float           # run length of the Fig. 10/11 runs [s] (window: last half)
    fig10_N: tuple               # normal loads of Fig. 10 [N]
    fig12_N: int                 # points of the Fig. 12(a) sweep over 10–130 N
    fig12_t_end: float
    workers: int | None = None   # worker processes (None: every CPU this process may use)
    executor: str = "processes"
    # Figs. 8, 9, 16: region maps over N in [10, 130] N × Ω in [1, 15] rad/s, two ICs, all four models
    regions_N: int = 100
    regions_Omega: int = 100
    regions_t_end: float = 300.0          # the near IC leaves a weakly unstable equilibrium slowly
    regions_t_from: float = 200.0         # (docs/sweeps.md); steady window = last 100 s
    # Figs. 12(b), 13, 14: bifurcation diagrams (points per control range, run length [s])
    bif_points: int = 100               # Figs. 12(b), 13
    fig14_N: int = 121                  # Fig. 14: points over N and over Ω (Model 3 is slow: ≤ 60 s a run)
    bif_t_end: float = 200.0
    fig15_t_end: float = 200.0
    # Figs. 10–15: every run is extended from its final state until it has settled, up to this
    # many seconds (stickslip.attractors; the run lengths above are the first runs)
    settle_cap: float = 2000.0


RESOLUTIONS = {
    "full": Resolution("full", 100, 100, (0.1, 0.01, 1e-3, 1e-4, 1e-5), 100.0, (1e-4, 1e-6, 1e-8),
                       300.0, 200.0, (30, 50, 70, 90, 110, 120), 121, 200.0),
    "quick": Resolution("quick", 100, 100, (0.1, 0.01, 1e-3, 1e-4), 100.0, (1e-4, 1e-6, 1e-8),
                        300.0, 200.0, (30, 50, 70, 90, 110, 120), 41, 200.0,
                        regions_N=7, regions_Omega=8, bif_points=15, fig14_N=11),
    "micro": Resolution("micro", 8, 10, (0.1, 0.01), 4.0, (1e-4,), 4.0, 4.0, (30, 120), 3, 3.0,
                        workers=1, executor="serial", regions_N=2, regions_Omega=2, regions_t_end=4.0,
                        regions_t_from=2.0, bif_points=3, fig14_N=3, bif_t_end=3.0, fig15_t_end=4.0,
                        settle_cap=6.0),
}
