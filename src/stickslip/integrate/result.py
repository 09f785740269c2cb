"""Typed, self-describing simulation results with NetCDF round trip."""

from __future__ import annotations

from ..errors import StickSlipError

import dataclasses
import json
from functools import cached_property
from pathlib import Path

import numpy as np
from numba import njit

from .. import __version__
from ..analysis.steady import SteadyState, summarize
from ..model import kernels
from ..model.parameters import Parameters, parameter_attrs
from ..model.system import assemble
from ..model.variants import STATE_NAMES, resolve_variant

__all__ = ["Stats", "Transitions", "Trajectory", "load_trajectory", "FileFormatError"]

FORMAT = "stickslip-trajectory-1"

_STATE_UNITS = ("m", "m", "m", "m", "rad", "rad", "m/s", "m/s", "m/s", "m/s", "rad/s", "rad/s")
_STATE_LONG_NAMES = (
    "upper plate x displacement", "upper plate y displacement",
    "lower plate x displacement", "lower plate y displacement",
    "upper plate rotation phi", "lower plate rotation psi (relative to Omega t)",
) + tuple(f"velocity of {n}" for n in STATE_NAMES[:6])


class FileFormatError(StickSlipError, ValueError):
    """A file that is not a stickslip result."""


@dataclasses.dataclass(frozen=True)
class Stats:
    """Integrator statistics.

    ``wall_time_s`` is the integration alone; ``compile_time_s`` the one-off JIT compilation
    (or cache load) of the kernels when this run was the first in the process, else 0.
    """

    accepted_steps: int = 0
    rejected_steps: int = 0
    rhs_calls: int = 0
    retaken_steps: int = 0
    slip_to_stick: int = 0
    stick_to_slip: int = 0
    wall_time_s: float = 0.0
    compile_time_s: float = 0.0

    @property
    def steps(self) -> int:
        """Accepted plus rejected steps."""
        return self.accepted_steps + self.rejected_steps


@dataclasses.dataclass(frozen=True)
class Transitions:
    """Exact stick↔slip transition instants.

    Attributes
    ----------
    time : ndarray (k,)
        Instants [s].
    kind : ndarray (k,) int8
        +1 slip → stick, −1 stick → slip.
    state : ndarray (k, 12)
        States at the transitions (after projection when entering stick).
    """

    time: np.ndarray
    kind: np.ndarray
    state: np.ndarray

    def __len__(self) -> int:
        return int(self.time.size)


@njit(cache=True)
def _series(states, p):
    """v_r (n, 2) and the sliding angle (n,) at each sample."""
    n = states.shape[0]
    vr = np.empty((n, 2))
    ang = np.empty(n)
    for i in range(n):
        vx, vy = kernels.relative_velocity(states[i], p)
        vr[i, 0] = vx
        vr[i, 1] = vy
        ang[i] = kernels.sliding_angle(states[i], p)
    return vr, ang


