"""The lists of library models that the README and load_model's docstring give name every model."""

import re
from pathlib import Path

from stickslip.model.library import library_names, load_model

README = Path(__file__).parents[1] / "README.md"


def _listed(text: str) -> set[str]:
    return set(re.findall(r"`+([a-z][a-z-]+)`+", text))


def test_the_readme_model_list_names_every_library_model():
    text = " ".join(README.read_text().split())
    sentence = text[text.index("Models (`--model`"):]
    sentence = sentence[:sentence.index("a model file")]
    assert set(library_names()) <= _listed(sentence)


def test_load_models_docstring_names_every_library_model():
    doc = " ".join(load_model.__doc__.split())
    start = doc.index("A library name")
    assert set(library_names()) <= _listed(doc[start:doc.index("a variant of", start)])


def test_orbit_help_names_no_plates_coordinate_as_the_only_section():
    from typer.testing import CliRunner

    from stickslip.cli import app

    res = CliRunner().invoke(app, ["orbit", "--help"], env={"COLUMNS": "200"})
    assert res.exit_code == 0 and "φ-maximum" not in res.stdout and "observed coordinate" in res.stdout
