#!/usr/bin/env bash
# Set-up + main job: reproduce the paper (Table 2, figures, report) into ./out (or the given --out).
source "$(dirname "${BASH_SOURCE[0]}")/_setup.sh"
exec "$VENV_PYTHON" -m mbs_models paper "$@"
