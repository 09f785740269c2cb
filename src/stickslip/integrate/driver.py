"""The ``simulate()`` driver: resolve the model, validate options, build the initial state, run a
method in chunks, wrap the result."""

from __future__ import annotations

import functools
import math
import time
from pathlib import Path
from typing import Mapping

import numpy as np

from ..errors import SimulationError
from ..memory import check_memory, format_bytes, largest_count, sample_bytes
from ..model.library import resolve_model
from ..model.library.two_plates import is_plates
from .fixed_step import run_fixed_step
from .initial import check_rigid_start, initial_state
from .interrupt import forget_ctrl_c, partial_on_ctrl_c
from .result import Stats, Trajectory, Transitions
from .runner import NO_STEP_CAP, run_event

__all__ = ["simulate", "METHODS", "MAX_SAMPLES", "check_samples", "round_down"]

#: Largest number of uniform samples a run may keep (each ~ (2n + 2 + 2 nc) float64 and a flag byte).
MAX_SAMPLES = 20_000_000


def round_down(x: float) -> float:
    """``x`` (> 0) rounded down to 3 significant digits: a setting quoted in a message that fits."""
    if not x > 0 or not math.isfinite(x):
        return 0.0
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    return math.floor(x / step * (1 + 1e-12)) * step  # 1e-12: 582 computed as 581.999… stays 582


def check_samples(system, duration: float, sample_rate: float, *, run: str = "the run",
                  rate_settable: bool = True) -> int:
    """The samples a run of ``duration`` seconds at ``sample_rate`` keeps, refused before anything is
    allocated when they are more than :data:`MAX_SAMPLES` or their memory
    (:func:`stickslip.memory.sample_bytes` each, the run written and drawn) is more than available.

    Parameters
    ----------
    system : FrictionModel
    duration, sample_rate : float
        Run length [s] and samples per second [Hz], finite and > 0.
    run : str
        The run's name in the message (``"the transient (t_transient)"``).
    rate_settable : bool
        Whether the caller's user sets the sample rate; if not, the message names only the length.

    Raises
    ------
    SimulationError, MemoryLimitError
        With the sample rate and the run length that fit (each on its own).
    """
    raw = duration * sample_rate
    count = math.floor(raw + 1e-9) + 1.0 if math.isfinite(raw) else math.inf  # a float: a huge request stays a number

    def fits(limit: float) -> str:
        length = f"shorten {run} to at most {round_down((limit - 1.0) / sample_rate):.3g} s"
        if not rate_settable:
            return length
        return f"lower the sample rate to at most {round_down((limit - 1.0) / duration):.3g} Hz or {length}"

    if count > MAX_SAMPLES:
        shown = f"{count:.3g}" if math.isfinite(count) else "more than 1e+308"
        raise SimulationError(f"{run} of {duration:.6g} s at {sample_rate:.6g} Hz keeps {shown} samples, more than the "
                              f"{MAX_SAMPLES:.3g} a run may keep; {fits(MAX_SAMPLES)}")
    per = sample_bytes(system.n, system.n_contacts)
    check_memory(count * per, f"{run} ({count:.3g} samples of model {system.name!r}, {format_bytes(per)} each)",
                 lambda memory: fits(min(largest_count(per, memory), MAX_SAMPLES)))
    return int(count)


#: Integration methods by name; ``aeom`` and ``naeom`` are the paper's fixed-step methods for the
#: two plates only.
METHODS = ("event", "aeom", "naeom")


def _check_positive(name: str, value, hint: str) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise SimulationError(f"{name} must be a number, got {value!r}; {hint}") from None
    if not math.isfinite(value) or value <= 0.0:
        raise SimulationError(f"{name} = {value} must be a finite number > 0; {hint}")
    return value


#: The runner of each method (:class:`.runner.RunOutput` from the same arguments).
RUNNERS = {"event": run_event, "aeom": functools.partial(run_fixed_step, "aeom"),
           "naeom": functools.partial(run_fixed_step, "naeom")}


