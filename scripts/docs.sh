#!/usr/bin/env bash
# Set-up + the documentation site: install the project with its `docs` extra (Sphinx, the theme, MyST, the
# gallery, a bundled MathJax; sphinx.ext.napoleon reads the docstrings) into .venv as scripts/_setup.sh does for
# the tests, then build docs/_build/html with every warning an error.  The gallery's examples run during the build.
# Extra arguments pass through to sphinx-build (e.g. -E to re-read every page).
source "$(dirname "${BASH_SOURCE[0]}")/_setup.sh"
DOCS_STAMP=.venv/.recoil-docs-installed
if [ ! -f "$DOCS_STAMP" ] || [ pyproject.toml -nt "$DOCS_STAMP" ] || [ "$LOCK" -nt "$DOCS_STAMP" ]; then
    echo "[docs] installing the docs extra into .venv" >&2
    "$VENV_PYTHON" -m pip install --quiet --disable-pip-version-check "${CONSTRAINTS[@]}" -e ".[docs]"
    touch "$DOCS_STAMP"
fi
export MPLBACKEND=Agg
started=$(date +%s)
"$VENV_PYTHON" -m sphinx -W --keep-going -b html docs docs/_build/html "$@"
echo "[docs] built docs/_build/html in $(( $(date +%s) - started )) s: open docs/_build/html/index.html" >&2
