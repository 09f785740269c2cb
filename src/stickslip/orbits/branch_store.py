"""Persistence of branches and fold curves: resumable journals, JSON records, NetCDF datasets.

Journals
--------
Append-only journals make long continuation runs resumable (the resumable store of
:mod:`stickslip.journal`, :class:`~stickslip.journal.LineJournal`).

A run that writes to ``OUT.nc`` holds the output's lock ``OUT.nc.lock`` (a second run on the same
output is refused with one line naming the holder) and keeps, while it works, a journal
``OUT.nc.journal`` beside it: a text file whose line 1 is the header (format, kind, digest,
settings, package version), written atomically when the journal is created, followed by one
checksummed JSON record per finished unit of work (a branch point of
:func:`~stickslip.orbits.branch.continue_orbit`, one N of
:func:`~stickslip.orbits.region_edge.fold_curve`), each written with one ``write`` and
``fsync``-ed, so a killed process or a power cut loses only the unit it was working on, and a
full disk loses nothing written before.

On reopening, the journal is cut at its first torn or corrupt record. The digest covers
everything that determines the results; a journal or an output file with another digest is
refused (:class:`JournalMismatch`), never mixed in, and so is a journal whose header cannot be
read. When the run ends, the caller writes ``OUT.nc`` atomically (:func:`write_dataset`) and
removes the journal, which releases the lock.

Floats go through JSON as ``repr`` text, which round-trips float64 exactly (NaN as ``NaN``), so a
resumed run restarts from bit-identical numbers.

Records and datasets
--------------------
The journal records of a branch point, its start orbit and its settings' digest, and the NetCDF
datasets of a :class:`~stickslip.orbits.branch.Branch` and a
:class:`~stickslip.orbits.region_edge.FoldCurve` (format ``stickslip-branch-1`` and
``stickslip-foldcurve-1``) are written and read here; the result types call these functions and
build themselves from the fields read back.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from .._version import __version__
from ..errors import FileFormatError, OrbitError
from ..files import OutputLock, atomic_write, save_netcdf
from ..integrate.result import Trajectory
from ..journal import FORMAT as JOURNAL_FORMAT
from ..journal import LineJournal, journal_path
from ..model.library import describe_system, system_from_description
from ..model.parameters import PARAMETER_UNITS, Parameters, parameter_attrs
from .models import model_attrs
from .section import Section
from .shooting import PeriodicOrbit

__all__ = ["Journal", "JournalMismatch", "journal_path", "digest_of", "array_digest", "encode_array",
           "decode_array", "write_atomically", "check_output", "open_output", "JOURNAL_FORMAT", "section_spec",
           "section_of", "point_record", "point_fields", "start_record", "start_fields", "start_digest",
           "branch_settings", "branch_dataset", "branch_fields", "fold_curve_dataset", "fold_curve_fields", "NetCDFResult",
           "plain_row", "write_dataset", "refuse_without_open_phases"]


class JournalMismatch(OrbitError):
    """A journal or output file at the requested path belongs to a run with other settings, or is corrupt."""


def digest_of(settings: dict) -> str:
    """16 hex digits of the SHA-256 of ``settings`` as canonical JSON (sorted keys)."""
    text = json.dumps(settings, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def array_digest(*arrays) -> str:
    """16 hex digits of the SHA-256 of the arrays' dtypes, shapes and bytes."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.tobytes())
    return h.hexdigest()[:16]


def encode_array(a) -> dict:
    """An ndarray as JSON-ready ``{"shape", "re"[, "im"]}`` (exact for float64/complex128)."""
    a = np.asarray(a)
    out = {"shape": list(a.shape), "re": np.real(a).astype(float).ravel().tolist()}
    if np.iscomplexobj(a):
        out["im"] = np.imag(a).astype(float).ravel().tolist()
    return out


def decode_array(d: dict) -> np.ndarray:
    """Inverse of :func:`encode_array`."""
    a = np.array(d["re"], dtype=float)
    if "im" in d:
        a = a + 1j * np.array(d["im"], dtype=float)
    return a.reshape(d["shape"])


