"""The ``simulate()`` driver: validate options, build the initial state, run a method, wrap results."""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import StickSlipError
from ..model.kernels import DEFAULT_SLIP_BAND
from ..model.parameters import Parameters
from ..model.system import System, assemble
from ..model.variants import STATE_NAMES
from . import method_event
from .fixed_step import run_aeom, run_naeom
from .result import Stats, Trajectory, Transitions, load_trajectory

__all__ = ["simulate", "initial_state", "SimulationError", "METHODS"]

#: Largest number of uniform samples a run may keep (12 states + extras ≈ 150 B each).
MAX_SAMPLES = 20_000_000


class SimulationError(StickSlipError, ValueError):
    """Invalid simulation options, or a run that could not finish."""


def _check_positive(name: str, value, hint: str) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise SimulationError(f"{name} must be a number, got {value!r}; {hint}") from None
    if not math.isfinite(value) or value <= 0.0:
        raise SimulationError(f"{name} = {value} must be a finite number > 0; {hint}")
    return value


def initial_state(system: System, ic="zero", perturbation=None) -> np.ndarray:
    """The 12-state initial condition.

    Parameters
    ----------
    system : System
    ic : {"zero", "equilibrium"}, array-like (12,), path to a run's ``.nc`` file, or Trajectory
        ``zero``: plates at rest, springs undeformed. ``equilibrium``: steady sliding (Eq. 14).
        A file or Trajectory: its final state (a continuation of that run).
    perturbation : float or array-like (12,), optional
        Added to the state: a float perturbs φ [rad], a 12-vector every state.

    Raises
    ------
    SimulationError
        For an unknown string, a wrong shape, a non-finite value, or a non-zero state of a
        locked DOF.
    """
    if isinstance(ic, Trajectory):
        s = ic.final_state
    elif isinstance(ic, (str, Path)) and str(ic) in ("zero", "equilibrium"):
        s = np.zeros(12)
        if str(ic) == "equilibrium":
            from ..stability.equilibrium import EquilibriumError, equilibrium

            try:
                s[:6] = equilibrium(system.params, system.variant)
            except EquilibriumError as exc:
                raise SimulationError(f"ic='equilibrium': {exc}") from exc
    elif isinstance(ic, Path) or (isinstance(ic, str) and ic.endswith(".nc")):
        s = load_trajectory(ic).final_state
    elif isinstance(ic, str):
        raise SimulationError(
            f"unknown initial condition {ic!r}; use 'zero', 'equilibrium', a path to a run .nc file, "
            "or 12 comma-separated numbers"
        )
    else:
        s = np.asarray(ic, dtype=float).copy()
        if s.shape != (12,):
            raise SimulationError(f"initial state must have 12 entries ({', '.join(STATE_NAMES)}), got shape {s.shape}")
    if perturbation is not None:
        delta = np.asarray(perturbation, dtype=float)
        if delta.ndim == 0:
            s[4] += float(delta)
        elif delta.shape == (12,):
            s = s + delta
        else:
            raise SimulationError(f"perturbation must be a number (added to phi) or 12 numbers, got shape {delta.shape}")
    if not np.all(np.isfinite(s)):
        raise SimulationError("initial state has a non-finite entry; give finite numbers")
    locked = ~np.concatenate([system.variant.mask, system.variant.mask])
    bad = [STATE_NAMES[i] for i in np.flatnonzero(locked & (s != 0.0))]
    if bad:
        raise SimulationError(
            f"initial state sets {', '.join(bad)} but those DOFs are locked in model {system.variant.name!r}; "
            "set them to 0 or choose a model that frees them"
        )
    return s


def _warm_up(kernel, y, t0, system, out_s, out_mode, out_F) -> float:
    """Compile (or load from cache) ``integrate_event`` on a 1 µs run, so that the timed run
    measures integration only; returns the seconds spent, 0 if already compiled."""
    if kernel.signatures:
        return 0.0
    start = time.perf_counter()
    kernel(y, t0, t0 + 1e-6, system.minv, system.damp, system.stiff, system.p, 1e-6, 1e-8, 1e-7, 1e-6,
           10, np.array([t0]), out_s[:1].copy(), out_mode[:1].copy(), out_F[:1].copy(),
           np.empty(1), np.empty(1, dtype=np.int8), np.empty((1, y.size)))
    return time.perf_counter() - start


def _run_event(system: System, y0: np.ndarray, t0: float, t_end: float, sample_times: np.ndarray,
               rtol: float, atol: float, dt: float | None, max_steps: int):
    h_max = dt if dt is not None else (t_end - t0)
    h_init = min(1e-3, h_max)  # ~1/100 of the fastest natural period of Table 1 (0.36 s)
    n = sample_times.size
    out_s = np.empty((n, method_event.N_STATE))  # every kept sample is written
    out_mode = np.empty(n, dtype=np.int8)
    out_F = np.empty((n, 2))
    y = np.zeros(method_event.N_STATE)
    y[:12] = y0
    compile_time = _warm_up(method_event.integrate_event, y, t0, system, out_s, out_mode, out_F)

    def run(tr_t, tr_kind, tr_s):
        res = method_event.integrate_event(y, t0, t_end, system.minv, system.damp, system.stiff, system.p,
                                           rtol, atol, h_init, h_max, max_steps, sample_times, out_s, out_mode,
                                           out_F, tr_t, tr_kind, tr_s)
        return res, res[6]

    res, tr_t, tr_kind, tr_s = method_event.with_transition_room(run, t_end - t0)
    status, t_reached, st = res[0], res[1], res[7]
    stats = dict(accepted_steps=int(st[0]), rejected_steps=int(st[1]), rhs_calls=int(st[2]),
                 retaken_steps=int(st[3]), slip_to_stick=int(st[4]), stick_to_slip=int(st[5]),
                 compile_time_s=compile_time)
    messages = {
        method_event.STATUS_OK: "success",
        method_event.STATUS_STEP_UNDERFLOW: f"step size underflow at t = {t_reached:.6g} s",
        method_event.STATUS_NOT_FINITE: f"state became non-finite at t = {t_reached:.6g} s",
        method_event.STATUS_MAX_STEPS: f"max_steps reached at t = {t_reached:.6g} s",
    }
    keep = sample_times <= t_reached
    return (messages[status], keep, out_s, out_mode, out_F, Transitions(tr_t, tr_kind, tr_s[:, :12]), stats)


