"""Model files: a friction-contact model with constant contact kinematics, stated in TOML.

```toml
name = "belt"
dofs = ["x"]              # names of q, in order; states are the dofs, then "d" + each dof
mass = [[1.0]]            # M, n×n
damping = [[0.1]]         # C, n×n
stiffness = [["k"]]       # K, n×n, may be non-symmetric; here an expression of [parameters]
force = [0.0]             # f0 (optional, default 0)

[parameters]              # optional: named numbers that entries use in expressions
k = 1.0

[[contact]]               # one table per contact
tangent = [[1.0]]         # G: 1 row (1-D friction) or 2 rows (2-D), n columns
drive = [1.5]             # w: surface velocity, one entry per row of G; v_r = G q̇ − drive
normal_force = 1.0        # N0 (a prescribed load; or, instead, a gap below)
normal_gradient = [0.0]   # n (optional, default 0): N = N0 + n·q
# gap = 0.0               # a unilateral contact: g = gap + gap_gradient·q, closed while g <= 0
# gap_gradient = [-1.0]
# [contact.normal]        # its normal law
# law = "compliant"       # λ = max(0, −stiffness g − damping ġ)
# stiffness = 40.0
# damping = 0.0
[contact.friction]
law = "exponential"       # "coulomb" or "exponential"
mu_k = 0.5
delta_mu = 0.5
alpha = 2.0
```

Every key is documented in ``docs/models.md``. A string where a number goes is an expression of
the ``[parameters]`` (:mod:`stickslip.model.expressions`). Every parameter is reached by
``--set`` and ``FrictionModel.replace``: a named parameter by its name (``k``), every entry by
its path: ``mass.0.0``, ``stiffness.x.y`` (indices or dof names), ``force.1``,
``contact.0.drive`` (a one-entry vector needs no index), ``contact.0.normal_force``,
``contact.1.friction.mu_k``, ``contact.0.gap``, ``contact.0.gap_gradient.y``,
``contact.0.normal.stiffness``, ``slip_band``. An entry written as an expression is set through its
parameters (a path into it is refused). Errors name the key and the fix in one line.

A model of finite-element size keeps its matrices in files, names its dofs by count, writes
vectors and rows as sparse tables, its damping as Rayleigh's, its many contacts as contact sets,
and carries its mesh's nodes (:mod:`stickslip.model.model_file_fe`; docs/models.md).

The file is checked once, when it is read (keys, shapes, names, expressions; each entry by
:class:`~stickslip.model.model_file_parser.Parser`; its matrix files and CSVs read), into a
:class:`_Template`; each model — the file's, and each ``replace`` of it — is the template's
entries evaluated at its parameter values, validated once by :class:`FrictionModel`.
"""

from __future__ import annotations

import dataclasses
import keyword
import sys
from pathlib import Path
from typing import Any, Mapping

import numpy as np
# scipy.sparse is imported in the functions that use it: a dense model (the two plates, most model
# files) never needs it, and its import costs every command's start-up time.

from ..errors import ExpressionError, FrictionLawError, ModelError, ModelFileError
from ..inputs import read_regular_file
from .expressions import RESERVED, Expression
from .friction import FrictionLaw
from .matrices import is_checked, is_sparse, mark_positive_definite
from .model_file_fe import ContactSet, FileMatrices, Triplets, dof_names, read_nodes
from .model_file_parser import (CONTACT_KEYS, FRICTION_KEYS, NORMAL_KEYS, Parser, check_keys, entry_label,
                                file_number, parse_entry, quote_text, show_value, with_defaults)
from .system_model import DEFAULT_SLIP_BAND, Contact, FrictionModel, NormalLaw, check_name, check_text

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["load_model_file", "model_from_spec", "resolve_path", "ModelFileError", "TOP_KEYS", "CONTACT_KEYS",
           "FRICTION_KEYS", "NORMAL_KEYS", "RESERVED_NAMES"]

TOP_KEYS = ("name", "description", "parameters", "dofs", "mass", "damping", "stiffness", "force", "units",
            "slip_band", "observe", "contact", "contact_set", "nodes")
