"""The report's studies share one process pool: the numbers do not depend on how the runs were spread."""

from __future__ import annotations

import json

import pytest

from validation.studies.report import ReportOptions, results_json, write_report


def _numbers(data: dict) -> dict:
    """results.json without what may differ between runs: timings, the machine, the worker count, the minute the
    report was made (the two runs below can straddle a minute)."""
    def strip(value):
        if isinstance(value, dict):
            return {k: strip(v) for k, v in value.items() if k not in ("timings", "machine", "wall_time", "workers", "date")}
        if isinstance(value, list):
            return [strip(v) for v in value]
        return value
    return strip(json.loads(json.dumps(results_json(data), default=str)))


@pytest.mark.slow
def test_same_report_in_one_process_and_on_the_pool(tmp_path):
    options = dict(gap_step=0.04, masses=(1000.0,), convention_labels=("default", "compression_only"))
    serial = write_report(tmp_path / "serial", ReportOptions.reduced(workers=1, **options))
    pooled = write_report(tmp_path / "pooled", ReportOptions.reduced(workers=2, **options))
    assert _numbers(serial) == _numbers(pooled)
    for name in ("table2.json", "table2.md"):
        assert (tmp_path / "serial" / name).read_bytes() == (tmp_path / "pooled" / name).read_bytes()
    for png in (tmp_path / "serial").glob("*.png"):
        assert png.read_bytes() == (tmp_path / "pooled" / png.name).read_bytes(), png.name
    stages = set(pooled["timings"])
    assert {"engine vs reference", "gap sweeps", "convention study", "calibration", "total"} <= stages