#: Integration methods by name: callables with the signature of ``_run_event``.
METHODS: dict[str, Callable] = {"event": _run_event, "aeom": run_aeom, "naeom": run_naeom}


def simulate(
    params: Parameters | None = None,
    t_end: float = 100.0,
    *,
    model="full",
    method: str = "event",
    ic="zero",
    perturbation=None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    dt: float | None = None,
    sample_rate: float = 1000.0,
    t0: float = 0.0,
    steady_from: float | None = None,
    max_steps: int = 50_000_000,
    slip_band: float = DEFAULT_SLIP_BAND,
) -> Trajectory:
    """Simulate the two-plate friction system with exact stick and slip.

    Parameters
    ----------
    params : Parameters, optional
        Physical parameters; default Table 1 with N = 50 N, Ω = 5 rad/s, μk = 0.2, Δμ = 0.1, α = 5.
    t_end : float
        Final time [s].
    model : str or iterable of DOF names
        ``full`` (Model 1), ``x`` (2), ``y`` (3), ``rotation`` (4), or the DOFs to free.
    method : str
        ``event`` (adaptive, exact transitions; default).
    ic : see :func:`initial_state`
    perturbation : float or (12,), optional
        Added to the initial state (a float perturbs φ [rad]).
    rtol, atol : float
        Local error tolerances of the adaptive method.
    dt : float, optional
        Largest step for ``event`` [s]; the fixed step of fixed-step methods.
    sample_rate : float
        Uniform output samples per second [Hz].
    t0 : float
        Initial time [s].
    steady_from : float, optional
        Start of the steady-state window [s]; default the last half of the run.
    max_steps : int
        Safety cap on integration steps.
    slip_band : float
        Low-speed band [m/s] inside which the slip direction is the quasi-static one
        (``stickslip.model.kernels.quasi_static_direction``); results converge as it → 0.

    Returns
    -------
    Trajectory

    Raises
    ------
    SimulationError
        For invalid options (each message names the fix).
    """
    params = Parameters() if params is None else params
    if not isinstance(params, Parameters):
        raise SimulationError(f"params must be a stickslip.Parameters, got {type(params).__name__}")
    if method not in METHODS:
        raise SimulationError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    t0 = float(t0)
    if not math.isfinite(t0):
        raise SimulationError("t0 must be finite")
    t_end = _check_positive("t_end - t0", float(t_end) - t0, "give t_end > t0 in seconds") + t0
    rtol = _check_positive("rtol", rtol, "typical values are 1e-6 … 1e-10")
    if not 1e-13 <= rtol <= 0.1:
        raise SimulationError(f"rtol = {rtol} is outside [1e-13, 0.1]: below 1e-13 round-off dominates; give a value in range")
    atol = _check_positive("atol", atol, "typical values are 1e-8 … 1e-12")
    sample_rate = _check_positive("sample_rate", sample_rate, "give samples per second, e.g. 1000")
    if dt is not None:
        dt = _check_positive("dt", dt, "give a step in seconds, e.g. 1e-4")
    n_samples = int(math.floor((t_end - t0) * sample_rate + 1e-9)) + 1
    if n_samples > MAX_SAMPLES:
        raise SimulationError(
            f"{n_samples} samples requested (t_end × sample_rate); lower sample_rate to keep ≤ {MAX_SAMPLES}"
        )
    slip_band = _check_positive("slip_band", slip_band, "give a speed in m/s, e.g. 1e-6")
    system = assemble(params, model, slip_band)
    y0 = initial_state(system, ic, perturbation)
    sample_times = t0 + np.arange(n_samples) / sample_rate

    start = time.perf_counter()
    status, keep, out_s, out_mode, out_F, transitions, stats = METHODS[method](
        system, y0, t0, t_end, sample_times, rtol, atol, dt, int(max_steps))
    wall = time.perf_counter() - start - stats.get("compile_time_s", 0.0)  # integration only

    ic_text = ic if isinstance(ic, str) else ("trajectory" if isinstance(ic, Trajectory) else str(Path(ic)) if isinstance(ic, Path) else "explicit")
    options = {"rtol": rtol, "atol": atol, "dt": dt, "sample_rate": sample_rate, "ic": ic_text,
               "perturbation": None if perturbation is None else np.asarray(perturbation, dtype=float).tolist(),
               "t0": t0, "t_end": t_end, "slip_band": slip_band}
    n_kept = int(np.count_nonzero(keep))  # the samples up to the time reached: a prefix, so views
    t_samples = sample_times[:n_kept]
    if steady_from is None:
        steady_from = t0 + 0.5 * (t_samples[-1] - t0)
    return Trajectory(
        t=t_samples,
        states=out_s[:n_kept, :12],
        mode=out_mode[:n_kept],
        friction=out_F[:n_kept],
        work=out_s[:n_kept, 12:14],
        transitions=transitions,
        stats=Stats(**stats, wall_time_s=wall),
        status=status,
        params=params,
        model=system.variant.name,
        method=method,
        options=options,
        steady_from=float(steady_from),
    )
