"""Sphinx configuration of digslam's documentation (``sphinx-build -W docs docs/_build/html``)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "_ext"))
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("MPLBACKEND", "Agg")

project = "digslam"
author = "digslam developers"
copyright = "digslam developers, MIT licence"  # noqa: A001 (Sphinx's name)

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "digslam_docs",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "make_gallery.py", "_ext", "_generated"]
myst_enable_extensions = ["colon_fence", "deflist", "dollarmath"]
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"exclude-members": "__init__, __new__"}
autodoc_inherit_docstrings = True
add_module_names = False

html_theme = "furo"
html_title = "digslam"
html_static_path = ["_static"]
html_css_files = ["digslam.css"]
html_show_sourcelink = False
napoleon_use_ivar = True  # "Attributes:" as fields: a NamedTuple's fields are then documented once
