"""Rows of a sweep's file read back (mbs_models.studies.table_rows): every row checked, a damaged one dropped and
its line named, whatever the damage -- a row cut anywhere, a second header, a cell that is no number."""

from __future__ import annotations

import pandas as pd
import pytest

from mbs_models import SceneError
from mbs_models.studies.sweep_table import SweepFile, frame
from mbs_models.studies.table_rows import Unreadable, csv_text

PARAMS, METRICS = ["contact.gap", "contact.law"], ["max_barrel_displacement", "impacts", "stop_reason"]
KINDS = {"contact.gap": "float", "contact.law": "text"}
ROWS = [
    {"contact.gap": 0.0, "contact.law": "flores", "max_barrel_displacement": 0.1 + 0.2, "impacts": 2,
     "stop_reason": "end_time", "wall_time": 0.25, "status": "ok", "error": None},
    {"contact.gap": 1 / 3, "contact.law": "hertz", "max_barrel_displacement": None, "impacts": None,
     "stop_reason": None, "wall_time": 1e-3, "status": "SimulationError", "error": "step budget, a,b exceeded"},
    {"contact.gap": 0.5, "contact.law": "hertz", "max_barrel_displacement": 0.25, "impacts": 0,
     "stop_reason": "end_time", "wall_time": 0.5, "status": "ok", "error": None},
]


def _file(tmp_path, rows=ROWS):
    """The file of ``rows`` as a sweep writes it, and its lines (bytes, each with its newline)."""
    path = tmp_path / "t.csv"
    SweepFile(path, PARAMS, METRICS, kinds=KINDS).append(rows)
    return path, path.read_bytes().splitlines(keepends=True)


def _read(path):
    file = SweepFile(path, PARAMS, METRICS, kinds=KINDS)
    return file.read(), file.unreadable


def test_the_error_cell_is_always_quoted():
    text = csv_text(frame(ROWS, PARAMS, METRICS, KINDS), header=True)
    lines = text.splitlines()
    assert lines[0].endswith(",status,error")
    assert lines[1].endswith(",ok,") and lines[3].endswith(",ok,")                    # ok: an empty error
    assert lines[2].endswith(',SimulationError,"step budget, a,b exceeded"')         # quoted, commas and all
    quoted = csv_text(frame([{**ROWS[1], "error": 'say "hi"'}], PARAMS, METRICS, KINDS), header=False)
    assert quoted.endswith(',"say ""hi"""\n')                                         # RFC 4180 doubling


@pytest.mark.parametrize("row", [0, 1, 2], ids=["ok", "failed", "last"])
@pytest.mark.parametrize("where", ["at the end", "before other rows"])
def test_a_row_cut_anywhere_and_ended_by_a_newline_is_dropped(tmp_path, row, where):
    """Every cut of a row -- after each of its characters -- followed by a newline (a fault that is no clean kill)
    is dropped and its line named; the complete rows are read as written."""
    path, lines = _file(tmp_path)
    line = lines[1 + row]
    others = [r for i, r in enumerate(ROWS) if i != row]
    expected = frame(others, PARAMS, METRICS, KINDS)
    for cut in range(1, len(line) - 1):   # the line without its newline, cut after `cut` bytes
        torn = line[:cut] + b"\n"
        kept = [lines[1 + i] for i in range(len(ROWS)) if i != row]
        body = kept + [torn] if where == "at the end" else [torn] + kept
        path.write_bytes(lines[0] + b"".join(body))
        table, unreadable = _read(path)
        number = 2 + (len(kept) if where == "at the end" else 0)
        assert [(u.count, u.numbers) for u in unreadable] == [(1, [number])], (cut, torn)
        pd.testing.assert_frame_equal(table, expected)


@pytest.mark.parametrize("damage", [
    lambda lines: lines[0],                                                    # a second header line
    lambda lines: lines[1].replace(b"0.30000000000000004", b"0.3x"),          # a metric that is no number
    lambda lines: lines[1].replace(b"0.30000000000000004", b"inf"),           # ... or not finite
    lambda lines: lines[1].replace(b",2,end_time", b",2.5,end_time"),         # a count that is not whole
    lambda lines: lines[1].replace(b",2,end_time", b",-2,end_time"),          # ... or negative
    lambda lines: lines[1].replace(b",0.25,ok", b",-0.25,ok"),                # a negative wall time
    lambda lines: lines[1].replace(b",0.25,ok", b",,ok"),                     # no wall time
    lambda lines: lines[1].replace(b",ok,", b",o,"),                          # a status cut short (no error)
    lambda lines: lines[1].replace(b",ok,", b",,"),                           # no status
    lambda lines: lines[1].replace(b",ok,", b",ok,\"an error\""),             # ok with an error
    lambda lines: lines[2].replace(b"SimulationError", b"Simulation Error"),  # a status that is no class name
    lambda lines: lines[2].replace(b'"step budget, a,b exceeded"', b"unquoted"),  # an error not quoted
    lambda lines: lines[2].replace(b'"step budget, a,b exceeded"', b""),      # a failure without its error
    lambda lines: lines[2].replace(b",,,,", b",0.1,,,"),                      # a failed point with a metric
    lambda lines: lines[1].rstrip(b"\n") + lines[3],                          # two rows run together
    lambda lines: b"\0" * 40 + b"\n",                                         # zeros (a crashed file system)
    lambda lines: lines[1].replace(b"flores", b"flo\xffres"),                 # not UTF-8
], ids=["header", "text", "inf", "count", "negative count", "negative time", "no time", "status cut", "no status",
        "ok with error", "status", "unquoted error", "no error", "failed with metric", "run together", "zeros",
        "not utf-8"])