REQUIRED_TOP = ("dofs", "mass", "stiffness")
#: Largest model file read [bytes]: a file of 64 dofs written out in full is about 100 kB, and
#: larger models keep their matrices in matrix files beside it.
MAX_MODEL_FILE_BYTES = 64 * 2**20
#: Names a parameter cannot take: the model file's keys (``--set mass=2`` is the path of a 1×1
#: mass), the functions and constant of expressions, and the names a sweep's grid gives other
#: meanings (``model``, ``ic``; ``perturb_<state>`` is refused as a prefix).
RESERVED_NAMES = frozenset(TOP_KEYS) | RESERVED | {"model", "ic"}


def _parameters(table) -> dict[str, float]:
    """The ``[parameters]`` table: valid names, finite numbers."""
    if not isinstance(table, Mapping):
        raise ModelFileError(f"parameters = {show_value(table)} must be a table of name = number, e.g. [parameters] "
                             "V = 0.2")
    out = {}
    for name, value in table.items():
        try:
            check_name(name, "parameters: name")
        except ModelError as exc:
            raise ModelFileError(str(exc)) from None
        if keyword.iskeyword(name) or name in RESERVED_NAMES or name.startswith("perturb_"):
            raise ModelFileError(f"parameters: the name {name!r} is reserved (a key of model files, a function or "
                                 "constant of expressions, or a sweep's model, ic, perturb_*); choose another name")
        if isinstance(value, str):
            raise ModelFileError(f"parameters.{name} = {quote_text(value)} is not a number; give a number (expressions "
                                 "go in the model's entries, not in [parameters])")
        out[name] = file_number(value, f"parameters.{name}")
    return out


@dataclasses.dataclass(frozen=True, eq=False)
class _Template:
    """A model file checked once: what every model built from it shares, and its entries.

    ``slots`` maps each entry's path (file order) to its float, :class:`Expression` or law name;
    ``targets`` maps the path to (container, index) where its value goes; ``shapes`` gives each
    container's array shape (None: a table of values, such as a contact's friction).
    """

    spec: dict
    name: str
    description: str
    dofs: tuple
    units: dict
    observe: str
    source: str
    contact_names: tuple
    shapes: dict
    targets: dict
    named: dict
    slots: dict
    fe: "_FEParts"
    parameters: dict = dataclasses.field(init=False)

    def __post_init__(self) -> None:
        raw = {p: v.text if isinstance(v, Expression) else v for p, v in self.slots.items()}
        object.__setattr__(self, "parameters", {**self.named, **raw})

    def resolve(self, path: str) -> str:
        """The parameter name of ``path``: a named parameter, or the canonical path of an entry."""
        if path in self.named:
            return path
        head, _, rest = path.partition(".")
        if head == "parameters" and rest in self.named:
            return rest
        return resolve_path(self.spec, path, self.dofs)

    def with_values(self, values: Mapping[str, Any]) -> FrictionModel:
        """The model at parameter values ``values`` (names and canonical paths, as in :attr:`parameters`).

        Entries whose value differs from the template's are replaced (a number, or a string: an
        expression); a named parameter moves every expression that uses it. Only the changed
        entries are checked here; the model is validated once when it is built.
        """
        named, slots, edits = self.named, self.slots, {}
        for name, old in self.named.items():
            new = values.get(name, old)
            if new is not old and new != old:
                named = dict(named) if named is self.named else named
                named[name] = _parameter_value(new, name)
                edits[f"parameters.{name}"] = named[name]
        for path, old in self.parameters.items():
            if path in self.named:
                continue
            new = values.get(path, old)
            if new is old or (type(new) is type(old) and new == old):
                continue
            current = self.slots[path]
            if isinstance(current, Expression):
                uses = ", ".join(sorted(current.names)) or "none"
                raise ModelFileError(f"--set {path}: {entry_label(path)} is the expression "
                                     f"{quote_text(current.text)} of "
                                     f"[parameters]; set the parameters it uses ({uses}) instead, or write a number "
                                     "in the file")
            slots = dict(slots) if slots is self.slots else slots
            if self.targets[path][1] == "law":
                slots[path] = new
            else:
                slots[path] = parse_entry(new, path, self.named)
                new = new if isinstance(new, str) else slots[path]
            edits[path] = new
        if not edits:
            return _build(self)
        return _build(dataclasses.replace(self, spec=_edited(self.spec, edits), named=named, slots=slots))


