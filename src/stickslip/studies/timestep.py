"""Step-size study of the paper's fixed-step methods (Sect. 4.2.1, Table 2, Figs. 5–6).

For each Δt and each of ``aeom`` and ``naeom`` the operating point of Sect. 4.2.1
(Ω = 5 rad/s, N = 50 N, μk = 0.2, Δμ = 0.1, α = 5, Table 1, Model 1, from rest) is simulated over
0–100 s; the wall time, the number of stick phases and the error of the steady state against a
converged ``event`` run are recorded. ``event`` itself is run at a few tolerances, so that the
cost of the three methods can be compared at equal accuracy.

Steady-state error measures (all over the last half of the run, the window of
``Trajectory.steady``):

``freq_error``
    |f − f_ref| / f_ref of the fundamental frequency of φ (1 if the run has come to rest).
``phi_pp_error``
    |Δφ − Δφ_ref| / Δφ_ref of the peak-to-peak amplitude of φ.
``phi_shape_error``
    RMS over one period of φ(τ) − φ_ref(τ), τ the phase from the last up-crossing of the
    reference mid level, divided by Δφ_ref: the waveform error of Figs. 5–6 with the (irrelevant)
    phase shift after 50 s of integration removed.
``F_shape_error``
    The same for |F| [N], divided by μs N.
"""

from __future__ import annotations

import dataclasses
import json
import math
import platform
import time
from pathlib import Path

import numpy as np

from .._version import __version__
from ..files import atomic_write_text
from ..integrate.driver import simulate
from ..model.parameters import Parameters

__all__ = ["PAPER_TABLE2", "DT_FULL", "DT_QUICK", "EVENT_RTOLS", "TimestepRun", "TimestepStudy",
           "run_timestep_study", "steady_errors", "period_waveform"]

#: Paper Table 2: seconds of computation for 0–100 s, (AEOM, NAEOM) per Δt [s].
PAPER_TABLE2: dict[float, tuple[float, float]] = {
    0.1: (0.08, 0.08),
    0.01: (0.49, 0.49),
    1e-3: (3.46, 958.15),
    1e-4: (31.36, 9581.69),
    1e-5: (406.53, 95814.03),
}
DT_FULL = (0.1, 0.01, 1e-3, 1e-4, 1e-5)
DT_QUICK = (0.1, 0.01, 1e-3, 1e-4)

#: Tolerances of the ``event`` rows of the comparison (relative; atol = rtol / 100).
EVENT_RTOLS = (1e-4, 1e-6, 1e-8)

#: Tolerance of the converged reference run: between rtol 1e-8 and 1e-10 the steady frequency
#: of this case agrees to 1e-9 relative and φ's amplitude to 1e-7 (measured), far below every
#: fixed-step error studied here (1e-11 ends in a step-size underflow near t = 97 s).
REFERENCE_RTOL = 1e-10

#: Points per period on which the waveforms are compared.
N_PHASE = 400

#: Length [s] of the time-history window kept per run for the figures (≈ 5 periods).
FIGURE_WINDOW = 2.0


def sect_421_parameters() -> Parameters:
    """The operating point of Sect. 4.2.1 (Table 1, Ω = 5 rad/s, N = 50 N, μk 0.2, Δμ 0.1, α 5)."""
    return Parameters(N=50.0, Omega=5.0, mu_k=0.2, delta_mu=0.1, alpha=5.0)


def period_waveform(t, x, phi, level, period, n=N_PHASE):
    """Signal ``x`` over its last full period, starting at the last but one up-crossing of φ
    through ``level``, on ``n`` points of phase τ ∈ [0, 1).

    Returns None if φ does not cross ``level`` upwards early enough (at rest, or a period longer
    than the window).
    """
    up = np.flatnonzero((phi[:-1] < level) & (phi[1:] >= level))
    if up.size == 0 or not math.isfinite(period):
        return None
    # linear interpolation of the crossing instants
    tc = t[up] + (level - phi[up]) * (t[up + 1] - t[up]) / (phi[up + 1] - phi[up])
    starts = tc[tc + period <= t[-1]]
    if starts.size == 0:
        return None
    tau = starts[-1] + period * np.arange(n) / n
    return np.interp(tau, t, x)