@dataclasses.dataclass(frozen=True, eq=False)
class Trajectory:
    """Result of :func:`stickslip.simulate`.

    Attributes
    ----------
    t : ndarray (n,)
        Uniform sample times [s].
    states : ndarray (n, 12)
        s = [x1, y1, x2, y2, φ, ψ, and their rates] [m, rad, m/s, rad/s].
    mode : ndarray (n,) int8
        1 in stick, 0 in slip.
    friction : ndarray (n, 2)
        Friction force on the upper plate (Fx, Fy) [N].
    work : ndarray (n, 2)
        Work done since t0 by friction on the plates and by the dampers [J].
    transitions : Transitions
    stats : Stats
    status : str
        ``"success"`` or the reason the run stopped early.
    params : Parameters
    model : str
    method : str
    options : dict
        rtol, atol, dt, sample_rate, ic.
    steady_from : float
        Start of the steady-state window used by :attr:`steady` [s].
    """

    t: np.ndarray
    states: np.ndarray
    mode: np.ndarray
    friction: np.ndarray
    work: np.ndarray
    transitions: Transitions
    stats: Stats
    status: str
    params: Parameters
    model: str
    method: str
    options: dict
    steady_from: float

    # ------------------------------------------------------------- derived series
    @cached_property
    def _vr_angle(self):
        return _series(np.ascontiguousarray(self.states), assemble(self.params, self.model).p)

    @property
    def relative_velocity(self) -> np.ndarray:
        """v_r (n, 2), Eq. (9) [m/s]."""
        return self._vr_angle[0]

    @property
    def sliding_angle_deg(self) -> np.ndarray:
        """Angle of v_r against the circumferential direction −e_n2 [deg], NaN in stick."""
        return np.degrees(self._vr_angle[1])

    @property
    def friction_magnitude(self) -> np.ndarray:
        """|F| (n,) [N]."""
        return np.hypot(self.friction[:, 0], self.friction[:, 1])

    @property
    def mechanical_energy(self) -> np.ndarray:
        """½ q̇ᵀ M q̇ + ½ qᵀ K q of the free DOFs (n,) [J]."""
        system = assemble(self.params, self.model)
        mass = np.where(system.variant.mask, system.mass, 0.0)  # locked DOFs: q̇ = 0, no energy
        q, dq = self.states[:, :6], self.states[:, 6:]
        return 0.5 * (dq**2 @ mass) + 0.5 * (q**2 @ system.stiff)

    @property
    def final_state(self) -> np.ndarray:
        """State at the last sample (12,)."""
        return self.states[-1].copy()

    @cached_property
    def steady(self) -> SteadyState:
        """Steady-state summary over t ≥ :attr:`steady_from`."""
        return self.steady_state(self.steady_from)

    def steady_state(self, t_from: float) -> SteadyState:
        """Steady-state summary over t ≥ ``t_from`` [s]."""
        return summarize(self.t, self.states, self.mode, self.transitions.time, self.transitions.kind, t_from)

    @cached_property
    def attractor(self):
        """What the steady window settles to, with its evidence
        (:func:`stickslip.analysis.settle.attractor`: may shoot an orbit or compute a Lyapunov
        exponent to confirm a claim)."""
        from ..analysis.settle import attractor

        return attractor(self)

    def summary(self) -> dict:
        """The verdict on the steady window, the steady-state summary and the run's cost, as a
        JSON-ready dict.

        Keys: ``settled``, ``attractor``, ``period_count``, ``fundamental_frequency_hz`` (None
        unless settled and periodic), ``dominant_frequency_hz`` (spectral peak), ``settle_time_s``,
        ``evidence`` (:class:`stickslip.analysis.settle.Attractor`); ``status``, ``model``,
        ``parameters``; ``t_end_s``, ``steady_from_s``, ``stick_fraction``, ``n_transitions``,
        ``phi_min``, ``phi_max`` [rad] of the window; ``steps``, ``wall_time_s``, ``method``;
        ``settle`` (the cap and steps of :func:`stickslip.analysis.settle.simulate_until_settled`)
        when the run was extended until settled.
        """
        s = self.steady
        out = {**self.attractor.to_dict(), "status": self.status, "model": self.model,
               "parameters": self.params.to_dict(), "t_end_s": float(self.t[-1]), "steady_from_s": s.t_from,
               "stick_fraction": s.stick_fraction, "n_transitions": s.n_transitions, "phi_min": s.phi_min,
               "phi_max": s.phi_max, "steps": self.stats.steps, "wall_time_s": self.stats.wall_time_s,
               "method": self.method}
        if "settle" in self.options:
            out["settle"] = self.options["settle"]
        return out

    def plot(self, **kwargs):
        """Overview figure; see :func:`stickslip.plot.plot_trajectory`."""
        from ..plot.trajectory import plot_trajectory

        return plot_trajectory(self, **kwargs)

    # ------------------------------------------------------------- xarray / NetCDF
    def to_xarray(self):
        """``xarray.Dataset`` with units, long names, the full parameter set and run options."""
        import xarray as xr

        coords = {"time": ("time", self.t, {"units": "s", "long_name": "time"})}
        data = {}
        for j, name in enumerate(STATE_NAMES):
            data[name] = ("time", self.states[:, j], {"units": _STATE_UNITS[j], "long_name": _STATE_LONG_NAMES[j]})
        data["mode"] = ("time", self.mode.astype(np.int8), {"long_name": "contact mode", "flag_values": "0 1", "flag_meanings": "slip stick"})
        data["Fx"] = ("time", self.friction[:, 0], {"units": "N", "long_name": "friction force on the upper plate, x"})
        data["Fy"] = ("time", self.friction[:, 1], {"units": "N", "long_name": "friction force on the upper plate, y"})
        data["F_abs"] = ("time", self.friction_magnitude, {"units": "N", "long_name": "friction force magnitude |F|"})
        vr = self.relative_velocity
        data["vr_x"] = ("time", vr[:, 0], {"units": "m/s", "long_name": "relative velocity x, Eq. (9)"})
        data["vr_y"] = ("time", vr[:, 1], {"units": "m/s", "long_name": "relative velocity y, Eq. (9)"})
        data["sliding_angle"] = ("time", self.sliding_angle_deg, {"units": "degree", "long_name": "angle of v_r against the circumferential direction"})
        data["work_friction"] = ("time", self.work[:, 0], {"units": "J", "long_name": "work of friction on the plates since t0"})
        data["work_damping"] = ("time", self.work[:, 1], {"units": "J", "long_name": "work of the dampers since t0"})
        data["transition_time"] = ("transition", self.transitions.time, {"units": "s"})
        data["transition_kind"] = ("transition", self.transitions.kind.astype(np.int8), {"flag_values": "-1 1", "flag_meanings": "stick_to_slip slip_to_stick"})
        data["transition_state"] = (("transition", "state"), self.transitions.state)
        attrs = {
            "format": FORMAT,
            "stickslip_version": __version__,
            "title": "stickslip trajectory of the two-plate friction model",
            "model": self.model,
            "method": self.method,
            "status": self.status,
            "steady_from": self.steady_from,
            "options": json.dumps(self.options),
            "stats": json.dumps(dataclasses.asdict(self.stats)),
            "parameters": json.dumps(self.params.to_dict()),
        }
        attrs.update(parameter_attrs(self.params.to_dict()))
        for key, value in self.steady.to_dict().items():
            attrs[f"steady_{key}"] = int(value) if isinstance(value, bool) else value
        ds = xr.Dataset(data, coords=coords, attrs=attrs)
        ds = ds.assign_coords(state=("state", list(STATE_NAMES)))
        return ds

    def to_netcdf(self, path: str | Path) -> Path:
        """Write :meth:`to_xarray` to a NetCDF-4 file (h5netcdf engine)."""
        path = Path(path)
        self.to_xarray().to_netcdf(path, engine="h5netcdf")
        return path

    @classmethod
    def from_xarray(cls, ds) -> "Trajectory":
        """Rebuild a trajectory from :meth:`to_xarray` output."""
        if ds.attrs.get("format") != FORMAT:
            raise FileFormatError(
                f"dataset is not a stickslip trajectory (format attribute {ds.attrs.get('format')!r}, "
                f"expected {FORMAT!r}); give a file written by `stickslip simulate`"
            )
        params = Parameters.from_dict(json.loads(ds.attrs["parameters"]))
        states = np.stack([ds[name].values for name in STATE_NAMES], axis=1)
        return cls(
            t=ds["time"].values,
            states=states,
            mode=ds["mode"].values.astype(np.int8),
            friction=np.stack([ds["Fx"].values, ds["Fy"].values], axis=1),
            work=np.stack([ds["work_friction"].values, ds["work_damping"].values], axis=1),
            transitions=Transitions(
                ds["transition_time"].values, ds["transition_kind"].values.astype(np.int8),
                ds["transition_state"].values.reshape(-1, 12),
            ),
            stats=Stats(**json.loads(ds.attrs["stats"])),
            status=ds.attrs["status"],
            params=params,
            model=resolve_variant(ds.attrs["model"]).name,
            method=ds.attrs["method"],
            options=json.loads(ds.attrs["options"]),
            steady_from=float(ds.attrs["steady_from"]),
        )


def load_trajectory(path: str | Path) -> Trajectory:
    """Read a trajectory written by :meth:`Trajectory.to_netcdf`.

    Raises
    ------
    FileFormatError
        If the file does not exist, is not NetCDF, or was not written by stickslip.
    """
    import xarray as xr

    path = Path(path)
    if not path.is_file():
        raise FileFormatError(f"{path} does not exist; give the path of a run.nc written by `stickslip simulate`")
    try:
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            ds.load()
            return Trajectory.from_xarray(ds)
    except FileFormatError:
        raise
    except Exception as exc:  # h5py/xarray raise many types for foreign files
        raise FileFormatError(
            f"{path} is not a stickslip NetCDF file ({type(exc).__name__}: {exc}); "
            "give a file written by `stickslip simulate`"
        ) from exc
