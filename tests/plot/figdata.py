"""Hand-made results for the figure tests, and readers of what a figure drew.

The plots are checked on data whose every value is known, never on data produced by a run, and
through their artists (mesh coordinates, cell colours, legend handles, labels), never pixels."""

import json
from types import SimpleNamespace

import numpy as np

from stickslip.analysis.outcome import outcome_code
from stickslip.sweep.spec import ATTRACTOR_ATTRS

UNITS = {"N": "N", "Omega": "rad/s", "delta_mu": "1", "frequency": "Hz", "period": "s", "amplitude": "rad",
         "stick_fraction": "1", "phi_mean": "rad", "peaks": "rad", "intensity_r_phi": "m s-1/2"}
PARAMS = {"N": 50.0, "Omega": 0.5, "mu_k": 0.2, "delta_mu": 0.1, "alpha": 5.0}


def make_sweep(coords: dict, t_from=100.0, t_end=200.0, model="full", **variables):
    """A sweep dataset over ``coords`` (dimension order = dict order) with the given variables
    (arrays of the grid's shape; ``peaks`` with one more trailing axis), ``done`` everywhere."""
    import xarray as xr

    dims = list(coords)
    shape = tuple(len(v) for v in coords.values())
    data = {"done": (dims, np.ones(shape, dtype=np.int8))}
    for name, values in variables.items():
        values = np.asarray(values, dtype=float)
        attrs = {"units": UNITS[name]} if name in UNITS else {}
        if name == "attractor":
            attrs = dict(ATTRACTOR_ATTRS)
        attrs.setdefault("long_name", name)
        data[name] = (dims + (["peak"] if name == "peaks" else []), values, attrs)
    ds = xr.Dataset(data, coords={d: (d, np.asarray(v), {"units": UNITS[d]} if d in UNITS else {})
                                  for d, v in coords.items()})
    ds.attrs.update(parameters=json.dumps(PARAMS), t_from=t_from, t_end=t_end, model=model)
    return ds


def outcome_codes(names):
    """The outcome codes (float array of the same shape) of outcome names."""
    return np.vectorize(outcome_code, otypes=[float])(np.asarray(names, dtype=object))


def make_stability_map(N, Omega, omega_c, *, missing=None, upper=None, labels=("Δμ = 0.1",), family="delta_mu"):
    """A StabilityMap whose members are unstable below ``omega_c[f](N)`` (max Re λ = Ω_c − Ω
    [1/s]) and, where ``upper[f]`` is given, again above ``upper[f](N)``; ``missing[f]`` marks
    grid cells without steady sliding (NaN)."""
    from stickslip.model.parameters import Parameters
    from stickslip.stability.maps import StabilityMap

    N, Omega = np.asarray(N, float), np.asarray(Omega, float)
    nF = len(omega_c)
    mrp = np.empty((nF, N.size, Omega.size))
    boundary = np.full((nF, N.size, 2), np.nan)
    direction = np.zeros((nF, N.size, 2), dtype=np.int8)
    for f in range(nF):
        oc = omega_c[f](N)
        mrp[f] = oc[:, None] - Omega[None, :]
        boundary[f, :, 0], direction[f, :, 0] = oc, -1
        if upper is not None and upper[f] is not None:
            ou = upper[f](N)
            above = Omega[None, :] > ou[:, None]
            mrp[f] = np.where(above, Omega[None, :] - ou[:, None], mrp[f])
            boundary[f, :, 1], direction[f, :, 1] = ou, 1
        if missing is not None and missing[f] is not None:
            mrp[f][missing[f]] = np.nan
    values = [float(s.split("=")[1]) for s in labels] if family else []
    return StabilityMap(params=Parameters(), model="full", N=N, Omega=Omega, family_name=family,
                        family_values=values, max_real_part=mrp, boundary=boundary, boundary_direction=direction,
                        boundary_jump=np.zeros_like(direction, dtype=bool), timings={})


