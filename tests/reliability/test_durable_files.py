"""The helpers of stickslip.files: the output lock, atomic replacement, durable appends, the loader."""

from __future__ import annotations

import errno
import json
import os
import signal
import socket
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from stickslip import files
from stickslip.files import AppendLog, FileFormatError, LockError, WriteError, atomic_write, lock, open_ours


_HOLDER = """
import sys, time
from stickslip.files import lock
held = lock(sys.argv[1])
print("held", flush=True)
time.sleep(120)
"""


def _holder(out: Path) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, "-c", _HOLDER, str(out)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "held"
    return proc


# ----------------------------------------------------------------------------- lock
def test_second_writer_is_refused_naming_the_holder_and_takes_over_when_it_dies(tmp_path):
    out = tmp_path / "s.nc"
    proc = _holder(out)
    try:
        with pytest.raises(LockError) as info:
            lock(out)
        message = str(info.value)
        assert f"process {proc.pid} on {socket.gethostname()}" in message and "\n" not in message
        assert "choose another output (--out)" in message
        holder = json.loads(files.lock_path(out).read_text())  # the failed attempt left the holder's record
        assert holder["pid"] == proc.pid
    finally:
        proc.send_signal(signal.SIGKILL)  # a holder that dies without releasing
        proc.wait()
    with lock(out) as held:  # its stale lock is taken over
        assert json.loads(held.path.read_text())["pid"] == os.getpid()
    assert not files.lock_path(out).exists()  # released: no lock file left beside the output


def test_lock_is_reentrant_in_a_thread_and_exclusive_between_threads(tmp_path):
    out = tmp_path / "s.nc"
    errors = []
    with lock(out):
        with lock(out):  # e.g. regions around sweep
            pass
        assert json.loads(files.lock_path(out).read_text())["pid"] == os.getpid()  # still ours

        def other():
            try:
                lock(out)
            except LockError as exc:
                errors.append(exc)

        t = threading.Thread(target=other)
        t.start()
        t.join()
    assert len(errors) == 1
    with lock(out):  # free again after the outer release
        pass


def test_dead_writers_temporaries_are_removed_when_the_lock_is_taken(tmp_path):
    out = tmp_path / "s.nc"
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    stale = tmp_path / f"s.{int(dead.stdout)}-0123abcd.tmp.nc"
    live = files.temporary_path(out)
    unrelated = tmp_path / "other.1-0123abcd.tmp.nc"
    for p in (stale, live, unrelated):
        p.write_text("x")
    with lock(out):
        pass
    assert not stale.exists() and live.exists() and unrelated.exists()


# ----------------------------------------------------------------------------- atomic replacement
def _failing_writer(fail_after: int, err: int = errno.ENOSPC):
    """A ``write(tmp)`` that writes ``fail_after`` bytes of new content, then fails like a full disk."""
    def write(tmp):
        with open(tmp, "wb") as fh:
            fh.write(b"n" * fail_after)
        raise OSError(err, os.strerror(err))
    return write


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(fail_after=st.integers(0, 5000), err=st.sampled_from([errno.ENOSPC, errno.EFBIG, errno.EDQUOT]))
def test_failed_atomic_write_leaves_the_old_file_and_no_temporary(tmp_path, fail_after, err):
    path = tmp_path / "a.nc"
    path.write_bytes(b"old content")
    with pytest.raises(WriteError, match="the disk or the file size limit is full") as info:
        atomic_write(path, _failing_writer(fail_after, err))
    assert "\n" not in str(info.value)
    assert path.read_bytes() == b"old content"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.nc"]


def test_other_errors_pass_through_unchanged(tmp_path):
    path = tmp_path / "a.nc"
    with pytest.raises(PermissionError):
        atomic_write(path, _failing_writer(10, errno.EACCES))
    assert list(tmp_path.iterdir()) == []


def test_atomic_write_replaces_the_whole_file(tmp_path):
    path = tmp_path / "a.txt"
    path.write_text("old")
    atomic_write(path, lambda tmp: tmp.write_text("new"))
    assert path.read_text() == "new" and sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


# ----------------------------------------------------------------------------- durable appends
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(records=st.lists(st.binary(min_size=1, max_size=200), min_size=1, max_size=5), torn=st.integers(0, 199))
def test_append_cut_short_by_a_full_disk_leaves_only_whole_records(tmp_path, monkeypatch, records, torn):
    path = tmp_path / f"log{len(list(tmp_path.iterdir()))}"
    log = AppendLog(path)
    for r in records[:-1]:
        log.append(r)
    real_write = os.write

    def full_disk(fd, data):  # writes part of the record, then the disk is full
        if fd == log._fd:
            real_write(fd, bytes(data[: min(torn, len(data) - 1)]))
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_write(fd, data)

    monkeypatch.setattr(files.os, "write", full_disk)
    with pytest.raises(WriteError, match="kept in"):
        log.append(records[-1])
    monkeypatch.setattr(files.os, "write", real_write)
    assert path.read_bytes() == b"".join(records[:-1])
    log.append(b"after")  # the log goes on from the last whole record
    assert path.read_bytes() == b"".join(records[:-1]) + b"after"
    log.close()


