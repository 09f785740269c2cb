"""Corrupted journals: a record that is torn, fails its checksum or carries an index that is not
an integer in range is dropped and its work computed again, never trusted; a journal whose header
cannot be read, of other settings or of an earlier format is refused in one line naming the fix."""

from __future__ import annotations

import json
import zlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from stickslip.cli import app

runner = CliRunner()


def one_line(res) -> str:
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert res.exit_code == 2, res.output
    assert len(lines) == 1 and lines[0].startswith("error:") and "Traceback" not in res.output, res.output
    return lines[0]


# ----------------------------------------------------------------------------- rows (sweeps, basins)
def _basins_journal(out, n: int = 4):
    """A basins journal of ``n`` states of the belt, with rows 0, 1, ... (no computing)."""
    from stickslip.basins import box
    from stickslip.basins.spec import build_spec
    from stickslip.basins.store import Journal
    from stickslip.model.library import load_model

    belt = load_model("belt")
    spec = build_spec(belt, box(belt, {"x": (-2.0, 2.0)}, n=n), param=None, values=())
    rows = np.arange(n * spec.row_width, dtype=float).reshape(n, -1) / 7.0
    journal = Journal(out, spec)
    journal.append(np.arange(n), rows)
    journal.close()
    return spec, rows, journal.path


