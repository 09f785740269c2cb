"""The checking half of model files: each entry of a file checked once and collected as a slot
(a number, an expression of the named parameters or a law name) with the container and index its
value goes to (:class:`Parser`); the keys of contacts and laws; the short forms errors show
values and paths in. :mod:`stickslip.model.model_file` builds the template and the models from
what it collects.
"""

from __future__ import annotations

import json
import reprlib
from typing import Mapping

from ..errors import ExpressionError, ModelError, ModelFileError
from .expressions import Expression, finite_number, grammar, parse_expression
from .model_file_fe import FILE_KEYS, SET_KEYS, ContactSet, FileMatrices, contact_set, dof_index, set_nodes
from .system_model import check_text

__all__ = ["Parser", "CONTACT_KEYS", "REQUIRED_CONTACT", "FRICTION_KEYS", "NORMAL_KEYS", "PRESCRIBED_KEYS",
           "UNILATERAL_KEYS", "with_defaults", "show_value", "quote_text", "entry_label", "file_number", "check_keys",
           "parse_entry"]

CONTACT_KEYS = ("name", "tangent", "drive", "normal_force", "normal_gradient", "normal_rate_gradient", "gap",
                "gap_gradient", "normal", "friction")
REQUIRED_CONTACT = ("tangent", "friction")
FRICTION_KEYS = ("law", "mu_k", "delta_mu", "alpha", "mu_v", "v_s")
NORMAL_KEYS = ("law", "stiffness", "damping", "restitution")
#: The keys of a prescribed load and of a unilateral contact (a contact has the one or the other).
PRESCRIBED_KEYS = ("normal_force", "normal_gradient", "normal_rate_gradient")
UNILATERAL_KEYS = ("gap", "gap_gradient", "normal")

#: Short reprs for messages: a value shown in an error stays on one short line, however deeply
#: nested or long (levels, list items and characters shown).
_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxstring, _SHORT.maxother = 3, 6, 40, 40


def show_value(value) -> str:
    return _SHORT.repr(value)


def quote_text(text: str) -> str:
    """An expression as the file writes it, on one line (control characters escaped)."""
    return json.dumps(text if len(text) <= 60 else text[:57] + "...", ensure_ascii=False)


def entry_label(path: str) -> str:
    """How errors name an entry: ``mass.0.1`` → ``mass[0][1]``, ``contact.0.drive.0`` → ``contact.0.drive[0]``."""
    parts = path.split(".")
    k = len(parts)
    while k > 1 and parts[k - 1].isdigit():
        k -= 1
    return ".".join(parts[:k]) + "".join(f"[{p}]" for p in parts[k:])


def file_number(value, where: str, hint: str = "") -> float:
    try:
        return finite_number(value)
    except ExpressionError as exc:
        raise ModelFileError(f"{where} = {show_value(value)} {exc}; give a finite number{hint}") from None


def check_keys(table: Mapping, known: tuple, where: str) -> None:
    unknown = sorted(map(str, set(table) - set(known)))
    if unknown:
        raise ModelFileError(f"{where}unknown key(s) {', '.join(unknown)}; valid keys are {', '.join(known)}")


def parse_entry(value, path: str, names) -> float | Expression:
    """A number of the file: a float, or an expression of the parameters ``names`` (a string)."""
    label = entry_label(path)
    if not isinstance(value, str):
        return file_number(value, label, " or an expression of [parameters] (a string)")
    try:
        check_text(value, label)
    except ModelError as exc:
        raise ModelFileError(str(exc)) from None
    try:
        return parse_expression(value, names)
    except ExpressionError as exc:
        raise ModelFileError(f"{label} = {quote_text(value)} is not a valid expression: {exc}; "
                             f"{grammar(names)}") from None


