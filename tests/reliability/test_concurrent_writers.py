"""Two `stickslip sweep` runs on one --out at the same time: one computes, the other refuses in one
line naming it (or, if it comes after the end, finds the finished file); the file equals a clean run."""

from __future__ import annotations

import pytest

from .helpers import assert_same_results, command, read_output, run, start

#: Long enough (20 points of 20 s) that the two processes overlap after their ~3 s start-up.
SWEEP = ["--t-end", "20"]


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    out = tmp_path_factory.mktemp("clean") / "s.nc"
    res = run(command("sweep", out, *SWEEP))
    assert res.returncode == 0, res.stderr
    return read_output("sweep", out)


def two_writers(out) -> list[str]:
    """Start two identical sweeps on ``out`` at once; how each ended (``computed``, ``refused``, ``found``)."""
    procs = [start(command("sweep", out, *SWEEP)) for _ in range(2)]
    ends = []
    for proc in procs:
        stdout, stderr = proc.communicate(timeout=600)
        if proc.returncode == 2:
            lines = [ln for ln in stderr.splitlines() if ln.strip()]
            assert len(lines) == 1 and "is being written by process" in lines[0], stderr
            assert "Traceback" not in stderr
            ends.append("refused")
        else:
            assert proc.returncode == 0, stderr
            ends.append("found" if '"points_computed": 0' in stdout else "computed")
    return ends


def check_trials(clean, tmp_path, trials: int) -> dict:
    counts = {"computed": 0, "refused": 0, "found": 0}
    for i in range(trials):
        out = tmp_path / f"t{i}" / "s.nc"
        out.parent.mkdir()
        ends = two_writers(out)
        assert ends.count("computed") == 1 and set(ends) <= {"computed", "refused", "found"}, ends
        for end in ends:
            counts[end] += 1
        assert_same_results("sweep", clean, read_output("sweep", out))
    return counts


def test_two_sweeps_on_one_output(clean, tmp_path):
    counts = check_trials(clean, tmp_path, 2)
    assert counts["refused"] >= 1, counts  # they did overlap, and the second was refused


@pytest.mark.slow
def test_two_sweeps_on_one_output_20_times(clean, tmp_path):
    counts = check_trials(clean, tmp_path, 20)
    print(f"20 trials of two concurrent sweeps: {counts}; every final file equal to the clean run")
