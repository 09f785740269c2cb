"""Lyapunov exponents across stick↔slip events: the largest by Benettin's two-trajectory method
(:func:`lyapunov_exponent`), the full spectrum from the variational equations with saltation
matrices and QR re-orthonormalisation (:func:`lyapunov_spectrum`).

Largest exponent:

A reference and a perturbed trajectory (initial separation d0 in the scaled norm) are each
advanced by one chunk of τ seconds with :func:`stickslip.simulate` (``event`` integrator,
``ic=`` the previous chunk's exact final state); the separation d is measured, ln(d/d0) is
accumulated, and the perturbed state is put back at distance d0 along the current separation.
λ = Σ ln(d_i/d0) / (n τ). The state is continuous at transitions (only accelerations jump), so
the separation stays O(d0) through events where the two trajectories enter stick at slightly
different instants, and the chunked renormalisation needs no saltation matrices.

Norm: Euclidean on the free states divided by the scales σ (peak-to-peak ranges over the second
half of the transient run, floored like the shooting scales); λ does not depend on the norm in
the limit, the scales only keep d0 small against every coordinate's own range.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time as _time

import numpy as np

from .._version import __version__
from ..errors import OrbitError, SimulationError
from ..integrate.driver import check_samples, round_down, simulate
from ..integrate.initial import initial_state, rigid_gaps
from ..model.bundle import CST
from ..model.physics import MODE_STICK
from ..memory import average_bytes, check_memory, format_bytes, largest_count
from ..model.system_model import FrictionModel
from .layout import free_states, resting_contacts
from .linear_flow import propagate
from .models import ModelResult, model_attrs, resolve
from .problem import ShootingProblem, scales, stick_count
from .shooting import PeriodicOrbit

__all__ = ["LyapunovResult", "lyapunov_exponent", "LyapunovSpectrum", "lyapunov_spectrum"]

#: Default initial separation in the scaled norm [-]: 1e-7 of the attractor's range is far
#: above the integration noise at rtol 1e-10 (~1e-10 σ) and far inside the linear regime.
DEFAULT_D0 = 1e-7

#: Samples per second of the transient run [Hz], whose second half sets the scales of the norm.
TRANSIENT_RATE = 200.0


@dataclasses.dataclass(frozen=True, eq=False)
class LyapunovResult(ModelResult):
    """Largest Lyapunov exponent with its convergence history.

    Parameters
    ----------
    exponent : float
        λ_max over the whole averaging time [1/s].
    time : ndarray (n,)
        Averaging time after each chunk [s].
    estimate : ndarray (n,)
        Running estimate of λ_max after each chunk [1/s].
    log_growth : ndarray (n,)
        ln(d/d0) of each chunk [-].
    chunk : float
        Renormalisation interval τ [s].
    d0 : float
        Scaled initial separation [-].
    t_transient : float
        Discarded transient before averaging [s].
    scale : ndarray (2 n_free,)
        Scales σ of the norm [state units].
    system : FrictionModel
        The model.
    options : dict
        rtol, atol, slip_band of the runs, seed and perturbation.
    """

    exponent: float
    time: np.ndarray
    estimate: np.ndarray
    log_growth: np.ndarray
    chunk: float
    d0: float
    t_transient: float
    scale: np.ndarray
    system: FrictionModel
    options: dict

    @property
    def standard_error(self) -> float:
        """Standard error of λ from the spread of the per-chunk growth rates [1/s] (treats
        chunks as independent; for a periodic orbit the estimate converges like 1/t instead)."""
        g = self.log_growth / self.chunk
        return float(np.std(g, ddof=1) / np.sqrt(g.size)) if g.size > 1 else float("nan")

    def to_xarray(self):
        """``xarray.Dataset`` of the convergence history with units and the parameters."""
        import xarray as xr

        data = {
            "estimate": ("time", self.estimate, {"long_name": "running estimate of the largest Lyapunov exponent", "units": "1/s"}),
            "log_growth": ("time", self.log_growth, {"long_name": "ln(d/d0) per renormalisation chunk", "units": "1"}),
        }
        attrs = {
            "title": "stickslip largest Lyapunov exponent (Benettin)",
            "stickslip_version": __version__,
            "exponent": self.exponent, "exponent_units": "1/s",
            "standard_error": self.standard_error,
            "chunk": self.chunk, "chunk_units": "s",
            "d0": self.d0,
            "t_transient": self.t_transient,
            "options": json.dumps(self.options),
            **model_attrs(self.system),
        }
        coords = {"time": ("time", self.time, {"units": "s", "long_name": "averaging time"})}
        return xr.Dataset(data, coords=coords, attrs=attrs)


def _check_memory(system, t_transient: float, t_average: float, interval: float, option: str) -> None:
    """Refuse, before anything runs, a transient whose samples or an average whose running
    estimates (one per ``interval`` seconds, named by ``option``) would not fit in memory."""
    if math.isfinite(t_transient):
        check_samples(system, t_transient, max(TRANSIENT_RATE, 1.0 / t_transient),
                      run="the transient (t_transient, --t-transient)", rate_settable=False)
    if not (math.isfinite(interval) and interval > 0):
        return
    count = t_average / interval
    per = average_bytes(2 * system.n)  # at most 2n exponents
    check_memory(count * per, f"an average over {t_average:.3g} s ({count:.3g} running estimates, one per "
                 f"{interval:g} s of {option}, {format_bytes(per)} each)",
                 lambda memory: f"shorten t_average (--t-average) to at most "
                                f"{round_down(largest_count(per, memory) * interval):.3g} s or lengthen {option}")


def _after_transient(model, ic, perturbation, t_transient, rtol, atol, slip_band, t_average=0.0,
                     interval=math.inf, option="chunk"):
    """The common start of the Lyapunov computations: resolve the start, check the memory of the
    transient and of the running estimates (one per ``interval`` of ``t_average``), run the transient.

    ``ic`` may be a :class:`PeriodicOrbit` (its model is then the default).
    Returns the flow map as a :class:`.problem.ShootingProblem` without a section (σ: the
    peak-to-peak ranges over the transient's second half) and the exact state at the end of the
    transient.
    """
    if isinstance(ic, PeriodicOrbit):
        model = ic.system if model is None else model
        ic = ic.state
    system = resolve(model, slip_band)
    atol = 1e-3 * rtol if atol is None else float(atol)
    if t_transient <= 0.0:
        raise OrbitError("t_transient must be > 0: the transient run sets the scales of the norm")
    _check_memory(system, t_transient, t_average, interval, option)
    if perturbation is None and isinstance(ic, str) and ic == "equilibrium":
        perturbation = 1e-3
    try:
        s = initial_state(system, ic, perturbation)
    except SimulationError as exc:
        raise OrbitError(f"bad initial condition: {exc}") from exc
    tr = simulate(system, t_transient, ic=s, sample_rate=max(TRANSIENT_RATE, 1.0 / t_transient), rtol=rtol, atol=atol)
    if tr.status != "success":
        raise OrbitError(f"the transient run failed: {tr.status}")
    half = tr.t >= 0.5 * t_transient
    problem = ShootingProblem.build(system, sigma=scales(np.ptp(tr.states[half], axis=0), free_states(system)),
                                    rtol=rtol, atol=atol)
    s_ref, _ = problem.flow(s, t_transient)  # exact end of the transient
    return problem, s_ref


def lyapunov_exponent(
    model=None,
    ic="equilibrium",
    *,
    t_transient: float = 50.0,
    t_average: float = 200.0,
    chunk: float = 1.0,
    d0: float = DEFAULT_D0,
    perturbation: float | None = None,
    rtol: float = 1e-10,
    atol: float | None = None,
    seed: int = 0,
    slip_band: float | None = None,
) -> LyapunovResult:
    """Largest Lyapunov exponent of the attractor reached from ``ic``.

    Parameters
    ----------
    model : FrictionModel, Parameters, str, optional
        The model as :func:`stickslip.simulate` takes it (default: the orbit's, else the plates, Table 1).
    ic : "equilibrium", "zero", array-like (2n,), Trajectory or PeriodicOrbit
        Start of the transient run (a PeriodicOrbit: its section state and model).
    t_transient : float
        Transient simulated and discarded first [s] (> 0: it also sets the norm's scales).
    t_average : float
        Averaging time [s] (rounded to whole chunks).
    chunk : float
        Renormalisation interval τ [s].
    d0 : float
        Initial separation in the scaled norm [-].
    perturbation : float, optional
        Added to φ of ``ic`` [rad]; default 1e-3 rad when ``ic`` is ``"equilibrium"`` (to leave
        the steady-sliding point, ~3 % of the φ amplitude of Fig. 10), else none.
    rtol, atol : float
        Integration tolerances (``atol`` default 1e-3 · rtol).
    seed : int
        Seed of the random initial separation direction.
    slip_band : float
        Low-speed band [m/s] (see :func:`stickslip.simulate`).

    Returns
    -------
    LyapunovResult

    Raises
    ------
    OrbitError
        If a run fails or the transient does not move (no scales).
    """
    n_chunks = int(round(t_average / chunk))
    if n_chunks < 1:
        raise OrbitError(f"t_average = {t_average} s is shorter than one chunk ({chunk} s)")
    problem, s_ref = _after_transient(model, ic, perturbation, t_transient, rtol, atol, slip_band, t_average, chunk,
                                      "chunk")
    free, sigma = problem.free, problem.sigma

    def perturbed(direction):
        sp = problem.perturbed(s_ref, direction, d0)
        d_start = float(np.linalg.norm((sp[free] - s_ref[free]) / sigma))
        if not d_start > 0.0:
            raise OrbitError("the separation vanished on projection onto the stick constraint; change seed")
        return sp, d_start

    rng = np.random.default_rng(seed)
    u = rng.standard_normal(free.size)
    s_pert, d_start = perturbed(u / np.linalg.norm(u))
    growth = np.empty(n_chunks)
    for i in range(n_chunks):
        s_ref, _ = problem.flow(s_ref, chunk)
        s_pert, _ = problem.flow(s_pert, chunk)
        delta = (s_pert[free] - s_ref[free]) / sigma
        d = float(np.linalg.norm(delta))
        if not np.isfinite(d) or d == 0.0:
            raise OrbitError(f"separation became {d} after chunk {i}; change d0 or seed")
        growth[i] = np.log(d / d_start)
        s_pert, d_start = perturbed(delta / d)
    time = chunk * np.arange(1, n_chunks + 1)
    estimate = np.cumsum(growth) / time
    return LyapunovResult(
        exponent=float(estimate[-1]), time=time, estimate=estimate, log_growth=growth, chunk=float(chunk),
        d0=float(d0), t_transient=float(t_transient), scale=sigma, system=problem.system,
        options=dict(problem.options, seed=seed, perturbation=perturbation),
    )


@dataclasses.dataclass(frozen=True, eq=False)
class LyapunovSpectrum(ModelResult):
    """Full Lyapunov spectrum with its convergence history.

    Parameters
    ----------
    exponents : ndarray (k,)
        λ_1 ≥ … ≥ λ_k over the whole averaging time [1/s] (k = 2 n_free). Directions that a
        stick phase collapses (v_c = 0 is dim conditions per contact) have λ = −∞ in exact arithmetic; they
        come out as large negative numbers set by round-off (~ln 1e-16 per stick phase).
    time : ndarray (n,)
        Averaging time at each record [s].
    estimate : ndarray (n, k)
        Running estimates of the exponents [1/s], columns in the order of ``exponents``.
    t_transient : float
        Discarded transient [s].
    scale : ndarray (k,)
        Scales σ of the norm [state units].
    stick_phases : int
        Slip → stick transitions during the averaging time.
    wall_time : float
        Seconds taken.
    system : FrictionModel
        The model.
    options : dict
        rtol, atol, slip_band of the runs, perturbation and method (``variational``: with record
        and qr_interval; ``finite-difference``: with chunk and d0).
    """

    exponents: np.ndarray
    time: np.ndarray
    estimate: np.ndarray
    t_transient: float
    scale: np.ndarray
    stick_phases: int
    wall_time: float
    system: FrictionModel
    options: dict

    @property
    def largest(self) -> float:
        """λ_1 [1/s]."""
        return float(self.exponents[0])

    def to_xarray(self):
        """``xarray.Dataset`` of the exponents and their convergence history."""
        import xarray as xr

        data = {
            "exponent": ("index", self.exponents, {"long_name": "Lyapunov exponent", "units": "1/s"}),
            "estimate": (("time", "index"), self.estimate,
                         {"long_name": "running estimate of the Lyapunov exponents", "units": "1/s"}),
        }
        attrs = {
            "title": "stickslip Lyapunov spectrum (variational equations, saltation matrices, QR)",
            "stickslip_version": __version__,
            "t_transient": self.t_transient,
            "stick_phases": self.stick_phases,
            "wall_time_s": self.wall_time,
            "options": json.dumps(self.options),
            **model_attrs(self.system),
        }
        coords = {"time": ("time", self.time, {"units": "s", "long_name": "averaging time"}),
                  "index": np.arange(1, self.exponents.size + 1)}
        return xr.Dataset(data, coords=coords, attrs=attrs)


def _largest_first(estimate: np.ndarray) -> np.ndarray:
    """Running estimates (n, k) with the columns ordered by their final value, largest first.

    QR keeps the columns in the order they grew (Benettin), which over a finite averaging
    time need not be the order of the exponents; the spectrum is reported sorted.
    """
    return estimate[:, np.argsort(-estimate[-1], kind="stable")]


#: Longest smooth piece between QR re-orthonormalisations [s]: growth rates of the paper's
#: cases are ≤ ~10 1/s (the fastest decaying modes, e.g. 3 1/s for N = 50 N), so the columns
#: stay within e^10 of each other and well conditioned; QR also follows every jump.
QR_INTERVAL = 1.0


def lyapunov_spectrum(
    model=None,
    ic="equilibrium",
    *,
    t_transient: float = 50.0,
    t_average: float = 200.0,
    record: float = 1.0,
    perturbation: float | None = None,
    rtol: float = 1e-10,
    atol: float | None = None,
    slip_band: float | None = None,
    method: str = "variational",
    chunk: float = 1.0,
    d0: float = DEFAULT_D0,
) -> LyapunovSpectrum:
    """All Lyapunov exponents of the attractor reached from ``ic`` (Benettin–Shimada–Nagashima).

    The variational equations with saltation matrices (:func:`.linear_flow.propagate`) carry
    an orthonormal frame (in the σ-scaled norm) along the ``event`` integrator's trajectory; it
    is re-orthonormalised by QR after every jump and at least every :data:`QR_INTERVAL`
    seconds, and λ_i = Σ ln |R_ii| / t.

    Parameters
    ----------
    model, ic, t_transient
        As :func:`lyapunov_exponent`.
    t_average : float
        Averaging time [s].
    record : float
        Interval of the running estimates in ``estimate`` [s] (≥ the QR interval is useful).
    perturbation : float, optional
        Added to φ of ``ic`` [rad]; default 1e-3 rad for ``"equilibrium"``, else none.
    rtol, atol : float
        Tolerances of the ``event`` run (``atol`` default 1e-3 · rtol).
    slip_band : float
        Low-speed band [m/s].
    method : {"variational", "finite-difference"}
        ``variational``: the variational equations with saltation matrices (above).
        ``finite-difference``: 2 n_free perturbed trajectories at distance ``d0`` around the
        reference, advanced by the ``event`` integrator chunk by chunk (τ = ``chunk``) and
        re-orthonormalised by QR after each chunk (the saltation is then inside the
        differences; needs no variational re-integration, so it also works where that one
        refuses, e.g. velocity reversals and in-band returns to v ≈ 0; directions collapsed
        by stick come out at ln(integration noise / d0) per chunk instead of −∞).
    chunk, d0 : float
        Chunk length [s] and scaled separation [-] of ``finite-difference``.

    Returns
    -------
    LyapunovSpectrum

    Raises
    ------
    OrbitError
        If a run fails or the variational re-integration does not reproduce the event sequence.
    """
    t_start = _time.perf_counter()
    if t_average <= 0.0:
        raise OrbitError(f"t_average = {t_average} s must be > 0")
    interval, option = (chunk, "chunk") if method == "finite-difference" else (record, "record")
    problem, s_ref = _after_transient(model, ic, perturbation, t_transient, rtol, atol, slip_band, t_average,
                                      interval, option)
    if method == "finite-difference":
        return _fd_spectrum(problem, s_ref, t_transient, t_average, chunk, d0, perturbation, t_start)
    if method != "variational":
        raise OrbitError(f"unknown method {method!r}; use 'variational' or 'finite-difference'")
    end, transitions = problem.flow(s_ref, t_average)
    free, sigma = problem.free, problem.sigma

    k = free.size
    D = _initial_frame(problem, s_ref)
    log_sum = np.zeros(k)
    times, sums = [0.0], [np.zeros(k)]

    def reorthonormalise(t, P):
        Q, log_r = _qr(P[free] / sigma[:, None])
        log_sum[:] += log_r
        out = np.zeros((2 * problem.system.n, k))
        out[free] = Q * sigma[:, None]
        if t - times[-1] >= record or t >= t_average:
            times.append(t)
            sums.append(log_sum.copy())
        return out

    propagate(problem.system, s_ref, t_average, transitions, end, D.copy(), scale=sigma, after=reorthonormalise,
              max_interval=QR_INTERVAL)
    time = np.array(times[1:])
    return _spectrum(problem, np.array(sums[1:]) / time[:, None], time, t_transient, stick_count(transitions), t_start,
                     dict(perturbation=perturbation, record=record, qr_interval=QR_INTERVAL, method="variational"))


#: Step [σ] of the differences that project the initial frame of the variational spectrum.
FRAME_STEP = 1e-6


def _initial_frame(problem, s_ref: np.ndarray) -> np.ndarray:
    """The variations (2n, 2 n_free) the variational spectrum starts from: σ-scaled unit vectors
    of the free states; where a contact sticks or a rigid contact is closed at ``s_ref``, projected
    as perturbed states are (:meth:`.problem.ShootingProblem.perturbed`, by differences of
    :data:`FRAME_STEP`), so the directions those constraints forbid collapse at once (exponents
    −∞, large negative numbers from round-off) instead of staying frozen (exponent 0) until an
    event collapses them."""
    free, sigma = problem.free, problem.sigma
    k = free.size
    D = np.zeros((2 * problem.system.n, k))
    D[free, np.arange(k)] = sigma
    system = problem.system
    stuck = np.any(resting_contacts(system, s_ref)[::CST] == MODE_STICK)
    closed = system.rigid and any(g[0] <= tol[0] for _, g, _, tol in rigid_gaps(system, s_ref))
    if stuck or closed:
        for j in range(k):
            D[:, j] = (problem.perturbed(s_ref, np.eye(k)[j], FRAME_STEP) - s_ref) / FRAME_STEP
    return D


def _qr(A: np.ndarray):
    """A = Q R with diag(R) ≥ 0: Q and ln |R_ii| (floored at the smallest float)."""
    Q, R = np.linalg.qr(A)
    sign = np.where(np.diag(R) < 0, -1.0, 1.0)
    return Q * sign[None, :], np.log(np.maximum(np.abs(np.diag(R)), np.finfo(float).tiny))


def _spectrum(problem, estimate, time, t_transient, stick_phases, t_start, options) -> LyapunovSpectrum:
    """The :class:`LyapunovSpectrum` of running estimates (n, k) at ``time`` (n,)."""
    estimate = _largest_first(estimate)
    return LyapunovSpectrum(
        exponents=estimate[-1].copy(), time=time, estimate=estimate, t_transient=float(t_transient),
        scale=problem.sigma, stick_phases=stick_phases, wall_time=_time.perf_counter() - t_start,
        system=problem.system, options=dict(problem.options, **options),
    )


def _fd_spectrum(problem, s_ref, t_transient, t_average, chunk, d0, perturbation, t_start) -> LyapunovSpectrum:
    """Benettin with 2 n_free perturbed trajectories and QR after every chunk (see
    :func:`lyapunov_spectrum`, ``method="finite-difference"``)."""
    n_chunks = int(round(t_average / chunk))
    if n_chunks < 1:
        raise OrbitError(f"t_average = {t_average} s is shorter than one chunk ({chunk} s)")
    free, sigma = problem.free, problem.sigma
    k = free.size
    Q = np.eye(k)
    log_sum = np.zeros(k)
    sums = np.empty((n_chunks, k))
    sticks = 0
    for i in range(n_chunks):
        starts = [problem.perturbed(s_ref, Q[:, j], d0) for j in range(k)]
        s_new, tr = problem.flow(s_ref, chunk)
        sticks += stick_count(tr)
        # columns Φ P Q_j: the chunk's flow after the projection onto v_c = 0 that a stuck
        # reference implies (part of the physical map: stick collapses those directions)
        A = np.column_stack([(problem.flow(sp, chunk)[0][free] - s_new[free]) / sigma for sp in starts]) / d0
        Q, log_r = _qr(A)
        log_sum += log_r
        sums[i] = log_sum
        s_ref = s_new
    time = chunk * np.arange(1, n_chunks + 1)
    return _spectrum(problem, sums / time[:, None], time, t_transient, sticks, t_start,
                     dict(perturbation=perturbation, method="finite-difference", chunk=chunk, d0=d0))
