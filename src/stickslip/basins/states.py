"""Initial states of a basin-stability study: random draws in a box, a regular grid, or a CSV table.

A state of a model with n coordinates has 2n entries named ``model.state_names`` (the dofs, then
``d`` + each dof). A box names some of them with a range ``LO:HI``; the others are held at the
**base state**: steady sliding (q = q_e, q̇ = 0, the default) or rest (q = 0, q̇ = 0), with any
state fixed to a value by ``fixed``. A CSV table gives every state of every row itself.

:class:`StateSpec` records how the states are made (it enters the study's digest, so a resumed
run draws the same states); :meth:`StateSpec.states` makes them for one model, whose steady
sliding may differ from one parameter value to the next.
"""

from __future__ import annotations

import csv
import dataclasses
import hashlib
import json
import math
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ..errors import BasinError
from ..memory import check_memory, format_bytes, largest_count

__all__ = ["BasinError", "StateSpec", "BASES", "box", "grid", "from_csv", "parse_range"]

#: Base states: what the states outside the box are held at.
BASES = ("equilibrium", "zero")

#: Most states a study may hold (each a row of the journal and of the NetCDF).
MAX_STATES = 10_000_000

#: Seeds of the random draws: what numpy's generator takes and the result's int64 attribute holds.
MAX_SEED = 2**63 - 1


@dataclasses.dataclass(frozen=True)
class StateSpec:
    """How the initial states are made.

    Attributes
    ----------
    kind : {"box", "grid", "ics"}
        Uniform random draws in a box, a regular grid over it, or a table read from a CSV file.
    names : tuple of str
        The box's states, in order (``box``, ``grid``); the CSV header (``ics``).
    lows, highs : tuple of float
        The box's ranges, one per name [units of each state].
    n : int
        Number of states.
    counts : tuple of int
        Grid points per box axis (``grid``), C order: the first axis varies slowest.
    seed : int
        Seed of the random draws (``box``).
    base : {"equilibrium", "zero"}
        State the entries outside the box are held at (``box``, ``grid``).
    fixed : tuple of (str, float)
        States set to a value on top of the base.
    table : ndarray (n, 2n) or None
        The states of a CSV file, in model state order (``ics``).
    source : str
        The CSV file the table was read from (``ics``), for messages and the result's attributes.
    """

    kind: str
    names: tuple
    lows: tuple = ()
    highs: tuple = ()
    n: int = 0
    counts: tuple = ()
    seed: int = 0
    base: str = "equilibrium"
    fixed: tuple = ()
    table: np.ndarray | None = None
    source: str = ""

    @property
    def size(self) -> int:
        """Number of states."""
        return self.n

    @property
    def needs_equilibrium(self) -> bool:
        """Whether the states depend on steady sliding (the base is the equilibrium)."""
        return self.kind != "ics" and self.base == "equilibrium"

    def to_json(self) -> str:
        """JSON of everything that determines the states (a CSV table by its SHA-256)."""
        d = {"kind": self.kind, "names": list(self.names), "lows": list(self.lows), "highs": list(self.highs),
             "n": self.n, "counts": list(self.counts), "seed": self.seed, "base": self.base,
             "fixed": [list(p) for p in self.fixed], "source": self.source}
        if self.table is not None:
            d["table_sha256"] = hashlib.sha256(np.ascontiguousarray(self.table, dtype=np.float64).tobytes()).hexdigest()
        return json.dumps(d, sort_keys=True)

    def axes(self) -> list[np.ndarray]:
        """The grid's values along each box axis (``grid`` only)."""
        return [np.linspace(lo, hi, k) for lo, hi, k in zip(self.lows, self.highs, self.counts)]

    def unit_draws(self) -> np.ndarray:
        """(n, d) positions in the unit box: uniform draws (``box``) or the grid (``grid``)."""
        if self.kind == "box":
            return np.random.default_rng(self.seed).random((self.n, len(self.names)))
        mesh = np.meshgrid(*[np.linspace(0.0, 1.0, k) for k in self.counts], indexing="ij")
        return np.stack([m.ravel() for m in mesh], axis=1)

    def states(self, model, equilibrium: np.ndarray | None = None) -> np.ndarray:
        """The (n, 2n) initial states for ``model``.

        Parameters
        ----------
        model : FrictionModel
        equilibrium : ndarray (n,), optional
            Steady sliding q_e of ``model`` (needed when the base is the equilibrium).

        Raises
        ------
        BasinError
            If the base is the equilibrium and none is given.
        """
        names = model.state_names
        if self.kind == "ics":
            return np.array(self.table, dtype=float)
        per = 8.0 * (2 * len(names) + 2 * len(self.names))  # the states and the unit draws with their scaled copy
        check_memory(self.n * per, f"{self.n:.3g} initial states of model {model.name!r} ({format_bytes(per)} each)",
                     lambda memory: f"give at most {largest_count(per, memory)} states")
        base = np.zeros(len(names))
        if self.base == "equilibrium":
            if equilibrium is None:
                raise BasinError(f"no steady sliding of model {model.name!r} to hold the states outside the box at; "
                                 "use the base state zero (--base zero) or fix them (--state NAME=VALUE)")
            base[:model.n] = equilibrium
        for name, value in self.fixed:
            base[names.index(name)] = value
        out = np.repeat(base[None, :], self.n, axis=0)
        u = self.unit_draws()
        for j, name in enumerate(self.names):
            out[:, names.index(name)] = self.lows[j] + u[:, j] * (self.highs[j] - self.lows[j])
        return out


