"""Model files: a friction-contact model with constant contact kinematics, stated in TOML.

```toml
name = "belt"
dofs = ["x"]              # names of q, in order; states are the dofs, then "d" + each dof
mass = [[1.0]]            # M, n×n
damping = [[0.1]]         # C, n×n
stiffness = [[1.0]]       # K, n×n, may be non-symmetric
force = [0.0]             # f0 (optional, default 0)

[[contact]]               # one table per contact
tangent = [[1.0]]         # G: 1 row (1-D friction) or 2 rows (2-D), n columns
drive = [1.5]             # w: surface velocity, one entry per row of G; v_r = G q̇ − drive
normal_force = 1.0        # N0
normal_gradient = [0.0]   # n (optional, default 0): N = N0 + n·q
[contact.friction]
law = "exponential"       # "coulomb" or "exponential"
mu_k = 0.5
delta_mu = 0.5
alpha = 2.0
```

Every key is documented in ``docs/models.md``. Every number of a file is a parameter that
``--set`` reaches by its path: ``mass.0.0``, ``stiffness.x.y`` (indices or dof names),
``force.1``, ``contact.0.drive`` (a one-entry vector needs no index), ``contact.0.normal_force``,
``contact.1.friction.mu_k``, ``slip_band``. Errors name the key and the fix in one line.
"""

from __future__ import annotations

import copy
import math
import sys
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..errors import FrictionLawError, ModelError, ModelFileError
from .friction import FrictionLaw
from .system_model import DEFAULT_SLIP_BAND, Contact, FrictionModel

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["load_model_file", "model_from_spec", "parameter_paths", "ModelFileError", "TOP_KEYS", "CONTACT_KEYS"]

TOP_KEYS = ("name", "description", "dofs", "mass", "damping", "stiffness", "force", "units", "slip_band", "observe",
            "contact")
REQUIRED_TOP = ("dofs", "mass", "damping", "stiffness", "contact")
CONTACT_KEYS = ("name", "tangent", "drive", "normal_force", "normal_gradient", "normal_rate_gradient", "friction")
REQUIRED_CONTACT = ("tangent", "normal_force", "friction")