def test_a_damaged_row_is_dropped(tmp_path, damage):
    """A line added to an intact file that is no row this library writes: dropped (line 5), the rows kept."""
    path, lines = _file(tmp_path)
    path.write_bytes(b"".join(lines) + damage(lines))
    table, unreadable = _read(path)
    assert [(u.count, u.numbers) for u in unreadable] == [(1, [5])]
    pd.testing.assert_frame_equal(table, frame(ROWS, PARAMS, METRICS, KINDS))


def test_empty_lines_are_no_rows(tmp_path):
    path, lines = _file(tmp_path)
    path.write_bytes(lines[0] + b"\n" + b"".join(lines[1:]) + b"\r\n" + b"   \n")
    table, unreadable = _read(path)
    assert [(u.count, u.numbers) for u in unreadable] == [(1, [7])]   # spaces are no empty line
    pd.testing.assert_frame_equal(table, frame(ROWS, PARAMS, METRICS, KINDS))


def test_damage_in_every_chunk_is_counted_with_its_line(tmp_path):
    """Read 2 lines at a time: the line numbers run on from chunk to chunk; the first five are listed."""
    path, lines = _file(tmp_path)
    bad = b"x,y\n"
    path.write_bytes(lines[0] + bad + lines[1] + bad + bad + lines[2] + bad + bad + bad + lines[3] + bad)
    file = SweepFile(path, PARAMS, METRICS, kinds=KINDS, chunk_rows=2)
    pd.testing.assert_frame_equal(file.read(), frame(ROWS, PARAMS, METRICS, KINDS))
    (unreadable,) = file.unreadable
    assert unreadable.count == 7 and unreadable.numbers == [2, 4, 5, 7, 8]   # and 9, 11
    assert unreadable.text() == f"{path}: 7 rows unreadable (line 2, 4, 5, 7, 8, ...): their points run again"


def test_the_line_says_how_many():
    one = Unreadable("t.csv")
    one.add([17])
    assert one.text() == "t.csv: 1 row unreadable (line 17): its point runs again"
    three = Unreadable("t.csv")
    three.add([17, 18])
    three.add([40])
    assert three.text() == "t.csv: 3 rows unreadable (line 17, 18, 40): their points run again"
    rows = Unreadable("t.parquet", "row")
    rows.add(range(1, 1235))
    assert rows.text() == "t.parquet: 1,234 rows unreadable (row 1, 2, 3, 4, 5, ...): their points run again"


def test_a_cell_with_a_line_break_is_not_written(tmp_path):
    """Rows are read back line by line: a line break in a cell is refused, not written (a sweep refuses such a
    parameter value before it runs; messages are made one line)."""
    from mbs_models import model_i, run_sweep

    with pytest.raises(ValueError, match="line break"):
        csv_text(frame([{**ROWS[0], "contact.law": "two\nlines"}], PARAMS, METRICS, KINDS), header=False)
    with pytest.raises(ValueError, match="line break"):
        csv_text(frame([{**ROWS[1], "error": "two\nlines"}], PARAMS, METRICS, KINDS), header=False)
    with pytest.raises(SceneError) as info:
        run_sweep(model_i(), {"name": ["one", "two\nlines"]}, out=tmp_path / "s.csv", progress=False)
    assert info.value.key == "name" and "line break" in info.value.message
    assert list(tmp_path.iterdir()) == []


def test_a_damaged_parquet_row_is_dropped_by_its_row_number(tmp_path):
    path = tmp_path / "t.parquet"
    pytest.importorskip("pyarrow")
    table = frame(ROWS, PARAMS, METRICS, KINDS)
    table.loc[1, "status"] = None        # a failed row without its status
    table.to_parquet(path, index=False)
    file = SweepFile(path, PARAMS, METRICS, kinds=KINDS)
    pd.testing.assert_frame_equal(file.read(), frame([ROWS[0], ROWS[2]], PARAMS, METRICS, KINDS))
    assert file.unreadable[0].text() == f"{path}: 1 row unreadable (row 2): its point runs again"


def test_a_sound_row_of_another_kind_is_another_sweep(tmp_path):
    """A row whose only fault is a parameter of another kind is not damaged but another sweep's: refused."""
    path, lines = _file(tmp_path)
    with pytest.raises(SceneError, match=r"another sweep's rows \(line 2: column 'contact.law' does not hold numbers"):
        SweepFile(path, PARAMS, METRICS, kinds={"contact.gap": "float", "contact.law": "float"}).read()
    path.write_bytes(b"".join(lines) + lines[1].replace(b"0.0,flores", b"wide,flores"))
    with pytest.raises(SceneError, match=r"line 5: column 'contact.gap' does not hold numbers"):
        _read(path)