def simulate(
    model=None,
    t_end: float = 100.0,
    *,
    method: str = "event",
    ic="zero",
    perturbation=None,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    dt: float | None = None,
    sample_rate: float = 1000.0,
    t0: float = 0.0,
    steady_from: float | None = None,
    max_steps: int | None = None,
    slip_band: float | None = None,
) -> Trajectory:
    """Simulate a friction-contact model with exact stick and slip.

    Parameters
    ----------
    model : FrictionModel, Parameters, str, optional
        The model: a :class:`FrictionModel` (the plates in a variant: ``two_plates(params,
        "rotation")``, Models 1–4 being ``full``, ``x``, ``y``, ``rotation``), a library name
        (``belt``, ...), a variant of the plates by name or a model file path, or the two plates'
        :class:`Parameters` (all DOFs free); default the plates with Table 1 at N = 50 N,
        Ω = 5 rad/s (:func:`stickslip.model.library.resolve_model`).
    t_end : float
        Final time [s].
    method : str
        ``event`` (adaptive, exact transitions; default); ``aeom`` or ``naeom`` (the paper's fixed-step
        methods, two plates only).
    ic : see :func:`initial_state`
    perturbation : float or (2n,), optional
        Added to the initial state (a float perturbs the observed coordinate, the plates' φ).
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
    max_steps : int, optional
        Cap on integration steps (default none: a run is stopped with Ctrl-C, which returns the
        part done).
    slip_band : float, optional
        Low-speed band [m/s] of the 2-D slip direction; default the model's (results converge as
        it → 0).

    Returns
    -------
    Trajectory
        Its ``status`` says how the run ended; an interrupted run (Ctrl-C) returns what was done.

    Raises
    ------
    SimulationError
        For invalid options (each message names the fix).
    MemoryLimitError
        When the samples asked for would not fit in the memory available (before any is allocated).
    """
    if method not in METHODS:
        raise SimulationError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    if slip_band is not None:
        slip_band = _check_positive("slip_band", slip_band, "give a speed in m/s, e.g. 1e-6")
    system = resolve_model(model, slip_band)
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
    n_samples = check_samples(system, t_end - t0, sample_rate)
    y0 = initial_state(system, ic, perturbation)
    check_rigid_start(system, y0)
    sample_times = t0 + np.arange(n_samples) / sample_rate

    if method != "event" and not is_plates(system):
        raise SimulationError(f"method {method!r} is the paper's fixed-step method for the two plates; "
                              f"model {system.name!r} runs with method='event' (CLI: --method event)")

    start = time.perf_counter()
    # a model with impacts tallies those of the steady window as it runs (exact beyond the kept states)
    window = {"impact_window": _steady_start(t0, sample_times, steady_from)} if system.rigid else {}
    out = RUNNERS[method](system, y0, t0, t_end, sample_times, rtol=rtol, atol=atol, dt=dt,
                          max_steps=NO_STEP_CAP if max_steps is None else int(max_steps), **window)
    wall = time.perf_counter() - start - out.stats["compile_time_s"]  # integration only
    if out.interrupted and not partial_on_ctrl_c():  # also when the run had just finished: the caller stops
        forget_ctrl_c()  # acted on here
        raise KeyboardInterrupt
    if out.record.n == 0:
        raise SimulationError(f"the run ended before its first sample ({out.status.message(out.t_reached, out.lost)})")
    options = {"rtol": rtol, "atol": atol, "dt": dt, "sample_rate": sample_rate, "ic": _ic_text(ic),
               "perturbation": None if perturbation is None else np.asarray(perturbation, dtype=float).tolist(),
               "t0": t0, "t_end": t_end, "slip_band": system.slip_band}
    return _trajectory(out, system, method, sample_times, options, steady_from, wall)


def _ic_text(ic) -> str:
    """How a run's options name its initial condition."""
    if isinstance(ic, str):
        return ic
    return ("trajectory" if isinstance(ic, Trajectory) else str(Path(ic)) if isinstance(ic, Path)
            else "states" if isinstance(ic, Mapping) else "explicit")


def _trajectory(out, system, method: str, sample_times: np.ndarray, options: dict, steady_from: float | None,
                wall: float) -> Trajectory:
    """The :class:`Trajectory` of a runner's output ``out`` (its samples up to the time reached;
    ``steady_from`` default: the last half of them)."""
    code, record, n_kept = out.status, out.record, out.record.n
    t0 = options["t0"]
    t_samples = sample_times[:n_kept]  # the samples up to the time reached: a prefix, so views
    steady_from = _steady_start(t0, t_samples, steady_from)
    n2 = 2 * system.n
    transitions = record.transitions()
    _, states, mode, friction = record.samples()
    return Trajectory(
        t=t_samples,
        states=states[:, :n2],
        mode=mode,
        friction=friction,
        work=states[:, n2:n2 + 2],
        transitions=Transitions(transitions.time, transitions.kind, transitions.state[:, :n2], transitions.contact,
                                transitions.dropped),
        stats=Stats(**out.stats, wall_time_s=wall),
        status=code.message(out.t_reached, out.lost),
        system=system,
        method=method,
        options=options,
        steady_from=float(steady_from),
        status_code=code,
        impact_tally=record.tally,
    )


def _steady_start(t0: float, sample_times: np.ndarray, steady_from: float | None) -> float:
    """The start of the steady window [s]: ``steady_from``, by default the last half of the samples."""
    return float(t0 + 0.5 * (sample_times[-1] - t0) if steady_from is None else steady_from)
