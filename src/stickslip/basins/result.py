"""The result of a basin-stability study: per-state labels, the attractor table, the fractions.

:func:`assemble` turns the journaled outcomes into a dataset, the same whatever order the
states finished in: per parameter value, the cycles claimed by the period rule are taken as
references in state order (one per distinct cycle, :func:`.cycles.find_cycle`), every periodic
outcome is labelled with the reference it matches, and a run still unsettled at ``t_end`` whose
last section crossings recur on a reference is labelled with it (``matched-at-end``). Cycles are
named by amplitude, largest first: ``periodic``, ``periodic-2``, …; the other labels are the
verdicts (``equilibrium``, ``quasiperiodic``, ``chaotic``, ``unbounded``, ``unsettled``,
``contact-lost``, ``failed``).

The fraction of an attractor is p = (states labelled with it) / n over the n classified states
of a parameter value, with the binomial standard error √(p (1 − p) / n).
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np

from .._version import __version__
from ..analysis.outcome import OUTCOMES, outcome_code, outcome_flags
from ..attractors import jsonable
from .cycles import find_cycle, run_matches
from .early import DECIDED, Outcome
from .spec import BasinSpec
from .store import FORMAT

__all__ = ["BasinResult", "assemble", "cycle_name"]


def cycle_name(rank: int) -> str:
    """Name of the cycle of amplitude rank ``rank`` (0: largest)."""
    return "periodic" if rank == 0 else f"periodic-{rank + 1}"


def _label_one(spec: BasinSpec, outcomes: list[tuple[int, Outcome]]):
    """(labels per state: ("cycle", i) or verdict name, decided_by per state, reference cycles
    sorted by amplitude) for one parameter value's outcomes (state index, outcome)."""
    rtol = spec.options.match_rtol
    refs = []
    for _, o in outcomes:
        if o.verdict == "periodic" and o.decided_by == "period-rule" and find_cycle(refs, o.cycle, rtol) < 0:
            refs.append(o.cycle)
    labels, decided = {}, {}
    for i, o in outcomes:
        decided[i] = o.decided_by
        if o.verdict == "periodic":
            k = find_cycle(refs, o.cycle, rtol)
            if k < 0:
                refs.append(o.cycle)
                k = len(refs) - 1
            labels[i] = k
        else:
            labels[i] = o.verdict
    for i, o in outcomes:
        if o.verdict == "unsettled" and o.section is not None:
            k = next((k for k, c in enumerate(refs) if run_matches(c, o.section, rtol)), -1)
            if k >= 0:
                labels[i] = k
                decided[i] = "matched-at-end"
    order = sorted(range(len(refs)), key=lambda k: -refs[k].amplitude)
    rank = {k: r for r, k in enumerate(order)}
    labels = {i: (cycle_name(rank[v]) if isinstance(v, int) else v) for i, v in labels.items()}
    return labels, decided, [refs[k] for k in order]