def test_ctrl_c_during_the_fsync_of_a_record_keeps_the_record(tmp_path, monkeypatch):
    """A Ctrl-C pressed while a finished point's record is being made durable is taken after it:
    the record stays and the interrupted run resumes from it."""
    path = tmp_path / "log"
    log = AppendLog(path)
    log.append(b"first")
    real_fsync = os.fsync

    def fsync_then_ctrl_c(fd):
        real_fsync(fd)
        os.kill(os.getpid(), signal.SIGINT)  # the handler runs before this function returns

    monkeypatch.setattr(files.os, "fsync", fsync_then_ctrl_c)
    with pytest.raises(KeyboardInterrupt):
        log.append(b"second")
    monkeypatch.setattr(files.os, "fsync", real_fsync)
    assert path.read_bytes() == b"firstsecond"
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    log.close()


# ----------------------------------------------------------------------------- the loader
@pytest.fixture(scope="module")
def sweep_file(tmp_path_factory):
    from stickslip.sweep import sweep

    out = tmp_path_factory.mktemp("sweep") / "s.nc"
    sweep({"N": [30.0, 50.0]}, out=out, executor="serial", t_end=2.0)
    return out


def _open_sweep(path):
    return open_ours(path, "sweep", what="a sweep file", versions=(1, 2))  # as load_sweep reads them


def test_loader_names_what_is_wrong(sweep_file, tmp_path):
    import xarray as xr

    cases = {"missing.nc": None, "text.nc": b"not a netcdf file", "empty.nc": b""}
    for name, content in cases.items():
        if content is not None:
            (tmp_path / name).write_bytes(content)
    with pytest.raises(FileFormatError, match="does not exist; give a sweep file"):
        _open_sweep(tmp_path / "missing.nc")
    with pytest.raises(FileFormatError, match="is not a stickslip NetCDF file .not NetCDF-4/HDF5: wrong signature"):
        _open_sweep(tmp_path / "text.nc")
    with pytest.raises(FileFormatError, match="not NetCDF-4/HDF5: empty"):
        _open_sweep(tmp_path / "empty.nc")
    xr.Dataset({"a": ("x", [1.0])}).to_netcdf(tmp_path / "foreign.nc", engine="h5netcdf")
    with pytest.raises(FileFormatError, match="is not a stickslip sweep file .format attribute None"):
        _open_sweep(tmp_path / "foreign.nc")
    with pytest.raises(FileFormatError, match="is a stickslip sweep file, not a stickslip branch file"):
        open_ours(sweep_file, "branch", what="a branch")
    newer = xr.load_dataset(sweep_file, engine="h5netcdf")
    newer.attrs["format"] = "stickslip-sweep-3"
    newer.to_netcdf(tmp_path / "newer.nc", engine="h5netcdf")
    with pytest.raises(FileFormatError, match="format version 3, which stickslip .* does not read .it reads 1, 2"):
        _open_sweep(tmp_path / "newer.nc")
    assert _open_sweep(sweep_file).attrs["complete"] == 1


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(keep=st.floats(0.0, 0.999))
def test_a_truncated_file_is_one_format_error(sweep_file, tmp_path, keep):
    data = sweep_file.read_bytes()
    cut = tmp_path / "cut.nc"
    cut.write_bytes(data[: int(keep * len(data))])
    with pytest.raises(FileFormatError) as info:
        _open_sweep(cut)
    assert "\n" not in str(info.value) and str(cut) in str(info.value)


# ----------------------------------------------------------------------------- the sweep journal
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(cut=st.floats(0.0, 1.0))
def test_a_journal_cut_anywhere_keeps_exactly_its_whole_records(sweep_file, tmp_path, cut):
    from stickslip.sweep.spec import SweepSpec
    from stickslip.sweep.store import Journal

    spec = SweepSpec.build({"N": [10.0, 20.0, 30.0, 40.0]}, t_end=2.0)
    out = tmp_path / f"j{len(list(tmp_path.iterdir()))}.nc"
    journal = Journal(out, spec)
    rows = np.arange(4 * spec.row_width, dtype=float).reshape(4, -1)
    journal.append(np.arange(4), rows)
    journal.close()
    size = journal.path.stat().st_size
    with open(journal.path, "r+b") as fh:
        fh.truncate(int(cut * size))
    whole = int(cut * size) // (8 * (spec.row_width + 2))
    reopened = Journal(out, spec)
    assert reopened.done_mask().tolist() == [i < whole for i in range(4)]
    kept = [r for _, r in reopened.blocks()]
    assert np.array_equal(np.concatenate(kept) if kept else np.empty((0, spec.row_width)), rows[:whole])
    reopened.close()