def steady_errors(traj, ref) -> dict:
    """Error measures of ``traj``'s steady state against ``ref`` (see the module docstring)."""
    s, r = traj.steady, ref.steady
    sel = traj.t >= s.t_from
    rsel = ref.t >= r.t_from
    phi_pp = s.maximum - s.minimum
    ref_pp = r.maximum - r.minimum
    level = 0.5 * (r.minimum + r.maximum)
    f = s.frequency_hz
    fr = r.frequency_hz
    freq_error = 1.0 if not math.isfinite(f) else abs(f - fr) / fr
    static = (traj.params.mu_k + traj.params.delta_mu) * traj.params.N
    ref_phi = period_waveform(ref.t[rsel], ref.states[rsel, 4], ref.states[rsel, 4], level, 1.0 / fr)
    ref_F = period_waveform(ref.t[rsel], ref.friction_magnitude[rsel], ref.states[rsel, 4], level, 1.0 / fr)
    phi = traj.states[sel, 4]
    F = traj.friction_magnitude[sel]
    if math.isfinite(f):
        w_phi = period_waveform(traj.t[sel], phi, phi, level, 1.0 / f)
        w_F = period_waveform(traj.t[sel], F, phi, level, 1.0 / f)
    else:
        w_phi = w_F = None
    if w_phi is None:  # at rest or no crossing of the reference level: a flat waveform
        w_phi = np.full(N_PHASE, float(phi.mean()))
        w_F = np.full(N_PHASE, float(F.mean()))
    rms = lambda a: float(np.sqrt(np.mean(a * a)))  # noqa: E731
    return {
        "freq_error": float(freq_error),
        "phi_pp_error": float(abs(phi_pp - ref_pp) / ref_pp),
        "phi_shape_error": rms(w_phi - ref_phi) / ref_pp,
        "F_shape_error": rms(w_F - ref_F) / static,
    }


@dataclasses.dataclass(frozen=True)
class TimestepRun:
    """One run of the study: its cost, steady state and errors against the reference."""

    method: str
    dt: float | None          # fixed step [s]; None for event
    rtol: float | None        # event tolerance; None for fixed-step runs
    wall_time_s: float
    steps: int
    rhs_calls: int
    stick_phases: int
    frequency_hz: float | None
    phi_min: float
    phi_max: float
    F_max: float
    stick_fraction: float
    errors: dict
    paper_time_s: float | None
    window_t: np.ndarray = dataclasses.field(repr=False, compare=False)
    window_phi: np.ndarray = dataclasses.field(repr=False, compare=False)
    window_F: np.ndarray = dataclasses.field(repr=False, compare=False)

    @property
    def ns_per_step(self) -> float:
        """Wall time per step [ns]."""
        return 1e9 * self.wall_time_s / max(self.steps, 1)

    @property
    def speed_up(self) -> float | None:
        """Paper's time / ours (None where the paper has no number)."""
        if self.paper_time_s is None or self.wall_time_s <= 0.0:
            return None
        return self.paper_time_s / self.wall_time_s

    def to_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if not f.name.startswith("window")}
        d["ns_per_step"] = self.ns_per_step
        d["speed_up_vs_paper"] = self.speed_up
        return d