def split_fields(text: str, option: str, form: str, hint: str, count: int, example: str) -> tuple[str, list[str]]:
    """``"NAME=A:B…"`` → (NAME, [A, B, …]) with exactly ``count`` fields, for the options that
    take a name and a colon-separated range.

    Raises
    ------
    BasinError
        ``{option} expects {form}`` without a name or ``=``; ``{option} {text}: {hint}`` for
        another number of fields; both end with ``e.g. {example}``.
    """
    name, sep, rest = str(text).partition("=")
    name = name.strip()
    if not sep or not name:
        raise BasinError(f"{option} expects {form}, got {text!r}; e.g. {example}")
    parts = rest.split(":")
    if len(parts) != count:
        raise BasinError(f"{option} {text}: {hint}; e.g. {example}")
    return name, parts


def parse_range(text: str, option: str = "--box") -> tuple[str, float, float]:
    """``"x=-1:2"`` → ``("x", -1.0, 2.0)``.

    Raises
    ------
    BasinError
        One line naming the fix for anything that is not NAME=LO:HI with finite numbers.
    """
    example = f"{option} x=-1:2"
    name, parts = split_fields(text, option, "NAME=LO:HI", "a range is LO:HI", 2, example)
    try:
        lo, hi = float(parts[0]), float(parts[1])
    except ValueError:
        raise BasinError(f"{option} {text}: LO and HI must be numbers; e.g. {example}") from None
    _check_bounds(option, name, lo, hi, text.strip())
    return name, lo, hi


