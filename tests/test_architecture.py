"""The architecture as the code states it: the import-linter layers contract of pyproject.toml
holds, breaks on a deliberate violation, names at most two upward imports (each explained in
docs/architecture.md), and the package's modules import each other without cycles (module- and
function-level imports both count)."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import grimp

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"


def _lint(src: Path) -> subprocess.CompletedProcess:
    """lint-imports on the package found under ``src``, with the project's contract."""
    env = dict(os.environ, PYTHONPATH=str(src))
    return subprocess.run([sys.executable, "-c", "from importlinter.cli import lint_imports_command as c; c()",
                           "--config", str(ROOT / "pyproject.toml"), "--no-cache"],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)


def _contract() -> dict:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    (layers,) = [c for c in config["contracts"] if c["type"] == "layers"]
    return layers


def test_the_layers_contract_is_kept():
    res = _lint(SRC)
    assert res.returncode == 0, res.stdout + res.stderr
    assert "1 kept, 0 broken" in res.stdout


def test_a_deliberate_violation_breaks_the_contract(tmp_path):
    copy = tmp_path / "src"
    shutil.copytree(SRC / "stickslip", copy / "stickslip", ignore=shutil.ignore_patterns("__pycache__", "*.nb*"))
    (copy / "stickslip" / "model" / "violation.py").write_text("from ..cli import app  # a model importing the CLI\n")
    res = _lint(copy)
    assert res.returncode != 0
    assert "stickslip.model is not allowed to import stickslip.cli" in res.stdout
    assert "stickslip.model.violation -> stickslip.cli" in res.stdout


def test_at_most_two_imports_run_up_a_layer_and_each_is_explained():
    upward = _contract().get("ignore_imports", [])
    assert len(upward) <= 2
    architecture = (ROOT / "docs" / "architecture.md").read_text()
    for imp in upward:
        assert f"`{imp}`" in architecture, f"docs/architecture.md does not explain {imp}"


def test_no_import_cycles():
    graph = grimp.build_graph("stickslip", include_external_packages=False)
    modules = sorted(graph.modules)
    cycles = []
    for importer in modules:
        for imported in graph.find_modules_directly_imported_by(importer):
            chain = graph.find_shortest_chain(importer=imported, imported=importer)
            if chain is not None:
                cycles.append(" -> ".join((importer,) + tuple(chain)))
    assert not cycles, "\n".join(cycles[:10])


def test_the_layer_diagram_of_the_docs_is_the_contract():
    text = (ROOT / "docs" / "architecture.md").read_text()
    block = text.split("<!-- layers:", 1)[1].split("```", 2)[1]
    documented = [line.strip() for line in block.strip().splitlines()]
    contract = [" | ".join(m.strip().removeprefix("stickslip.") for m in layer.split("|"))
                for layer in _contract()["layers"]]
    assert documented == contract