def write_atomically(path: Path, write) -> Path:
    """Call ``write(tmp)`` on a unique temporary file beside ``path``, then replace ``path`` by it
    (:func:`stickslip.files.atomic_write`: fsync-ed; a full disk raises WriteError, ``path`` unchanged)."""
    return atomic_write(path, write)


class Journal(LineJournal):
    """The append-only journal of one resumable run (:class:`stickslip.journal.LineJournal`).

    Parameters
    ----------
    out : path
        The run's output file; the journal is ``OUT.journal`` beside it.
    kind : str
        What the records are (``branch``, ``fold-curve``); part of the header.
    digest : str
        :func:`digest_of` the settings that determine the results.
    settings : dict
        Stored in the header (JSON), for the record.
    lock : OutputLock, optional
        The output's lock, already held by the caller (default: taken here). Held until
        :meth:`close` or :meth:`remove`.
    overwrite : bool
        Discard an existing journal (start over).

    Raises
    ------
    JournalMismatch
        If a journal with another kind or digest, of an earlier format or with a corrupt header
        exists at that path.
    stickslip.files.LockError
        If another process is writing ``out``.
    """

    def __init__(self, out, kind: str, digest: str, settings: dict, lock: OutputLock | None = None,
                 overwrite: bool = False):
        super().__init__(out, kind=kind, digest=digest, settings=settings, noun=f"{kind} run",
                         differs="settings or start differ", error=JournalMismatch, overwrite=overwrite, lock=lock,
                         saved="the finished orbits" if kind == "branch" else "the finished N values",
                         restart="pass resume=False (--overwrite)")


def check_output(out, kind: str, digest: str, attrs: dict) -> None:
    """Refuse a finished output whose attributes do not carry ``digest``.

    Raises
    ------
    JournalMismatch
        The file was written by a run with other settings (or by an older version, no digest).
    """
    if attrs.get("digest") != digest:
        raise JournalMismatch(f"{out} holds a {kind} of different settings or start (digest {attrs.get('digest')} "
                              f"vs {digest}); choose another output (--out) or delete {out}")


def open_output(out, kind: str, digest: str, settings: dict, resume: bool, read):
    """The journal to continue, or the finished result, of a run writing to ``out``.

    Parameters
    ----------
    out : path
    kind, digest, settings
        As :class:`Journal`.
    resume : bool
        False: discard an existing journal and start over (a finished output is replaced when
        the new run ends, not before).
    read : callable
        ``read(out)`` → (attrs dict, finished result) of an existing output file.

    Returns
    -------
    (Journal or None, result or None)
        A journal (new, or with the records of an interrupted run) when there is work to do;
        ``(None, result)`` when ``out`` is a finished output of the same settings.

    Raises
    ------
    JournalMismatch
        If the journal or the output file belongs to a run with other settings, the output is
        not a stickslip file of this kind, or the journal is corrupt.
    stickslip.files.LockError
        If another process is writing ``out``.
    """
    out = Path(out)
    lock = OutputLock(out).acquire()  # before anything is read: one writer at a time
    with lock.released_on_error():
        if resume and out.exists() and not journal_path(out).exists():
            try:
                attrs, result = read(out)
            except FileFormatError as exc:
                raise JournalMismatch(f"{exc}; refusing to overwrite it: choose another output (--out) or delete "
                                      f"{out}") from None
            check_output(out, kind, digest, attrs)
            lock.release()
            return None, result
        return Journal(out, kind, digest, settings, lock=lock, overwrite=not resume), None


# ----------------------------------------------------------------------- records of a branch
def section_spec(section: Section) -> list:
    """A section as JSON-ready ``[index, value, direction, name]``."""
    return [section.index, section.value, section.direction, section.name]


def section_of(spec) -> Section:
    """Inverse of :func:`section_spec`."""
    index, value, direction, name = spec
    return Section(index=int(index), value=float(value), direction=int(direction), name=name)


