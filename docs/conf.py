"""Sphinx configuration of the stickslip documentation site.

Build: ``sphinx-build -W -j auto -b html docs docs/_build/html`` (or ``make -C docs html``). The
gallery runs every script in ``examples/`` (as many at once as ``-j`` allows) and keeps its
figures; ``-D plot_gallery=0`` skips running them.
"""

import re
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))  # the checkout's package when it is not installed

import stickslip

project = "stickslip"
author = "the stickslip authors"
copyright = "the stickslip authors"
version = release = stickslip.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "sphinxcontrib.typer",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip",
                    "auto_examples/*.md5", "auto_examples/*.codeobj.json", "**/*.pickle",
                    "figures/**/*.md"]  # tables a study writes beside its figures, not pages
html_static_path = ["_static"]
html_css_files = ["stickslip.css"]

# -- Markdown pages (the user guide) ---------------------------------------------------------
myst_enable_extensions = ["dollarmath", "deflist"]
myst_heading_anchors = 4  # [text](page.md#a-heading) links between the guide's pages

# -- API reference --------------------------------------------------------------------------
autosummary_generate = True
autodoc_typehints = "none"          # the numpydoc sections state the types
toc_object_entries_show_parents = "hide"  # methods in the page contents by their own names
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks = set()


# -- Gallery ---------------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "abort_on_example_error": True,
    "show_memory": False,
    "line_numbers": False,
    "min_reported_time": 1,
    "parallel": True,  # the examples run in parallel (joblib processes), as many as sphinx-build -j says
}

# -- HTML --------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"stickslip {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "header_links_before_dropdown": 6,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"index": [], "getting_started": [], "cli": [], "changelog": []}
html_show_sourcelink = False


# -- Docstrings -------------------------------------------------------------------------------
# Docstrings write magnitudes as |v| and |F|; in reStructuredText |...| is a substitution. Outside
# ``literals`` a bar is made literal before numpydoc and docutils read the docstring.
_LITERAL_OR_BAR = re.compile(r"(``.*?``)|\|")


def _escape_bars(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        lines[i] = _LITERAL_OR_BAR.sub(lambda m: m.group(1) or r"\|", line)


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars, priority=100)
