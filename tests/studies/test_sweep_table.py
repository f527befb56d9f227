"""The sweep's table and file (mbs_models.studies.sweep_table): typed columns, exact round trips, cut lines."""

from __future__ import annotations

import sys

import numpy as np
import pandas as pd
import pytest

from mbs_models import SceneError
from mbs_models.studies.sweep_table import SweepFile, check_out, frame

PARAMS, METRICS = ["contact.gap", "contact.law"], ["max_barrel_displacement", "impacts", "stop_reason"]
ROWS = [
    {"contact.gap": 0.0, "contact.law": "flores", "max_barrel_displacement": 0.1 + 0.2, "impacts": 2,
     "stop_reason": "end_time", "wall_time": 0.25, "status": "ok", "error": None},
    {"contact.gap": 1 / 3, "contact.law": "hertz", "max_barrel_displacement": None, "impacts": None,
     "stop_reason": None, "wall_time": 1e-3, "status": "SimulationError", "error": 'step budget, "quoted", a,b'},
]


def test_types_are_fixed_by_the_column():
    table = frame(ROWS, PARAMS, METRICS)
    assert list(table.columns) == PARAMS + METRICS + ["wall_time", "status", "error"]
    assert str(table["contact.gap"].dtype) == "float64" and table["contact.law"].dtype == object
    assert str(table["impacts"].dtype) == "Int64" and table["impacts"].isna().tolist() == [False, True]
    assert table["error"].tolist() == [None, 'step budget, "quoted", a,b']


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_round_trip_is_exact(tmp_path, suffix):
    file = SweepFile(tmp_path / f"t{suffix}", PARAMS, METRICS)
    file.append(ROWS[:1])
    file.append(ROWS[1:])
    again = SweepFile(tmp_path / f"t{suffix}", PARAMS, METRICS).read()
    pd.testing.assert_frame_equal(again, frame(ROWS, PARAMS, METRICS))
    assert again["contact.gap"][1] == 1 / 3 and again["max_barrel_displacement"][0] == 0.1 + 0.2


def test_a_csv_line_cut_short_is_dropped(tmp_path):
    path = tmp_path / "t.csv"
    file = SweepFile(path, PARAMS, METRICS)
    file.append(ROWS)
    text = path.read_text()
    path.write_text(text[:-7])  # a kill in the middle of the last row
    again = SweepFile(path, PARAMS, METRICS).read()
    pd.testing.assert_frame_equal(again, frame(ROWS[:1], PARAMS, METRICS))
    assert path.read_text() == text[:text.rstrip("\n").rfind("\n") + 1]


def test_a_file_of_another_table_is_refused(tmp_path):
    path = tmp_path / "t.csv"
    SweepFile(path, PARAMS, METRICS).append(ROWS)
    with pytest.raises(SceneError, match="another sweep") as info:
        SweepFile(path, ["absorber.mass"], METRICS).read()
    assert info.value.key == "out"


def test_write_all_replaces_the_file(tmp_path):
    path = tmp_path / "t.csv"
    file = SweepFile(path, PARAMS, METRICS)
    file.append(ROWS)
    file.write_all(frame(ROWS[::-1], PARAMS, METRICS))
    assert SweepFile(path, PARAMS, METRICS).read()["contact.law"].tolist() == ["hertz", "flores"]
    assert [p.name for p in tmp_path.iterdir()] == ["t.csv"]  # no temporary file left


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
@pytest.mark.parametrize("mask, mode", [(0o022, 0o644), (0o077, 0o600)])
def test_files_honour_the_umask(tmp_path, suffix, mask, mode):
    """The table (appended, rewritten) and its settings file get ``0666 & ~umask``, as any tool's outputs."""
    import os
    import stat

    saved = os.umask(mask)
    try:
        file = SweepFile(tmp_path / f"t{suffix}", PARAMS, METRICS)
        file.write_settings({"end_time": 10.0})
        file.append(ROWS[:1])
        file.finish(lambda chunk: np.zeros(len(chunk), dtype=np.int64))
        file.append(ROWS[1:])
        file.write_all(frame(ROWS, PARAMS, METRICS))
        file.finish(lambda chunk: np.arange(len(chunk), dtype=np.int64))
    finally:
        os.umask(saved)
    assert len(list(tmp_path.iterdir())) == 2  # the table and its settings, no temporary file or journal
    for path in tmp_path.iterdir():
        assert stat.S_IMODE(path.stat().st_mode) == mode, path.name


@pytest.mark.parametrize("name, needle", [("t.txt", ".csv or .parquet"), ("missing/t.csv", "does not exist"),
                                          (".", "directory")])
def test_bad_paths(tmp_path, name, needle):
    with pytest.raises(SceneError, match=needle) as info:
        check_out(tmp_path / name if name != "." else tmp_path)
    assert info.value.key == "out"


def test_parquet_without_pyarrow_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    with pytest.raises(SceneError, match=r"recoil-mbs\[parquet\]"):
        check_out(tmp_path / "t.parquet")
    assert check_out(tmp_path / "t.csv") == tmp_path / "t.csv"