def _parameter_value(value, name: str) -> float:
    if isinstance(value, str):
        raise ModelFileError(f"parameter {name} = {quote_text(value)} is not a number; give a number")
    return file_number(value, f"parameters.{name}")


def _edited(spec: dict, edits: Mapping[str, Any]) -> dict:
    """A copy of ``spec`` with the values at the canonical paths ``edits`` replaced; only the
    tables and lists on the way to an edit are copied (``spec`` itself is never changed)."""
    out = dict(spec)
    copied = {id(out)}
    for path, value in edits.items():
        parts = path.split(".")
        node = out
        for part in parts[:-1]:
            key = int(part) if isinstance(node, list) else part
            child = node[key]
            if id(child) not in copied:
                child = list(child) if isinstance(child, list) else dict(child)
                copied.add(id(child))
                node[key] = child
            node = child
        node[int(parts[-1]) if isinstance(node, list) else parts[-1]] = value
    return out


def _plain_copy(value):
    """A copy of the checked tables and lists of a file (no shared containers with the caller's)."""
    if isinstance(value, Mapping):
        return {k: _plain_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_plain_copy(v) for v in value]
    return value



@dataclasses.dataclass(frozen=True, eq=False)
class _FEParts:
    """What a template holds beside its slots: the matrix files read (key → CSR), the contact sets'
    structure and the mesh nodes."""

    matrices: Mapping = dataclasses.field(default_factory=dict)
    sets: tuple = ()
    nodes: Any = None


def _header(spec: Mapping[str, Any], dofs: tuple, default_name: str) -> tuple[dict, str, dict, dict]:
    """The name and description, the observed dof, the units and the named parameters, checked."""
    texts = {key: spec.get(key, default) for key, default in (("name", default_name), ("description", ""))}
    for key, text in texts.items():
        if not isinstance(text, str):
            raise ModelFileError(f"{key} must be a string, got {show_value(text)}")
        check_text(text, key)
    names = set(dofs)
    observe = spec.get("observe", dofs[0])
    if not isinstance(observe, str) or observe not in names:
        shown = ", ".join(dofs[:10]) + (", ..." if len(dofs) > 10 else "")
        raise ModelFileError(f"observe = {show_value(observe)} is not a dof; give one of {shown}")
    units = spec.get("units", {})
    if not isinstance(units, Mapping) or not all(isinstance(v, str) for v in units.values()):
        raise ModelFileError('units must be a table of dof = "unit", e.g. units = { x = "m" }')
    named = _parameters(spec.get("parameters", {}))
    unknown = [str(k) for k in units if k not in names and k not in named]
    if unknown:
        raise ModelFileError(f"units: {unknown[0]!r} is neither a dof nor a named parameter; units are given for "
                             f"the dofs ({', '.join(dofs[:10])}) and the [parameters] ({', '.join(named) or 'none'})")
    return texts, observe, dict(units), named


def _dofs(spec: Mapping[str, Any], base) -> tuple[tuple, FileMatrices]:
    """The dof names and the matrix files (read once; the dofs may be named after their labels)."""
    if not isinstance(spec, Mapping):
        raise ModelFileError("a model file holds a table of keys (name, dofs, mass, ...)")
    check_keys(spec, TOP_KEYS, "")
    for key in REQUIRED_TOP:
        if key not in spec:
            hint = {"dofs": 'e.g. dofs = ["x"] or dofs = { count = 100, prefix = "u" }'}.get(
                key, f"give the {key} matrix, one row per dof, or its file (\"{key[0].upper()}.mtx\")")
            raise ModelFileError(f"key {key!r} is missing; {hint}")
    if "contact" not in spec and "contact_set" not in spec:
        raise ModelFileError("key 'contact' is missing; add at least one [[contact]] table (or a [contact_set.NAME])")
    files = FileMatrices.read(spec, base)
    dofs = dof_names(spec["dofs"], files.labels)
    if isinstance(spec["dofs"], list):
        for i, dof in enumerate(dofs):
            check_name(dof, f"dofs[{i}]")
    files.check_sizes(len(dofs))
    return dofs, files


