"""Sphinx configuration of the recoil-mbs documentation site (``bash scripts/docs.sh`` builds it).

Pages are MyST Markdown; numbers a page quotes are substitutions loaded from ``_generated/numbers.json``
(``python scripts/docs_numbers.py --write`` computes them; ``tests/docs/test_numbers.py`` keeps them current);
the key reference and the tables of the guarantee and of the benchmark are generated at build time by the local
extensions in ``_ext/`` from the code's own declarations and ``_generated/bench.json``.  No network: MathJax is
served from the bundled copy of ``sphinx-mathjax-offline``, and there is no intersphinx.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(DOCS / "_ext"))

import mbs_models  # noqa: E402

project = "recoil-mbs"
author = "the recoil-mbs authors"
copyright = "the recoil-mbs authors, BSD-3-Clause"
release = version = mbs_models.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",
    "sphinx_gallery.gen_gallery",
    "attribute_sections",
    "key_reference",
    "generated_tables",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_generated", "**/_*.md", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.json", "auto_examples/*.md5"]
templates_path = ["_templates"]

# ---------------------------------------------------------------- MyST: math, fences, the numbers
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "substitution", "deflist"]
myst_heading_anchors = 3
#: every ``{{ name }}`` a page quotes: the text of ``_generated/numbers.json`` (computed from the code)
myst_substitutions = {name: entry["text"]
                      for name, entry in json.loads((DOCS / "_generated" / "numbers.json").read_text()).items()}

# ---------------------------------------------------------------- API reference
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"show-inheritance": True}
autodoc_typehints = "signature"
autodoc_typehints_format = "short"
autodoc_member_order = "bysource"
autodoc_class_signature = "mixed"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_ivar = True
napoleon_custom_sections = [("Class attributes", "params_style")]

# ---------------------------------------------------------------- the gallery (examples/gallery, run at build time)
sphinx_gallery_conf = {
    "examples_dirs": "../examples/gallery",      # relative to docs/ (sphinx-gallery writes sub-gallery toctrees
                                                 # from these paths: absolute ones break them)
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "remove_config_comments": True,
    "image_scrapers": ("matplotlib",),
    "matplotlib_animations": False,
    "default_thumb_file": None,
    "show_memory": False,
    "plot_gallery": "True",
    "capture_repr": (),          # a cell's last expression (a Legend, a list of lines) is not printed as output
}

# ---------------------------------------------------------------- HTML
html_theme = "pydata_sphinx_theme"
html_title = "recoil-mbs"
html_static_path = ["_static"]
html_js_files = ["recoil.js"]           # gallery figures open full size on click
html_show_sourcelink = False
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "navbar_align": "left",
    "header_links_before_dropdown": 7,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
    "icon_links": [],
    "search_bar_text": "Search the docs",
}
html_sidebars = {"index": []}
html_last_updated_fmt = None

nitpicky = False
suppress_warnings = ["myst.header"]