class Parser:
    """Checks the entries of a file and collects them as slots of a :class:`_Template`."""

    def __init__(self, n: int, names, dofs=()) -> None:
        self.n, self.names = n, names
        self.index = {dof: i for i, dof in enumerate(dofs)}
        self.slots: dict = {}
        self.targets: dict = {}
        self.shapes: dict = {"scalars": None}

    def number(self, value, path: str, container: str, index) -> None:
        self.slots[path] = parse_entry(value, path, self.names)
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
            raise ModelFileError(f"{key} must be a list of {n} number(s){table}, got {show_value(value)}")
        if len(value) != n:
            raise ModelFileError(f"{key} must be a list of {n} number(s), got {show_value(value)}")
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
            check_keys(value, ("rayleigh",), "damping: ")
            if not isinstance(value["rayleigh"], list) or len(value["rayleigh"]) != 2:
                raise ModelFileError(f"damping.rayleigh = {show_value(value['rayleigh'])} must be [alpha, beta]: "
                                     "C = alpha M "
                                     "+ beta K")
            self.vector(value["rayleigh"], 2, "damping.rayleigh", "rayleigh")
        elif isinstance(value, Mapping):
            raise ModelFileError(f"{key} = {show_value(value)}: give a matrix (rows of numbers), a matrix file "
                                 f"(\"{key[0].upper()}"
                                 f".mtx\" or {{ file = ... }}, keys {', '.join(FILE_KEYS)})"
                                 + (", or { rayleigh = [alpha, beta] }" if key == "damping" else ""))
        else:
            self.matrix(value, self.n, key, key)

    def contact(self, c: int, table) -> str:
        """Contact ``c``'s entries; returns its name."""
        where = f"contact.{c}"
        if not isinstance(table, Mapping):
            raise ModelFileError(f"{where} must be a table ([[contact]])")
        check_keys(table, CONTACT_KEYS, f"{where}: ")
        self.normal_keys(where, table)
        if not any(key in table for key in (*REQUIRED_CONTACT, "drive")):
            if "normal" not in table:  # a frictionless contact acts through its gap only
                raise ModelFileError(f"{where}: a contact without tangent and friction acts along its normal only; "
                                     "give it gap_gradient with a [contact.normal] table, or a tangent with a "
                                     "[contact.friction] table")
            return self.contact_name(where, table, c)
        for key in REQUIRED_CONTACT:
            if key not in table:
                hint = {"tangent": "the rows of G, e.g. tangent = [[1.0]]",
                        "friction": "add a [contact.friction] table with law, mu_k, delta_mu"}[key]
                raise ModelFileError(f"{where}.{key} is missing; give {hint} (or leave out tangent, drive and "
                                     "friction for a contact without friction)")
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
                self.law_table(value, f"{where}.friction", FRICTION_KEYS, f"{c}.friction", "coulomb, exponential or stribeck")
            elif key == "normal":
                self.normal_table(value, f"{where}.normal", f"{c}.normal")
        return self.contact_name(where, table, c)

    def contact_name(self, where: str, table, c: int) -> str:
        """Contact ``c``'s name, checked; a frictionless one's gap and normal law collected first."""
        if "tangent" not in table:
            for key, value in table.items():
                if key == "gap":
                    self.number(value, f"{where}.{key}", "scalars", f"{c}.{key}")
                elif key == "gap_gradient":
                    self.vector(value, self.n, f"{where}.{key}", f"{c}.{key}", sparse=True)
                elif key == "normal":
                    self.normal_table(value, f"{where}.normal", f"{c}.normal")
        name = table.get("name", f"contact{c}")
        if not isinstance(name, str):
            raise ModelFileError(f"{where}.name = {show_value(name)} must be a string")
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
            raise ModelFileError(f"{where}: a rigid contact has no stiffness or damping; give restitution = e in "
                                 "[0, 1], "
                                 "or law = \"compliant\" for a contact spring")
        if law == "compliant" and "restitution" in table:
            raise ModelFileError(f"{where}: restitution is a rigid contact's; a compliant contact dissipates through "
                                 "its "
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
        check_keys(table, SET_KEYS, f"{where}: ")
        if "friction" not in table:
            raise ModelFileError(f"{where}.friction is missing; add a [{where}.friction] table with law, mu_k, "
                                 "delta_mu")
        nodes = set_nodes(table, where, base)
        cset = contact_set(name, table, nodes, self.index)
        table = dict(with_defaults({**table, "nodes": nodes}, gap="gap" not in cset.per_node))
        if not cset.unilateral and "normal_force" not in table and "normal_force" not in cset.per_node:
            raise ModelFileError(f"{where}.normal_force is missing; give normal_force = N0 > 0 [N] (for the set or per "
                                 f"node) for contacts that are always pressed, or a normal column with a "
                                 f"[{where}.normal] "
                                 "table for contacts that open and close")
        for key, value in table.items():
            if key == "drive":
                self.vector(value, cset.dim, f"{where}.drive", cset.container("drive"))
            elif key in ("gap", "normal_force"):
                self.number(value, f"{where}.{key}", "scalars", cset.container(key))
            elif key == "friction":
                self.law_table(value, f"{where}.friction", FRICTION_KEYS, cset.container("friction"),
                               "coulomb, exponential or stribeck")
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
        check_keys(table, keys, f"{where}: ")
        self.shapes[container] = None
        for key, value in table.items():
            if key != "law":
                self.number(value, f"{where}.{key}", container, key)
            elif isinstance(value, str):
                self.slots[f"{where}.law"] = value
                self.targets[f"{where}.law"] = (container, "law")
            else:
                raise ModelFileError(f"{where}.law = {show_value(value)} is not a law name; choose {laws}")


def with_defaults(table, gap: bool = True):
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
