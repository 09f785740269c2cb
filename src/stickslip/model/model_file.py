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

The file is checked once, when it is read (keys, shapes, names, expressions), into a
:class:`_Template`; each model — the file's, and each ``replace`` of it — is the template's
entries evaluated at its parameter values, validated once by :class:`FrictionModel`.
"""

from __future__ import annotations

import dataclasses
import json
import keyword
import reprlib
import sys
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import scipy.sparse as sp

from ..errors import ExpressionError, FrictionLawError, ModelError, ModelFileError
from ..files import read_regular_file
from .expressions import RESERVED, Expression, finite_number, grammar, parse_expression
from .friction import FrictionLaw
from .matrices import is_checked, is_sparse, mark_positive_definite
from .model_file_fe import (FILE_KEYS, SET_KEYS, ContactSet, FileMatrices, Triplets, contact_set, dof_index, dof_names,
                            read_nodes, set_nodes)
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
CONTACT_KEYS = ("name", "tangent", "drive", "normal_force", "normal_gradient", "normal_rate_gradient", "gap",
                "gap_gradient", "normal", "friction")
REQUIRED_CONTACT = ("tangent", "friction")
FRICTION_KEYS = ("law", "mu_k", "delta_mu", "alpha", "mu_v")
NORMAL_KEYS = ("law", "stiffness", "damping", "restitution")
#: The keys of a prescribed load and of a unilateral contact (a contact has the one or the other).
PRESCRIBED_KEYS = ("normal_force", "normal_gradient", "normal_rate_gradient")
UNILATERAL_KEYS = ("gap", "gap_gradient", "normal")

#: Names a parameter cannot take: the model file's keys (``--set mass=2`` is the path of a 1×1
#: mass), the functions and constant of expressions, and the names a sweep's grid gives other
#: meanings (``model``, ``ic``; ``perturb_<state>`` is refused as a prefix).
RESERVED_NAMES = frozenset(TOP_KEYS) | RESERVED | {"model", "ic"}

#: Short reprs for messages: a value shown in an error stays on one short line, however deeply
#: nested or long (levels, list items and characters shown).
_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxstring, _SHORT.maxother = 3, 6, 40, 40


def _show(value) -> str:
    return _SHORT.repr(value)


def _quote(text: str) -> str:
    """An expression as the file writes it, on one line (control characters escaped)."""
    return json.dumps(text if len(text) <= 60 else text[:57] + "...", ensure_ascii=False)


def _label(path: str) -> str:
    """How errors name an entry: ``mass.0.1`` → ``mass[0][1]``, ``contact.0.drive.0`` → ``contact.0.drive[0]``."""
    parts = path.split(".")
    k = len(parts)
    while k > 1 and parts[k - 1].isdigit():
        k -= 1
    return ".".join(parts[:k]) + "".join(f"[{p}]" for p in parts[k:])


def _number(value, where: str, hint: str = "") -> float:
    try:
        return finite_number(value)
    except ExpressionError as exc:
        raise ModelFileError(f"{where} = {_show(value)} {exc}; give a finite number{hint}") from None


def _check_keys(table: Mapping, known: tuple, where: str) -> None:
    unknown = sorted(map(str, set(table) - set(known)))
    if unknown:
        raise ModelFileError(f"{where}unknown key(s) {', '.join(unknown)}; valid keys are {', '.join(known)}")


def _entry(value, path: str, names) -> float | Expression:
    """A number of the file: a float, or an expression of the parameters ``names`` (a string)."""
    label = _label(path)
    if not isinstance(value, str):
        return _number(value, label, " or an expression of [parameters] (a string)")
    try:
        check_text(value, label)
    except ModelError as exc:
        raise ModelFileError(str(exc)) from None
    try:
        return parse_expression(value, names)
    except ExpressionError as exc:
        raise ModelFileError(f"{label} = {_quote(value)} is not a valid expression: {exc}; {grammar(names)}") from None


def _parameters(table) -> dict[str, float]:
    """The ``[parameters]`` table: valid names, finite numbers."""
    if not isinstance(table, Mapping):
        raise ModelFileError(f"parameters = {_show(table)} must be a table of name = number, e.g. [parameters] V = 0.2")
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
            raise ModelFileError(f"parameters.{name} = {_quote(value)} is not a number; give a number (expressions "
                                 "go in the model's entries, not in [parameters])")
        out[name] = _number(value, f"parameters.{name}")
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
                raise ModelFileError(f"--set {path}: {_label(path)} is the expression {_quote(current.text)} of "
                                     f"[parameters]; set the parameters it uses ({uses}) instead, or write a number "
                                     "in the file")
            slots = dict(slots) if slots is self.slots else slots
            if self.targets[path][1] == "law":
                slots[path] = new
            else:
                slots[path] = _entry(new, path, self.named)
                new = new if isinstance(new, str) else slots[path]
            edits[path] = new
        if not edits:
            return _build(self)
        return _build(dataclasses.replace(self, spec=_edited(self.spec, edits), named=named, slots=slots))


def _parameter_value(value, name: str) -> float:
    if isinstance(value, str):
        raise ModelFileError(f"parameter {name} = {_quote(value)} is not a number; give a number")
    return _number(value, f"parameters.{name}")


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


class _Parser:
    """Checks the entries of a file and collects them as slots of a :class:`_Template`."""

    def __init__(self, n: int, names, dofs=()) -> None:
        self.n, self.names = n, names
        self.index = {dof: i for i, dof in enumerate(dofs)}
        self.slots: dict = {}
        self.targets: dict = {}
        self.shapes: dict = {"scalars": None}

    def number(self, value, path: str, container: str, index) -> None:
        self.slots[path] = _entry(value, path, self.names)
        self.targets[path] = (container, index)

    def vector(self, value, n: int, key: str, container: str, sparse: bool = False) -> None:
        """n entries (a one-entry vector may be written as a number), or a sparse table of dof =
        value (``sparse``: kept as a CSR row (1, n), else a dense vector)."""
        if isinstance(value, Mapping) and n == self.n:
            self.shapes[container] = ("sparse", 1, n) if sparse else (n,)
            for dof, v in value.items():
                i = dof_index(self.index, dof, f"{key}.{dof}")
                self.number(v, f"{key}.{dof}", container, (0, i) if sparse else i)
            return
        if not isinstance(value, list):
            if n == 1 and (isinstance(value, (int, float, str)) and not isinstance(value, bool)):
                self.shapes[container] = (1,)
                return self.number(value, key, container, 0)
            table = " or a table of dof = number" if n == self.n else ""
            raise ModelFileError(f"{key} must be a list of {n} number(s){table}, got {_show(value)}")
        if len(value) != n:
            raise ModelFileError(f"{key} must be a list of {n} number(s), got {_show(value)}")
        self.shapes[container] = (n,)
        for i, v in enumerate(value):
            self.number(v, f"{key}.{i}", container, i)

    def matrix(self, value, rows: int | None, key: str, container: str, flat: bool = False) -> int:
        """A matrix of ``rows`` (None: any number of) rows of n entries, each row a list or (contact
        rows) a sparse table of dof = number; returns the number of rows."""
        n = self.n
        if flat:  # a single row written flat
            value = [value]
        if rows is None and isinstance(value, list) and value and all(isinstance(r, Mapping) for r in value):
            self.shapes[container] = ("sparse", len(value), n)
            for i, row in enumerate(value):
                for dof, v in row.items():
                    j = dof_index(self.index, dof, f"{key}.{dof}" if flat else f"{key}.{i}.{dof}")
                    self.number(v, f"{key}.{dof}" if flat else f"{key}.{i}.{dof}", container, (i, j))
            return len(value)
        if not isinstance(value, list) or not value or not all(isinstance(row, list) for row in value):
            example = f"[[{', '.join(['1.0'] * n)}]]" if n <= 8 else "[{ u0 = 1.0 }] (rows as tables of dof = number)"
            raise ModelFileError(f"{key} must be a list of rows, each a list of {n} numbers, e.g. "
                                 f"{key.split('.')[-1]} = {example}")
        if rows is not None and len(value) != rows:
            raise ModelFileError(f"{key} must have {rows} row(s) (one per dof), got {len(value)}")
        for i, row in enumerate(value):
            if len(row) != n:
                raise ModelFileError(f"{key} row {i} must have {n} number(s) (one per dof), got {len(row)}")
        self.shapes[container] = (len(value), n)
        for i, row in enumerate(value):
            for j, v in enumerate(row):
                self.number(v, f"{key}.{j}" if flat else f"{key}.{i}.{j}", container, (i, j))
        return len(value)

    def square(self, key: str, value, files: FileMatrices) -> None:
        """``mass``, ``stiffness`` or ``damping``: a matrix file (its ``scale`` a slot), Rayleigh
        damping (its two coefficients), or the matrix written out."""
        if key in files.matrices:
            self.number(files.tables[key]["scale"], f"{key}.scale", "scalars", f"{key}.scale")
        elif key == "damping" and isinstance(value, Mapping) and "rayleigh" in value:
            _check_keys(value, ("rayleigh",), "damping: ")
            if not isinstance(value["rayleigh"], list) or len(value["rayleigh"]) != 2:
                raise ModelFileError(f"damping.rayleigh = {_show(value['rayleigh'])} must be [alpha, beta]: C = alpha M "
                                     "+ beta K")
            self.vector(value["rayleigh"], 2, "damping.rayleigh", "rayleigh")
        elif isinstance(value, Mapping):
            raise ModelFileError(f"{key} = {_show(value)}: give a matrix (rows of numbers), a matrix file (\"{key[0].upper()}"
                                 f".mtx\" or {{ file = ... }}, keys {', '.join(FILE_KEYS)})"
                                 + (", or { rayleigh = [alpha, beta] }" if key == "damping" else ""))
        else:
            self.matrix(value, self.n, key, key)

    def contact(self, c: int, table) -> str:
        """Contact ``c``'s entries; returns its name."""
        where = f"contact.{c}"
        if not isinstance(table, Mapping):
            raise ModelFileError(f"{where} must be a table ([[contact]])")
        _check_keys(table, CONTACT_KEYS, f"{where}: ")
        for key in REQUIRED_CONTACT:
            if key not in table:
                hint = {"tangent": "the rows of G, e.g. tangent = [[1.0]]",
                        "friction": "add a [contact.friction] table with law, mu_k, delta_mu"}[key]
                raise ModelFileError(f"{where}.{key} is missing; give {hint}")
        self.normal_keys(where, table)
        tangent = table["tangent"]
        flat = isinstance(tangent, Mapping) or (isinstance(tangent, list) and bool(tangent)
                                                and not isinstance(tangent[0], (list, Mapping)))
        dim = self.matrix(tangent, None, f"{where}.tangent", f"{c}.tangent", flat=flat)
        if dim not in (1, 2):
            raise ModelFileError(f"{where}.tangent must have 1 row (1-D friction) or 2 rows (2-D), got {dim}")
        self.shapes[f"{c}.drive"] = (dim,)
        for key, value in table.items():
            if key in ("drive", "normal_gradient", "normal_rate_gradient"):
                self.vector(value, dim if key == "drive" else self.n, f"{where}.{key}", f"{c}.{key}", sparse=True)
            elif key in ("normal_force", "gap"):
                self.number(value, f"{where}.{key}", "scalars", f"{c}.{key}")
            elif key == "gap_gradient":
                self.vector(value, self.n, f"{where}.{key}", f"{c}.{key}", sparse=True)
            elif key == "friction":
                self.law_table(value, f"{where}.friction", FRICTION_KEYS, f"{c}.friction", "coulomb or exponential")
            elif key == "normal":
                self.normal_table(value, f"{where}.normal", f"{c}.normal")
        name = table.get("name", f"contact{c}")
        if not isinstance(name, str):
            raise ModelFileError(f"{where}.name = {_show(name)} must be a string")
        check_text(name, f"{where}.name")
        return name

    @staticmethod
    def normal_keys(where: str, table) -> None:
        """A contact has a prescribed load or a gap with a normal law: one of them, whole."""
        prescribed = [k for k in PRESCRIBED_KEYS if k in table]
        unilateral = [k for k in UNILATERAL_KEYS if k in table]
        if prescribed and unilateral:
            raise ModelFileError(f"{where}: {prescribed[0]} (a prescribed load) and {unilateral[0]} (a unilateral "
                                 "contact) both given; give normal_force for a contact that is always pressed, or "
                                 "gap_gradient with a [contact.normal] table for one that opens and closes")
        if not prescribed and not unilateral:
            raise ModelFileError(f"{where}.normal_force is missing; give normal_force = N0 > 0 [N] for a contact that "
                                 "is always pressed, or gap_gradient with a [contact.normal] table for one that opens "
                                 "and closes")
        if prescribed and "normal_force" not in table:
            raise ModelFileError(f"{where}.normal_force is missing; give N0 > 0 [N]")
        for key in ("gap_gradient", "normal"):
            if unilateral and key not in table:
                hint = ("W of g = gap + W·q, one number per dof" if key == "gap_gradient" else
                        'a [contact.normal] table, e.g. law = "compliant", stiffness = 40.0')
                raise ModelFileError(f"{where}.{key} is missing for a unilateral contact; give {hint}")

    def normal_table(self, table, where: str, container: str) -> None:
        """A ``[contact.normal]`` table: a compliant law's stiffness, a rigid law's restitution, and
        neither's numbers on the other (the file's keys checked, not only their values)."""
        self.law_table(table, where, NORMAL_KEYS, container, "compliant or rigid")
        law = table.get("law", "compliant")
        if law == "rigid" and ("stiffness" in table or "damping" in table):
            raise ModelFileError(f"{where}: a rigid contact has no stiffness or damping; give restitution = e in [0, 1], "
                                 "or law = \"compliant\" for a contact spring")
        if law == "compliant" and "restitution" in table:
            raise ModelFileError(f"{where}: restitution is a rigid contact's; a compliant contact dissipates through its "
                                 "damping (or give law = \"rigid\")")
        if law == "compliant" and "stiffness" not in table:
            raise ModelFileError(f"{where}.stiffness is missing; give the contact stiffness k > 0 [N/m], e.g. "
                                 "stiffness = 40.0, or law = \"rigid\" for a contact without one")

    def contact_set(self, name: str, table, base) -> tuple[ContactSet, dict]:
        """``[contact_set.NAME]``: its structure, and its table as the frozen spec keeps it (nodes
        inline, defaults written out); its numbers become slots."""
        where = f"contact_set.{name}"
        if not isinstance(table, Mapping):
            raise ModelFileError(f"{where} must be a table ([contact_set.{name}])")
        _check_keys(table, SET_KEYS, f"{where}: ")
        if "friction" not in table:
            raise ModelFileError(f"{where}.friction is missing; add a [{where}.friction] table with law, mu_k, delta_mu")
        nodes = set_nodes(table, where, base)
        cset = contact_set(name, table, nodes, self.index)
        table = dict(_with_defaults({**table, "nodes": nodes}, gap="gap" not in cset.per_node))
        if not cset.unilateral and "normal_force" not in table and "normal_force" not in cset.per_node:
            raise ModelFileError(f"{where}.normal_force is missing; give normal_force = N0 > 0 [N] (for the set or per "
                                 f"node) for contacts that are always pressed, or a normal column with a [{where}.normal] "
                                 "table for contacts that open and close")
        for key, value in table.items():
            if key == "drive":
                self.vector(value, cset.dim, f"{where}.drive", cset.container("drive"))
            elif key in ("gap", "normal_force"):
                self.number(value, f"{where}.{key}", "scalars", cset.container(key))
            elif key == "friction":
                self.law_table(value, f"{where}.friction", FRICTION_KEYS, cset.container("friction"),
                               "coulomb or exponential")
            elif key == "normal":
                self.normal_table(value, f"{where}.normal", cset.container("normal"))
        count = len(cset.nodes)
        self.shapes[cset.container("node_drive")] = (count, cset.dim)
        for key in ("gap", "normal_force"):
            self.shapes[cset.container(f"node_{key}")] = (count,)
        for k, (node, row) in enumerate(nodes.items()):
            for key in sorted(cset.per_node & set(row)):
                index = (k, 1 if key == "drive2" else 0) if key.startswith("drive") else k
                container = "node_drive" if key.startswith("drive") else f"node_{key}"
                self.number(row[key], f"{where}.nodes.{node}.{key}", cset.container(container), index)
        return cset, table

    def law_table(self, table, where: str, keys: tuple, container: str, laws: str) -> None:
        """A law's table (``[contact.friction]``, ``[contact.normal]``): its law's name and numbers."""
        if not isinstance(table, Mapping):
            raise ModelFileError(f"{where} must be a table ([contact.{where.rsplit('.', 1)[1]}])")
        _check_keys(table, keys, f"{where}: ")
        self.shapes[container] = None
        for key, value in table.items():
            if key != "law":
                self.number(value, f"{where}.{key}", container, key)
            elif isinstance(value, str):
                self.slots[f"{where}.law"] = value
                self.targets[f"{where}.law"] = (container, "law")
            else:
                raise ModelFileError(f"{where}.law = {_show(value)} is not a law name; choose {laws}")


