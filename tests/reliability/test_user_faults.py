"""Faults an adversarial user found, each one line (or working) instead of a traceback or a
wrong result: seeds out of range, an ASCII console, numba's environment variables, a run file
continued with another model, a CSV with a byte-order mark, numbers of hundreds of digits quoted
as typed, and the numbering of the stability table."""

import os
import subprocess
import sys

import numpy as np
import pytest
from typer.testing import CliRunner

from stickslip.basins import from_csv
from stickslip.cli import app
from stickslip.cli._app import exact
from stickslip.model.library import load_model

runner = CliRunner()
BOXED = ["basins", "--model", "belt", "--box", "x=-1:1", "--n", "10", "--executor", "serial", "--no-progress"]


def one_line(res, code: int = 2) -> str:
    assert res.exit_code == code, res.output
    assert res.exception is None or isinstance(res.exception, SystemExit), res.exception
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1, res.output
    return lines[0]


def stickslip(*args, **env) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", "from stickslip.cli import app; app()", *args], capture_output=True,
                          text=True, timeout=300, env=dict(os.environ, **env))


@pytest.mark.parametrize("seed", ["-1", "99999999999999999999999", str(2**63)])
def test_a_seed_out_of_range_is_refused_before_anything_is_computed(seed, tmp_path):
    """(-1 was a ValueError traceback; 10^23 computed every state, then failed writing, every time.)"""
    line = one_line(runner.invoke(app, [*BOXED, "--seed", seed, "--out", str(tmp_path / "b.nc")]))
    assert line == f"error: --seed {seed}: give an integer 0 … 2^63 − 1"  # as typed, every digit
    assert not list(tmp_path.iterdir())


def test_the_largest_seed_runs(tmp_path):
    res = runner.invoke(app, [*BOXED, "--seed", str(2**63 - 1), "--out", str(tmp_path / "b.nc"), "--no-plot"])
    assert res.exit_code == 0, res.output


def test_an_ascii_console_prints_what_it_cannot_encode_as_question_marks(tmp_path):
    """(PYTHONIOENCODING=ascii was a UnicodeEncodeError traceback at the first '–'.)"""
    res = stickslip("simulate", "--model", "belt", "--t-end", "5", "--no-plot", "--out", str(tmp_path / "x.nc"),
                    PYTHONIOENCODING="ascii")
    assert res.returncode == 0 and "Traceback" not in res.stderr, res.stderr
    assert "time" in res.stdout and "0 ? 5 s" in res.stdout  # "0 – 5 s"


def test_an_invalid_numba_thread_count_is_ignored_with_a_warning():
    """(NUMBA_NUM_THREADS=0 was a ValueError traceback from inside numba's import.)"""
    res = stickslip("models", "belt", NUMBA_NUM_THREADS="0")
    assert res.returncode == 0, res.stderr
    assert res.stderr.strip() == ("warning: NUMBA_NUM_THREADS=0 is not a number of threads >= 1 and is ignored "
                                  "(stickslip runs no parallel numba code); unset it or give a number >= 1")


def test_numba_without_its_compiler_is_refused_in_one_line(tmp_path, monkeypatch):
    """(NUMBA_DISABLE_JIT=1 was an AttributeError traceback from packing the model.)"""
    monkeypatch.setenv("NUMBA_DISABLE_JIT", "1")
    line = one_line(runner.invoke(app, ["simulate", "--model", "belt", "--out", str(tmp_path / "x.nc")]))
    assert line.startswith("error: NUMBA_DISABLE_JIT=1: stickslip's kernels must be compiled")
    assert line.endswith("unset NUMBA_DISABLE_JIT or set it to 0") and not list(tmp_path.iterdir())


@pytest.fixture(scope="module")
def plates_run(tmp_path_factory):
    path = tmp_path_factory.mktemp("runs") / "plates.nc"
    assert runner.invoke(app, ["simulate", "--t-end", "2", "--no-plot", "--out", str(path)]).exit_code == 0
    return path


@pytest.mark.parametrize("model", ["belt", "x"])
def test_a_run_file_is_not_continued_with_another_model(model, plates_run, tmp_path):
    """(--ic plates.nc --model belt printed "overridden: --model" and ran the plates.)"""
    line = one_line(runner.invoke(app, ["simulate", "--ic", str(plates_run), "--model", model, "--t-end", "1",
                                        "--no-plot", "--out", str(tmp_path / "c.nc")]))
    assert line.startswith(f"error: --model {model}: {plates_run} is a run of model two-plates (full), and a run "
                           "continues its own model")
    assert not list(tmp_path.iterdir())