def _check_bounds(option: str, name: str, lo: float, hi: float, given: str) -> None:
    """Refuse bounds that are not finite or not ordered, quoting them as ``given`` (as the user wrote them)."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise BasinError(f"{option} {given}: LO and HI must be finite numbers")
    if lo >= hi:
        raise BasinError(f"{option} {given}: LO must be < HI; e.g. {option} {name}={min(lo, hi) - 1:g}:"
                         f"{max(lo, hi) + 1:g}")


def _check_state(model, name: str, option: str) -> None:
    names = model.state_names
    if name not in names:
        raise BasinError(f"{option} {name}: unknown state {name!r} of model {model.name!r}; states are "
                         f"{', '.join(names)}")
    dof = names.index(name) % model.n
    if not model.free[dof]:
        raise BasinError(f"{option} {name}: the DOF {model.dofs[dof]} is locked in model {model.name!r} (its states "
                         "stay 0); choose a free state")


def _box(model, ranges: Mapping[str, Sequence[float]] | Sequence, option: str = "--box"):
    items = [(k, *v) for k, v in ranges.items()] if isinstance(ranges, Mapping) else [tuple(r) for r in ranges]
    if not items:
        raise BasinError(f"give at least one {option} NAME=LO:HI (the states to vary); e.g. {option} "
                         f"{model.state_names[0]}=-1:1")
    names, lows, highs = [], [], []
    for item in items:
        if len(item) != 3:
            raise BasinError(f"{option}: give each range as NAME=LO:HI (name, low, high), got {item!r}")
        name, given_lo, given_hi = str(item[0]), item[1], item[2]
        _check_state(model, name, option)
        if name in names:
            raise BasinError(f"{option} {name} is given twice; give each state once")
        try:
            lo, hi = float(given_lo), float(given_hi)
        except (TypeError, ValueError):
            raise BasinError(f"{option} {name}={given_lo}:{given_hi}: LO and HI must be numbers") from None
        _check_bounds(option, name, lo, hi, f"{name}={given_lo}:{given_hi}")
        names.append(name)
        lows.append(lo)
        highs.append(hi)
    return tuple(names), tuple(lows), tuple(highs)


def _fixed(model, fixed: Mapping[str, float] | None, box_names) -> tuple:
    out = []
    for name, value in (fixed or {}).items():
        _check_state(model, name, "--state")
        if name in box_names:
            raise BasinError(f"--state {name} is also a --box axis; give it in one of them")
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise BasinError(f"--state {name}={value!r}: give a number") from None
        if not math.isfinite(value):
            raise BasinError(f"--state {name}={value}: give a finite number")
        out.append((name, value))
    return tuple(out)


def _check_seed(seed) -> int:
    """The seed as an int of 0 … :data:`MAX_SEED` (numpy refuses negative seeds; the result's
    attributes hold it as int64)."""
    try:
        value = int(seed)
    except (TypeError, ValueError):
        raise BasinError(f"--seed {seed!r}: give an integer 0 … 2^63 − 1") from None
    if (isinstance(seed, float) and value != seed) or not 0 <= value <= MAX_SEED:
        raise BasinError(f"--seed {seed}: give an integer 0 … 2^63 − 1")
    return value


def _check_base(base: str) -> str:
    if base not in BASES:
        raise BasinError(f"--base {base}: choose one of {', '.join(BASES)}")
    return base


def box(model, ranges, n: int, *, seed: int = 0, base: str = "equilibrium",
        fixed: Mapping[str, float] | None = None) -> StateSpec:
    """``n`` uniform random states in a box (:class:`StateSpec`).

    Parameters
    ----------
    model : FrictionModel
    ranges : mapping name → (LO, HI), or sequence of (name, LO, HI)
        The states to vary (names of ``model.state_names``), LO < HI.
    n : int
        Number of draws, ≥ 1.
    seed : int
        Seed of numpy's default generator, 0 … 2^63 − 1.
    base : {"equilibrium", "zero"}
        State of the entries outside the box.
    fixed : mapping name → value, optional
        States outside the box set to a value.

    Raises
    ------
    BasinError
        Unknown or locked state, LO ≥ HI, non-finite bounds, n ≤ 0 or above :data:`MAX_STATES`, a
        seed outside 0 … 2^63 − 1.
    """
    names, lows, highs = _box(model, ranges)
    try:
        n = int(n)
    except (TypeError, ValueError):
        raise BasinError(f"--n {n!r}: give the number of random states, an integer >= 1") from None
    if n <= 0 or n > MAX_STATES:
        raise BasinError(f"--n {n}: give the number of random states, 1 … {MAX_STATES}")
    return StateSpec("box", names, lows, highs, n=n, seed=_check_seed(seed), base=_check_base(base),
                     fixed=_fixed(model, fixed, names))


def grid(model, ranges, counts: int | Sequence[int], *, base: str = "equilibrium",
         fixed: Mapping[str, float] | None = None) -> StateSpec:
    """A regular grid over a box, ends included (:class:`StateSpec`); one count for every axis
    or one per axis, each ≥ 2."""
    names, lows, highs = _box(model, ranges)
    counts = [counts] * len(names) if np.ndim(counts) == 0 else list(counts)
    if len(counts) != len(names):
        raise BasinError(f"--grid: give one count for every axis or {len(names)} counts (one per --box), got "
                         f"{len(counts)}")
    try:
        counts = tuple(int(k) for k in counts)
    except (TypeError, ValueError):
        raise BasinError(f"--grid {counts}: give integers >= 2 (points per axis)") from None
    if any(k < 2 for k in counts):
        raise BasinError(f"--grid {','.join(map(str, counts))}: give >= 2 points per axis")
    size = int(np.prod(counts))
    if size > MAX_STATES:
        raise BasinError(f"--grid {','.join(map(str, counts))}: {size} states; give at most {MAX_STATES}")
    return StateSpec("grid", names, lows, highs, n=size, counts=counts, base=_check_base(base),
                     fixed=_fixed(model, fixed, names))


def from_csv(model, path) -> StateSpec:
    """States read from a CSV file: a header naming every state of ``model`` (any order), then one
    state per row (:class:`StateSpec`; results keep the row order).

    Raises
    ------
    BasinError
        One line naming the file and the row or column: missing file, no header or rows, a state
        missing from the header or a column that is not a state, a row with the wrong number of
        fields, a value that is not a finite number, a non-zero value of a locked DOF.
    """
    path = Path(path)
    names = model.state_names
    if not path.is_file():
        raise BasinError(f"--ics {path}: no such file; give a CSV file whose header names the states "
                         f"{','.join(names)}")
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:  # a byte-order mark (spreadsheets) is skipped
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise BasinError(f"--ics {path}: cannot be read as CSV ({exc})") from None
    rows = [r for r in rows if any(c.strip() for c in r)]
    if not rows:
        raise BasinError(f"{path}: empty; the first line must name the states {','.join(names)}")
    header = [c.strip() for c in rows[0]]
    extra = [c for c in header if c not in names]
    if extra:
        raise BasinError(f"{path}: column {extra[0]!r} is not a state of model {model.name!r}; the header names the "
                         f"states {','.join(names)}")
    twice = sorted({c for c in header if header.count(c) > 1})
    if twice:
        raise BasinError(f"{path}: column {twice[0]!r} appears twice in the header; name each state once")
    missing = [c for c in names if c not in header]
    if missing:
        raise BasinError(f"{path}: column(s) {', '.join(missing)} missing from the header; name every state of model "
                         f"{model.name!r}: {','.join(names)}")
    if len(rows) == 1:
        raise BasinError(f"{path}: a header but no states; add one state per row")
    if len(rows) - 1 > MAX_STATES:
        raise BasinError(f"{path}: {len(rows) - 1} states; give at most {MAX_STATES}")
    order = [header.index(c) for c in names]
    table = np.empty((len(rows) - 1, len(names)))
    for i, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise BasinError(f"{path} row {i}: {len(row)} field(s), the header has {len(header)}; give one value per "
                             "column")
        for j, col in enumerate(order):
            text = row[col].strip()
            try:
                value = float(text)
            except ValueError:
                raise BasinError(f"{path} row {i}, column {names[j]}: {text!r} is not a number") from None
            if not math.isfinite(value):
                raise BasinError(f"{path} row {i}, column {names[j]}: {text} is not a finite number")
            table[i - 2, j] = value
    locked = ~np.concatenate([model.free, model.free])
    bad = np.argwhere(table[:, locked] != 0.0)
    if bad.size:
        i, j = bad[0]
        name = [n for n, lk in zip(names, locked) if lk][j]
        raise BasinError(f"{path} row {i + 2}, column {name}: {table[i, names.index(name)]:g} but that DOF is locked "
                         f"in model {model.name!r}; give 0")
    return StateSpec("ics", tuple(header), n=table.shape[0], table=table, source=str(path))