def _template(spec: Mapping[str, Any], source: str, default_name: str, base=None) -> _Template:
    """Check a model file's content (keys, shapes, names, expressions) once; read its files."""
    dofs, files = _dofs(spec, base)
    texts, observe, units, named = _header(spec, dofs, default_name)
    tables = spec.get("contact", [])
    if isinstance(tables, Mapping):
        tables = [tables]
    if not isinstance(tables, list) or ("contact" in spec and not tables):
        raise ModelFileError("contact must be one or more [[contact]] tables")
    tables = [with_defaults(table) for table in tables]
    sets = spec.get("contact_set", {})
    if not isinstance(sets, Mapping) or ("contact_set" in spec and not sets):
        raise ModelFileError("contact_set must hold one or more [contact_set.NAME] tables")
    n = len(dofs)
    parser = Parser(n, tuple(named), dofs)
    contact_names, plans, set_tables, nodes, frozen = [], [], {}, None, {}
    for key, value in spec.items():  # file order: the order of the parameters
        if key in ("mass", "damping", "stiffness"):
            parser.square(key, value, files)
        elif key == "force":
            parser.vector(value, n, key, key)
        elif key == "slip_band":
            parser.number(value, key, "scalars", key)
        elif key == "contact":
            contact_names = [parser.contact(c, table) for c, table in enumerate(tables)]
            frozen["contact"] = tables
        elif key == "contact_set":
            for name, table in sets.items():
                plan, set_tables[name] = parser.contact_set(str(name), table, base)
                plans.append(plan)
            frozen["contact_set"] = set_tables
        elif key == "nodes":
            nodes, frozen["nodes"] = read_nodes(value, base, parser.index, files.labels)
    parser.shapes.setdefault("force", (n,))
    frozen = _plain_copy({**spec, **files.tables, **frozen})  # checked: plain tables, lists and values
    if "slip_band" not in frozen:  # a parameter of every model file
        frozen["slip_band"] = DEFAULT_SLIP_BAND
        parser.number(DEFAULT_SLIP_BAND, "slip_band", "scalars", "slip_band")
    return _Template(spec=frozen, name=texts["name"], description=texts["description"], dofs=dofs,
                     units=units, observe=observe, source=source, contact_names=tuple(contact_names),
                     shapes=parser.shapes, targets=parser.targets, named=named, slots=parser.slots,
                     fe=_FEParts(matrices=files.matrices, sets=tuple(plans), nodes=nodes))


def _value(raw, path: str, named: Mapping[str, float]):
    """An entry's value at the parameters ``named``: its float, its expression's value, or its law name."""
    if not isinstance(raw, Expression):
        return raw
    try:
        return raw(named)
    except ExpressionError as exc:
        used = ", ".join(f"{k} = {named[k]:g}" for k in sorted(raw.names))
        raise ModelFileError(f"{entry_label(path)} = {quote_text(raw.text)} cannot be evaluated"
                             f"{' with ' + used if used else ''}: {exc}; fix the expression or give other parameter "
                             "values") from None


def _containers(t: _Template) -> dict:
    """Every container of ``t`` filled with its slots' values at ``t``'s parameters: dense arrays,
    CSR matrices (sparse tables), tables of law values."""
    out = {}
    for key, shape in t.shapes.items():
        out[key] = {} if shape is None else Triplets(*shape[1:]) if shape[0] == "sparse" else np.zeros(shape)
    for path, raw in t.slots.items():
        container, index = t.targets[path]
        out[container][index] = _value(raw, path, t.named)
    return {key: value.matrix() if isinstance(value, Triplets) else value for key, value in out.items()}


