"""Functions a reader can hold: no function or method of the package is longer than
:data:`MAX_LINES` lines (its signature, docstring and body) or takes more than
:data:`MAX_POSITIONAL` positional parameters (``self`` and ``cls`` count); arrays that travel
together are bundled instead (``integrate/bundles.py``)."""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "stickslip"

MAX_LINES = 120
MAX_POSITIONAL = 12

def _functions(tree: ast.AST, prefix: str = ""):
    """(qualified name, node) of every function and method in ``tree``, nested ones included."""
    for node in ast.iter_child_nodes(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            yield prefix + node.name, node
            yield from _functions(node, f"{prefix}{node.name}.")
        elif isinstance(node, ast.ClassDef):
            yield from _functions(node, f"{prefix}{node.name}.")
        else:
            yield from _functions(node, prefix)


def _census(package: Path = PACKAGE) -> dict:
    """Every function over a limit: "path:name" -> (lines, positional parameters)."""
    over = {}
    for path in sorted(package.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for name, node in _functions(tree):
            lines = node.end_lineno - node.lineno + 1
            positional = len(node.args.posonlyargs) + len(node.args.args)
            if lines > MAX_LINES or positional > MAX_POSITIONAL:
                over[f"{path.relative_to(package).as_posix()}:{name}"] = (lines, positional)
    return over


def test_no_function_is_longer_than_120_lines_or_takes_more_than_12_positional_parameters():
    over = _census()
    assert not over, "over the limits (lines, positional parameters): " + ", ".join(
        f"{name} {size}" for name, size in sorted(over.items()))


def test_the_census_sees_a_long_function_and_a_long_signature(tmp_path):
    """The check itself: a function of 121 lines and a method of 13 positional parameters (``self``
    counted) are found, their neighbours within the limits are not."""
    body = "\n".join(f"    x{i} = {i}" for i in range(119))
    (tmp_path / "long.py").write_text(f"def long():\n{body}\n    return x0\n\n\ndef short():\n    return 1\n")
    args = ", ".join(f"a{i}" for i in range(12))
    (tmp_path / "wide.py").write_text(f"class C:\n    def wide(self, {args}):\n        return a0\n\n"
                                      f"    def narrow(self, {args[:-5]}):\n        return a0\n")
    assert _census(tmp_path) == {"long.py:long": (121, 0), "wide.py:C.wide": (2, 13)}
