# Sourced by the entry scripts: create .venv (once) and install the project with its test extra (pytest,
# hypothesis, and what the tests import: Dask distributed, pyarrow), the cluster extra (Dask: the sweep tests
# run a local cluster) and the parquet extra (pyarrow), at the versions of requirements/lock.txt (the stack
# the tests were last run with).  RECOIL_UNLOCKED=1 installs from pyproject.toml's ranges instead.
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
LOCK=requirements/lock.txt
CONSTRAINTS=(-c "$LOCK")
if [ "${RECOIL_UNLOCKED:-0}" = 1 ]; then
    CONSTRAINTS=()
    STAMP=.venv/.recoil-installed-unlocked
fi
if [ ! -f "$STAMP" ] || [ pyproject.toml -nt "$STAMP" ] || [ "$LOCK" -nt "$STAMP" ]; then
    echo "[setup] installing the project and its dependencies into .venv${CONSTRAINTS:+ (versions of $LOCK)}" >&2
    if ! .venv/bin/python -m pip install --quiet --disable-pip-version-check "${CONSTRAINTS[@]}" \
            -e ".[test,cluster,parquet]"; then
        echo "[setup] installing failed; the versions of $LOCK were tested with CPython 3.11 on x86-64 Linux." >&2
        echo "[setup] RECOIL_UNLOCKED=1 installs the newest versions pyproject.toml allows instead (untested)." >&2
        exit 1
    fi
    rm -f .venv/.recoil-installed .venv/.recoil-installed-unlocked
    touch "$STAMP"
fi
VENV_PYTHON="$ROOT/.venv/bin/python"
