"""Stick time of each contact and of any contact, from exact transition instants: against
intervals written out by hand and against the sampled modes of a two-contact run."""

import numpy as np
import pytest

import stickslip
from stickslip.analysis.signal import stick_time
from stickslip.attractors import run_summary


def test_overlapping_stick_phases_of_two_contacts():
    # contact 0 sticks 1–4 s, contact 1 sticks 2–6 s and 7–8 s, window 0–10 s:
    # any contact 1–6 and 7–8 (6 s); contact 0: 3 s; contact 1: 5 s
    times = np.array([1.0, 2.0, 4.0, 6.0, 7.0, 8.0])
    kinds = np.array([1, 1, -1, -1, 1, -1])
    contacts = np.array([0, 1, 0, 1, 1, 1])
    total, each = stick_time(0.0, 10.0, 0, times, kinds, contacts, 2)
    assert total == pytest.approx(6.0) and each.tolist() == pytest.approx([3.0, 5.0])
    # stuck at the window's start (contact 1, bit 1) and at its end (contact 0)
    total, each = stick_time(0.0, 10.0, 0b10, np.array([3.0, 9.0]), np.array([-1, 1]), np.array([1, 0]), 2)
    assert total == pytest.approx(4.0) and each.tolist() == pytest.approx([1.0, 3.0])


def test_one_contact_is_the_plain_stick_time():
    times, kinds = np.array([1.0, 2.5, 4.0, 6.0]), np.array([1, -1, 1, -1])
    total, each = stick_time(0.0, 7.0, 0, times, kinds, np.zeros(4, dtype=np.int8), 1)
    assert total == stick_time(0.0, 7.0, 0, times, kinds) == each[0] == pytest.approx(3.5)


def test_two_contact_run_reports_each_contact_by_name(tmp_path):
    traj = stickslip.simulate("popp-stelter", 60.0, sample_rate=2000.0)
    summary = run_summary(traj)
    contacts = summary["contacts"]
    assert list(contacts) == list(traj.system.contact_names)
    sel = traj.t >= traj.steady_from
    for c, name in enumerate(traj.system.contact_names):
        sampled = float(np.mean((traj.mode[sel].astype(np.int64) >> c) & 1))  # independent: the sampled modes
        assert contacts[name]["stick_fraction"] == pytest.approx(sampled, abs=5e-3)
        assert contacts[name]["n_transitions"] == int(((traj.transitions.contact == c)
                                                       & (traj.transitions.time > traj.steady.t_from)).sum())
    fractions = [c["stick_fraction"] for c in contacts.values()]
    assert max(fractions) <= summary["stick_fraction"] <= sum(fractions) + 1e-12
    assert summary["stick_fraction"] == pytest.approx(float(np.mean(traj.mode[sel] != 0)), abs=5e-3)
    ds = traj.to_xarray()
    assert ds["stick"].dims == ("time", "contact") and list(ds["contact"].values) == list(traj.system.contact_names)
    assert np.array_equal(ds["stick"].values, (traj.mode[:, None].astype(np.int64) >> np.arange(2)) & 1)