def _matrices(t: _Template, out: dict) -> tuple:
    """M, C, K: written out, or from files (times their ``scale``), C also by Rayleigh or zero."""
    import scipy.sparse as sp  # noqa: PLC0415 - see the module's imports

    scalars = out["scalars"]
    for key, base in t.fe.matrices.items():
        scale = scalars[f"{key}.scale"]
        out[key] = base if scale == 1.0 else (base * scale).tocsr()
        if key == "mass" and out[key] is not base and scale > 0.0 and is_checked(base):
            mark_positive_definite(out[key])  # a positive multiple of a checked M is as definite
    M, K = out["mass"], out["stiffness"]
    if "rayleigh" in out:
        alpha, beta = out["rayleigh"]
        if is_sparse(M) or is_sparse(K):
            M, K = sp.csr_matrix(M), sp.csr_matrix(K)
            return out["mass"], (alpha * M + beta * K).tocsr(), out["stiffness"]
        return M, alpha * M + beta * K, K
    if "damping" not in out:
        n = len(t.dofs)
        return M, sp.csr_matrix((n, n)) if is_sparse(M) else np.zeros((n, n)), K
    return M, out["damping"], K


def _law(table, where: str) -> FrictionLaw:
    try:
        return FrictionLaw.from_mapping(table, where=where)
    except FrictionLawError as exc:
        raise ModelFileError(str(exc)) from None


def _set_contacts(cset: ContactSet, out: dict) -> list[Contact]:
    """The contacts of a contact set: shared laws, per-node or shared numbers."""
    where = f"contact_set.{cset.name}"
    law = _law(out[cset.container("friction")], f"{where}.friction")
    normal = NormalLaw(**out[cset.container("normal")]) if cset.unilateral else None
    scalars = out["scalars"]
    drives = out[cset.container("node_drive")]
    if "drive" not in cset.per_node:
        drives[:] = out.get(cset.container("drive"), np.zeros(cset.dim))
    gaps = out[cset.container("node_gap")] if "gap" in cset.per_node else \
        np.full(len(cset.nodes), scalars.get(cset.container("gap"), 0.0))
    loads = out[cset.container("node_normal_force")] if "normal_force" in cset.per_node else \
        np.full(len(cset.nodes), scalars.get(cset.container("normal_force"), 0.0))
    contacts = []
    for k, name in enumerate(cset.contact_names):
        if cset.unilateral:
            contacts.append(Contact(dim=cset.dim, friction=law, tangent=cset.tangent[k], drive=drives[k], name=name,
                                    normal=normal, gap=float(gaps[k]), gap_gradient=cset.gap_gradient[k]))
            continue
        if not loads[k] > 0.0:
            raise ModelFileError(f"{where}: normal_force = {loads[k]:g} at node {cset.nodes[k]} must be > 0 (the "
                                 "contact must be pressed)")
        contacts.append(Contact(dim=cset.dim, friction=law, normal_force=float(loads[k]), tangent=cset.tangent[k],
                                drive=drives[k], name=name))
    return contacts


def _build(t: _Template) -> FrictionModel:
    """The model of template ``t`` at its parameter values (validated once, by FrictionModel)."""
    out = _containers(t)
    scalars = out["scalars"]
    contacts = []
    for c, name in enumerate(t.contact_names):
        if f"{c}.tangent" not in out:  # no tangent and no friction: a frictionless unilateral contact
            contacts.append(Contact(name=name, normal=NormalLaw(**out[f"{c}.normal"]),
                                    gap=scalars.get(f"{c}.gap", 0.0), gap_gradient=out[f"{c}.gap_gradient"]))
            continue
        law = _law(out[f"{c}.friction"], f"contact.{c}.friction")
        G = out[f"{c}.tangent"]
        if f"{c}.normal" in out:  # unilateral: a gap and its normal law
            normal = NormalLaw(**out[f"{c}.normal"])
            contacts.append(Contact(dim=G.shape[0], friction=law, tangent=G, drive=out[f"{c}.drive"], name=name,
                                    normal=normal, gap=scalars.get(f"{c}.gap", 0.0),
                                    gap_gradient=out[f"{c}.gap_gradient"]))
            continue
        N0 = scalars[f"{c}.normal_force"]
        if N0 <= 0.0:
            raise ModelFileError(f"contact.{c}.normal_force = {N0:g} must be > 0 (the contact must be pressed)")
        contacts.append(Contact(dim=G.shape[0], friction=law, normal_force=N0, tangent=G, drive=out[f"{c}.drive"],
                                normal_gradient=out.get(f"{c}.normal_gradient"),
                                normal_rate_gradient=out.get(f"{c}.normal_rate_gradient"), name=name))
    for cset in t.fe.sets:
        contacts += _set_contacts(cset, out)
    mass, damping, stiffness = _matrices(t, out)
    return FrictionModel(
        name=t.name, dofs=t.dofs, mass=mass, damping=damping, stiffness=stiffness,
        force=out["force"], contacts=tuple(contacts), parameters=t.parameters, builder=t.with_values,
        source=t.source, units=dict(t.units), slip_band=scalars["slip_band"], description=t.description,
        spec=t.spec, resolver=t.resolve, observed=t.observe, nodes=t.fe.nodes,
    )