def make_trajectory(t_end=100.0, steady_from=50.0, *, periodic=True, frequency=2.0):
    """The attributes of a Trajectory that the overview figure reads: φ = 0.01 sin(2π f t), ψ = 0,
    stick wherever φ > 0.009, |F| = 10 N (15 N in stick), sampled at 200 Hz."""
    from stickslip.analysis.steady import SteadyState
    from stickslip.model.parameters import Parameters

    t = np.linspace(0.0, t_end, int(200 * t_end) + 1)
    states = np.zeros((t.size, 12))
    states[:, 4] = 0.01 * np.sin(2 * np.pi * frequency * t)
    states[:, 10] = 0.02 * np.pi * frequency * np.cos(2 * np.pi * frequency * t)
    mode = (states[:, 4] > 0.009).astype(np.int8)
    steady = SteadyState(t_from=steady_from, t_to=t_end, fundamental_frequency_hz=frequency if periodic else np.nan,
                         dominant_frequency_hz=frequency, periodic=periodic, period_multiplicity=1 if periodic else 0,
                         stick_fraction=float(mode.mean()), contact_stick_fractions=(float(mode.mean()),),
                         n_transitions=0, coordinate="phi", minimum=-0.01,
                         maximum=0.01)
    from stickslip.model.library import two_plates

    params = Parameters(N=50.0, Omega=5.0)
    friction = np.zeros((t.size, 2))
    friction[:, 0] = np.where(mode == 1, 15.0, 10.0)
    return SimpleNamespace(t=t, states=states, mode=mode, friction=friction, friction_magnitude=friction[:, 0],
                           normal_force=np.full((t.size, 1), params.N), params=params, system=two_plates(params),
                           is_plates=True, observed=4, steady_from=steady_from, steady=steady, model="full",
                           method="event")


def filled_colours(ax):
    """RGBA of every filled area drawn in ``ax``: each cell of each QuadMesh, each filled
    contour, each patch in the data area (spans, bars)."""
    from matplotlib.collections import PolyCollection, QuadMesh
    from matplotlib.contour import ContourSet

    colours = []
    for artist in ax.get_children():
        if isinstance(artist, QuadMesh):
            rgba = mesh_rgba(artist).reshape(-1, 4)
            colours += [tuple(np.round(c, 4)) for c in rgba[rgba[:, 3] > 0]]
        elif isinstance(artist, (ContourSet, PolyCollection)):
            colours += [tuple(np.round(c, 4)) for c in np.asarray(artist.get_facecolor()).reshape(-1, 4)]
    return set(colours)


def legend_patch_colours(ax):
    """RGBA of the filled legend handles of ``ax``."""
    from matplotlib.patches import Patch

    legend = ax.get_legend()
    if legend is None:
        return set()
    return {tuple(np.round(h.get_facecolor(), 4)) for h in legend.legend_handles if isinstance(h, Patch)}


def mesh_rgba(mesh):
    """RGBA (ny, nx, 4) of the cells of a QuadMesh; masked cells transparent."""
    arr = mesh.get_array()
    rgba = np.asarray(mesh.to_rgba(arr)).reshape(arr.shape + (4,))
    if mesh.get_alpha() is not None:  # to_rgba leaves out the artist's own alpha
        rgba[..., 3] *= mesh.get_alpha()
    rgba[np.ma.getmaskarray(arr)] = 0.0
    return rgba


def mesh_edges(mesh):
    """(x edges, y edges) of a QuadMesh on a rectilinear grid."""
    c = mesh.get_coordinates()
    return c[0, :, 0], c[:, 0, 1]


def top_cell_colours(ax):
    """RGBA (ny, nx, 4) of the topmost opaque-or-translucent cell of the QuadMeshes in ``ax``
    (all on one grid), in drawing order; transparent where no mesh draws the cell."""
    from matplotlib.collections import QuadMesh

    meshes = sorted((c for c in ax.collections if isinstance(c, QuadMesh)), key=lambda c: c.get_zorder())
    top = None
    for mesh in meshes:
        rgba = mesh_rgba(mesh)
        top = rgba if top is None else np.where(rgba[..., 3:] > 0, rgba, top)
    return top


def legend_entries(ax):
    """{label: handle} of the legend of ``ax``."""
    legend = ax.get_legend()
    if legend is None:
        return {}
    return {t.get_text(): h for t, h in zip(legend.get_texts(), legend.legend_handles)}


def capture_saved_figures(monkeypatch):
    """List that receives every Figure saved while the test runs (the file is written too)."""
    from matplotlib.figure import Figure

    saved, original = [], Figure.savefig

    def savefig(self, *args, **kwargs):
        saved.append(self)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return saved


def handle_colour(handle):
    """RGBA of a legend handle: a patch's face, a line's colour, a collection's first face."""
    from matplotlib.colors import to_rgba
    from matplotlib.lines import Line2D

    if isinstance(handle, Line2D):
        return to_rgba(handle.get_color())
    face = np.asarray(handle.get_facecolor(), dtype=float).reshape(-1, 4)
    return tuple(face[0])
