"""Every public name of ``stickslip`` (``stickslip.__all__``) that takes arguments has a numpydoc
docstring whose Parameters section lists each of them; the API pages of the documentation site
are built from these docstrings."""

import inspect

import pytest

import stickslip

# numpydoc comes with the docs extra (pip install -e ".[docs]"); CI's documentation step runs this file
NumpyDocString = pytest.importorskip("numpydoc.docscrape", reason="needs the docs extra").NumpyDocString

#: Public names whose docstrings do not list their parameters yet, with the names they miss (e.g.
#: ``{"Name": "all"}`` while a module is being changed elsewhere); remove an entry once its
#: docstring is complete (the test fails on an entry that is no longer needed).
INCOMPLETE: dict[str, str] = {}


def public_callables():
    for name in stickslip.__all__:
        obj = getattr(stickslip, name)
        if callable(obj):
            yield name, obj


def parameters(obj):
    """The names a caller may pass (``self``, ``*args`` and ``**kwargs`` left out); none for an
    exception class that keeps ``Exception``'s signature (a message)."""
    try:
        sig = inspect.signature(obj)
    except ValueError:
        assert issubclass(obj, BaseException), obj
        return []
    return [p.name for p in sig.parameters.values() if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]


def listed(obj):
    """The names the docstring's Parameters and Other Parameters sections list."""
    doc = NumpyDocString(inspect.getdoc(obj) or "")
    names = set()
    for section in ("Parameters", "Other Parameters"):
        for item in doc[section]:
            names.update(n.strip().lstrip("*") for n in item.name.split(","))
    return names


def missing(obj):
    return [p for p in parameters(obj) if p not in listed(obj)]


@pytest.mark.parametrize("name, obj", list(public_callables()), ids=[n for n, _ in public_callables()])
def test_public_name_lists_its_parameters(name, obj):
    assert inspect.getdoc(obj), f"stickslip.{name} has no docstring"
    absent = missing(obj)
    if name in INCOMPLETE:
        assert absent, f"stickslip.{name} now lists its parameters: remove it from INCOMPLETE"
        pytest.skip(f"stickslip.{name}: its docstring does not list {absent} yet")
    assert not absent, f"stickslip.{name}: the numpydoc Parameters section does not list {absent}"


def test_every_public_name_is_on_an_api_page():
    from pathlib import Path

    pages = "\n".join(p.read_text() for p in (Path(__file__).parents[1] / "docs" / "api").glob("*.rst"))
    absent = [n for n in stickslip.__all__ if n != "__version__" and f":: {n}\n" not in pages]
    assert not absent, f"public names without an entry in docs/api/*.rst: {absent}"
