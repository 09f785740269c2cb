"""The summary of a run: its verdict, its steady window and its cost, as one JSON-ready dict."""

from __future__ import annotations

from ..analysis.signal import OPEN, SLIP, STICK
from ..integrate.result import Trajectory
from .verdict import Attractor, attractor

__all__ = ["run_summary"]


def run_summary(traj: Trajectory, verdict: Attractor | None = None) -> dict:
    """The verdict on the steady window, the steady-state summary and the run's cost.

    Parameters
    ----------
    traj : Trajectory
    verdict : Attractor, optional
        The verdict already reached for ``traj``'s steady window (default:
        :func:`~.verdict.attractor` of it, which may shoot an orbit or compute a Lyapunov
        exponent to confirm a claim).

    Returns
    -------
    dict
        Keys: ``settled``, ``attractor``, ``period_count``, ``fundamental_frequency_hz`` (None
        unless settled and periodic), ``dominant_frequency_hz`` (spectral peak),
        ``settle_time_s``, ``evidence`` (:class:`~.verdict.Attractor`); ``status``, ``model``,
        ``parameters``; ``t_end_s``, ``steady_from_s``, ``stick_fraction`` (some contact stuck),
        ``n_transitions``, ``contacts`` (by name: each contact's ``stick_fraction`` and
        ``n_transitions`` stick↔slip in the window); with unilateral contacts also
        ``open_fraction`` (some contact open) and, by contact, ``open_fraction`` and ``openings``;
        with rigid contacts ``impacts`` and ``max_impact_speed`` [m/s] in the window (NaN, with
        ``max_impact_speed_reason``, where it is unknown);
        ``coordinate`` (the model's observed dof) and its extremes ``<coordinate>_min``,
        ``<coordinate>_max`` in the window (the plates: ``phi_min``, ``phi_max``); ``steps``, ``wall_time_s``, ``method``; ``settle``
        (the cap and steps of :func:`~.settle.simulate_until_settled`) when the run was extended
        until settled.
    """
    verdict = attractor(traj) if verdict is None else verdict
    s = traj.steady
    out = {**verdict.to_dict(), "status": traj.status, "model": traj.model,
           "parameters": dict(traj.system.parameters), "t_end_s": float(traj.t[-1]), "steady_from_s": s.t_from,
           "stick_fraction": s.stick_fraction, "n_transitions": s.n_transitions,
           "contacts": _contacts(traj, s), "coordinate": s.coordinate,
           f"{s.coordinate}_min": s.minimum, f"{s.coordinate}_max": s.maximum, "steps": traj.stats.steps,
           "wall_time_s": traj.stats.wall_time_s, "method": traj.method}
    if s.open_fraction is not None:
        out["open_fraction"] = s.open_fraction
    if s.impacts is not None:
        out["impacts"] = s.impacts
        out["max_impact_speed"] = s.max_impact_speed
        if s.max_impact_speed_reason:
            out["max_impact_speed_reason"] = s.max_impact_speed_reason
    if "settle" in traj.options:
        out["settle"] = traj.options["settle"]
    return out


def _contacts(traj: Trajectory, steady) -> dict:
    """Each contact's stick fraction and stick↔slip transitions in the steady window, by name
    (and its open fraction and openings where contacts open and close)."""
    tr = traj.transitions
    window = (tr.time > steady.t_from) & (tr.time <= steady.t_to)
    stick_slip = window & ((tr.kind == STICK) | (tr.kind == SLIP))
    out = {}
    for c, name in enumerate(traj.system.contact_names):
        out[name] = {"stick_fraction": steady.contact_stick_fractions[c],
                     "n_transitions": int(((tr.contact == c) & stick_slip).sum())}
        if steady.open_fraction is not None:
            out[name].update(open_fraction=steady.contact_open_fractions[c],
                             openings=int(((tr.contact == c) & window & (tr.kind == OPEN)).sum()))
    return out
