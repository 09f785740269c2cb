"""What a sweep computes: the grid, the per-point simulation options, and the reduction of one run.

A point of the grid is one :func:`stickslip.simulate` run, reduced at once to a fixed-length row
of numbers (peaks, classification, frequencies, intensity, stick fraction) so that nothing of
the trajectory outlives the point and memory stays flat as the grid grows.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import time
from typing import Any, Mapping, Sequence

import numpy as np

from ..analysis.settle import ATTRACTORS, DEFAULT_CAP_S
from ..errors import StickSlipError
from ..model.parameters import Parameters
from ..model.variants import DOF_NAMES, STATE_NAMES, resolve_variant

__all__ = ["SweepSpec", "SweepError", "NAMED_ICS", "initial_condition", "COLUMNS", "evaluate", "evaluate_batch",
           "NEAR_PERTURBATION"]

#: Perturbation of φ added to the equilibrium by the ``near`` initial condition [rad]:
#: 5 % of φ_e ≈ 0.0197 rad at N = 50 N (Eq. 14), small enough to stay in the basin of a stable
#: equilibrium and large enough that an unstable one departs within a few seconds.
NEAR_PERTURBATION = 1e-3

#: Named initial conditions (Sect. 4.2.2 uses one far from and one near the equilibrium).
NAMED_ICS = {
    "zero": "plates at rest, springs undeformed (q = 0, q̇ = 0)",
    "far": "q = 0 with the upper plate carried along by the lower plate's surface (v_r = 0 at "
           "t = 0): ẏ1 = Ω r when y1 is free, else φ̇ = Ω",
    "near": f"the equilibrium of Eq. (14) with φ raised by {NEAR_PERTURBATION:g} rad",
    "equilibrium": "the equilibrium of Eq. (14) exactly",
}

_SPECIAL_DIMS = ("model", "ic")


class SweepError(StickSlipError, ValueError):
    """An invalid sweep definition, or an output that belongs to another sweep."""


def initial_condition(name: str, params: Parameters, model) -> tuple[Any, float | None]:
    """(ic, perturbation) arguments of :func:`stickslip.simulate` for a named initial condition."""
    if name == "zero":
        return "zero", None
    if name == "equilibrium":
        return "equilibrium", None
    if name == "near":
        return "equilibrium", NEAR_PERTURBATION
    if name == "far":
        free = resolve_variant(model).free
        s = np.zeros(12)
        if "y1" in free:
            # q = 0: X = r, Y = 0 and v_r = (ẋ1 − ẋ2, ẏ1 − ẏ2 + r φ̇ − Ω r) (Eq. 9) vanishes for ẏ1 = Ω r
            s[6 + DOF_NAMES.index("y1")] = params.Omega * params.r
        else:
            s[6 + DOF_NAMES.index("phi")] = params.Omega
        return s, None
    raise SweepError(f"unknown initial condition {name!r}; choose one of {', '.join(NAMED_ICS)}")


# ----------------------------------------------------------------------------- the row schema
def _columns(n_peaks: int):
    """(name, width, attrs) of each reduced quantity, in row order."""
    cols = [
        ("kind", 1, {"long_name": "steady-state kind", "flag_values": "-1 0 1 2 3",
                     "flag_meanings": "failed equilibrium periodic-slip periodic-stick-slip non-periodic",
                     "comment": "periodic only when settled (and confirmed by shooting for more than one "
                                "peak per period); non-periodic includes unsettled runs"}),
        ("attractor", 1, {"long_name": "what the run settles to", "flag_values": "-1 0 1 2 3 4 5",
                          "flag_meanings": "failed " + " ".join(ATTRACTORS)}),
        ("settled", 1, {"long_name": "the window shows the attractor (1) or a transient (0)"}),
        ("period_count", 1, {"long_name": "peaks of phi per period of a settled periodic orbit, 0 otherwise"}),
        ("period", 1, {"units": "s", "long_name": "period of a settled periodic orbit (return map of the peaks of phi)"}),
        ("fundamental_frequency", 1, {"units": "Hz",
                                      "long_name": "fundamental frequency 1/period of a settled periodic orbit"}),
        ("frequency", 1, {"units": "Hz", "long_name": "1/period when the peaks of phi repeat, else their mean rate"}),
        ("dominant_frequency", 1, {"units": "Hz", "long_name": "highest peak of the amplitude spectrum of phi"}),
        ("settle_time", 1, {"units": "s", "long_name": "simulated time by which the run was seen settled"}),
        ("stick_fraction", 1, {"units": "1", "long_name": "fraction of the steady window in stick"}),
        ("n_transitions", 1, {"long_name": "stick-slip transitions in the steady window"}),
        ("amplitude", 1, {"units": "rad", "long_name": "peak-to-peak phi in the steady window"}),
        ("phi_min", 1, {"units": "rad", "long_name": "minimum of phi in the steady window"}),
        ("phi_max", 1, {"units": "rad", "long_name": "maximum of phi in the steady window"}),
        ("phi_mean", 1, {"units": "rad", "long_name": "time mean of phi in the steady window"}),
        ("n_peaks", 1, {"long_name": "peaks of phi found in the steady window"}),
        ("intensity_r_phi", 1, {"units": "m s-1/2", "long_name": "intensity index I of r*phi, Eq. (16)"}),
        ("intensity_x1", 1, {"units": "m s-1/2", "long_name": "intensity index I of x1, Eq. (16)"}),
        ("intensity_y1", 1, {"units": "m s-1/2", "long_name": "intensity index I of y1, Eq. (16)"}),
        ("intensity_translation", 1, {"units": "m s-1/2",
                                      "long_name": "intensity index I of the translation (x1, y1), Eq. (16)"}),
        ("angle_min", 1, {"units": "degree", "long_name": "minimum angle of v_r against the circumferential direction (Fig. 11)"}),
        ("angle_max", 1, {"units": "degree", "long_name": "maximum angle of v_r against the circumferential direction (Fig. 11)"}),
        ("t_reached", 1, {"units": "s", "long_name": "time the run reached (t_end, or the settle time or cap "
                                                     "when settling, unless it failed)"}),
        ("steps", 1, {"long_name": "integration steps (accepted + rejected)"}),
        ("wall_time", 1, {"units": "s", "long_name": "wall time of the point (simulation and reduction)"}),
        ("peaks", n_peaks, {"units": "rad", "long_name": "last peak values of phi in the steady window (events dphi = 0)"}),
    ]
    return cols


#: Columns of the default schema (64 peaks), for reference.
COLUMNS = tuple(c[0] for c in _columns(64))

#: Columns that depend on the machine, not on the computation; excluded from identity checks.
TIMING_COLUMNS = ("wall_time",)


@dataclasses.dataclass(frozen=True)
class SweepSpec:
    """A sweep: the grid and the options of each run.

    Attributes
    ----------
    dims : tuple of (name, tuple of values)
        Swept dimensions in order. A name is a :class:`~stickslip.Parameters` field, ``model``
        (values: model names), ``ic`` (values: :data:`NAMED_ICS`), or ``perturb_<state>`` (added
        to that state of the initial condition, e.g. ``perturb_phi`` [rad]).
    params : dict
        Base parameters (:meth:`Parameters.to_dict`).
    model, ic : str
        Defaults when not swept.
    t_end, t_from : float
        Run length and start of the steady window [s]. When settling: the first run's length
        and the start of its window; the window length t_end − t_from is also the step.
    settle : bool
        Extend each run from its final state until it has settled or reaches ``cap``
        (:func:`stickslip.analysis.settle.simulate_until_settled`).
    cap : float
        Longest run when settling [s].
    confirm : bool
        Confirm a period of more than one peak by shooting and chaos or a torus by the largest
        Lyapunov exponent (:func:`stickslip.analysis.settle.attractor`); without it no such
        claim is made.
    sample_rate : float
        Output samples per second of each run [Hz].
    rtol, atol : float
        Tolerances of the ``event`` method.
    max_steps : int
        Step cap per run: a run that stalls fails fast and is recorded as ``failed``.
    n_peaks : int
        Number of (last) peak values kept per point.
    method : str
        Integration method.
    """

    dims: tuple
    params: dict
    model: str = "full"
    ic: str = "zero"
    t_end: float = 200.0
    t_from: float = 100.0
    settle: bool = False
    cap: float = DEFAULT_CAP_S
    confirm: bool = True
    sample_rate: float = 200.0
    rtol: float = 1e-8
    atol: float = 1e-10
    max_steps: int = 5_000_000
    n_peaks: int = 64
    method: str = "event"

    @classmethod
    def build(cls, grid: Mapping[str, Sequence], params: Parameters | None = None, *, t_end: float = 200.0,
              t_from: float | None = None, **options) -> "SweepSpec":
        """Validate a grid ``{name: values}`` and options into a spec (see the attributes)."""
        params = Parameters() if params is None else params
        if not isinstance(params, Parameters):
            raise SweepError(f"params must be a stickslip.Parameters, got {type(params).__name__}")
        if not grid:
            raise SweepError("the grid is empty; give at least one dimension, e.g. {'N': [30, 50, 70]}")
        fields = {f.name for f in dataclasses.fields(Parameters)} - {"friction_law"}
        dims = []
        for name, values in grid.items():
            values = list(np.atleast_1d(np.asarray(values, dtype=object)))
            if not values:
                raise SweepError(f"dimension {name!r} has no values")
            if name in _SPECIAL_DIMS:
                values = [str(v) for v in values]
                for v in values:
                    if name == "ic" and v not in NAMED_ICS:
                        raise SweepError(f"ic value {v!r} unknown; choose from {', '.join(NAMED_ICS)}")
                    if name == "model":
                        resolve_variant(v)
            elif name in fields or (name.startswith("perturb_") and name[8:] in STATE_NAMES):
                try:
                    values = [float(v) for v in values]
                except (TypeError, ValueError):
                    raise SweepError(f"dimension {name!r} needs numbers, got {values!r}") from None
                if not all(math.isfinite(v) for v in values):
                    raise SweepError(f"dimension {name!r} has non-finite values")
                if name in fields:
                    params.replace(**{name: values[0]})  # validates (e.g. N > 0) before any run
                    params.replace(**{name: values[-1]})
            else:
                raise SweepError(
                    f"cannot sweep {name!r}: give a parameter ({', '.join(sorted(fields))}), 'model', 'ic' "
                    f"or perturb_<state> with state one of {', '.join(STATE_NAMES)}"
                )
            if len(set(values)) != len(values):
                raise SweepError(f"dimension {name!r} repeats a value")
            dims.append((name, tuple(values)))
        t_end = float(t_end)
        t_from = 0.5 * t_end if t_from is None else float(t_from)
        if not 0.0 <= t_from < t_end:
            raise SweepError(f"t_from = {t_from} s must lie in [0, t_end = {t_end} s)")
        model = str(options.pop("model", "full"))
        resolve_variant(model)
        ic = str(options.pop("ic", "zero"))
        if ic not in NAMED_ICS:
            raise SweepError(f"ic {ic!r} unknown; choose from {', '.join(NAMED_ICS)}")
        spec = cls(dims=tuple(dims), params=params.to_dict(), model=model, ic=ic, t_end=t_end, t_from=t_from, **options)
        if spec.n_peaks < 1:
            raise SweepError("n_peaks must be >= 1")
        if spec.sample_rate * (t_end - t_from) < 8:
            raise SweepError("the steady window holds fewer than 8 samples; raise sample_rate or t_end")
        if not (math.isfinite(spec.cap) and spec.cap >= t_end):
            raise SweepError(f"cap = {spec.cap} s must be a finite number ≥ t_end = {t_end} s")
        return spec

    # ---------------------------------------------------------------- geometry of the grid
    @property
    def names(self) -> tuple[str, ...]:
        return tuple(d[0] for d in self.dims)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(d[1]) for d in self.dims)

    @property
    def size(self) -> int:
        return int(np.prod(self.shape))

    @property
    def columns(self):
        return _columns(self.n_peaks)

    @property
    def row_width(self) -> int:
        return sum(c[1] for c in self.columns)

    def point(self, flat_index: int) -> dict:
        """The swept values at a flat (C-order) index."""
        idx = np.unravel_index(int(flat_index), self.shape)
        return {name: values[i] for (name, values), i in zip(self.dims, idx)}

    def to_json(self) -> str:
        d = dataclasses.asdict(self)
        d["dims"] = [[n, list(v)] for n, v in self.dims]
        return json.dumps(d, sort_keys=True)

    @classmethod
    def from_json(cls, text: str) -> "SweepSpec":
        d = json.loads(text)
        d["dims"] = tuple((n, tuple(v)) for n, v in d["dims"])
        return cls(**d)

    @property
    def digest(self) -> str:
        """Hash of everything that determines the results."""
        return hashlib.sha256(self.to_json().encode()).hexdigest()[:16]


# ----------------------------------------------------------------------------- one point
def evaluate(spec: SweepSpec, flat_index: int) -> np.ndarray:
    """Simulate one grid point and reduce it to a row of :attr:`SweepSpec.row_width` numbers."""
    from ..analysis.classify import kind_code
    from ..analysis.intensity import angle_range, trajectory_intensities
    from ..analysis.settle import attractor, simulate_until_settled
    from ..integrate.driver import SimulationError, simulate
    from ..integrate.status import Status

    start = time.perf_counter()
    values = spec.point(flat_index)
    changes = {k: v for k, v in values.items() if k not in _SPECIAL_DIMS and not k.startswith("perturb_")}
    params = Parameters.from_dict(spec.params).replace(**changes) if changes else Parameters.from_dict(spec.params)
    model = values.get("model", spec.model)
    ic, pert = initial_condition(values.get("ic", spec.ic), params, model)
    deltas = {k[8:]: v for k, v in values.items() if k.startswith("perturb_")}
    if deltas:
        vec = np.zeros(12)
        if pert is not None:
            vec[4] += pert
        for name, v in deltas.items():
            vec[STATE_NAMES.index(name)] += v
        pert = vec
    out = {name: math.nan for name, _, _ in spec.columns}
    peaks = np.full(spec.n_peaks, math.nan)
    run = dict(model=model, method=spec.method, ic=ic, perturbation=pert, rtol=spec.rtol, atol=spec.atol,
               sample_rate=spec.sample_rate, max_steps=spec.max_steps)
    try:
        if spec.settle:
            window = spec.t_end - spec.t_from
            traj = simulate_until_settled(params, cap=spec.cap, t_min=spec.t_end, window=window, step=window,
                                          keep="window", confirm=spec.confirm, lyapunov=spec.confirm, **run)
        else:
            traj = simulate(params, spec.t_end, steady_from=spec.t_from, **run)
    except SimulationError:
        traj = None
    if traj is not None and traj.status_code == Status.INTERRUPTED:
        raise KeyboardInterrupt  # Ctrl-C: the point is not done (the journal keeps the others; resume redoes it)
    if traj is not None:
        out["t_reached"] = float(traj.t[-1])
        out["steps"] = float(traj.stats.steps)
    if traj is None or traj.status != "success":
        out["kind"] = -1.0
        unbounded = traj is not None and traj.attractor.attractor == "unbounded"
        out["attractor"] = float(traj.attractor.code) if unbounded else -1.0
    else:
        verdict = traj.attractor if spec.settle else attractor(traj, confirm=spec.confirm, lyapunov=spec.confirm)
        c = verdict.classification
        t_from = traj.steady_from
        sel = traj.t >= t_from
        phi = traj.states[sel, 4]
        out.update(kind=float(kind_code(verdict.kind)), attractor=float(verdict.code), settled=float(verdict.settled),
                   period_count=float(verdict.period_count or 0), period=verdict.period_s,
                   fundamental_frequency=_nan(verdict.fundamental_frequency_hz), frequency=c.frequency_hz,
                   dominant_frequency=_nan(verdict.dominant_frequency_hz),
                   settle_time=_nan(verdict.settle_time_s), stick_fraction=c.stick_fraction, amplitude=c.amplitude,
                   phi_min=float(phi.min()), phi_max=float(phi.max()),
                   phi_mean=float(np.sum(0.5 * (phi[1:] + phi[:-1]) * np.diff(traj.t[sel])) / (traj.t[sel][-1] - traj.t[sel][0])),
                   n_peaks=float(len(c.peaks)))
        tt = traj.transitions.time
        out["n_transitions"] = float(np.sum((tt > t_from) & (tt <= traj.t[-1])))
        for key, val in trajectory_intensities(traj, t_from).items():
            out[f"intensity_{key}"] = val
        out["angle_min"], out["angle_max"] = angle_range(traj, t_from)
        last = c.peaks.value[-spec.n_peaks:]
        peaks[: last.size] = last
    out["wall_time"] = time.perf_counter() - start
    row = np.empty(spec.row_width)
    j = 0
    for name, width, _ in spec.columns:
        row[j : j + width] = peaks if name == "peaks" else out[name]
        j += width
    return row


def _nan(x) -> float:
    return math.nan if x is None else float(x)


def evaluate_batch(spec: SweepSpec, indices) -> tuple[np.ndarray, np.ndarray]:
    """(indices, rows) of a batch of flat indices; module-level so executors can pickle it."""
    indices = np.asarray(indices, dtype=np.int64)
    rows = np.empty((indices.size, spec.row_width))
    for k, i in enumerate(indices):
        rows[k] = evaluate(spec, int(i))
    return indices, rows


def warm_up(spec: SweepSpec | None = None) -> float:
    """Prepare a worker process: compile or load the numba kernels (a 10 ms run) and import the
    analysis that :func:`evaluate` uses (~0.5 s of imports that would otherwise land on the
    first point of every worker). Returns the seconds taken."""
    from ..analysis import classify, intensity  # noqa: F401
    from ..integrate.driver import simulate
    from ..stability import equilibrium  # noqa: F401  (imported by the intensity of each point)

    start = time.perf_counter()
    simulate(None, 0.01, sample_rate=1000.0)
    return time.perf_counter() - start
