"""Property tests of option validation (hypothesis).

Every numeric option of ``simulate``, ``stability``, ``orbit``, ``sweep`` (``--grid`` and its run
options) and ``bifurcation`` (``--range``, ``--peaks``) is given non-finite, negative, zero, huge
and mistyped values. Whatever the value, the command either runs (exit 0), stops a run early
(exit 1), or refuses (exit 2), and then says so in exactly one ``error:`` line (other lines may
only be ``warning:`` lines); it never ends in a traceback. Values outside an option's domain
(non-finite, mistyped, negative for a non-negative option, zero for a positive one) must be
refused with exit 2. Some valid values make a run that does not end in reasonable time (φ
perturbed by 1e6 rad): after :data:`PATIENCE_S` the test presses Ctrl-C (SIGINT), and the
command must then end with exit 130 and one ``interrupted:`` line.

The CI variant runs one value of each kind per option plus a few random ones; the slow variant
(``pytest -m slow``) draws many. Huge values are 1e6 … 1e7 in CI and up to 1.7e308 in the slow
variant. A huge ``--perturb`` (either sign) is left to the slow variant: a run whose φ starts 1e6 rad away
takes minutes before its first chunk ends and Ctrl-C is honoured.
Set ``STICKSLIP_PROPERTY_COUNTS`` to a file name to get the number of inputs tried, by command
and kind, as JSON.
"""

import collections
import contextlib
import json
import math
import os
import signal
import tempfile
import threading

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from stickslip.cli import app

runner = CliRunner()

NON_FINITE = ["nan", "inf", "-inf", "NaN", "-Infinity", "1e999"]
ZERO = ["0", "-0", "0.0", "0e5"]
MISTYPED = ["abc", "", "1,2", "[red]", "a:b:c", ":smile:", "1e", "0x10", "--", "None", "1.2.3", " "]

#: (option, domain): ``pos`` > 0, ``nonneg`` ≥ 0, ``any`` finite; ``posint`` an integer ≥ 1.
SIMULATE = [("--N", "pos"), ("--omega", "any"), ("--mu-k", "nonneg"), ("--delta-mu", "nonneg"),
            ("--alpha", "nonneg"), ("--t-end", "pos"), ("--dt", "pos"), ("--rtol", "pos"), ("--atol", "pos"),
            ("--perturb", "any"), ("--sample-rate", "pos"), ("--steady-from", "nonneg"), ("--set k_px", "nonneg"),
            ("--set m_p", "pos")]
STABILITY = [("--N", "pos"), ("--omega", "any"), ("--mu-k", "nonneg"), ("--delta-mu", "nonneg"),
             ("--alpha", "nonneg"), ("--set k_py", "nonneg")]
ORBIT = [("--N", "pos"), ("--omega", "any"), ("--search-time", "pos"), ("--period-multiplicity", "posint"),
         ("--rtol", "pos"), ("--tol", "pos"), ("--slip-band", "pos")]
SWEEP = [("--t-end", "pos"), ("--sample-rate", "pos"), ("--t-from", "nonneg"), ("--rtol", "pos"), ("--atol", "pos")]
BIFURCATION = [("--peaks", "posint")]

#: The quick base of each command (a short run; outputs go to a fresh folder per input).
BASE = {
    "simulate": ["simulate", "--t-end", "0.05", "--sample-rate", "1000", "--json"],
    "stability": ["stability", "--json"],
    "orbit": ["orbit", "--search-time", "0.5", "--no-plot", "--json"],
    "sweep": ["sweep", "--t-end", "0.05", "--executor", "serial", "--no-plot", "--no-progress",
              "--json"],
    "bifurcation": ["bifurcation", "--range", "40,50", "--t-end", "0.05", "--executor", "serial", "--no-plot",
                    "--no-progress", "--json"],
}

TRIED = collections.Counter()

#: Seconds a command may run before the test interrupts it.
PATIENCE_S = 20.0