def _number(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ModelFileError(f"{where} = {value!r} is not a number; give a number")
    try:
        number = float(value)
    except OverflowError:
        raise ModelFileError(f"{where} = {value} is too large for a float; give a number below 1e308") from None
    if not math.isfinite(number):
        raise ModelFileError(f"{where} = {value} is not finite; give a finite number")
    return number


def _vector(value, n: int, where: str) -> np.ndarray:
    if not isinstance(value, list):
        value = [value] if n == 1 else value
    if not isinstance(value, list) or len(value) != n:
        raise ModelFileError(f"{where} must be a list of {n} number(s), got {value!r}")
    return np.array([_number(v, f"{where}[{i}]") for i, v in enumerate(value)])


def _matrix(value, rows: int | None, n: int, where: str) -> np.ndarray:
    if not isinstance(value, list) or not value or not all(isinstance(row, list) for row in value):
        raise ModelFileError(f"{where} must be a list of rows, each a list of {n} numbers, e.g. "
                             f"{where.split('.')[-1]} = [[{', '.join(['1.0'] * n)}]]")
    if rows is not None and len(value) != rows:
        raise ModelFileError(f"{where} must have {rows} row(s) (one per dof), got {len(value)}")
    out = np.empty((len(value), n))
    for i, row in enumerate(value):
        if len(row) != n:
            raise ModelFileError(f"{where} row {i} must have {n} number(s) (one per dof), got {len(row)}")
        for j, v in enumerate(row):
            out[i, j] = _number(v, f"{where}[{i}][{j}]")
    return out


def model_from_spec(spec: Mapping[str, Any], *, source: str = "python", name: str = "model") -> FrictionModel:
    """Build a :class:`FrictionModel` from a model file's content (a parsed TOML mapping).

    Raises
    ------
    ModelFileError
        Naming the key and the fix, for a missing key, an unknown key, a wrong shape, a
        non-number, a mass that is not symmetric positive definite, an unknown law or N0 ≤ 0.
    """
    if not isinstance(spec, Mapping):
        raise ModelFileError("a model file holds a table of keys (name, dofs, mass, ...)")
    unknown = sorted(set(spec) - set(TOP_KEYS))
    if unknown:
        raise ModelFileError(f"unknown key(s) {', '.join(unknown)}; valid keys are {', '.join(TOP_KEYS)}")
    for key in REQUIRED_TOP:
        if key not in spec:
            hint = {"contact": "add at least one [[contact]] table", "dofs": 'e.g. dofs = ["x"]'}.get(
                key, f"give the {key} matrix, one row per dof")
            raise ModelFileError(f"key {key!r} is missing; {hint}")
    dofs = spec["dofs"]
    if not isinstance(dofs, list) or not dofs or not all(isinstance(d, str) and d for d in dofs):
        raise ModelFileError(f"dofs must be a non-empty list of names, e.g. dofs = [\"x\", \"y\"], got {dofs!r}")
    n = len(dofs)
    model_name = spec.get("name", name)
    if not isinstance(model_name, str):
        raise ModelFileError(f"name must be a string, got {model_name!r}")
    mats = {key: _matrix(spec[key], n, n, key) for key in ("mass", "damping", "stiffness")}
    force = _vector(spec["force"], n, "force") if "force" in spec else np.zeros(n)
    slip_band = _number(spec["slip_band"], "slip_band") if "slip_band" in spec else DEFAULT_SLIP_BAND
    observe = spec.get("observe", dofs[0])
    if observe not in dofs:
        raise ModelFileError(f"observe = {observe!r} is not a dof; give one of {', '.join(dofs)}")
    units = spec.get("units", {})
    if not isinstance(units, Mapping) or not all(isinstance(v, str) for v in units.values()):
        raise ModelFileError('units must be a table of dof = "unit", e.g. units = { x = "m" }')
    tables = spec["contact"]
    if isinstance(tables, Mapping):
        tables = [tables]
    if not isinstance(tables, list) or not tables:
        raise ModelFileError("contact must be one or more [[contact]] tables")
    contacts = []
    for c, table in enumerate(tables):
        where = f"contact.{c}"
        if not isinstance(table, Mapping):
            raise ModelFileError(f"{where} must be a table ([[contact]])")
        unknown = sorted(set(table) - set(CONTACT_KEYS))
        if unknown:
            raise ModelFileError(f"{where}: unknown key(s) {', '.join(unknown)}; valid keys are {', '.join(CONTACT_KEYS)}")
        for key in REQUIRED_CONTACT:
            if key not in table:
                hint = {"tangent": "the rows of G, e.g. tangent = [[1.0]]", "normal_force": "N0 > 0 [N]",
                        "friction": "add a [contact.friction] table with law, mu_k, delta_mu"}[key]
                raise ModelFileError(f"{where}.{key} is missing; give {hint}")
        tangent = table["tangent"]
        if isinstance(tangent, list) and tangent and not isinstance(tangent[0], list):
            tangent = [tangent]
        G = _matrix(tangent, None, n, f"{where}.tangent")
        if G.shape[0] not in (1, 2):
            raise ModelFileError(f"{where}.tangent must have 1 row (1-D friction) or 2 rows (2-D), got {G.shape[0]}")
        dim = G.shape[0]
        w = _vector(table["drive"], dim, f"{where}.drive") if "drive" in table else np.zeros(dim)
        N0 = _number(table["normal_force"], f"{where}.normal_force")
        if N0 <= 0.0:
            raise ModelFileError(f"{where}.normal_force = {N0:g} must be > 0 (the contact must be pressed)")
        grad = _vector(table["normal_gradient"], n, f"{where}.normal_gradient") if "normal_gradient" in table else None
        rate = (_vector(table["normal_rate_gradient"], n, f"{where}.normal_rate_gradient")
                if "normal_rate_gradient" in table else None)
        friction = table["friction"]
        if not isinstance(friction, Mapping):
            raise ModelFileError(f"{where}.friction must be a table ([contact.friction])")
        try:
            law = FrictionLaw.from_mapping(friction, where=f"{where}.friction")
        except FrictionLawError as exc:
            raise ModelFileError(str(exc)) from None
        contacts.append(Contact(dim=dim, friction=law, normal_force=N0, tangent=G, drive=w, normal_gradient=grad,
                                normal_rate_gradient=rate, name=str(table.get("name", f"contact{c}"))))
    frozen = copy.deepcopy(dict(spec))
    frozen["contact"] = [dict(t) for t in tables]
    frozen.setdefault("slip_band", slip_band)  # a parameter of every model file
    parameters = parameter_paths(frozen)
    return FrictionModel(
        name=model_name, dofs=tuple(dofs), mass=mats["mass"], damping=mats["damping"],
        stiffness=mats["stiffness"], force=force, contacts=tuple(contacts), parameters=parameters,
        builder=lambda values: model_from_spec(_with_values(frozen, values), source=source, name=model_name),
        source=source, units=dict(units), slip_band=slip_band, description=str(spec.get("description", "")),
        spec=frozen, resolver=lambda path: resolve_path(frozen, path), observed=observe,
    )


def parameter_paths(spec: Mapping[str, Any]) -> dict[str, Any]:
    """Every number (and law name) of a model file by its path, in file order."""
    out: dict[str, Any] = {}

    def walk(prefix: str, value) -> None:
        if isinstance(value, bool):
            return
        if isinstance(value, (int, float)):
            out[prefix] = float(value)
        elif isinstance(value, list):
            for i, item in enumerate(value):
                walk(f"{prefix}.{i}", item)
        elif isinstance(value, Mapping):
            for key, item in value.items():
                if key in ("name", "description", "dofs", "units", "observe"):
                    continue
                walk(f"{prefix}.{key}" if prefix else key, item)
        elif prefix.endswith("friction.law"):
            out[prefix] = value

    walk("", spec)
    return out


def resolve_path(spec: Mapping[str, Any], path: str) -> str:
    """The canonical parameter path of ``path``: dof names as indices, and the index of a
    one-entry vector or 1×1 matrix may be left out (``contact.0.drive`` = ``contact.0.drive.0``)."""
    dofs = list(spec.get("dofs", []))
    parts = path.split(".")
    node: Any = spec
    canonical: list[str] = []
    for part in parts:
        if isinstance(node, list):
            if part in dofs:
                part = str(dofs.index(part))
            if not part.isdigit() or int(part) >= len(node):
                raise ModelFileError(f"--set {path}: {'.'.join(canonical) or 'root'} has no entry {part!r}")
            node = node[int(part)]
        elif isinstance(node, Mapping):
            if part not in node:
                raise ModelFileError(f"--set {path}: no key {part!r} under {'.'.join(canonical) or 'the model'}; "
                                     f"keys there: {', '.join(str(k) for k in node)}")
            node = node[part]
        else:
            raise ModelFileError(f"--set {path}: {'.'.join(canonical)} is a number, it has no {part!r}")
        canonical.append(part)
    while isinstance(node, list) and len(node) == 1:
        node = node[0]
        canonical.append("0")
    if isinstance(node, (list, Mapping)):
        raise ModelFileError(f"--set {path}: that is a table or list, not one number; give an entry such as {path}.0")
    return ".".join(canonical)


def _with_values(spec: Mapping[str, Any], values: Mapping[str, Any]) -> dict:
    """A copy of ``spec`` with the numbers at the given (canonical or alias) paths replaced."""
    out = copy.deepcopy(dict(spec))
    for path, value in values.items():
        canonical = resolve_path(out, path).split(".")
        node = out
        for part in canonical[:-1]:
            node = node[int(part)] if isinstance(node, list) else node[part]
        last = canonical[-1]
        if isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
    return out


def load_model_file(path: str | Path, source: str | None = None) -> FrictionModel:
    """Read a model file (TOML). Errors name the file, the key and the fix in one line.

    ``source`` labels the model's origin (default ``file:PATH``)."""
    path = Path(path)
    if not path.is_file():
        raise ModelFileError(f"model file {path} does not exist; give the path of a .toml model file "
                             "or a library model name (stickslip models)")
    try:
        spec = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ModelFileError(f"{path} is not valid TOML ({exc}); fix the syntax") from None
    try:
        return model_from_spec(spec, source=source or f"file:{path}", name=path.stem)
    except ModelError as exc:
        raise ModelFileError(f"{path}: {exc}") from None
