"""Expressions of named parameters (stickslip.model.expressions): values against Python's own
float arithmetic and math functions, and every construct outside the grammar refused."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from stickslip.errors import StickSlipError
from stickslip.model.expressions import MAX_DEPTH, MAX_LENGTH, ExpressionError, parse_expression

NAMES = ("V", "k1", "kc")
VALUES = {"V": 0.2, "k1": 50.0, "kc": 3.5}


def value(text, values=VALUES):
    return parse_expression(text, NAMES)(values)


@pytest.mark.parametrize("text, expected", [
    ("V", 0.2), ("k1 + kc", 53.5), ("-kc", -3.5), ("+kc", 3.5), ("k1 - kc * 2", 43.0), ("(k1 - kc) * 2", 93.0),
    ("k1 / 4", 12.5), ("2 ** 3", 8.0), ("2 ** -1", 0.5), ("-2 ** 2", -4.0), ("(-2) ** 2", 4.0), ("2 ** 3 ** 2", 512.0),
    ("sqrt(16)", 4.0), ("exp(0)", 1.0), ("sin(0)", 0.0), ("cos(0)", 1.0), ("cos(pi)", -1.0), ("pi", math.pi),
    ("1e-3 * k1", 0.05), ("  V  ", 0.2), ("3", 3.0),
])
def test_values(text, expected):
    result = value(text)
    assert type(result) is float and result == expected


def test_names_used():
    assert parse_expression("k1 + kc * sqrt(pi)", NAMES).names == frozenset({"k1", "kc"})
    assert parse_expression("2", NAMES).names == frozenset()


@pytest.mark.parametrize("text, words", [
    ("V*", "syntax error"), ("", "syntax error"), ("V; 1", "syntax error"), ("V = 1", "syntax error"),
    ("W + 1", "unknown name 'W'"), ("__import__('os').system('true')", "not a function"),
    ("math.pi", "not allowed"), ("V.real", "not allowed"), ("V if V else kc", "not allowed"), ("V < 1", "not allowed"),
    ("[V]", "not allowed"), ("'V'", "is not a number"), ("True", "is not a number"), ("1j", "is not a number"),
    ("V // 2", "operator //"), ("V % 2", "operator %"), ("not V", "operator not"), ("V and kc", "operator and"),
    ("sqrt(1, 2)", "one argument"), ("sqrt()", "one argument"), ("sin(x=1)", "one argument"),
    ("sqrt(*[1])", "one argument"), ("log(2)", "not a function"), ("sqrt", "is a function"),
    ("lambda: 1", "not allowed"), ("1e999", "not finite"), ("V" * (MAX_LENGTH + 1), f"longer than {MAX_LENGTH}"),
    ("-" * (MAX_DEPTH + 5) + "1", f"more than {MAX_DEPTH} levels"), ("(" * 300 + "1" + ")" * 300, "syntax error"),
])
def test_refused(text, words):
    with pytest.raises(ExpressionError) as info:
        parse_expression(text, NAMES)
    message = str(info.value)
    assert "\n" not in message
    assert words in message, message
    assert isinstance(info.value, StickSlipError)


@pytest.mark.parametrize("text, values, words", [
    ("1 / (V - 0.2)", VALUES, "divides by zero"), ("sqrt(V - 1)", VALUES, "outside its domain"),
    ("(-8) ** (1 / 3)", VALUES, "outside its domain"), ("0 ** -1", VALUES, "outside its domain"),
    ("exp(1000)", VALUES, "overflows"), ("10 ** 400", VALUES, "overflows"), ("1e308 * k1", VALUES, "not finite"),
    ("1e308 * k1 - 1e308 * k1", VALUES, "not finite"),
])
def test_evaluation_refused(text, values, words):
    expression = parse_expression(text, NAMES)
    with pytest.raises(ExpressionError, match=words):
        expression(values)


# --------------------------------------------------------------------------- against Python's arithmetic
OPS = ("+", "-", "*", "/", "**")
FUNCS = ("sqrt", "exp", "sin", "cos")


@st.composite
def trees(draw, depth=0):
    """Random expression text; every literal written as a float."""
    kind = draw(st.sampled_from(["leaf", "leaf", "binary", "unary", "call"] if depth < 5 else ["leaf"]))
    if kind == "leaf":
        return draw(st.one_of(st.sampled_from(NAMES + ("pi",)),
                              st.floats(0.0, 1e3, allow_nan=False).map(lambda x: repr(float(x)))))
    if kind == "binary":
        return f"({draw(trees(depth + 1))} {draw(st.sampled_from(OPS))} {draw(trees(depth + 1))})"
    if kind == "unary":
        return f"-({draw(trees(depth + 1))})"
    return f"{draw(st.sampled_from(FUNCS))}({draw(trees(depth + 1))})"


def oracle(text, values):
    """Python's own evaluation of ``text`` (the test's independent evaluator; literals are floats).
    None where Python raises or gives no finite real number."""
    namespace = {"__builtins__": {}, "pi": math.pi, **{f: getattr(math, f) for f in FUNCS}, **values}
    try:
        result = eval(text, namespace)  # the test's reference evaluator, on text the test generated
    except (ZeroDivisionError, OverflowError, ValueError, TypeError):  # TypeError: a complex power into math.*
        return None
    if isinstance(result, complex) or not math.isfinite(result):
        return None
    return result


@settings(max_examples=400, deadline=None)
@given(text=trees(), values=st.fixed_dictionaries({n: st.floats(-1e3, 1e3, allow_nan=False) for n in NAMES}))
def test_any_expression_equals_python_arithmetic(text, values):
    expected = oracle(text, values)
    expression = parse_expression(text, NAMES)
    if expected is None:
        with pytest.raises(ExpressionError):
            expression(values)
    else:
        assert expression(values) == expected
