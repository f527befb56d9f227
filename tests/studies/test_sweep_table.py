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


@pytest.mark.parametrize("name, needle", [("t.txt", ".csv or .parquet"), ("a_file/t.csv", "not a directory"),
                                          ("a_file/deeper/t.csv", "not a writable directory"), (".", "directory")])
def test_bad_paths(tmp_path, name, needle):
    (tmp_path / "a_file").write_text("")
    with pytest.raises(SceneError, match=needle) as info:
        check_out(tmp_path / name if name != "." else tmp_path)
    assert info.value.key == "out"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]   # nothing created


def test_a_missing_directory_is_checked_without_being_created_and_made_by_the_file(tmp_path):
    target = tmp_path / "new" / "deeper" / "t.csv"
    assert check_out(target) == target and not (tmp_path / "new").exists()
    SweepFile(target, ["contact.gap"], ["max_barrel_displacement"])
    assert target.parent.is_dir()


def test_parquet_without_pyarrow_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    with pytest.raises(SceneError, match=r"recoil-mbs\[parquet\]"):
        check_out(tmp_path / "t.parquet")
    assert check_out(tmp_path / "t.csv") == tmp_path / "t.csv"


def _many_rows(count: int) -> list[dict]:
    """``count`` rows of both kinds (ok and failed), gaps i / 7 (floats with all their digits)."""
    return [{**ROWS[i % 2], "contact.gap": i / 7, "impacts": None if i % 2 else i} for i in range(count)]


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_finish_puts_the_rows_in_order_chunk_by_chunk(tmp_path, suffix):
    """Rows appended in any order end in the order of their index, read and written 7 rows at a time, through
    several sorted runs (a carry of 5 rows): the table equals the one sorted in memory, and a CSV file has the
    very bytes of one to_csv of it."""
    rows = _many_rows(60)
    order = np.random.default_rng(5).permutation(60)
    path = tmp_path / f"t{suffix}"
    file = SweepFile(path, PARAMS, METRICS, chunk_rows=7)
    for start in range(0, 60, 4):
        file.append([rows[i] for i in order[start:start + 4]])
    seen = []
    stats = file.finish(lambda chunk: np.rint(chunk["contact.gap"].to_numpy() * 7).astype(np.int64),
                        on_chunk=seen.append, carry_rows=5, fan_in=2)
    assert stats.runs > 2 and stats.rows_out == 60
    expected = frame(rows, PARAMS, METRICS)
    pd.testing.assert_frame_equal(SweepFile(path, PARAMS, METRICS).read(), expected)
    pd.testing.assert_frame_equal(pd.concat(seen, ignore_index=True), expected)
    if suffix == ".csv":
        whole = tmp_path / "whole.csv"
        expected.to_csv(whole, index=False)
        assert path.read_bytes() == whole.read_bytes()
    else:
        assert not file.journal_path.exists()
        read = pd.read_parquet(path)
        assert str(read["impacts"].dtype) == "Int64" and read["contact.gap"].tolist() == [i / 7 for i in range(60)]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([path.name] + (["whole.csv"] if suffix == ".csv" else []))


def test_reading_in_chunks_equals_reading_whole(tmp_path):
    rows = _many_rows(25)
    SweepFile(tmp_path / "t.csv", PARAMS, METRICS).append(rows)
    chunks = list(SweepFile(tmp_path / "t.csv", PARAMS, METRICS, chunk_rows=4).chunks())
    assert [len(c) for c in chunks] == [4] * 6 + [1]
    pd.testing.assert_frame_equal(pd.concat(chunks, ignore_index=True), frame(rows, PARAMS, METRICS))


def test_a_parquet_table_appends_to_its_journal(tmp_path):
    file = SweepFile(tmp_path / "t.parquet", PARAMS, METRICS)
    file.append(ROWS[:1])
    assert file.journal_path == tmp_path / "t.parquet.rows.csv" and not file.path.exists()
    assert file.has_rows()
    file.finish(lambda chunk: np.zeros(len(chunk), dtype=np.int64))
    file.append(ROWS[1:])           # the table and a journal: both are read
    pd.testing.assert_frame_equal(SweepFile(file.path, PARAMS, METRICS).read(), frame(ROWS, PARAMS, METRICS))


def test_kinds_fix_the_parameter_types(tmp_path):
    """A text parameter whose values look like numbers stays text, whatever the rows in the file."""
    rows = [{**ROWS[0], "contact.law": "0.0003"}]
    kinds = {"contact.gap": "float", "contact.law": "text"}
    SweepFile(tmp_path / "t.csv", PARAMS, METRICS, kinds=kinds).append(rows)
    read = SweepFile(tmp_path / "t.csv", PARAMS, METRICS, kinds=kinds).read()
    assert read["contact.law"].tolist() == ["0.0003"]
    with pytest.raises(SceneError, match=r"another sweep's rows \(line 2: column 'contact.law' does not hold "
                                         r"true/false\)"):   # a sound row: another sweep's, not a damaged one
        SweepFile(tmp_path / "t.csv", PARAMS, METRICS, kinds={"contact.gap": "float", "contact.law": "bool"}).read()


def test_a_cut_line_is_found_from_the_end(tmp_path):
    from mbs_models.studies.sweep_table import drop_cut_line

    path = tmp_path / "t.csv"
    path.write_bytes(b"a,b\n" + b"1,2\n" * 50_000 + b"3,")
    drop_cut_line(path, block=64)
    assert path.read_bytes() == b"a,b\n" + b"1,2\n" * 50_000
    drop_cut_line(path)                               # nothing cut: unchanged
    assert path.stat().st_size == 4 + 4 * 50_000
    path.write_bytes(b"a,")                            # the header itself cut short
    drop_cut_line(path, block=1)
    assert path.read_bytes() == b""


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_file_of_its_header_alone_has_no_rows(tmp_path, suffix):
    kinds = {"contact.gap": "float", "contact.law": "text"}
    path = tmp_path / f"t{suffix}"
    empty = frame([], PARAMS, METRICS, kinds)
    empty.to_csv(path, index=False) if suffix == ".csv" else empty.to_parquet(path, index=False)
    file = SweepFile(path, PARAMS, METRICS, kinds=kinds)
    assert list(file.chunks()) == []
    file.append(ROWS)
    pd.testing.assert_frame_equal(file.read(), frame(ROWS, PARAMS, METRICS, kinds))