def point_record(point) -> dict:
    """A branch point as a JSON-ready dict (exact floats: a resumed run restarts bit for bit);
    ``open_phases`` and ``open_time`` only where the model has unilateral contacts,
    ``impact_speed`` only where the point's period has impacts."""
    enc = encode_array
    rec = {"v": enc(point.v), "J": enc(point.J), "M": enc(point.M), "tangent": enc(point.tangent),
           "multipliers": enc(point.multipliers), "stick_phases": int(point.stick_phases),
           "stick_time": float(point.stick_time), "residual": float(point.residual),
           "iterations": int(point.iterations)}
    if point.open_phases is not None:
        rec.update(open_phases=int(point.open_phases), open_time=float(point.open_time))
    if point.impact_speed is not None:
        rec["impact_speed"] = float(point.impact_speed)
    return rec


def point_fields(rec: dict) -> dict:
    """The fields of the branch point of a :func:`point_record`."""
    dec = decode_array
    opened = {} if "open_phases" not in rec else dict(open_phases=int(rec["open_phases"]),
                                                      open_time=float(rec["open_time"]))
    if "impact_speed" in rec:
        opened["impact_speed"] = float(rec["impact_speed"])
    return dict(v=dec(rec["v"]), J=dec(rec["J"]), M=dec(rec["M"]), tangent=dec(rec["tangent"]),
                multipliers=dec(rec["multipliers"]).astype(complex), stick_phases=int(rec["stick_phases"]),
                stick_time=float(rec["stick_time"]), residual=float(rec["residual"]), iterations=int(rec["iterations"]),
                **opened)


def refuse_without_open_phases(out, records: list | None = None, branch=None) -> None:
    """Refuse the journal ``records`` or the finished ``branch`` of a run writing to ``out`` of a
    model with unilateral contacts when they lack the open phases (written by an earlier version,
    which did not count them: resumed, the branch would miss its grazing points).

    Raises
    ------
    JournalMismatch
        One line naming the fix (start over).
    """
    old_points = records is not None and any("point" in r and "open_phases" not in r for r in records)
    if old_points or (branch is not None and branch.open_phases is None):
        where = journal_path(Path(out)) if old_points else out
        raise JournalMismatch(f"{where} was written by an earlier stickslip that did not count the open phases of "
                              "the unilateral contacts (its grazing points would be missing); start over with "
                              "resume=False (--overwrite) or choose another output (--out)")


def start_record(start) -> dict:
    """What a branch keeps of its start orbit (state, period, stick phases, scale, the model's
    description, section, options) as a JSON-ready dict (exact floats)."""
    return {"state": start.state.tolist(), "period": start.period, "stick_phases": start.stick_phases,
            "scale": start.scale.tolist(), "system": describe_system(start.system),
            "section": section_spec(start.section), "options": start.options}


def start_fields(rec: dict) -> dict:
    """Inverse of :func:`start_record`: the fields of the start."""
    return dict(state=np.array(rec["state"], dtype=float), period=float(rec["period"]),
                stick_phases=int(rec["stick_phases"]), scale=np.array(rec["scale"], dtype=float),
                system=system_from_description(rec["system"]), section=section_of(rec["section"]),
                options=dict(rec["options"]))


def start_digest(start, system) -> str:
    """Digest of the ``start`` argument of ``continue_orbit`` (an orbit, a run or a state) of ``system``."""
    if isinstance(start, PeriodicOrbit):
        return digest_of({"orbit": array_digest(start.state, np.array([start.period]), start.scale),
                          "system": describe_system(start.system), "section": section_spec(start.section),
                          "options": {k: start.options.get(k) for k in ("rtol", "atol", "slip_band")}})
    if isinstance(start, Trajectory):
        return digest_of({"run": array_digest(start.t, start.states, start.mode),
                          "system": describe_system(start.system)})
    if start is None or isinstance(start, str):
        return digest_of({"start": repr(start), "system": describe_system(system)})
    if isinstance(start, dict):
        return digest_of({"state": {k: float(v) for k, v in start.items()}, "system": describe_system(system)})
    return digest_of({"state": array_digest(np.asarray(start, dtype=float)), "system": describe_system(system)})