def test_naming_the_run_files_own_model_continues_it(plates_run, tmp_path):
    res = runner.invoke(app, ["simulate", "--ic", str(plates_run), "--model", "full", "--t-end", "1", "--no-plot",
                              "--out", str(tmp_path / "c.nc")])
    assert res.exit_code == 0, res.output
    assert f"continuing {plates_run} from t = 2 s" in res.output and "overridden" not in res.output


def test_a_csv_with_a_byte_order_mark_is_read(tmp_path):
    """(Spreadsheets save UTF-8 CSV with a BOM; the header's first name was refused.)"""
    belt = load_model("belt")
    path = tmp_path / "ics.csv"
    path.write_bytes("x,dx\n0.5,1\n-1,0\n".encode("utf-8-sig"))
    assert np.array_equal(from_csv(belt, path).table, [[0.5, 1.0], [-1.0, 0.0]])


def test_numbers_of_hundreds_of_digits_are_quoted_as_typed(tmp_path):
    line = one_line(runner.invoke(app, [*BOXED, "--n", "9" * 300, "--out", str(tmp_path / "b.nc")]))
    assert line == f"error: --n {'9' * 300}: give the number of random states, 1 … 10000000"


def test_a_set_value_beyond_a_float_is_refused_quoting_what_was_typed(tmp_path):
    digits = "12" * 200  # 400 digits: no float holds it
    line = one_line(runner.invoke(app, ["simulate", "--set", f"N={digits}", "--t-end", "1", "--json"]))
    assert line == (f"error: --set N={digits}: {digits} is beyond the range of a float (about ±1.8e308); "
                    "give a finite number")


def test_a_set_value_named_in_a_conflict_is_quoted_as_typed():
    digits = "1" + "2" * 56  # a float holds it, but not its digits
    line = one_line(runner.invoke(app, ["simulate", "--set", f"N={digits}", "--N", "5", "--t-end", "1", "--json"]))
    assert line == f"error: --set N={digits} and --N 5 both set N; give one of them"
    line = one_line(runner.invoke(app, ["simulate", "--set", digits, "--t-end", "1", "--json"]))
    assert line == f"error: --set expects NAME=VALUE, got '{digits}'; e.g. --set k_px=400"


@pytest.mark.parametrize("value, shown", [
    (50.0, "50"), (0.1, "0.1"), (1.0000001, "1.0000001"), (1e300, "1e+300"), (-2.5e-7, "-2.5e-07"), (12, "12"),
])
def test_an_options_value_is_quoted_to_its_last_digit(value, shown):
    assert exact(value) == shown
    assert float(shown) == value


def test_a_relative_tolerance_is_refused_with_the_value_given():
    """(``:g`` showed --rtol 1.0000001 as 1, the very value the message says is too large.)"""
    line = one_line(runner.invoke(app, ["orbit", "--tol", "1.0000001"]))
    assert line.startswith("error: --tol 1.0000001: a relative tolerance must be < 1")


@pytest.mark.parametrize("axes, start", [
    (["N=-1:2:3", "Omega=1:2:3"], "error: --axis N=-1:2:3: parameter N = -1.0 must be > 0"),
    (["N=1:2:3", "Omega=-1:1:3"], "error: --axis Omega=-1:1:3: Omega = 0 has no steady sliding"),
    (["foo=1:2:3", "N=1:2:3"], "error: --axis foo=1:2:3: unknown parameter(s) foo of model 'two-plates'"),
    (["N=1,2,x", "Omega=1:2:3"], "error: --axis N=1,2,x: give numbers separated by commas"),
])
def test_stability_map_axis_errors_name_the_axis(tmp_path, axes, start):
    args = ["stability-map", *[a for axis in axes for a in ("--axis", axis)], "--no-plot", "--out", str(tmp_path / "m.nc")]
    assert one_line(runner.invoke(app, args)).startswith(start)


def test_lyapunov_with_a_huge_transient_names_its_own_option(tmp_path):
    """(It said "lower sample_rate", an option lyapunov does not have, with a 300-digit count.)"""
    line = one_line(runner.invoke(app, ["lyapunov", "--model", "belt", "--t-transient", "1e300", "--no-plot",
                                        "--out", str(tmp_path / "l.nc")]))
    assert line == ("error: the transient (t_transient, --t-transient) of 1e+300 s at 200 Hz keeps 2e+302 samples, "
                    "more than the 2e+07 a run may keep; shorten the transient (t_transient, --t-transient) to at most "
                    "9.99e+04 s")


def test_the_stability_table_numbers_its_modes_from_one():
    """(The two modes of popp-stelter were numbered 0 and 2: the indices of their eigenvalues.)"""
    res = runner.invoke(app, ["stability", "--model", "popp-stelter"])
    assert res.exit_code == 0, res.output
    numbers = [ln.split("│")[1].strip() for ln in res.output.splitlines() if ln.startswith("│ ") and "x" in ln]
    assert numbers[-2:] == ["1", "2"], res.output
