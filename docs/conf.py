"""Sphinx configuration of screwkin's documentation site (docs/README.md says how to build it).

Sphinx, not MkDocs: the command reference is generated from screwkin's own argparse parser by
sphinx-argparse, the gallery runs examples/gallery/*.py at build time with sphinx-gallery (the tool
of Matplotlib's, NumPy's and scikit-learn's galleries), and the API page is autodoc of the public
names of screwkin/__init__.py; the pages are MyST Markdown, the theme PyData's.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(ROOT))  # the screwkin of this checkout, whatever is installed
os.environ.setdefault("MPLBACKEND", "Agg")
# the gallery's scripts run `python -m screwkin`: the same checkout's screwkin in their subprocesses
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p)

import screwkin  # noqa: E402

project = "screwkin"
author = "the screwkin developers"
copyright = "screwkin developers, BSD-3-Clause"
version = release = screwkin.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinxarg.ext",
    "sphinx_gallery.gen_gallery",
    "screwkin_docs",  # docs/_ext: one reference page per command, from screwkin.cli's table
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
exclude_patterns = ["_build", "README.md", "reference/notes", "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip",
                    "auto_examples/*.md5", "auto_examples/*.codeobj.json"]
suppress_warnings = ["myst.header"]  # format.md and the module map start at level-2 headings, as the README's

html_theme = "pydata_sphinx_theme"
html_title = f"screwkin {release}"
html_static_path = []
html_theme_options = {
    "navigation_depth": 2,
    "show_toc_level": 2,
    "footer_start": ["copyright"],
    "footer_end": [],
}
html_last_updated_fmt = None

autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the signatures say the names; the docstrings say the types in words
autodoc_default_options = {"members": False}

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples" / "gallery"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",  # every plot_*.py runs at build time
    "ignore_pattern": r"__init__\.py|_screwkin_cli\.py",  # _screwkin_cli.py: the helper they share
    "download_all_examples": False,
    "remove_config_comments": True,
    "matplotlib_animations": (True, "jshtml"),
    "within_subsection_order": "FileNameSortKey",
    "reset_modules": ("matplotlib",),
    "abort_on_example_error": True,
    "show_memory": False,
    "plot_gallery": "True",
}