def branch_settings(system, param, start, section, rtol, atol, numerics: dict) -> dict:
    """Everything that determines a branch (its digest; the journal header)."""
    return {"start": start_digest(start, system), "system": describe_system(system), "param": param,
            "section": section_spec(section), "rtol": rtol, "atol": atol, "slip_band": system.slip_band,
            **numerics}


# ----------------------------------------------------------------------- NetCDF
class NetCDFResult:
    """``to_netcdf`` of a result that has ``to_xarray`` (a branch, a fold curve)."""

    def to_netcdf(self, path, *, overwrite: bool = False) -> Path:
        """Write :meth:`to_xarray` to ``path`` (NetCDF4 via h5netcdf; atomically: temporary file + rename).

        An existing ``path`` is replaced only with ``overwrite=True``
        (:class:`stickslip.errors.OutputError` otherwise).
        """
        return write_dataset(self.to_xarray(), path, overwrite=overwrite)


def write_dataset(ds, path, *, overwrite: bool = True) -> Path:
    """Write ``ds`` to ``path`` (NetCDF4 via h5netcdf) under the output's lock, atomically
    (:func:`stickslip.files.save_netcdf`); a full disk names the journal that keeps the run.
    ``overwrite=True`` for the study's own ``out`` (its command checked it when it started)."""
    path = Path(path)
    journal = journal_path(path)
    kept = f"{path} is left as it was" + (f" and the finished work is kept in {journal}" if journal.exists() else "")
    return save_netcdf(ds, path, overwrite=overwrite, kept=kept)


