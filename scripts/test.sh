#!/usr/bin/env bash
# Set-up + tests: the fast suite by default; extra pytest arguments pass through (e.g. -m slow).
source "$(dirname "${BASH_SOURCE[0]}")/_setup.sh"
exec "$VENV_PYTHON" -m pytest "$@"