def _with_defaults(table, gap: bool = True):
    """A unilateral contact's (or contact set's) table with its optional numbers written out (gap 0
    unless ``gap`` is False, contact damping 0 or a rigid contact's restitution 0), so that
    ``--set`` reaches them like any entry (a copy; the caller's table is not changed)."""
    if not (isinstance(table, Mapping) and isinstance(table.get("normal"), Mapping)):
        return table
    normal = {**table["normal"]}
    if normal.get("law") == "rigid":
        if "stiffness" not in normal and "damping" not in normal:  # a rigid law given either is refused
            normal.setdefault("restitution", 0.0)
    elif "restitution" not in normal:
        normal.setdefault("damping", 0.0)
    return {**table, **({"gap": table.get("gap", 0.0)} if gap else {}), "normal": normal}


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
            raise ModelFileError(f"{key} must be a string, got {_show(text)}")
        check_text(text, key)
    names = set(dofs)
    observe = spec.get("observe", dofs[0])
    if not isinstance(observe, str) or observe not in names:
        shown = ", ".join(dofs[:10]) + (", ..." if len(dofs) > 10 else "")
        raise ModelFileError(f"observe = {_show(observe)} is not a dof; give one of {shown}")
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
    _check_keys(spec, TOP_KEYS, "")
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
    tables = [_with_defaults(table) for table in tables]
    sets = spec.get("contact_set", {})
    if not isinstance(sets, Mapping) or ("contact_set" in spec and not sets):
        raise ModelFileError("contact_set must hold one or more [contact_set.NAME] tables")
    n = len(dofs)
    parser = _Parser(n, tuple(named), dofs)
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
        raise ModelFileError(f"{_label(path)} = {_quote(raw.text)} cannot be evaluated"
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
