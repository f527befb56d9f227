"""A sweep point without a solve, for the tests of a sweep's table and faults (not of its physics).

:func:`fake_point` stands in for :func:`mbs_models.studies.point.evaluate_point`: a full row of every metric
column, made from the point's values alone (the same in any process, run after run: a resumed table can be
compared with an uninterrupted one), every 17th gap (in mm) a failed point, after ``FAKE_SECONDS`` of sleep (a
sweep long enough to be killed while it runs).  Module-level, so that forked workers and subprocesses (this
directory is on the tests' path) share it.
"""

from __future__ import annotations

import io
import time

import pandas as pd

#: Seconds each point takes.
FAKE_SECONDS = 0.002


def fake_point(scene, overrides, settings=None):
    from mbs_models.studies.point import failed_row, metric_columns

    time.sleep(FAKE_SECONDS)
    mass, gap = overrides.get("absorber.mass", 1000.0), overrides.get("contact.gap", 0.0)
    if round(gap * 1000) % 17 == 5:
        return failed_row(scene, overrides, "SimulationError", f"made to fail at gap {gap!r}, mass {mass!r}",
                          FAKE_SECONDS)
    row = dict(overrides)
    for i, column in enumerate(metric_columns(scene)):
        row[column] = mass * (i + 1) / 7 + gap / 3     # floats with all their digits
    row.update(impacts=int(mass) % 5, steps=int(mass * 10 + gap * 1e4), stop_reason="end_time",
               wall_time=FAKE_SECONDS, status="ok", error=None)
    return row


def patch(monkeypatch) -> None:
    """Points are :func:`fake_point` (in this process and the pool's forked workers)."""
    from mbs_models.studies import point

    monkeypatch.setattr(point, "evaluate_point", fake_point)


def as_read(table: pd.DataFrame) -> pd.DataFrame:
    """A table as plain pandas reads it from CSV, without wall times (they differ from run to run)."""
    return pd.read_csv(io.StringIO(table.to_csv(index=False)), keep_default_na=False,
                       na_values=[""]).drop(columns="wall_time")
