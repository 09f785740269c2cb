"""Runs extended until they have settled.

:func:`simulate_until_settled` runs :func:`stickslip.simulate` for ``t_min`` seconds, then
extends the run from its final state in steps of ``step`` seconds (``simulate(..., ic=traj,
t0=traj.t[-1])``), judging the trailing ``window`` seconds after each
(:func:`~.verdict.attractor`), until the verdict is settled or the run reaches ``cap`` seconds.
"""

from __future__ import annotations

import dataclasses
import math

from ..errors import SimulationError
from ..integrate.driver import check_samples, simulate
from ..integrate.result import Trajectory
from .confirm import QUASI_SPAN_S
from .summary import run_summary
from .verdict import Attractor, attractor

__all__ = ["SettledRun", "simulate_until_settled", "DEFAULT_CAP_S", "DEFAULT_WINDOW_S", "DEFAULT_STEP_S",
           "DEFAULT_T_MIN_S"]

#: Defaults of :func:`simulate_until_settled` [s]. The paper's stick-slip orbits settle to the
#: period rule's 1e-5 within 500–700 s from rest (Model 1, N = 50–120 N, Ω = 0.5 and 5 rad/s:
#: slowest multipliers 0.994 per 0.65 s); the cap leaves a factor ~3 and bounds the samples
#: kept (2000 s at 1 kHz: 2·10⁶ samples, ~0.26 GB).
DEFAULT_CAP_S = 2000.0
DEFAULT_WINDOW_S = 100.0
DEFAULT_STEP_S = 100.0
DEFAULT_T_MIN_S = 200.0


@dataclasses.dataclass(frozen=True)
class SettledRun:
    """A run extended until settled (:func:`simulate_until_settled`), with the verdict it reached.

    Parameters
    ----------
    trajectory : Trajectory
        The run; ``steady_from`` is the start of the last window judged and ``options["settle"]``
        holds ``cap_s``, ``window_s``, ``step_s``, ``t_min_s``, ``settled``, ``attractor``,
        ``settle_time_s`` and ``extensions``.
    attractor : Attractor
        The verdict on the last window (not computed again).
    """

    trajectory: Trajectory
    attractor: Attractor

    @property
    def settle(self) -> dict:
        """The cap, window, steps and outcome of the extensions."""
        return self.trajectory.options["settle"]

    def summary(self) -> dict:
        """:func:`~.summary.run_summary` of the run with its verdict."""
        return run_summary(self.trajectory, self.attractor)


def simulate_until_settled(model=None, *, cap: float = DEFAULT_CAP_S, t_min: float = DEFAULT_T_MIN_S,
                           window: float = DEFAULT_WINDOW_S, step: float = DEFAULT_STEP_S, dof: str | None = None,
                           keep: str = "all", confirm: bool = True, lyapunov: bool = True, t0: float = 0.0,
                           **simulate_options) -> SettledRun:
    """Simulate until the run has settled (module docstring) or reaches ``cap``.

    Parameters
    ----------
    model : FrictionModel, Parameters or str, optional
        The model, as :func:`stickslip.simulate` takes it.
    cap : float
        Longest run [s] (measured from ``t0``).
    t_min : float
        Length of the first run [s].
    window : float
        Trailing window judged after each run [s].
    step : float
        Length of each extension [s].
    dof : str, optional
        Coordinate whose maxima form the section (default the model's observed one).
    keep : {"all", "window"}
        Keep every sample of the run, or only the last max(window, QUASI_SPAN_S) seconds
        (memory stays flat however long the run; for sweeps).
    confirm, lyapunov : bool
        See :func:`~.verdict.attractor`.
    t0 : float
        Initial time [s].
    **simulate_options
        ``ic``, ``perturbation``, ``method``, ``rtol``, ``atol``, ``dt``,
        ``sample_rate``, ``max_steps``, ``slip_band`` of :func:`stickslip.simulate`.

    Returns
    -------
    SettledRun
    """
    for name, value in (("cap", cap), ("t_min", t_min), ("window", window), ("step", step)):
        if not (math.isfinite(value) and value > 0):
            raise SimulationError(f"{name} = {value} s must be a finite number > 0")
    if window > t_min:
        raise SimulationError(f"window = {window} s is longer than the first run (t_min = {t_min} s); "
                              "give t_min ≥ window")
    if keep not in ("all", "window"):
        raise SimulationError(f"keep = {keep!r}: choose 'all' or 'window'")
    if "steady_from" in simulate_options or "t_end" in simulate_options:
        raise SimulationError("simulate_until_settled sets the run length and window itself; "
                              "give cap, t_min, window and step instead of t_end and steady_from")
    t0 = float(t0)
    end = t0 + min(t_min, cap)
    traj = simulate(model, end, t0=t0, **simulate_options)
    if keep == "all":  # the extensions keep every sample up to the cap: refused now if they would not fit
        check_samples(traj.system, cap, traj.options["sample_rate"], run="the run up to the cap (cap, --cap)")
    simulate_options.pop("ic", None)
    simulate_options.pop("perturbation", None)
    cache: dict = {}
    extensions = 0
    while True:
        t_from = max(float(traj.t[-1]) - window, float(traj.t[0]))
        verdict = attractor(traj, t_from, dof=dof, confirm=confirm, lyapunov=lyapunov, cache=cache)
        if verdict.settled or traj.status != "success" or traj.t[-1] >= t0 + cap - 1e-9:
            break
        more = simulate(traj.system, min(float(traj.t[-1]) + step, t0 + cap), ic=traj, t0=float(traj.t[-1]),
                        **simulate_options)
        traj = traj.joined(more)
        if keep == "window":
            traj = traj.tail(float(traj.t[-1]) - max(window, QUASI_SPAN_S))
        extensions += 1
    settle = {"cap_s": float(cap), "window_s": float(window), "step_s": float(step), "t_min_s": float(t_min),
              "settled": verdict.settled, "attractor": verdict.attractor,
              "settle_time_s": verdict.settle_time_s, "extensions": extensions}
    traj = dataclasses.replace(traj, steady_from=t_from, options=dict(traj.options, settle=settle))
    return SettledRun(traj, verdict)
