"""Arithmetic expressions of named parameters, for the numbers of model files.

A model file's ``[parameters]`` table names numbers (``V = 0.2``); a string where a number goes is
an expression of them (``drive = ["V"]``, ``stiffness = [["k1 + kc", "-kc"], ...]``). The grammar:

    expression := number | name | pi | expression op expression | - expression | + expression
                | ( expression ) | function ( expression )
    op         := + - * / **
    function   := sqrt exp sin cos

Numbers are floats (``2`` is 2.0). The text is parsed once with :mod:`ast` and only the node
types above are accepted (never ``eval``); the accepted tree is turned into nested closures that
evaluate it from a mapping of parameter values. Evaluation refuses a division by zero, a math
domain error (``sqrt(-1)``, ``(-8) ** (1/3)``), an overflow and a result that is not finite.
"""

from __future__ import annotations

import ast
import dataclasses
import math
import numbers
import operator
from typing import Callable, Collection, Mapping

from ..errors import ExpressionError

__all__ = ["Expression", "ExpressionError", "FUNCTIONS", "CONSTANTS", "RESERVED", "MAX_LENGTH", "MAX_DEPTH",
           "parse_expression", "grammar", "finite_number"]

#: Functions an expression may call (one argument each).
FUNCTIONS: dict[str, Callable[[float], float]] = {"sqrt": math.sqrt, "exp": math.exp, "sin": math.sin, "cos": math.cos}

#: Named constants.
CONSTANTS = {"pi": math.pi}

#: Names a parameter cannot take (they mean a function or a constant in an expression).
RESERVED = frozenset(FUNCTIONS) | frozenset(CONSTANTS)

#: Longest expression text [characters]: a model file's formula is one short line; the limit keeps
#: the parser away from pathological input (megabytes of text, deeply nested parentheses).
MAX_LENGTH = 1000

#: Deepest accepted expression tree [nodes]: hand-written formulas are a few levels deep; the limit
#: keeps the recursive evaluation far inside Python's recursion limit (1000 frames).
MAX_DEPTH = 100

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: math.pow}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}


def finite_number(value) -> float:
    """``value`` (a real number such as an int, float or numpy scalar; not a bool) as a finite float.

    Raises
    ------
    ExpressionError
        Saying what ``value`` is instead: not a number, too large for a float, or not finite.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ExpressionError("is not a number")
    try:
        number = float(value)
    except OverflowError:
        raise ExpressionError("is too large for a float (above 1e308)") from None
    if not math.isfinite(number):
        raise ExpressionError("is not finite")
    return number


def grammar(names: Collection[str]) -> str:
    """The fix every expression error ends with: what an expression may use."""
    listed = ", ".join(names) if names else "(none: add a [parameters] table, e.g. V = 0.2)"
    return f"use + - * / ** ( ) sqrt exp sin cos pi and the names in [parameters]: {listed}"


@dataclasses.dataclass(frozen=True, eq=False)
class Expression:
    """A parsed expression.

    Attributes
    ----------
    text : str
        The expression as written.
    names : frozenset of str
        The parameters it uses.
    """

    text: str
    names: frozenset
    _evaluate: Callable[[Mapping[str, float]], float] = dataclasses.field(repr=False)

    def __call__(self, values: Mapping[str, float]) -> float:
        """The value for parameter values ``values`` (every name in :attr:`names` must be there).

        Raises
        ------
        ExpressionError
            For a division by zero, a math domain error, an overflow or a result that is not finite.
        """
        try:
            value = self._evaluate(values)
        except ZeroDivisionError:
            raise ExpressionError("it divides by zero") from None
        except OverflowError:
            raise ExpressionError("it overflows (a result beyond 1e308)") from None
        except ValueError:
            raise ExpressionError("a function or power is outside its domain (e.g. sqrt of a negative number, "
                                  "0 ** -1 or a negative number to a fractional power)") from None
        if not math.isfinite(value):
            raise ExpressionError(f"its value {value} is not finite")
        return value


def parse_expression(text: str, names: Collection[str]) -> Expression:
    """Parse ``text`` as an expression of the parameters ``names``.

    Raises
    ------
    ExpressionError
        Saying what is wrong (syntax, an operation or a name that is not allowed, an unknown name).
    """
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"it is longer than {MAX_LENGTH} characters")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as exc:
        raise ExpressionError(f"syntax error ({exc.msg})") from None
    except (RecursionError, MemoryError, ValueError):
        raise ExpressionError("it cannot be parsed (nested too deeply or a number too long)") from None
    used: set[str] = set()
    evaluate = _compile(tree.body, frozenset(names), used, 0)
    return Expression(text, frozenset(used), evaluate)


def _compile(node: ast.AST, names: frozenset, used: set, depth: int) -> Callable[[Mapping[str, float]], float]:
    """Closure evaluating ``node`` from the parameter values; refuses any node outside the grammar."""
    if depth > MAX_DEPTH:
        raise ExpressionError(f"it is nested more than {MAX_DEPTH} levels deep")
    if isinstance(node, ast.Constant):
        try:
            number = finite_number(node.value)
        except ExpressionError as exc:
            raise ExpressionError(f"{_describe(node)} {exc}") from None
        return lambda values: number
    if isinstance(node, ast.Name):
        if node.id in CONSTANTS:
            constant = CONSTANTS[node.id]
            return lambda values: constant
        if node.id in FUNCTIONS:
            raise ExpressionError(f"{node.id} is a function; call it, e.g. {node.id}(x)")
        if node.id not in names:
            raise ExpressionError(f"unknown name {node.id!r}")
        used.add(node.id)
        name = node.id
        return lambda values: values[name]
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        op = _BINARY[type(node.op)]
        left = _compile(node.left, names, used, depth + 1)
        right = _compile(node.right, names, used, depth + 1)
        return lambda values: op(left(values), right(values))
    if isinstance(node, ast.UnaryOp) and type(node.op) in _UNARY:
        op = _UNARY[type(node.op)]
        operand = _compile(node.operand, names, used, depth + 1)
        return lambda values: op(operand(values))
    if isinstance(node, ast.Call):
        func = node.func.id if isinstance(node.func, ast.Name) else None
        if func not in FUNCTIONS:
            raise ExpressionError(f"{ast.unparse(node.func)}(...) is not a function here")
        if len(node.args) != 1 or node.keywords or isinstance(node.args[0], ast.Starred):
            raise ExpressionError(f"{func} takes one argument, e.g. {func}(x)")
        function = FUNCTIONS[func]
        argument = _compile(node.args[0], names, used, depth + 1)
        return lambda values: function(argument(values))
    raise ExpressionError(f"{_describe(node)} is not allowed")


def _describe(node: ast.AST) -> str:
    """What a refused node is, for the message (the operator's symbol, or the node's source)."""
    if isinstance(node, (ast.BinOp, ast.UnaryOp, ast.BoolOp)):
        symbol = {ast.FloorDiv: "//", ast.Mod: "%", ast.MatMult: "@", ast.BitAnd: "&", ast.BitOr: "|",
                  ast.BitXor: "^", ast.LShift: "<<", ast.RShift: ">>", ast.Invert: "~", ast.Not: "not",
                  ast.And: "and", ast.Or: "or"}.get(type(node.op), type(node.op).__name__)
        return f"the operator {symbol}"
    try:
        source = ast.unparse(node)
    except (RecursionError, ValueError):
        source = type(node).__name__
    return repr(source if len(source) <= 40 else source[:37] + "...")
