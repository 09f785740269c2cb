"""Commands imported when asked for (:mod:`stickslip.cli._lazy`): the top-level options and the
list of commands import none of the computing stack, every command is still there, and the list
shows each command's own help line."""

import importlib
import json
import subprocess
import sys
import textwrap
import types

import pytest
import typer.main
from typer.testing import CliRunner

from stickslip.cli import app
from stickslip.cli._lazy import COMMANDS, import_all

#: Modules a command computes with; none is needed to print the version or the list of commands.
HEAVY = ["numpy", "scipy", "numba", "xarray", "matplotlib", "dask", "stickslip.model", "stickslip.integrate"]

SCRIPT = textwrap.dedent("""
    import json, sys
    from stickslip.cli import app
    try:
        app(sys.argv[1:])
    except SystemExit as exc:
        code = exc.code
    heavy = %r
    print(json.dumps({"code": code, "loaded": [name for name in heavy if name in sys.modules]}), file=sys.stderr)
""")


def _imports_of(*args: str) -> dict:
    run = subprocess.run([sys.executable, "-c", SCRIPT % (HEAVY,), *args], capture_output=True,
                         text=True, timeout=120)
    return json.loads(run.stderr.strip().splitlines()[-1])


def test_version_and_help_import_nothing_heavy():
    for args in (["--version"], ["--help"]):
        seen = _imports_of(*args)
        assert seen == {"code": 0, "loaded": []}, args


def test_the_list_of_models_builds_no_model():
    seen = _imports_of("models")
    assert seen["code"] == 0
    # the packages stickslip.model and .integrate without their modules: the library's table of contents
    assert not set(seen["loaded"]) & {"numpy", "scipy", "numba", "xarray", "matplotlib", "dask"}


def test_a_command_imports_its_module_when_it_runs():
    seen = _imports_of("models", "belt")
    assert seen["code"] == 0 and "stickslip.model" in seen["loaded"]


def test_the_table_lists_every_command_with_its_own_help_line():
    import_all()
    group = typer.main.get_command(app)
    built = {name: group.commands[name] for name in group.commands}
    assert set(built) == set(COMMANDS)  # registered in import order; listed in the table's order
    assert group.list_commands(None) == list(COMMANDS)
    for name, command in built.items():
        module = command.callback.__module__ if command.callback else None
        first_paragraph = " ".join(command.help.split("\n\n")[0].split())
        assert first_paragraph == COMMANDS[name].line, name
        if module is not None:  # a group (``study``) registers no callback of its own
            assert module == f"stickslip.cli.{COMMANDS[name].module}", name


def test_help_lines_and_typos_as_before():
    runner = CliRunner()
    listing = runner.invoke(app, ["--help"], env={"COLUMNS": "200"})
    assert listing.exit_code == 0
    for name in COMMANDS:
        assert f" {name} " in listing.output
    typo = runner.invoke(app, ["simulat"])
    assert typo.exit_code == 2 and "Did you mean 'simulate'?" in typo.output


#: Packages whose public names are imported on first use (:func:`stickslip._startup.export_on_first_use`).
LAZY_PACKAGES = ["stickslip", "stickslip.model", "stickslip.stability", "stickslip.analysis", "stickslip.integrate",
                 "stickslip.orbits", "stickslip.attractors"]


@pytest.mark.parametrize("package", LAZY_PACKAGES)
def test_every_public_name_of_a_package_imported_on_first_use_is_there(package):
    module = importlib.import_module(package)
    for name in module.__all__:
        value = getattr(module, name)
        assert not isinstance(value, types.ModuleType), f"{package}.{name}"
    assert set(module._EXPORTS) <= set(module.__all__)  # the table holds public names only
    assert dir(module) == sorted(module.__all__)


def test_a_function_named_like_its_module_stays_the_function_whichever_is_imported_first():
    script = textwrap.dedent("""
        import json, sys
        import stickslip.analysis.classify, stickslip.stability.equilibrium, stickslip.stability.maps
        import stickslip.model.library
        from stickslip.analysis import classify, intensity
        from stickslip.stability import equilibrium
        import stickslip
        values = [classify, intensity, equilibrium, stickslip.stability, stickslip.model.library]
        print(json.dumps([type(v).__name__ for v in values]))
    """)
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout) == ["function"] * 5