def assemble(spec: BasinSpec, models: list[dict], initial: np.ndarray, indices: np.ndarray, rows: np.ndarray,
             attrs: dict | None = None):
    """The study's dataset from its journaled outcomes.

    Parameters
    ----------
    spec : BasinSpec
    models : list of dict
        Per parameter value: ``equilibrium`` ((2n,) or None), ``stable`` (bool), ``max_real_part``
        [1/s], ``period`` (T_c [s]), ``unilateral`` (bool: the model has contacts that open; its
        attractors then get an ``open_fraction``), ``open_at_equilibrium`` (bool: steady sliding
        leaves some contact open; the equilibrium's ``open_fraction`` is then 1).
    initial : ndarray (n_params, n_states, 2n)
        The initial states.
    indices, rows : ndarray
        Flat indices (p · n_states + i) and outcome rows of the classified states.
    attrs : dict, optional
        More attributes (executor, timings).

    Returns
    -------
    xarray.Dataset
    """
    import xarray as xr

    N = spec.n_states
    per_param = [[] for _ in range(spec.n_params)]
    for flat, row in sorted(zip(indices.tolist(), rows), key=lambda x: x[0]):
        per_param[flat // N].append((flat % N, Outcome.from_row(row, spec.n_dofs)))
    labelled = [_label_one(spec, outs) for outs in per_param]
    n_cycles = max((len(refs) for _, _, refs in labelled), default=0)
    present = {v for labels, _, _ in labelled for v in labels.values()}
    names = (["equilibrium"] if "equilibrium" in present else []) + [cycle_name(r) for r in range(n_cycles)]
    names += [v for v in OUTCOMES[2:] if v in present]
    arrays = _tables(spec, models, per_param, labelled, names)
    coords = {"state": ("state", np.arange(N)), "attractor": ("attractor", np.array(names, dtype=object)),
              "state_name": ("state_name", np.array(spec.state_names, dtype=object))}
    if spec.param:
        coords["param"] = ("param", np.array(spec.values), {"long_name": spec.param, "path": spec.param})
    done = arrays["label"] >= 0
    return xr.Dataset(_variables(spec, models, initial, arrays, names), coords=coords,
                      attrs={**_attributes(spec, done), **(attrs or {})})


def _tables(spec: BasinSpec, models: list[dict], per_param: list, labelled: list, names: list[str]) -> dict:
    """Per state (P, N): ``label``, ``verdict``, ``decided``, ``t_decided``, ``steps``, ``wall``; per
    attractor (P, L): ``count``, ``multiplicity``, ``period``, ``amplitude``, ``stick_fraction``,
    ``open_fraction`` and ``rep`` (P, L, 2n), the states on the attractors."""
    P, N, n, L = spec.n_params, spec.n_states, spec.n_dofs, len(names)
    code = {name: i for i, name in enumerate(names)}
    out = dict(label=np.full((P, N), -1, dtype=np.int16), verdict=np.full((P, N), -1, dtype=np.int8),
               decided=np.full((P, N), -1, dtype=np.int8), t_decided=np.full((P, N), np.nan),
               steps=np.full((P, N), -1, dtype=np.int64), wall=np.full((P, N), np.nan),
               multiplicity=np.zeros((P, L), dtype=np.int16), count=np.zeros((P, L), dtype=np.int64),
               rep=np.full((P, L, 2 * n), np.nan),
               **{key: np.full((P, L), np.nan) for key in ("period", "amplitude", "stick_fraction", "open_fraction")})
    label, rep = out["label"], out["rep"]
    for p, ((labels, dec, refs), outs) in enumerate(zip(labelled, per_param)):
        for i, o in outs:
            label[p, i] = code[labels[i]]
            out["verdict"][p, i] = outcome_code(o.verdict)
            out["decided"][p, i] = DECIDED.index(dec[i])
            out["t_decided"][p, i], out["steps"][p, i], out["wall"][p, i] = o.t_decided, o.steps, o.wall_time
            if not np.isfinite(rep[p, label[p, i], 0]):
                rep[p, label[p, i]] = o.state  # the first state of each label, for verdicts without a cycle
        out["count"][p] = np.bincount(label[p][label[p] >= 0], minlength=L)
        for r, c in enumerate(refs):
            a = code[cycle_name(r)]
            out["period"][p, a], out["amplitude"][p, a], out["stick_fraction"][p, a] = \
                c.period, c.amplitude, c.stick_fraction
            out["open_fraction"][p, a] = np.nan if c.open_fraction is None else c.open_fraction
            out["multiplicity"][p, a] = c.multiplicity
            rep[p, a] = c.state
        eq = models[p]["equilibrium"]
        if "equilibrium" in code and eq is not None:
            a = code["equilibrium"]
            # at rest in steady sliding: a contact open there stays open the whole window
            out["amplitude"][p, a], out["stick_fraction"][p, a] = 0.0, 0.0
            out["open_fraction"][p, a] = 1.0 if models[p].get("open_at_equilibrium") else 0.0
            rep[p, a] = eq
    return out


def _variables(spec: BasinSpec, models: list[dict], initial: np.ndarray, arrays: dict, names: list[str]) -> dict:
    """The dataset's variables from :func:`_tables` (the ``param`` dimension only when a parameter is varied)."""
    n = spec.n_dofs
    done = arrays["label"] >= 0
    n_done = done.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        fraction = arrays["count"] / n_done[:, None]
        se = np.sqrt(fraction * (1.0 - fraction) / n_done[:, None])
    lead = ("param",) if spec.param else ()

    def v(array, dims, a):
        return (lead + dims, array if spec.param else array[0], a)

    flags = dict(flag_values=np.arange(len(names), dtype=np.int16), flag_meanings=" ".join(names))
    eq_states = np.array([m["equilibrium"] if m["equilibrium"] is not None else np.full(2 * n, np.nan)
                          for m in models])
    data = {
        "label": v(arrays["label"], ("state",),
                   {"long_name": "attractor reached from each initial state (-1: not classified)", **flags}),
        "verdict": v(arrays["verdict"], ("state",), {"long_name": "outcome of each state's run (-1: not classified)",
                                                     **outcome_flags()}),
        "decided_by": v(arrays["decided"], ("state",), {"long_name": "how the verdict was reached (-1: not classified)",
                                                        "flag_values": np.arange(len(DECIDED), dtype=np.int8),
                                                        "flag_meanings": " ".join(DECIDED)}),
        "t_decided": v(arrays["t_decided"], ("state",),
                       {"units": "s", "long_name": "simulated time at which the verdict was reached"}),
        "steps": v(arrays["steps"], ("state",), {"long_name": "integration steps of the state's run"}),
        "wall_time": v(arrays["wall"], ("state",),
                       {"units": "s", "long_name": "wall time of the state's run (machine-dependent)"}),
        "initial_state": v(initial, ("state", "state_name"), {"long_name": "initial state"}),
        "done": v(done.astype(np.int8), ("state",), {"long_name": "state classified (1) or pending (0)"}),
        "count": v(arrays["count"], ("attractor",), {"long_name": "states that reach the attractor"}),
        "fraction": v(fraction, ("attractor",), {"long_name": "basin stability: fraction of the classified states"}),
        "standard_error": v(se, ("attractor",), {"long_name": "standard error sqrt(p (1 - p) / n) of the fraction"}),
        "period": v(arrays["period"], ("attractor",), {"units": "s", "long_name": "period of a cycle"}),
        "frequency": v(1.0 / arrays["period"], ("attractor",), {"units": "Hz", "long_name": "1 / period of a cycle"}),
        "amplitude": v(arrays["amplitude"], ("attractor",),
                       {"long_name": "peak-to-peak amplitude of the observed coordinate on the attractor"}),
        "multiplicity": v(arrays["multiplicity"], ("attractor",),
                          {"long_name": "maxima of the observed coordinate per period"}),
        "stick_fraction": v(arrays["stick_fraction"], ("attractor",), {"long_name": "fraction of a period in stick"}),
        "representative_state": v(arrays["rep"], ("attractor", "state_name"),
                                  {"long_name": "a state on the attractor (for verdicts without one: the final "
                                                "state of the first run given that label)"}),
        "steady_sliding": v(eq_states, ("state_name",), {"long_name": "steady-sliding state (q_e, 0)"}),
        "steady_sliding_stable": v(np.array([int(m["stable"]) for m in models], dtype=np.int8), (),
                                   {"long_name": "steady sliding linearly stable (1) or not (0)"}),
        "max_real_part": v(np.array([m["max_real_part"] for m in models]), (),
                           {"units": "1/s", "long_name": "largest real part of steady sliding's eigenvalues"}),
        "characteristic_period": v(np.array([m["period"] for m in models]), (),
                                   {"units": "s", "long_name": "T_c: chunks and samples are sized by it"}),
    }
    if any(m.get("unilateral") for m in models):
        data["open_fraction"] = v(arrays["open_fraction"], ("attractor",),
                                  {"long_name": "fraction of a period with some contact open"})
    return data


def _attributes(spec: BasinSpec, done: np.ndarray) -> dict:
    """The dataset's attributes: format, model, spec and digest, the states' sampler, the options."""
    st = spec.states
    model_desc = json.loads(spec.model_key)
    return {
        "format": FORMAT, "stickslip_version": __version__,
        "title": f"stickslip basin stability of model {model_desc.get('name')}",
        "model": model_desc.get("name", ""), "model_description": spec.model_key, "spec": spec.to_json(),
        "digest": spec.digest, "param": spec.param or "", "sampler": st.kind,
        "box": json.dumps({name: [lo, hi] for name, lo, hi in zip(st.names, st.lows, st.highs)}),
        "grid_counts": json.dumps(list(st.counts)), "seed": st.seed, "base": st.base, "ics_file": st.source,
        "n_states": spec.n_states, "states_done": int(done.sum()), "complete": int(done.all()),
        **{k: (int(val) if isinstance(val, bool) else val) for k, val in dataclasses.asdict(spec.options).items()},
    }


@dataclasses.dataclass(frozen=True, eq=False)
class BasinResult:
    """A basin-stability study's result (a view on its dataset).

    Parameters
    ----------
    path : Path or None
        The NetCDF file (``format = stickslip-basins-1``).
    dataset : xarray.Dataset
        Dimensions ``state``, ``attractor``, ``state_name`` (and ``param`` for a parameter study);
        variables as written by :func:`assemble`.
    timings : dict
        ``total_s``, ``compute_s``, ``states_computed``, ``states_resumed``, ``batch_size``,
        ``executor``, ``workers``, ``interrupted``.
    """

    path: Path | None
    dataset: object
    timings: dict = dataclasses.field(default_factory=dict)

    def to_xarray(self):
        """The result as an ``xarray.Dataset``."""
        return self.dataset

    @property
    def complete(self) -> bool:
        """Whether every state is classified (False after an interruption)."""
        return bool(int(self.dataset.attrs["complete"]))

    @property
    def names(self) -> list[str]:
        """Attractor labels, in code order."""
        return [str(x) for x in self.dataset["attractor"].values]

    @property
    def n(self):
        """Classified states (per parameter value: an array for a parameter study)."""
        n = self.dataset["done"].sum("state").values
        return int(n) if np.ndim(n) == 0 else n

    def _by_name(self, var: str) -> dict:
        values = self.dataset[var].values
        return {name: (float(values[..., i]) if values.ndim == 1 else values[..., i].copy())
                for i, name in enumerate(self.names)}

    @property
    def fractions(self) -> dict:
        """Label → fraction of the classified states (an array over the parameter values for a study)."""
        return self._by_name("fraction")

    @property
    def standard_errors(self) -> dict:
        """Label → √(p (1 − p) / n)."""
        return self._by_name("standard_error")

    def labels(self) -> np.ndarray:
        """Label name of every state ("" where not classified)."""
        code = np.nan_to_num(self.dataset["label"].values, nan=-1).astype(int)
        names = np.array(self.names + [""], dtype=object)
        return names[np.where(code >= 0, code, len(self.names))]

    def attractors(self, param_index: int | None = None) -> list[dict]:
        """The attractor table (of one parameter value for a study): label, name, count, fraction,
        standard error, period [s], frequency [Hz], amplitude, multiplicity, stick fraction (and open
        fraction for a model with contacts that open) and a representative state {state name:
        value}; attractors not reached there are left out."""
        ds = self.dataset if param_index is None or "param" not in self.dataset.dims else \
            self.dataset.isel(param=param_index)
        if "param" in ds.dims:
            raise ValueError("a parameter study: give param_index")
        out = []
        for i, name in enumerate(self.names):
            if int(ds["count"].values[i]) == 0:
                continue

            def num(var):
                x = float(ds[var].values[i])
                return x if math.isfinite(x) else None

            state = ds["representative_state"].values[i]
            out.append({"label": i, "name": name, "count": int(ds["count"].values[i]), "fraction": num("fraction"),
                        "standard_error": num("standard_error"), "period": num("period"),
                        "frequency": num("frequency"), "amplitude": num("amplitude"),
                        "multiplicity": int(ds["multiplicity"].values[i]), "stick_fraction": num("stick_fraction"),
                        **({"open_fraction": num("open_fraction")} if "open_fraction" in ds else {}),
                        "state": {str(s): (float(x) if math.isfinite(x) else None)
                                  for s, x in zip(ds["state_name"].values, state)}})
        return out

    def to_json(self) -> dict:
        """``{"n", "fractions", "standard_errors", "attractors"}`` (for a parameter study also
        ``param`` and ``values``, and lists over the values)."""
        def clean(d):
            return jsonable({k: (v.tolist() if np.ndim(v) else v) for k, v in d.items()})

        out = {"n": self.n if np.ndim(self.n) == 0 else self.n.tolist(), "fractions": clean(self.fractions),
               "standard_errors": clean(self.standard_errors)}
        if "param" in self.dataset.dims:
            out["param"] = self.dataset.attrs["param"]
            out["values"] = self.dataset["param"].values.tolist()
            out["attractors"] = [self.attractors(p) for p in range(self.dataset.sizes["param"])]
        else:
            out["attractors"] = self.attractors()
        out["complete"] = self.complete
        return jsonable(out)
