"""The report's header: which paper, when, and with what (package, commit, libraries, machine)."""

from __future__ import annotations

import datetime
import os
import subprocess
from pathlib import Path

import pytest

from validation.studies.provenance import FIELDS, provenance, source_commit

REPOSITORY = Path(__file__).resolve().parents[3]


def test_every_field_is_filled():
    fields = provenance(datetime.datetime(2026, 1, 2, 3, 4, tzinfo=datetime.timezone.utc))
    assert set(fields) == {key for key, _ in FIELDS}
    assert fields["date"] == "2026-01-02 03:04 UTC"
    assert fields["paper"] == "Analysis of a dynamic system subjected to an impulsive and internal contact force"
    assert fields["machine"].endswith(f", {os.cpu_count()} CPUs")
    import numpy
    import scipy
    assert fields["numpy"] == numpy.__version__ and fields["scipy"] == scipy.__version__
    assert fields["package"].startswith("recoil-mbs ")


def test_commit_is_the_checkouts():
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPOSITORY, capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    assert source_commit(REPOSITORY).split(" ")[0] == head


def test_commit_outside_a_checkout_is_unknown(tmp_path):
    assert source_commit(tmp_path) == "unknown"
