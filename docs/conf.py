"""Sphinx configuration of the tpm-viz docs site (Sphinx + furo + MyST).

Build (CI: warnings are errors): ``sphinx-build -W --keep-going -b html docs docs/_build/html``, or
``tpm-viz docs [--serve]``. The API reference is generated from the docstrings (autodoc + autosummary: one page per
layer folder listing its modules, one page per module); the examples' pages from ``examples/`` (``_ext/tpm_docs.py``).
"""

from __future__ import annotations

import pathlib
import sys

DOCS = pathlib.Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path[:0] = [str(ROOT), str(DOCS / "_ext")]

project = "tpm-viz"
author = "the tpm-viz authors"
copyright = "2025, the tpm-viz authors"
release = version = "0.1.0"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "tpm_docs",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "README.md", "**/.ipynb_checkpoints"]
templates_path = ["_templates"]

# Every reference must resolve; names of other projects (numpy, viser, ...) have no inventory offline, so they are
# accepted by module name only (tpm_docs checks that each such name is imported by the package).
nitpicky = True

myst_heading_anchors = 4  # [text](page.md#a-heading) links are checked like any other reference
myst_enable_extensions = ["colon_fence", "deflist"]
suppress_warnings = ["myst.xref_ambiguous"]

# a module's own members (its __all__ may re-export: those are documented where they are defined)
autodoc_default_options = {
    "members": True,
    "undoc-members": True,  # dataclass fields, enum members, constants: listed even without a docstring of their own
    "ignore-module-all": True,
    "show-inheritance": True,
    "member-order": "bysource",
}
autodoc_typehints = "signature"
autodoc_typehints_format = "short"
autodoc_preserve_defaults = True
autodoc_class_signature = "mixed"
add_module_names = False
python_use_unqualified_type_names = True

html_theme = "furo"
html_title = "tpm-viz"
html_static_path: list[str] = []
html_show_sourcelink = False
html_copy_source = False
