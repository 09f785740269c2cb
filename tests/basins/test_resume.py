"""Nothing classified is lost: a study resumes from its journal after a torn write, a kill -9 or
Ctrl-C, to the labels of an uninterrupted run; one writer per output; a finished output is not
recomputed, and another study's output is not overwritten unless asked."""

import os
import signal
import threading
import time

import numpy as np
import pytest

from stickslip.basins import BasinError, basin_stability, box, load_basins
from stickslip.basins.store import journal_dir
from stickslip.files import LockError, OutputLock
from stickslip.model.library import load_model

from reliability.helpers import STICKSLIP, leftovers, run, start

BELT = load_model("belt")
STATES = box(BELT, {"x": (-2.0, 2.0), "dx": (-2.0, 2.0)}, n=400, seed=5)
#: The CLI study of the kill and Ctrl-C tests (a few seconds of work on 2 workers).
ARGS = ["basins", "--model", "belt", "--box", "x=-2:2", "--box", "dx=-2:2", "--n", "4000", "--seed", "2",
        "--workers", "2", "--no-plot", "--no-progress", "--json"]


def same_labels(a, b):
    """Per-state labels, the attractor names and the fractions identical; the cycles' features
    equal to the precision of the period rule (the reference run of a cycle may differ)."""
    assert list(a["attractor"].values) == list(b["attractor"].values)
    assert np.array_equal(a["label"].values, b["label"].values)
    assert np.array_equal(a["fraction"].values, b["fraction"].values)
    assert np.array_equal(a["count"].values, b["count"].values)
    assert np.allclose(a["period"].values, b["period"].values, rtol=1e-5, equal_nan=True)
    assert a.attrs["digest"] == b.attrs["digest"] and a.attrs["complete"] == b.attrs["complete"] == 1


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    out = tmp_path_factory.mktemp("clean") / "b.nc"
    return basin_stability(BELT, STATES, out=out, executor="serial").to_xarray()


def test_a_torn_journal_resumes_to_the_clean_labels(clean, tmp_path):
    out = tmp_path / "b.nc"
    basin_stability(BELT, STATES, out=out, executor="serial", keep_journal=True)
    rows = journal_dir(out) / "rows.f64"
    data = rows.read_bytes()
    record = len(data) // 400
    rows.write_bytes(data[:150 * record + record // 3])  # 150 whole records and a torn one
    out.unlink()
    res = basin_stability(BELT, STATES, out=out, executor="serial")
    assert res.timings["states_resumed"] == 150 and res.timings["states_computed"] == 250
    same_labels(res.to_xarray(), clean)
    assert not journal_dir(out).exists()


def test_a_finished_output_is_not_recomputed_and_another_study_is_refused(clean, tmp_path):
    out = tmp_path / "b.nc"
    basin_stability(BELT, STATES, out=out, executor="serial")
    again = basin_stability(BELT, STATES, out=out, executor="serial")
    assert again.timings["states_computed"] == 0
    same_labels(again.to_xarray(), clean)
    other = box(BELT, {"x": (-1.0, 1.0), "dx": (-2.0, 2.0)}, n=50)
    with pytest.raises(BasinError, match="holds a different basin study; pass overwrite=True"):
        basin_stability(BELT, other, out=out, executor="serial")
    assert basin_stability(BELT, other, out=out, executor="serial", overwrite=True).n == 50


def test_one_writer_per_output(tmp_path):
    out = tmp_path / "b.nc"
    with OutputLock(out):
        with pytest.raises(LockError, match="is being written by process"):
            # the lock is re-entrant within a thread: take it from another one
            errors = []
            t = threading.Thread(target=lambda: errors.append(_try(out)))
            t.start()
            t.join()
            raise errors[0]


def _try(out):
    try:
        basin_stability(BELT, STATES, out=out, executor="serial")
    except LockError as exc:
        return exc
    return AssertionError("a second writer was let in")


def test_ctrl_c_keeps_what_is_done_and_resumes(tmp_path):
    states = box(BELT, {"x": (-2.0, 2.0), "dx": (-2.0, 2.0)}, n=3000, seed=6)
    t = time.perf_counter()
    reference = basin_stability(BELT, states, out=tmp_path / "clean.nc", executor="serial").to_xarray()
    wall = time.perf_counter() - t
    out = tmp_path / "b.nc"
    # within the study however fast the machine: the same study took `wall` just before
    timer = threading.Timer(0.4 * wall, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        first = basin_stability(BELT, states, out=out, executor="serial", batch_size=20)
    finally:
        timer.cancel()
    if first.complete:
        pytest.skip("the study finished before the interrupt (machine too fast for this timing)")
    assert first.timings["interrupted"]
    partial = load_basins(out)
    done = int(partial.attrs["states_done"])
    assert 0 < done < 3000 and partial.attrs["complete"] == 0 and journal_dir(out).exists()
    assert np.all((partial["label"].values >= 0) == (partial["done"].values == 1))
    res = basin_stability(BELT, states, out=out, executor="serial")
    assert res.timings["states_resumed"] == done
    same_labels(res.to_xarray(), reference)


@pytest.fixture(scope="module")
def clean_cli(tmp_path_factory):
    warm = tmp_path_factory.mktemp("warm") / "w.nc"
    assert run([STICKSLIP, *ARGS, "--out", str(warm)]).returncode == 0
    out = tmp_path_factory.mktemp("clean-cli") / "b.nc"
    t = time.perf_counter()
    res = run([STICKSLIP, *ARGS, "--out", str(out)])
    assert res.returncode == 0, res.stderr
    return load_basins(out), time.perf_counter() - t


@pytest.mark.parametrize("fraction", [0.35, 0.7])
def test_kill_9_then_the_same_command_resumes_to_the_clean_result(clean_cli, tmp_path, fraction):
    reference, wall = clean_cli
    out = tmp_path / "b.nc"
    proc = start([STICKSLIP, *ARGS, "--out", str(out)])
    time.sleep(fraction * wall)
    proc.send_signal(signal.SIGKILL)
    proc.communicate()
    if out.exists():  # a snapshot or the finished file: whole and readable
        load_basins(out)
    res = run([STICKSLIP, *ARGS, "--out", str(out)])
    assert res.returncode == 0, res.stderr
    same_labels(load_basins(out), reference)
    assert leftovers(out) == []


def test_cli_ctrl_c_keeps_a_partial_result_and_resumes(clean_cli, tmp_path):
    reference, wall = clean_cli
    out = tmp_path / "b.nc"
    proc = start([STICKSLIP, *ARGS, "--out", str(out)])
    time.sleep(0.6 * wall)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    if proc.returncode == 0:
        pytest.skip("the command finished before the interrupt")
    assert proc.returncode == 130, stderr
    if "holds all 4000 states, classified" in stderr:  # the Ctrl-C came after the last batch: the study is whole
        assert load_basins(out).attrs["complete"] == 1 and leftovers(out) == []
        return
    assert "interrupted:" in stderr and "run the same command again to resume" in stderr
    assert "Traceback" not in stderr
    partial = load_basins(out)
    assert partial.attrs["complete"] == 0 and journal_dir(out).exists()
    res = run([STICKSLIP, *ARGS, "--out", str(out)])
    assert res.returncode == 0, res.stderr
    same_labels(load_basins(out), reference)
    assert leftovers(out) == []