@contextlib.contextmanager
def ctrl_c_after(seconds: float):
    """Send SIGINT to this process after ``seconds`` unless the block has ended; a SIGINT that
    arrives after the block is ignored."""
    inside = [True]

    def handler(signum, frame):
        if inside[0]:
            raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, handler)
    timer = threading.Timer(seconds, lambda: inside[0] and os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        yield
    finally:
        inside[0] = False
        timer.cancel()
        signal.signal(signal.SIGINT, previous)


def kind(text: str, integer: bool = False) -> str:
    """``mistyped``, ``nonfinite``, ``negative``, ``zero`` or ``positive``."""
    try:
        x = int(text) if integer else float(text)
    except ValueError:
        return "mistyped"
    if not math.isfinite(x):
        return "nonfinite"
    return "negative" if x < 0 else ("zero" if x == 0 else "positive")


def refused_by_domain(text: str, domain: str) -> bool:
    k = kind(text, integer=domain == "posint")
    return k in ("mistyped", "nonfinite") or (k == "negative" and domain != "any") or (
        k == "zero" and domain in ("pos", "posint"))


def floats(huge: float):
    """Values of every kind as text; negative and huge ones up to ``huge`` in magnitude."""
    return st.one_of(st.sampled_from(NON_FINITE), st.floats(-huge, -1e-300).map(repr), st.sampled_from(ZERO),
                     st.floats(1e6, huge).map(repr), st.sampled_from(MISTYPED), st.text(max_size=6))


def integers():
    return st.one_of(st.sampled_from(["nan", "inf", "1.5", "1e3", "abc", ""]), st.integers(-10**30, -1).map(str),
                     st.just("0"), st.integers(10**12, 10**40).map(str), st.text(max_size=4))


def check(command: str, args: list, refused: bool, what: str) -> None:
    """Run ``command`` with ``args`` in a fresh folder; assert the outcome properties."""
    TRIED[f"{command} {what}"] += 1
    with tempfile.TemporaryDirectory() as folder:
        cwd = os.getcwd()
        os.chdir(folder)
        try:
            with ctrl_c_after(PATIENCE_S):
                res = runner.invoke(app, [*BASE[command], *args])
        finally:
            os.chdir(cwd)
    context = f"stickslip {' '.join(BASE[command] + args)}\n{res.output}"
    assert res.exception is None or isinstance(res.exception, SystemExit), context
    assert res.exit_code in (0, 1, 2, 130), context
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    if res.exit_code:
        first = "interrupted:" if res.exit_code == 130 else "error:"
        assert sum(ln.startswith(first) for ln in lines) == 1, context
        assert all(ln.startswith((first, "warning:")) for ln in lines), context
    TRIED[f"exit {res.exit_code}"] += 1
    if refused:
        assert res.exit_code == 2, context


def option_args(option: str, value: str) -> list:
    flag, _, name = option.partition(" ")
    return [flag, f"{name}={value}"] if name else [flag, value]


def range_text(parts: list) -> str:
    return ":".join(parts) if len(parts) == 3 else ",".join(parts)


def range_refused(parts: list) -> bool:
    """A range (start:stop:count) or list of N values that is certainly refused."""
    values = parts[:2] if len(parts) == 3 else parts
    if any(refused_by_domain(v, "pos") for v in values):
        return True
    return len(parts) == 3 and (kind(parts[2], integer=True) != "positive" or int(parts[2]) < 2)


def ranges(huge: float):
    value = floats(huge)
    counts = st.one_of(integers(), st.integers(2, 4).map(str))
    return st.one_of(st.lists(value, min_size=1, max_size=3), st.tuples(value, value, counts).map(list))


CI = settings(max_examples=3, derandomize=True, deadline=None, database=None,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
MANY = settings(max_examples=40, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
CI_HUGE, SLOW_HUGE = 1e7, 1.7e308

FLOAT_EXAMPLES = ("nan", "-1", "0", "1e6", "abc")


#: Options whose huge values are drawn only in the slow variant (see the module docstring).
SLOW_WHEN_HUGE = {("simulate", "--perturb")}


def _huge(text: str) -> bool:
    """A finite value of magnitude ≥ 1e6 (the huge values drawn)."""
    return kind(text) in ("positive", "negative") and abs(float(text)) >= 1e6


def _numeric(command: str, option: str, domain: str, value: str) -> None:
    grid = ["--grid", "N=50"] if command == "sweep" else []
    check(command, grid + option_args(option, value), refused_by_domain(value, domain),
          f"{option} {kind(value, integer=domain == 'posint')}")


@pytest.mark.parametrize("command, option, domain", [("simulate", *o) for o in SIMULATE]
                         + [("stability", *o) for o in STABILITY] + [("orbit", *o) for o in ORBIT]
                         + [("sweep", *o) for o in SWEEP] + [("bifurcation", *o) for o in BIFURCATION])
@CI
@given(value=st.data())
@example(value=None)
def test_numeric_options(command, option, domain, value):
    slow = (command, option) in SLOW_WHEN_HUGE
    if value is None:  # one value of each kind, always
        for text in (("nan", "-1", "0", "1000000000000", "1.5") if domain == "posint" else FLOAT_EXAMPLES):
            if not (slow and _huge(text)):
                _numeric(command, option, domain, text)
        return
    text = value.draw(integers() if domain == "posint" else floats(CI_HUGE))
    if not (slow and _huge(text)):
        _numeric(command, option, domain, text)


@pytest.mark.slow
@pytest.mark.parametrize("command, option, domain", [("simulate", *o) for o in SIMULATE]
                         + [("stability", *o) for o in STABILITY] + [("orbit", *o) for o in ORBIT]
                         + [("sweep", *o) for o in SWEEP] + [("bifurcation", *o) for o in BIFURCATION])
@MANY
@given(value=st.data())
def test_numeric_options_many(command, option, domain, value):
    _numeric(command, option, domain, value.draw(integers() if domain == "posint" else floats(SLOW_HUGE)))


GRID_EXAMPLES = (["nan"], ["-1", "50"], ["0"], ["1e6", "1e7"], ["abc"], ["10", "20", "0"], ["10", "20", "1e3"],
                 ["10", "20", "1000000000000"], ["30", "30", "3"], [""])


def _grid(command: str, name: str, parts: list) -> None:
    refused = range_refused(parts) if name == "N" else any(kind(p) in ("mistyped", "nonfinite") for p in parts[:2])
    text = range_text(parts)
    args = ["--grid", f"{name}={text}"] if command == "sweep" else ["--param", name, "--range", text]
    check(command, args, refused, f"{args[0]} {'range' if len(parts) == 3 else 'list'}")


@pytest.mark.parametrize("command, name", [("sweep", "N"), ("sweep", "Omega"), ("bifurcation", "N")])
@CI
@given(parts=st.data())
@example(parts=None)
def test_grid_and_range_values(command, name, parts):
    if parts is None:
        for fixed in GRID_EXAMPLES:
            _grid(command, name, list(fixed))
        return
    _grid(command, name, parts.draw(ranges(CI_HUGE)))


@pytest.mark.slow
@pytest.mark.parametrize("command, name", [("sweep", "N"), ("sweep", "Omega"), ("bifurcation", "N")])
@MANY
@given(parts=st.data())
def test_grid_and_range_values_many(command, name, parts):
    _grid(command, name, parts.draw(ranges(SLOW_HUGE)))


@pytest.fixture(scope="module", autouse=True)
def _counts():
    yield
    path = os.environ.get("STICKSLIP_PROPERTY_COUNTS")
    if path:
        with open(path, "a") as fh:
            fh.write(json.dumps(dict(sorted(TRIED.items()))) + "\n")