def model_from_spec(spec: Mapping[str, Any], *, source: str = "python", name: str = "model",
                    base: str | Path | None = None) -> FrictionModel:
    """Build a :class:`FrictionModel` from a model file's content (a parsed TOML mapping).

    ``base`` is the folder that relative paths of matrix files, contact nodes and nodes are
    relative to (the model file's; default the current folder).

    Raises
    ------
    ModelFileError
        Naming the key and the fix, for a missing key, an unknown key, a wrong shape, a
        non-number, a bad expression or parameter, a mass that is not symmetric positive
        definite, an unknown law or N0 ≤ 0; a matrix file that is missing, unreadable, of another
        size or with a non-finite entry.
    """
    return _build(_template(spec, source, name, None if base is None else Path(base)))


def resolve_path(spec: Mapping[str, Any], path: str, dofs=None) -> str:
    """The canonical parameter path of ``path``: dof names as indices, and the index of a
    one-entry vector or 1×1 matrix may be left out (``contact.0.drive`` = ``contact.0.drive.0``).
    ``dofs``: the dof names (default the spec's ``dofs`` list)."""
    dofs = spec.get("dofs", []) if dofs is None else dofs
    index = {dof: i for i, dof in enumerate(dofs)} if isinstance(dofs, (list, tuple)) else {}
    parts = path.split(".")
    node: Any = spec
    canonical: list[str] = []
    for part in parts:
        if isinstance(node, list):
            if part in index:
                part = str(index[part])
            if not part.isdigit() or int(part) >= len(node):
                raise ModelFileError(f"--set {path}: {'.'.join(canonical) or 'root'} has no entry {part!r}")
            node = node[int(part)]
        elif isinstance(node, Mapping):
            if part not in node or (not canonical and part == "parameters"):
                if not canonical:
                    named = ", ".join(spec.get("parameters", {})) or "none (name one in a [parameters] table)"
                    keys = ", ".join(str(k) for k in node if k != "parameters")
                    raise ModelFileError(f"--set {path}: no key {part!r} under the model and no parameter of that "
                                         f"name; named parameters: {named}; keys there: {keys}")
                raise ModelFileError(f"--set {path}: no key {part!r} under {'.'.join(canonical)}; "
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


def load_model_file(path: str | Path, source: str | None = None) -> FrictionModel:
    """Read a model file (TOML). Errors name the file, the key and the fix in one line.

    ``source`` labels the model's origin (default ``file:PATH``)."""
    path = Path(path)
    if not path.exists() and not path.is_symlink():
        raise ModelFileError(f"model file {path} does not exist; give the path of a .toml model file "
                             "or a library model name (stickslip models)")
    data = read_regular_file(path, MAX_MODEL_FILE_BYTES, "model file", ModelFileError,
                             "give the matrices of a large model in matrix files beside it (docs/models.md)")
    try:
        spec = tomllib.loads(data.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ModelFileError(f"{path} is not valid TOML ({exc}); fix the syntax") from None
    except RecursionError:
        raise ModelFileError(f"{path}: a value is nested too deeply to read; a model file holds numbers, lists "
                             "and matrices (lists of lists): fix the brackets") from None
    try:
        return model_from_spec(spec, source=source or f"file:{path}", name=path.stem, base=path.parent)
    except ModelError as exc:
        raise ModelFileError(f"{path}: {exc}") from None
