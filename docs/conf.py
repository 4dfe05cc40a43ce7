"""Sphinx configuration of the colldet documentation: API reference (autodoc + numpydoc), gallery
(sphinx-gallery: every example is run by the build and its figures are generated, never committed)."""
from __future__ import annotations

import os
import sys
from importlib.metadata import version as _version
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "docs"))  # gallery_scrapers (named by a string: the config stays picklable)
os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("COLLDET_COMPILE_NOTICE", "0")

project = "colldet"
author = "The colldet authors"
copyright = "2026, The colldet authors"
release = _version("colldet")
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "gallery/README.rst", "auto_gallery/*.ipynb", "auto_gallery/*.py",
                    "auto_gallery/*.zip", "auto_gallery/*.md5", "auto_gallery/*.json"]

autodoc_default_options = {"members": True, "imported-members": False, "show-inheritance": False}
autodoc_member_order = "bysource"
autosummary_generate = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
# annotations written ``ArrayLike`` are shown so, not as numpy's expanded union of a dozen types
autodoc_type_aliases = {"ArrayLike": "numpy.typing.ArrayLike", "DTypeLike": "numpy.typing.DTypeLike"}


sphinx_gallery_conf = {
    "examples_dirs": "gallery",
    "gallery_dirs": "auto_gallery",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib", "gallery_scrapers.bare_figure_scraper"),  # docs/gallery_scrapers.py
}

html_theme = "furo"
html_title = f"colldet {release}"
myst_heading_anchors = 3
suppress_warnings = ["myst.xref_missing"]
