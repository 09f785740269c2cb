"""What a sweep computes: the grid, the per-point simulation options, and the reduction of one run.

A point of the grid is one :func:`stickslip.simulate` run, reduced at once to a fixed-length row
of numbers (peaks, classification, frequencies, intensity, stick fraction) so that nothing of
the trajectory outlives the point and memory stays flat as the grid grows.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import math
import time
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from ..analysis.intensity import angle_range, intensity, trajectory_intensities
from ..analysis.outcome import outcome_code, outcome_flags
from ..analysis.signal import OPEN, SLIP, STICK
from ..attractors import DEFAULT_CAP_S, attractor, simulate_until_settled
from ..errors import EquilibriumError, SimulationError, SweepError
from ..integrate.driver import simulate
from ..integrate.initial import NAMED_STARTS, NEAR_PERTURBATION, start_names
from ..integrate.status import Status
from ..model.library import describe_system, resolve_model, system_from_description, two_plates
from ..model.library.two_plates import is_plates, plates_parameters
from ..model.parameters import Parameters
from ..model.system_model import DEFAULT_SLIP_BAND, FrictionModel
from ..model.variants import resolve_variant
from ..stability.equilibrium import steady_sliding

__all__ = ["SweepSpec", "SweepError", "NAMED_ICS", "initial_condition", "COLUMNS", "evaluate", "evaluate_batch",
           "NEAR_PERTURBATION", "spec_system", "observed_columns", "columns_of"]

#: Named initial conditions: those of every model, then the plates' own (``far``; a model's own
#: starts are in ``FrictionModel.starts``).
NAMED_ICS = {**NAMED_STARTS, **{k: v.description for k, v in two_plates().starts.items()}}

#: Dimensions that are not numeric parameters: ``model`` (the variants of a model that has them,
#: the plates' Models 1-4) and ``ic`` (named initial conditions).
_SPECIAL_DIMS = ("model", "ic")


def initial_condition(name: str, system: FrictionModel) -> tuple[Any, float | None]:
    """(ic, perturbation) arguments of :func:`stickslip.simulate` for the named initial condition
    ``name`` of ``system`` (:func:`stickslip.integrate.initial.start_names`)."""
    if name not in start_names(system):
        raise SweepError(f"unknown initial condition {name!r} of model {system.name!r}; choose one of "
                         f"{', '.join(start_names(system))}")
    if name == "near":
        return "equilibrium", NEAR_PERTURBATION
    if name in NAMED_STARTS:
        return name, None
    return system.starts[name].state.copy(), None


# ----------------------------------------------------------------------------- the row schema
#: Attributes of a sweep's ``attractor`` variable: the outcome of each point's run.
ATTRACTOR_ATTRS = {"long_name": "what the run settles to (its outcome)", **outcome_flags(),
                   "comment": "periodic only when settled (and confirmed by shooting for more than one peak per "
                              "period); an oscillation with stick_fraction > 0 is stick-slip"}


def _columns(n_peaks: int, observed: str = "phi", plates: bool = True, unit: str = "rad", unilateral: bool = False):
    """(name, width, attrs) of each reduced quantity, in row order.

    ``observed``: the model's observed coordinate (the plates' φ), which the ``<observed>_min``,
    ``_max``, ``_mean``, ``amplitude`` and ``peaks`` columns follow, in ``unit``. ``plates``: the
    plates' own reductions (the intensities of Eq. 16 and the sliding angles of Fig. 11); other
    models get one ``intensity`` of the observed coordinate instead. ``unilateral``: the model has
    contacts that open and close, and gets ``open_fraction`` and ``openings`` after
    ``n_transitions``.
    """
    cols = [
        ("attractor", 1, ATTRACTOR_ATTRS),
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
    if unilateral:
        at = [name for name, _, _ in cols].index("n_transitions") + 1
        cols[at:at] = [
            ("open_fraction", 1, {"units": "1", "long_name": "fraction of the steady window with some contact open"}),
            ("openings", 1, {"long_name": "contact openings (closed to open) in the steady window"}),
        ]
    if plates and observed == "phi":
        return cols
    plates_only = ("intensity_r_phi", "intensity_x1", "intensity_y1", "intensity_translation", "angle_min", "angle_max")
    out = []
    for name, width, attrs in cols:
        if name in plates_only and not plates:
            if name == "intensity_r_phi":
                out.append(("intensity", 1, {"long_name": f"intensity index I of {observed} about steady sliding, "
                                                          "Eq. (16)", "comment": "unit of the coordinate times s-1/2"}))
            continue
        attrs = dict(attrs)
        for key in ("long_name", "comment"):
            if key in attrs and name not in plates_only:
                attrs[key] = attrs[key].replace("phi", observed)
        if name in ("amplitude", "phi_min", "phi_max", "phi_mean", "peaks"):
            attrs.pop("units", None)
            if unit:
                attrs["units"] = unit
            attrs["coordinate"] = observed
            name = name.replace("phi", observed) if name.startswith("phi_") else name
        out.append((name, width, attrs))
    return out


def columns_of(system: FrictionModel, n_peaks: int = 64):
    """(name, width, attrs) of each reduced quantity of a sweep of ``system``, in row order."""
    observed = system.dofs[system.observed_index]
    return _columns(n_peaks, observed, is_plates(system), system.units.get(observed, ""), system.unilateral)


def observed_columns(observed: str) -> tuple[str, str, str]:
    """The names of the minimum, maximum and mean columns of the observed coordinate."""
    return f"{observed}_min", f"{observed}_max", f"{observed}_mean"


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
        Swept dimensions in order. A name is a numeric parameter of the model (the plates'
        ``N``, a model file's ``contact.0.drive``), ``model`` (values: variants of a model that
        has them, the plates' ``full`` … ``rotation``), ``ic`` (values: named starts of the model,
        :func:`stickslip.integrate.initial.start_names`), or ``perturb_<state>`` (added to that
        state of the initial condition, e.g. ``perturb_phi`` [rad]).
    params : dict
        Base parameters of the model (``FrictionModel.parameters``).
    model : str
        How results name the model (the plates' variant, else the model's name).
    ic : str
        Initial condition when not swept.
    t_end, t_from : float
        Run length and start of the steady window [s]. When settling: the first run's length
        and the start of its window; the window length t_end − t_from is also the step.
    settle : bool
        Extend each run from its final state until it has settled or reaches ``cap``
        (:func:`stickslip.attractors.simulate_until_settled`).
    cap : float
        Longest run when settling [s].
    confirm : bool
        Confirm a period of more than one peak by shooting and chaos or a torus by the largest
        Lyapunov exponent (:func:`stickslip.attractors.attractor`); without it no such
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
    system : dict or None
        The model, as :func:`~stickslip.model.library.describe_system` writes it (every worker
        rebuilds it: :func:`spec_system`); None for the plates, which ``params`` and ``model``
        (their variant) describe.
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
    system: dict | None = None

    @classmethod
    def build(cls, grid: Mapping[str, Sequence], model=None, *, t_end: float = 200.0,
              t_from: float | None = None, **options) -> "SweepSpec":
        """Validate a grid ``{name: values}`` and options into a spec (see the attributes).

        ``model``: as :func:`stickslip.simulate` takes it (default the plates with Table 1).
        """
        system = _resolve_model(model)
        fields = {k for k, v in system.parameters.items() if not isinstance(v, (str, bool))}
        states = system.state_names
        if not grid:
            raise SweepError("the grid is empty; give at least one dimension, e.g. {'N': [30, 50, 70]}")
        dims = []
        for name, values in grid.items():
            values = list(np.atleast_1d(np.asarray(values, dtype=object)))
            if not values:
                raise SweepError(f"dimension {name!r} has no values")
            if name not in _SPECIAL_DIMS and not name.startswith("perturb_"):
                name = _canonical(system, name)
            if name in _SPECIAL_DIMS:
                values = [str(v) for v in values]
                for v in values:
                    if name == "ic":
                        initial_condition(v, system)
                    if name == "model":
                        if "variant" not in system.parameters:
                            raise SweepError(f"cannot sweep 'model' with model {system.name!r}: it has no variants "
                                             "(the plates' full, x, y, rotation); run one sweep per model")
                        resolve_variant(v)
            elif name in fields or (name.startswith("perturb_") and name[8:] in states):
                try:
                    values = [float(v) for v in values]
                except (TypeError, ValueError):
                    raise SweepError(f"dimension {name!r} needs numbers, got {values!r}") from None
                if not all(math.isfinite(v) for v in values):
                    raise SweepError(f"dimension {name!r} has non-finite values")
                if name in fields:  # validates (e.g. N > 0) before any run
                    for v in (values[0], values[-1]):
                        system.replace(**{name: v})
            else:
                special = "'model', 'ic'" if "variant" in system.parameters else "'ic'"
                raise SweepError(
                    f"cannot sweep {name!r}: give a parameter ({', '.join(sorted(fields))}), {special} "
                    f"or perturb_<state> with state one of {', '.join(states)}"
                )
            if len(set(values)) != len(values):
                raise SweepError(f"dimension {name!r} repeats a value")
            dims.append((name, tuple(values)))
        t_end = float(t_end)
        t_from = 0.5 * t_end if t_from is None else float(t_from)
        if not 0.0 <= t_from < t_end:
            raise SweepError(f"t_from = {t_from} s must lie in [0, t_end = {t_end} s)")
        ic = str(options.pop("ic", "zero"))
        initial_condition(ic, system)
        spec = cls(dims=tuple(dims), ic=ic, t_end=t_end, t_from=t_from, **_described(system), **options)
        if spec.n_peaks < 1:
            raise SweepError("n_peaks must be >= 1")
        if spec.sample_rate * (t_end - t_from) < 8:
            raise SweepError("the steady window holds fewer than 8 samples; raise sample_rate or t_end")
        if spec.settle and not (math.isfinite(spec.cap) and spec.cap >= t_end):
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
        return columns_of(spec_system(self), self.n_peaks)

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
        if d["system"] is None:  # the plates (:func:`_described`): the spec and digest of earlier versions
            del d["system"]
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


def _described(system: FrictionModel) -> dict:
    """``params``, ``model`` and ``system`` of a spec of ``system``. The plates with their default
    slip band are described by their Parameters and variant alone (``system`` None): the specs and
    digests of the plates' sweeps do not depend on how the model is stated in code."""
    if is_plates(system) and system.slip_band == DEFAULT_SLIP_BAND:
        return dict(params=plates_parameters(system).to_dict(), model=system.label, system=None)
    return dict(params=dict(system.parameters), model=system.label or system.name, system=describe_system(system))