def branch_dataset(branch):
    """``xarray.Dataset`` of a branch with dims ``point``, ``state``, ``multiplier`` and ``special``."""
    import xarray as xr

    unit = branch.system.units.get(branch.param, PARAMETER_UNITS.get(branch.param, ""))
    observed = branch.system.dofs[branch.system.observed_index]
    sp = branch.special
    data = {
        "value": ("point", branch.values, {"long_name": f"continuation parameter {branch.param}", "units": unit}),
        "period": ("point", branch.periods, {"long_name": "period", "units": "s"}),
        "state_on_section": (("point", "state"), branch.states, {"long_name": "state on the Poincaré section",
                                                                 "units": " ".join(branch.system.state_units)}),
        "multiplier_real": (("point", "multiplier"), branch.multipliers.real, {"long_name": "Floquet multiplier, real part", "units": "1"}),
        "multiplier_imag": (("point", "multiplier"), branch.multipliers.imag, {"long_name": "Floquet multiplier, imaginary part", "units": "1"}),
        "stable": ("point", branch.stable.astype(np.int8), {"long_name": "1 if every non-trivial multiplier is inside the unit circle"}),
        "n_unstable": ("point", branch.n_unstable.astype(np.int16), {"long_name": "non-trivial multipliers outside the unit circle"}),
        "stick_phases": ("point", branch.stick_phases.astype(np.int16), {"long_name": "stick phases per period"}),
        "stick_time": ("point", branch.stick_time, {"long_name": "time in stick per period", "units": "s"}),
        "amplitude": ("point", branch.amplitude, {"long_name": f"peak-to-peak range of {observed} over one period",
                                                  "units": branch.system.units.get(observed, ""),
                                                  "coordinate": observed}),
        "arclength": ("point", branch.arclength, {"long_name": "scaled pseudo-arclength", "units": "1"}),
        "residual": ("point", branch.residuals, {"long_name": "scaled shooting residual", "units": "1"}),
        "iterations": ("point", branch.iterations.astype(np.int16), {"long_name": "corrector iterations"}),
        **_open_variables(branch),
        "special_kind": ("special", np.array([p.kind for p in sp], dtype=str), {"long_name": "kind of special point"}),
        "special_index": ("special", np.array([p.index for p in sp], dtype=np.int32),
                          {"long_name": "lies between branch points index and index + 1"}),
        "special_value": ("special", np.array([p.value for p in sp], dtype=float), {"long_name": f"{branch.param} at the special point", "units": unit}),
        "special_period": ("special", np.array([p.period for p in sp], dtype=float), {"long_name": "period at the special point", "units": "s"}),
        "special_before": ("special", np.array([p.before for p in sp], dtype=float), {"long_name": "test function before"}),
        "special_after": ("special", np.array([p.after for p in sp], dtype=float), {"long_name": "test function after"}),
        "special_bracket": ("special", np.array([p.bracket for p in sp], dtype=float), {"long_name": "final bracket width", "units": unit}),
        "special_located": ("special", np.array([p.located for p in sp], dtype=np.int8), {"long_name": "1 if located to tolerance"}),
        "special_state": (("special", "state"), np.array([p.state for p in sp], dtype=float).reshape(len(sp), 2 * branch.system.n),
                          {"long_name": "state on the section at the special point"}),
        "special_multiplier_real": (("special", "multiplier"), np.array([np.real(p.multipliers) for p in sp], dtype=float)
                                    .reshape(len(sp), branch.multipliers.shape[1]),
                                    {"long_name": "Floquet multiplier at the special point, real part", "units": "1"}),
        "special_multiplier_imag": (("special", "multiplier"), np.array([np.imag(p.multipliers) for p in sp], dtype=float)
                                    .reshape(len(sp), branch.multipliers.shape[1]),
                                    {"long_name": "Floquet multiplier at the special point, imaginary part", "units": "1"}),
    }
    for side in ("before", "after"):  # the multipliers of the two points a special point was found between
        mult = np.array([getattr(p, f"multipliers_{side}") for p in sp], dtype=complex) \
            .reshape(len(sp), branch.multipliers.shape[1])
        for part, values in (("real", mult.real), ("imag", mult.imag)):
            data[f"special_multiplier_{side}_{part}"] = (("special", "multiplier"), values, {
                "long_name": f"Floquet multiplier of the branch point {side} the special point, "
                             f"{'real' if part == 'real' else 'imaginary'} part", "units": "1"})
    coords = {"point": np.arange(len(branch)), "state": list(branch.system.state_names),
              "multiplier": np.arange(branch.multipliers.shape[1]), "special": np.arange(len(sp))}
    attrs = {
        "title": f"stickslip branch of periodic orbits in {branch.param} (pseudo-arclength continuation)",
        "format": "stickslip-branch-1",
        "stickslip_version": __version__,
        "param": branch.param, "param_units": unit,
        "section": branch.section.name,
        "section_spec": json.dumps(section_spec(branch.section)),
        "digest": branch.digest,
        "stop_reason": branch.stop_reason,
        "options": json.dumps(branch.options),
        "timings": json.dumps(branch.timings),
        **model_attrs(branch.system),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _open_variables(branch) -> dict:
    """The flight phases of a branch's points as dataset variables (none for a model without
    unilateral contacts)."""
    if branch.open_phases is None:
        return {}
    return {"open_phases": ("point", branch.open_phases.astype(np.int16),
                            {"long_name": "openings of the unilateral contacts per period (flight phases)"}),
            "open_time": ("point", branch.open_time, {"long_name": "time with some unilateral contact open per period",
                                                      "units": "s"})}


def branch_fields(ds) -> dict:
    """The fields of the branch of a dataset written by :func:`branch_dataset` (files of this
    version: with ``section_spec`` and the special points' multipliers); ``special`` is a list of
    the fields of each special point; ``open_phases`` and ``open_time`` are None where the file has
    no such variables (a model without unilateral contacts, or a file of an earlier version)."""
    mult = ds["multiplier_real"].values + 1j * ds["multiplier_imag"].values
    smult = ds["special_multiplier_real"].values + 1j * ds["special_multiplier_imag"].values
    side = {k: (ds[f"special_{k}_real"].values + 1j * ds[f"special_{k}_imag"].values) if f"special_{k}_real" in ds
            else np.full(smult.shape, np.nan + 0j) for k in ("multiplier_before", "multiplier_after")}
    special = [dict(kind=str(ds["special_kind"].values[k]), index=int(ds["special_index"].values[k]),
                    value=float(ds["special_value"].values[k]), period=float(ds["special_period"].values[k]),
                    state=ds["special_state"].values[k], multipliers=smult[k],
                    before=float(ds["special_before"].values[k]), after=float(ds["special_after"].values[k]),
                    bracket=float(ds["special_bracket"].values[k]), located=bool(ds["special_located"].values[k]),
                    multipliers_before=side["multiplier_before"][k], multipliers_after=side["multiplier_after"][k])
               for k in range(ds.sizes.get("special", 0))]
    return dict(param=ds.attrs["param"], values=ds["value"].values, periods=ds["period"].values,
                states=ds["state_on_section"].values, multipliers=mult, stable=ds["stable"].values.astype(bool),
                n_unstable=ds["n_unstable"].values.astype(int), stick_phases=ds["stick_phases"].values.astype(int),
                stick_time=ds["stick_time"].values, amplitude=ds["amplitude"].values,
                arclength=ds["arclength"].values, residuals=ds["residual"].values,
                iterations=ds["iterations"].values.astype(int), special=special, stop_reason=ds.attrs["stop_reason"],
                system=system_from_description(json.loads(ds.attrs["system"])),
                section=section_of(json.loads(ds.attrs["section_spec"])), options=json.loads(ds.attrs["options"]),
                timings=json.loads(ds.attrs["timings"]), digest=str(ds.attrs.get("digest", "")),
                open_phases=ds["open_phases"].values.astype(int) if "open_phases" in ds else None,
                open_time=ds["open_time"].values if "open_time" in ds else None)


def fold_curve_dataset(fc):
    """``xarray.Dataset`` of a fold curve over ``N``."""
    import xarray as xr

    data = {
        "edge": ("N", fc.edge, {"long_name": "Omega where the stick-slip branch ends", "units": "rad/s"}),
        "kind": ("N", np.array(fc.kind, dtype=str), {"long_name": "fold | stick-vanishing | bounds | failed"}),
        "located": ("N", fc.located.astype(np.int8), {"long_name": "1 if located to tolerance"}),
        "period": ("N", fc.period, {"long_name": "period at the edge", "units": "s"}),
        "omega_stable_max": ("N", fc.omega_stable_max, {"long_name": "largest Omega of a stable orbit", "units": "rad/s"}),
        "points": ("N", fc.points.astype(np.int32), {"long_name": "branch points"}),
        "seconds": ("N", fc.seconds, {"long_name": "wall time", "units": "s"}),
        "message": ("N", np.array(fc.message, dtype=str), {"long_name": "stop reason or error"}),
    }
    attrs = {"title": "stickslip: end of the stick-slip branch over N (upper edge of Region II, Fig. 8)",
             "format": "stickslip-foldcurve-1", "stickslip_version": __version__, "model": fc.model,
             "omega_start": fc.omega_start, "timings": json.dumps(fc.timings),
             "parameters": json.dumps(fc.params.to_dict()), "digest": fc.digest}
    attrs.update(parameter_attrs(fc.params.to_dict()))
    return xr.Dataset(data, coords={"N": ("N", fc.N, {"units": "N", "long_name": "normal load"})}, attrs=attrs)


def fold_curve_fields(ds) -> dict:
    """The fields of the fold curve of a dataset written by :func:`fold_curve_dataset`."""
    return dict(N=ds["N"].values, edge=ds["edge"].values, kind=tuple(str(k) for k in ds["kind"].values),
                located=ds["located"].values.astype(bool), period=ds["period"].values,
                omega_stable_max=ds["omega_stable_max"].values, points=ds["points"].values.astype(int),
                seconds=ds["seconds"].values, message=tuple(str(m) for m in ds["message"].values),
                omega_start=float(ds.attrs["omega_start"]),
                params=Parameters.from_dict(json.loads(ds.attrs["parameters"])), model=ds.attrs["model"],
                timings=json.loads(ds.attrs["timings"]), digest=str(ds.attrs.get("digest", "")))


def plain_row(row) -> list:
    """A row of ``fold_curve`` (see ``FoldCurve.rows``) as JSON-ready Python values."""
    edge, kind, located, period, stable_max, points, seconds, message = row
    return [float(edge), str(kind), bool(located), float(period), float(stable_max), int(points), float(seconds),
            str(message)]

