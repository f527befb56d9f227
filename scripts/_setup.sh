# Sourced by the entry scripts: create .venv (once) and install the project with its test extra, the
# cluster extra (Dask: the sweep tests run a local cluster) and the parquet extra (pyarrow).
# Needs only Python >= 3.11 with venv and pip; the packages come from PyPI.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
PYTHON="${PYTHON:-python3}"
"$PYTHON" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "Python >= 3.11 is required, found " + sys.version.split()[0])'
if [ ! -x .venv/bin/python ]; then
    echo "[setup] creating virtual environment .venv" >&2
    "$PYTHON" -m venv .venv
fi
STAMP=.venv/.recoil-installed
if [ ! -f "$STAMP" ] || [ pyproject.toml -nt "$STAMP" ]; then
    echo "[setup] installing the project and its dependencies into .venv" >&2
    .venv/bin/python -m pip install --quiet --disable-pip-version-check -e ".[test,cluster,parquet]"
    touch "$STAMP"
fi
VENV_PYTHON="$ROOT/.venv/bin/python"