def _resolve_model(model) -> FrictionModel:
    """The model of a sweep (as :func:`stickslip.simulate` takes it), one its workers can rebuild."""
    if model is not None and not isinstance(model, (Parameters, FrictionModel, str, Path)):
        raise SweepError(f"model must be a FrictionModel, the plates' Parameters or a model's name, got "
                         f"{type(model).__name__}")
    system = resolve_model(model)
    if system.builder is None or (system.spec is None and system.source == "python"):
        raise SweepError(f"model {system.name!r} was defined in Python and cannot be rebuilt by the sweep's workers; "
                         "state it as a model file (.toml)")
    return system


def _canonical(system, name: str) -> str:
    """The model's own name of a parameter path (``stiffness.x.x`` → ``stiffness.0.0``)."""
    try:
        return system.resolver(name) if system.resolver is not None else name
    except Exception:  # an unknown path is reported with the valid names below
        return name


@functools.lru_cache(maxsize=8)
def _system_from_json(text: str):
    return system_from_description(json.loads(text))


def spec_system(spec: "SweepSpec") -> FrictionModel:
    """The model of a sweep (rebuilt once per process)."""
    if spec.system is None:  # the plates (:func:`_described`)
        return _plates_from_json(json.dumps(spec.params, sort_keys=True), spec.model)
    return _system_from_json(json.dumps(spec.system, sort_keys=True))


