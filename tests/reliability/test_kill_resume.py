"""kill -9 at random moments of every resumable command, then the same command again: the result
equals an uninterrupted run, and whatever the kill left is never a corrupt output."""

from __future__ import annotations

import random
import signal
import time

import pytest

from .helpers import COMMANDS, assert_same_results, command, leftovers, read_output, run, start

#: Kill moments as fractions of the clean run's wall time (seeded: a failure names its case).
_RNG = random.Random(20240611)
QUICK = {name: [_RNG.uniform(0.15, 0.6)] for name in COMMANDS}
MANY = {name: sorted(_RNG.uniform(0.05, 0.8) for _ in range(12)) for name in COMMANDS}


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """Uninterrupted runs: (dataset, wall seconds) per command. Each command runs once first to fill
    the compiled-kernel cache, so that the timed run (and the kill moments drawn from it) measures
    the command, not a one-off compilation."""
    results = {}
    for name in COMMANDS:
        warm = tmp_path_factory.mktemp(f"warm-{name}") / f"{name}.nc"
        assert run(command(name, warm)).returncode == 0
        out = tmp_path_factory.mktemp(f"clean-{name}") / f"{name}.nc"
        t = time.perf_counter()
        res = run(command(name, out))
        assert res.returncode == 0, res.stderr
        results[name] = (read_output(name, out), time.perf_counter() - t)
    return results


def kill_and_resume(name: str, fraction: float, clean, tmp_path) -> bool:
    """Kill ``name`` after ``fraction`` of its clean wall time, check what is left, resume, compare.
    Returns whether the kill landed before the command finished."""
    reference, wall = clean[name]
    out = tmp_path / f"{name}.nc"
    proc = start(command(name, out))
    time.sleep(fraction * wall)
    proc.send_signal(signal.SIGKILL)
    proc.communicate()
    killed = proc.returncode == -signal.SIGKILL
    if out.exists():  # a snapshot or the finished file: always complete and readable, never torn
        try:
            read_output(name, out)
        except Exception as exc:  # pragma: no cover - the failure this suite exists for
            pytest.fail(f"kill at {fraction:.2f} of the run left a corrupt {out.name}: {exc}")
    res = run(command(name, out))
    assert res.returncode == 0, res.stderr
    assert_same_results(name, reference, read_output(name, out))
    assert leftovers(out) == [], "journal, scratch or temporary files left after the resumed run"
    return killed


@pytest.mark.parametrize("name", list(COMMANDS))
def test_killed_command_resumes_to_the_clean_result(name, clean, tmp_path):
    killed = [kill_and_resume(name, f, clean, _sub(tmp_path, i)) for i, f in enumerate(QUICK[name])]
    assert any(killed), "no kill landed while the command ran"


@pytest.mark.slow
@pytest.mark.parametrize("name", list(COMMANDS))
def test_many_kills_resume_to_the_clean_result(name, clean, tmp_path):
    killed = [kill_and_resume(name, f, clean, _sub(tmp_path, i)) for i, f in enumerate(MANY[name])]
    print(f"{name}: {sum(killed)} of {len(killed)} kills landed while it ran; every resume equal to the clean run")


def _sub(tmp_path, i):
    path = tmp_path / f"trial{i}"
    path.mkdir()
    return path
