"""When and with what a report was made: date, package version and commit, libraries, machine.

Nothing here imports Exudyn (``validation`` stays independent of the engine's code): its version is
read from the installed distribution's metadata.
"""

from __future__ import annotations

import datetime
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path

import mbs_models

from .paper import PAPER_TITLE

#: The fields of :func:`provenance`, in the order the report shows them, with their labels.
FIELDS = (("paper", "Paper replicated"), ("date", "Made on"), ("package", "Package"), ("commit", "Commit"),
          ("exudyn", "Exudyn"), ("numpy", "numpy"), ("scipy", "scipy"), ("machine", "Machine"))


def _distribution_version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "unknown"


def source_commit(directory: Path | None = None) -> str:
    """The git commit of the checkout holding ``directory`` (default: the ``mbs_models`` package), with
    " (uncommitted changes)" when its work tree differs from it; "unknown" outside a checkout or without git."""
    directory = Path(directory or Path(mbs_models.__file__).resolve().parent)
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=directory, capture_output=True, text=True,
                                timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=directory,
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return (commit + " (uncommitted changes)" if dirty else commit) if commit else "unknown"


def provenance(now: datetime.datetime | None = None) -> dict[str, str]:
    """The report's header: ``{field: text}`` for every field of :data:`FIELDS` (all strings)."""
    now = now or datetime.datetime.now(datetime.timezone.utc)
    return {
        "paper": PAPER_TITLE,
        "date": now.strftime("%Y-%m-%d %H:%M UTC") if now.tzinfo else now.strftime("%Y-%m-%d %H:%M"),
        "package": f"recoil-mbs {mbs_models.__version__}",
        "commit": source_commit(),
        "exudyn": _distribution_version("exudyn"),
        "numpy": _distribution_version("numpy"),
        "scipy": _distribution_version("scipy"),
        "machine": f"{platform.platform()}, {platform.machine() or 'unknown CPU type'}, {os.cpu_count()} CPUs",
    }
