"""Every command of docs/models.md runs as written: in a fresh folder holding the files the page
shows (a ```toml block whose first line is ``# NAME.toml``), each ``stickslip`` or ``python -m``
line of its ```bash blocks, in order, exits 0. The studies (sweep, continue, basins,
stability-map) take minutes on two cores and are marked slow."""

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from stickslip.cli import app

DOC = Path(__file__).resolve().parents[2] / "docs" / "models.md"
TEXT = DOC.read_text()

#: Files the page shows: ```toml blocks that start with "# NAME.toml".
FILES = dict(re.findall(r"```toml\n# (\S+\.toml)\n(.*?)```", TEXT, re.DOTALL))

#: The commands of the page's ```bash blocks, in order (comments and blank lines dropped).
COMMANDS = [args for block in re.findall(r"```bash\n(.*?)```", TEXT, re.DOTALL)
            for args in (shlex.split(line, comments=True) for line in block.replace("\\\n", " ").splitlines()) if args]

#: Commands that run a study (minutes on two shared cores with a cold compile cache).
STUDIES = ("sweep", "continue", "basins", "stability-map")


def test_the_page_shows_its_files_and_commands():
    assert "two-mass.toml" in FILES and len(COMMANDS) >= 10
    named = {arg for args in COMMANDS for arg in args if arg.endswith(".toml")}
    assert named <= set(FILES), f"commands use {named - set(FILES)} that the page does not show"


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A folder with the page's files, where the commands run in order (later ones read earlier outputs)."""
    path = tmp_path_factory.mktemp("models_doc")
    for name, text in FILES.items():
        (path / name).write_text(text)
    return path


def run(args, folder, monkeypatch):
    monkeypatch.chdir(folder)
    if args[0] == "python":
        res = subprocess.run([sys.executable, *args[1:]], check=False, capture_output=True, text=True, timeout=600)
        assert res.returncode == 0, res.stderr
        return
    assert args[0] == "stickslip", args
    res = CliRunner().invoke(app, args[1:])
    assert res.exit_code == 0, f"{shlex.join(args)}\n{res.output}"


@pytest.mark.parametrize("args", [pytest.param(a, marks=pytest.mark.slow) if a[1] in STUDIES else a
                                  for a in COMMANDS], ids=lambda a: " ".join(a[:4]))
def test_command_runs_as_written(args, folder, monkeypatch):
    run(args, folder, monkeypatch)