@dataclasses.dataclass(frozen=True)
class TimestepStudy:
    """Result of :func:`run_timestep_study`."""

    params: Parameters
    t_end: float
    reference: TimestepRun
    runs: list
    machine: dict

    def fixed(self, method: str) -> list:
        """Fixed-step runs of ``method``, by decreasing Δt."""
        return sorted((r for r in self.runs if r.method == method), key=lambda r: -r.dt)

    def event_runs(self) -> list:
        """``event`` runs at the study tolerances, by decreasing rtol."""
        return sorted((r for r in self.runs if r.method == "event"), key=lambda r: -r.rtol)

    def to_dict(self) -> dict:
        return {
            "study": "timestep (paper Sect. 4.2.1, Table 2, Figs. 5-6)",
            "stickslip_version": __version__,
            "parameters": self.params.to_dict(),
            "t_end_s": self.t_end,
            "machine": self.machine,
            "reference": self.reference.to_dict(),
            "runs": [r.to_dict() for r in self.runs],
        }

    def markdown(self) -> str:
        """The study table beside the paper's Table 2 (Markdown)."""
        ref = self.reference
        lines = [
            f"Sect. 4.2.1 case: Ω = {self.params.Omega:g} rad/s, N = {self.params.N:g} N, μk = {self.params.mu_k:g}, "
            f"Δμ = {self.params.delta_mu:g}, α = {self.params.alpha:g}, Table 1, Model 1, 0–{self.t_end:g} s from rest. "
            f"Reference: `event`, rtol = {ref.rtol:g}: f = {ref.frequency_hz:.6f} Hz, "
            f"φ = {ref.phi_min:.6f} … {ref.phi_max:.6f} rad, {ref.stick_phases} stick phases. "
            f"Machine: {self.machine.get('processor') or self.machine.get('machine')}, one core.",
            "",
            "| method | Δt [s] / rtol | paper [s] | ours [s] | speed-up | ns/step | steps | stick phases "
            "| f error | φ p-p error | φ shape error | \\|F\\| shape error |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        ]

        def row(r, label):
            e = r.errors
            paper = "–" if r.paper_time_s is None else f"{r.paper_time_s:,.2f}"
            speed = "–" if r.speed_up is None else f"{r.speed_up:,.0f}×"
            return (f"| {r.method} | {label} | {paper} | {r.wall_time_s:.4f} | {speed} | {r.ns_per_step:,.0f} | "
                    f"{r.steps:,} | {r.stick_phases} | {e['freq_error']:.2e} | {e['phi_pp_error']:.2e} | "
                    f"{e['phi_shape_error']:.2e} | {e['F_shape_error']:.2e} |")

        for method in ("aeom", "naeom"):
            for r in self.fixed(method):
                lines.append(row(r, f"{r.dt:g}"))
        for r in self.event_runs():
            lines.append(row(r, f"rtol {r.rtol:g}"))
        return "\n".join(lines) + "\n"

    def save(self, out_dir) -> dict:
        """Write ``timestep.md`` and ``timestep.json`` into ``out_dir``; returns the paths."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        md = out / "timestep.md"
        atomic_write_text(md, self.markdown())
        js = out / "timestep.json"
        atomic_write_text(js, json.dumps(self.to_dict(), indent=2, default=_json_default))
        return {"markdown": md, "json": js}


def _json_default(value):
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def _run(params, t_end, method, *, dt=None, rtol=None):
    kw = {"dt": dt} if dt is not None else {"rtol": rtol, "atol": rtol / 100.0}
    return simulate(params, t_end, method=method, **kw)


def _summarise(traj, ref, method, dt, rtol, paper) -> TimestepRun:
    s = traj.steady
    sel = traj.t >= traj.t[-1] - FIGURE_WINDOW
    f = s.frequency_hz
    initial_stick = int(traj.mode[0] == 1)
    return TimestepRun(
        method=method, dt=dt, rtol=rtol,
        wall_time_s=float(traj.stats.wall_time_s), steps=int(traj.stats.steps), rhs_calls=int(traj.stats.rhs_calls),
        stick_phases=int(traj.stats.slip_to_stick) + initial_stick,
        frequency_hz=None if not math.isfinite(f) else float(f),
        phi_min=float(s.minimum), phi_max=float(s.maximum),
        F_max=float(traj.friction_magnitude[traj.t >= s.t_from].max()),
        stick_fraction=float(s.stick_fraction),
        errors=steady_errors(traj, ref) if ref is not None else {
            "freq_error": 0.0, "phi_pp_error": 0.0, "phi_shape_error": 0.0, "F_shape_error": 0.0},
        paper_time_s=paper,
        window_t=traj.t[sel].copy(), window_phi=traj.states[sel, 4].copy(), window_F=traj.friction_magnitude[sel].copy(),
    )


def _warm_up(params):
    """Compile every method before timing (compilation is not part of the comparison)."""
    for method in ("aeom", "naeom"):
        simulate(params, 0.01, method=method, dt=1e-3)
    simulate(params, 0.01, method="event")


def run_timestep_study(dts=DT_FULL, *, methods=("aeom", "naeom"), event_rtols=EVENT_RTOLS,
                       t_end: float = 100.0, params: Parameters | None = None,
                       reference_rtol: float = REFERENCE_RTOL, progress=None) -> TimestepStudy:
    """Run the step-size study of Sect. 4.2.1.

    Parameters
    ----------
    dts : sequence of float
        Fixed steps Δt [s] (paper: 0.1, 0.01, 1e-3, 1e-4, 1e-5).
    methods : sequence of str
        Fixed-step methods to run (``aeom``, ``naeom``).
    event_rtols : sequence of float
        Tolerances of the ``event`` comparison runs.
    t_end : float
        Simulated time [s] (paper: 100).
    params : Parameters, optional
        Default :func:`sect_421_parameters`.
    reference_rtol : float
        Tolerance of the converged ``event`` reference.
    progress : callable, optional
        Called with a one-line message after each run.

    Returns
    -------
    TimestepStudy
    """
    params = sect_421_parameters() if params is None else params
    say = progress or (lambda msg: None)
    _warm_up(params)
    ref_traj = _run(params, t_end, "event", rtol=reference_rtol)
    if ref_traj.status != "success" or not math.isfinite(ref_traj.steady.frequency_hz):
        raise RuntimeError(f"the reference event run did not give a steady oscillation ({ref_traj.status})")
    reference = _summarise(ref_traj, None, "event", None, reference_rtol, None)
    say(f"reference event rtol={reference_rtol:g}: {reference.wall_time_s:.3f} s")
    runs = []
    for method in methods:
        col = ("aeom", "naeom").index(method)
        for dt in dts:
            traj = _run(params, t_end, method, dt=dt)
            paper = PAPER_TABLE2.get(dt, (None, None))[col]
            run = _summarise(traj, ref_traj, method, float(dt), None, paper)
            runs.append(run)
            say(f"{method} dt={dt:g}: {run.wall_time_s:.3f} s, {run.stick_phases} stick phases, "
                f"f error {run.errors['freq_error']:.2e}")
    for rtol in event_rtols:
        traj = _run(params, t_end, "event", rtol=rtol)
        run = _summarise(traj, ref_traj, "event", None, float(rtol), None)
        runs.append(run)
        say(f"event rtol={rtol:g}: {run.wall_time_s:.3f} s, f error {run.errors['freq_error']:.2e}")
    machine = {"machine": platform.machine(), "processor": _cpu_name(), "python": platform.python_version(),
               "date": time.strftime("%Y-%m-%d")}
    return TimestepStudy(params=params, t_end=float(t_end), reference=reference, runs=runs, machine=machine)


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()