@functools.lru_cache(maxsize=8)
def _plates_from_json(params: str, variant: str):
    return two_plates(Parameters.from_dict(json.loads(params)), variant)


# ----------------------------------------------------------------------------- one point
def evaluate(spec: SweepSpec, flat_index: int) -> np.ndarray:
    """Simulate one grid point and reduce it to a row of :attr:`SweepSpec.row_width` numbers."""
    start = time.perf_counter()
    values = spec.point(flat_index)
    changes = {k: v for k, v in values.items() if k not in _SPECIAL_DIMS and not k.startswith("perturb_")}
    if "model" in values:
        changes["variant"] = values["model"]
    base = spec_system(spec)
    system = base.replace(**changes) if changes else base
    ic, pert = initial_condition(values.get("ic", spec.ic), system)
    n, observed, state_names = system.n, system.observed_index, system.state_names
    deltas = {k[8:]: v for k, v in values.items() if k.startswith("perturb_")}
    if deltas:
        vec = np.zeros(2 * n)
        if pert is not None:
            vec[observed] += pert
        for name, v in deltas.items():
            vec[state_names.index(name)] += v
        pert = vec
    out = {name: math.nan for name, _, _ in spec.columns}
    peaks = np.full(spec.n_peaks, math.nan)
    run = dict(method=spec.method, ic=ic, perturbation=pert, rtol=spec.rtol, atol=spec.atol,
               sample_rate=spec.sample_rate, max_steps=spec.max_steps)
    try:
        if spec.settle:
            window = spec.t_end - spec.t_from
            settled = simulate_until_settled(system, cap=spec.cap, t_min=spec.t_end, window=window, step=window,
                                             keep="window", confirm=spec.confirm, lyapunov=spec.confirm, **run)
            traj, verdict = settled.trajectory, settled.attractor
        else:
            traj = simulate(system, spec.t_end, steady_from=spec.t_from, **run)
            verdict = None
    except SimulationError:
        traj = verdict = None
    if traj is not None and traj.status_code == Status.INTERRUPTED:
        raise KeyboardInterrupt  # Ctrl-C: the point is not done (the journal keeps the others; resume redoes it)
    if traj is not None:
        out["t_reached"] = float(traj.t[-1])
        out["steps"] = float(traj.stats.steps)
    if traj is None or traj.status != "success":  # the run stopped early: unbounded, contact-lost or failed
        verdict = None if traj is None else verdict or attractor(traj, confirm=spec.confirm, lyapunov=spec.confirm)
        out["attractor"] = float(outcome_code("failed") if verdict is None else verdict.code)
    else:
        verdict = verdict or attractor(traj, confirm=spec.confirm, lyapunov=spec.confirm)
        c = verdict.classification
        t_from = traj.steady_from
        sel = traj.t >= t_from
        x = traj.states[sel, observed]
        x_min, x_max, x_mean = observed_columns(system.dofs[observed])
        out.update(attractor=float(verdict.code), settled=float(verdict.settled),
                   period_count=float(verdict.period_count or 0), period=verdict.period_s,
                   fundamental_frequency=_nan(verdict.fundamental_frequency_hz),
                   frequency=c.frequency_hz if c.outcome == "periodic" else c.peak_rate_hz,
                   dominant_frequency=_nan(verdict.dominant_frequency_hz),
                   settle_time=_nan(verdict.settle_time_s), stick_fraction=c.stick_fraction, amplitude=c.amplitude,
                   n_peaks=float(len(c.peaks)))
        out[x_min], out[x_max] = float(x.min()), float(x.max())
        out[x_mean] = float(np.sum(0.5 * (x[1:] + x[:-1]) * np.diff(traj.t[sel])) / (traj.t[sel][-1] - traj.t[sel][0]))
        tt = traj.transitions.time
        window = (tt > t_from) & (tt <= traj.t[-1])
        out["n_transitions"] = float(np.sum(window & ((traj.transitions.kind == STICK) | (traj.transitions.kind == SLIP))))
        if system.unilateral:
            out["open_fraction"] = traj.steady_state(t_from).open_fraction
            out["openings"] = float(np.sum(window & (traj.transitions.kind == OPEN)))
        if is_plates(system):  # the plates' own reductions (Eq. 16, Fig. 11)
            for key, val in trajectory_intensities(traj, t_from).items():
                out[f"intensity_{key}"] = val
            out["angle_min"], out["angle_max"] = angle_range(traj, t_from)
        else:
            out["intensity"] = _observed_intensity(traj, system, observed, t_from)
        last = c.peaks.value[-spec.n_peaks:]
        peaks[: last.size] = last
    out["wall_time"] = time.perf_counter() - start
    row = np.empty(spec.row_width)
    j = 0
    for name, width, _ in spec.columns:
        row[j : j + width] = peaks if name == "peaks" else out[name]
        j += width
    return row


def _observed_intensity(traj, system, observed: int, t_from: float) -> float:
    """Eq. (16) of the observed coordinate about its steady-sliding value (NaN without one)."""
    try:
        q_e = steady_sliding(system)[observed]
    except EquilibriumError:
        return math.nan
    return intensity(traj.t, traj.states[:, observed], q_e, t_from=t_from)


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
    """Prepare a worker process: compile or load the numba kernels (a 10 ms run), which would
    otherwise land on the first point of every worker. Returns the seconds taken."""
    start = time.perf_counter()
    simulate(None, 0.01, sample_rate=1000.0)
    return time.perf_counter() - start
