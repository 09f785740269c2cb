"""Initial states of a basin study: boxes, grids, CSV tables, and one-line errors for bad input."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from stickslip.basins import BasinError, box, from_csv, grid, parse_param, parse_range
from stickslip.model.library import load_model

BELT = load_model("belt")
PLATES_ROTATION = load_model("two-plates").replace(variant="rotation")


def test_box_draws_are_uniform_in_the_box_and_fixed_by_the_seed():
    spec = box(BELT, {"x": (-2, 2), "dx": (0, 1)}, n=4000, seed=3)
    s = spec.states(BELT, np.array([0.5]))
    assert s.shape == (4000, 2)
    assert s[:, 0].min() >= -2 and s[:, 0].max() <= 2 and s[:, 1].min() >= 0 and s[:, 1].max() <= 1
    # uniform: each quarter of the x range holds a quarter of the draws (binomial 5 sigma)
    counts = np.histogram(s[:, 0], bins=4, range=(-2, 2))[0]
    assert np.all(np.abs(counts - 1000) < 5 * np.sqrt(4000 * 0.25 * 0.75))
    again = box(BELT, {"x": (-2, 2), "dx": (0, 1)}, n=4000, seed=3).states(BELT, np.array([0.5]))
    other = box(BELT, {"x": (-2, 2), "dx": (0, 1)}, n=4000, seed=4).states(BELT, np.array([0.5]))
    assert np.array_equal(s, again) and not np.array_equal(s, other)


def test_states_outside_the_box_sit_at_the_base_state():
    spec = box(BELT, [("dx", -1, 1)], n=10)
    assert np.all(spec.states(BELT, np.array([0.52489])) [:, 0] == 0.52489)  # steady sliding q_e
    zero = box(BELT, [("dx", -1, 1)], n=10, base="zero").states(BELT, None)
    assert np.all(zero[:, 0] == 0.0)
    fixed = box(BELT, [("dx", -1, 1)], n=10, base="zero", fixed={"x": 0.3}).states(BELT, None)
    assert np.all(fixed[:, 0] == 0.3)


def test_grid_is_regular_with_ends_included_first_axis_slowest():
    spec = grid(BELT, {"x": (0, 1), "dx": (-1, 1)}, [3, 5], base="zero")
    s = spec.states(BELT, None)
    assert s.shape == (15, 2)
    assert np.allclose(s[:, 0].reshape(3, 5), [[0.0] * 5, [0.5] * 5, [1.0] * 5])
    assert np.allclose(s[:5, 1], [-1, -0.5, 0, 0.5, 1])
    assert [a.tolist() for a in spec.axes()] == [[0.0, 0.5, 1.0], [-1.0, -0.5, 0.0, 0.5, 1.0]]


def test_csv_rows_keep_their_order_and_columns_any_order(tmp_path):
    path = tmp_path / "ics.csv"
    path.write_text("dx,x\n0.1,0.2\n-1,3\n\n5e-1,-2\n")
    s = from_csv(BELT, path).states(BELT)
    assert np.array_equal(s, [[0.2, 0.1], [3.0, -1.0], [-2.0, 0.5]])


@pytest.mark.parametrize("make, words", [
    (lambda: box(BELT, {"z": (0, 1)}, n=5), "unknown state 'z' of model 'belt'; states are x, dx"),
    (lambda: box(BELT, {"x": (1, 1)}, n=5), "--box x=1:1: LO must be < HI"),
    (lambda: box(BELT, {"x": (2, 1)}, n=5), "LO must be < HI"),
    (lambda: box(BELT, {"x": (0, float("inf"))}, n=5), "must be finite"),
    (lambda: box(BELT, {"x": (0, 1)}, n=0), "--n 0: give the number of random states"),
    (lambda: box(BELT, {"x": (0, 1)}, n=-3), "--n -3"),
    (lambda: box(BELT, {}, n=5), "give at least one --box"),
    (lambda: box(BELT, {"x": (0, 1)}, n=5, base="far"), "--base far: choose one of equilibrium, zero"),
    (lambda: box(BELT, {"x": (0, 1)}, n=5, fixed={"x": 1.0}), "--state x is also a --box axis"),
    (lambda: grid(BELT, {"x": (0, 1)}, 1), "give >= 2 points per axis"),
    (lambda: grid(BELT, {"x": (0, 1), "dx": (0, 1)}, [3, 3, 3]), "give one count for every axis"),
    (lambda: box(PLATES_ROTATION, {"x1": (0, 1)}, n=5), "the DOF x1 is locked"),
    (lambda: parse_range("x=1"), "a range is LO:HI"),
    (lambda: parse_range("x=a:2"), "LO and HI must be numbers"),
    (lambda: parse_range("x"), "expects NAME=LO:HI"),
    (lambda: parse_param("contact.0.drive=2:1:5"), "LO must be < HI"),
    (lambda: parse_param("contact.0.drive=1:2:1"), "K must be 2 … 10000000 values"),
    (lambda: parse_param("contact.0.drive=1:2"), "PATH=LO:HI:K"),
])
def test_bad_states_are_one_line_errors(make, words):
    with pytest.raises(BasinError) as exc:
        make()
    assert words in str(exc.value) and "\n" not in str(exc.value)


@pytest.mark.parametrize("text, words", [
    ("x,dx\n1,2\n", None),
    ("x\n1\n", "column(s) dx missing from the header"),
    ("x,dx,y\n1,2,3\n", "column 'y' is not a state of model 'belt'"),
    ("x,x,dx\n1,2,3\n", "column 'x' appears twice"),
    ("x,dx\n1,2\n3\n", "row 3: 1 field(s), the header has 2"),
    ("x,dx\n1,2\n3,4,5\n", "row 3: 3 field(s)"),
    ("x,dx\n1,2\n3,abc\n", "row 3, column dx: 'abc' is not a number"),
    ("x,dx\nnan,1\n", "row 2, column x: nan is not a finite number"),
    ("x,dx\n", "a header but no states"),
    ("", "empty; the first line must name the states x,dx"),
])
def test_csv_errors_name_the_row_or_column(tmp_path, text, words):
    path = tmp_path / "ics.csv"
    path.write_text(text)
    if words is None:
        assert from_csv(BELT, path).size == 1
        return
    with pytest.raises(BasinError) as exc:
        from_csv(BELT, path)
    assert words in str(exc.value) and str(path) in str(exc.value) and "\n" not in str(exc.value)


def test_csv_refuses_a_locked_dof_and_a_missing_file(tmp_path):
    names = PLATES_ROTATION.state_names
    path = tmp_path / "p.csv"
    row = ["0"] * len(names)
    row[names.index("y1")] = "0.1"
    path.write_text(",".join(names) + "\n" + ",".join(row) + "\n")
    with pytest.raises(BasinError, match="row 2, column y1: 0.1 but that DOF is locked"):
        from_csv(PLATES_ROTATION, path)
    with pytest.raises(BasinError, match="no such file"):
        from_csv(BELT, tmp_path / "missing.csv")


@settings(max_examples=60, deadline=None)
@given(st.text(alphabet=st.characters(blacklist_categories=("Cs", "Cc", "Zl", "Zp"), blacklist_characters=',"'),
               max_size=12))
def test_any_cell_is_a_finite_number_or_a_one_line_error(tmp_path_factory, cell):
    path = tmp_path_factory.mktemp("csv") / "ics.csv"
    path.write_text(f"x,dx\n0,{cell}\n1,1\n", encoding="utf-8")
    try:
        expected = float(cell.strip())
    except ValueError:
        expected = None
    if expected is not None and np.isfinite(expected):
        assert from_csv(BELT, path).states(BELT)[0, 1] == expected
        return
    with pytest.raises(BasinError) as exc:
        from_csv(BELT, path)
    assert "row 2, column dx" in str(exc.value) and "\n" not in str(exc.value)