def _set_index(path, record: int, value: float, *, forge: bool) -> None:
    """Replace the index of ``record``; ``forge``: recompute its check word too (only the index
    checks can catch it then), else leave the end of the record intact."""
    size = path.stat().st_size
    raw = np.frombuffer(path.read_bytes(), dtype=np.uint8).reshape(-1, size // 4).copy()
    raw[record, :8] = np.array([value], dtype="<f8").view(np.uint8)
    if forge:
        from stickslip.journal import ROW_MAGIC

        word = (ROW_MAGIC << 32) | zlib.crc32(raw[record, :-8].tobytes())
        raw[record, -8:] = np.array([word], dtype="<u8").view(np.uint8)
    path.write_bytes(raw.tobytes())


@pytest.mark.parametrize("value", [-1.0, 0.7, 1e6, float("nan")])
@pytest.mark.parametrize("forge", [False, True])
def test_a_row_with_a_bad_index_is_dropped(value, forge, tmp_path):
    """Before: index 0.7 gave state 0 the row of state 3 (a wrong label, exit 0), -1 marked the
    last state done, 1e6 raised IndexError."""
    from stickslip.basins.store import Journal

    out = tmp_path / "b.nc"
    spec, rows, path = _basins_journal(out)
    _set_index(path, 3, value, forge=forge)
    journal = Journal(out, spec)
    idx, kept = journal.read()
    journal.close()
    assert idx.tolist() == [0, 1, 2] and np.array_equal(kept, rows[:3])


def test_a_zeroed_row_is_dropped_not_read_as_state_0(tmp_path):
    from stickslip.basins.store import Journal

    out = tmp_path / "b.nc"
    spec, rows, path = _basins_journal(out)
    data = bytearray(path.read_bytes())
    record = len(data) // 4
    data[2 * record:3 * record - 8] = bytes(record - 8)  # its end left as it was
    path.write_bytes(bytes(data))
    journal = Journal(out, spec)
    idx, kept = journal.read()
    journal.close()
    assert idx.tolist() == [0, 1, 3] and np.array_equal(kept, rows[[0, 1, 3]])
    assert path.stat().st_size == 3 * record  # rewritten without it: appends go on after good records


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(byte=st.integers(0, 4 * 8 * 1000), bit=st.integers(0, 7))
def test_one_flipped_bit_drops_exactly_its_record(tmp_path, byte, bit):
    from stickslip.basins.store import Journal

    out = tmp_path / f"b{byte}-{bit}.nc"
    spec, rows, path = _basins_journal(out)
    data = bytearray(path.read_bytes())
    byte %= len(data)
    data[byte] ^= 1 << bit
    path.write_bytes(bytes(data))
    journal = Journal(out, spec)
    idx, kept = journal.read()
    journal.close()
    hit = byte // (len(data) // 4)
    assert idx.tolist() == [i for i in range(4) if i != hit] and np.array_equal(kept, np.delete(rows, hit, 0))


def test_a_study_resumed_from_a_corrupted_journal_has_the_clean_labels(tmp_path):
    """End to end: a zeroed record (its end left as it was) is computed again, and the labels equal
    those of an uninterrupted run (before: it was read as state 0, one label differed, exit 0)."""
    from stickslip.basins import basin_stability, box
    from stickslip.basins.store import journal_dir
    from stickslip.model.library import load_model

    belt = load_model("belt")
    states = box(belt, {"x": (-2.0, 2.0), "dx": (-2.0, 2.0)}, n=60, seed=5)
    clean = basin_stability(belt, states, out=tmp_path / "clean.nc", executor="serial").to_xarray()
    out = tmp_path / "b.nc"
    basin_stability(belt, states, out=out, executor="serial", keep_journal=True)
    out.unlink()
    path = journal_dir(out) / "rows.f64"
    data = bytearray(path.read_bytes())
    record = len(data) // 60
    data[10 * record:11 * record - 8] = bytes(record - 8)
    path.write_bytes(bytes(data))
    res = basin_stability(belt, states, out=out, executor="serial")
    assert res.timings["states_resumed"] == 59 and res.timings["states_computed"] == 1
    ds = res.to_xarray()
    assert np.array_equal(ds["label"].values, clean["label"].values)
    assert np.array_equal(ds["fraction"].values, clean["fraction"].values)


@pytest.mark.parametrize("command, what", [
    (["sweep", "--model", "belt", "--grid", "contact.0.drive=0.5,1", "--t-end", "5", "--executor", "serial"],
     "sweep"),
    (["basins", "--model", "belt", "--box", "x=-2:2", "--n", "4", "--t-end", "20", "--executor", "serial"],
     "basins"),
])
@pytest.mark.parametrize("manifest", [b"\xff\xfe not text", b'{"format": "stickslip-journal-2", ', b"[1, 2]"])
def test_a_corrupt_manifest_is_one_line_and_overwrite_starts_over(command, what, manifest, tmp_path):
    """Before: a JSONDecodeError or UnicodeDecodeError traceback."""
    out = tmp_path / "o.nc"
    (tmp_path / "o.nc.journal").mkdir()
    (tmp_path / "o.nc.journal" / "manifest.json").write_bytes(manifest)
    args = [*command, "--no-plot", "--no-progress", "--out", str(out)]
    line = one_line(runner.invoke(app, args))
    assert "o.nc.journal is corrupt" in line and "--overwrite" in line
    res = runner.invoke(app, args + ["--overwrite"])
    assert res.exit_code == 0, res.output
    assert out.exists() and not (tmp_path / "o.nc.journal").exists()


def test_a_journal_of_an_earlier_format_is_refused_in_one_line(tmp_path):
    from stickslip.sweep import SweepError
    from stickslip.sweep.spec import SweepSpec
    from stickslip.sweep.store import Journal

    spec = SweepSpec.build({"N": [10.0, 20.0]}, t_end=2.0)
    out = tmp_path / "s.nc"
    (tmp_path / "s.nc.journal").mkdir()
    (tmp_path / "s.nc.journal" / "manifest.json").write_text(
        json.dumps({"format": "stickslip-sweep-journal-1", "digest": spec.digest}))
    with pytest.raises(SweepError, match="earlier stickslip .format stickslip-sweep-journal-1.*--overwrite") as info:
        Journal(out, spec)
    assert "\n" not in str(info.value)
    Journal(out, spec, overwrite=True).remove()  # starting over is allowed
    assert not (tmp_path / "s.nc.journal").exists() and not (tmp_path / "s.nc.lock").exists()


# ----------------------------------------------------------------------------- lines (continuation, fold curves)
def _line_journal(out, n: int = 3):
    from stickslip.orbits.branch_store import Journal

    journal = Journal(out, "branch", "d1", {"a": 1})
    for k in range(n):
        journal.append({"point": k, "v": [k / 3.0, float("nan")]})
    journal.close()
    return journal.path


@pytest.mark.parametrize("junk", [b"null\n", b"[1, 2]\n", b'{"point": 9}\n', b"\x00\x00\x00\n"])
def test_a_bad_line_ends_the_records_read_back(junk, tmp_path):
    """Before: a `null` line was read back as a record and the resumed run raised TypeError."""
    from stickslip.orbits.branch_store import Journal

    out = tmp_path / "b.nc"
    path = _line_journal(out)
    lines = path.read_bytes().split(b"\n")
    path.write_bytes(b"\n".join(lines[:2]) + b"\n" + junk + b"\n".join(lines[2:]))  # after record 0
    journal = Journal(out, "branch", "d1", {"a": 1})
    assert [r["point"] for r in journal.records] == [0]  # a sequence: nothing after the bad line is used
    journal.append({"point": 1, "v": [1.0]})
    journal.close()
    again = Journal(out, "branch", "d1", {"a": 1})
    assert [r["point"] for r in again.records] == [0, 1]
    again.remove()


def test_a_continuation_journal_with_a_corrupt_header_says_so(tmp_path):
    """Before: "the journal of a different branch run (digest None vs ...)"."""
    from stickslip.orbits.branch_store import Journal, JournalMismatch

    out = tmp_path / "b.nc"
    path = _line_journal(out)
    path.write_bytes(b"{garbage\n" + path.read_bytes().split(b"\n", 1)[1])
    with pytest.raises(JournalMismatch, match="b.nc.journal is corrupt .* pass resume=False .--overwrite. to start "
                                              "over") as info:
        Journal(out, "branch", "d1", {"a": 1})
    assert "digest None" not in str(info.value) and "\n" not in str(info.value)
    assert not (tmp_path / "b.nc.lock").exists()  # the refusal released the lock
