"""A table put in key order chunk by chunk (mbs_models.studies.table_sort): the order of a full sort, the first
row of a key kept, any input order, temporary files removed."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from mbs_models.studies.table_sort import sort_chunks


def _table(keys: np.ndarray) -> pd.DataFrame:
    """Rows that say where they came from: the key, the input position, a text column."""
    return pd.DataFrame({"key": keys, "position": np.arange(len(keys)), "text": [f"row {k}" for k in keys]})


def _chunks(frame: pd.DataFrame, size: int):
    for start in range(0, len(frame), size):
        chunk = frame.iloc[start:start + size].reset_index(drop=True)
        yield chunk["key"].to_numpy(), chunk


def _sorted(frame: pd.DataFrame, tmp_path, size: int, **options):
    written = []
    stats = sort_chunks(_chunks(frame, size), lambda keys, chunk: written.append((keys, chunk)), tmp_path,
                        **options)
    out = pd.concat([c for _, c in written], ignore_index=True) if written else frame.iloc[:0]
    for keys, chunk in written:
        assert keys.tolist() == chunk["key"].tolist()
    assert list(tmp_path.iterdir()) == []     # every temporary run removed
    return out, stats


def _expected(frame: pd.DataFrame) -> pd.DataFrame:
    """A full in-memory sort by key, the first row of each key kept (pandas, not the code under test)."""
    return frame.sort_values("key", kind="stable").drop_duplicates("key", keep="first").reset_index(drop=True)


@pytest.mark.parametrize("order", ["sorted", "nearly", "shuffled", "reversed"])
@pytest.mark.parametrize("carry, fan_in", [(50, 2), (400, 3), (10_000, 8)])
def test_any_order_comes_out_sorted(tmp_path, order, carry, fan_in):
    rng = np.random.default_rng(7)
    keys = np.arange(3000, dtype=np.int64) * 3
    if order == "nearly":      # as a sweep's rows finish: each at most 30 places from its own
        keys = keys[np.argsort(np.arange(3000) + rng.uniform(0, 30, 3000))]
    elif order == "shuffled":
        keys = rng.permutation(keys)
    elif order == "reversed":
        keys = keys[::-1].copy()
    frame = _table(keys)
    out, stats = _sorted(frame, tmp_path, 97, carry_rows=carry, fan_in=fan_in)
    pd.testing.assert_frame_equal(out, _expected(frame))
    assert stats.rows_in == stats.rows_out == 3000
    if order in ("sorted", "nearly") and carry >= 50:
        assert stats.runs == 1          # rows within carry_rows of their place make one run: no merge


def test_a_resumed_file_is_two_runs(tmp_path):
    """A file from a killed run (points 0..1999 but 17 and 300) and its resumed run (17, 300, then the rest)."""
    first = np.array([k for k in range(2000) if k not in (17, 300)])
    keys = np.concatenate([first, [17, 300], np.arange(2000, 2500)])
    out, stats = _sorted(_table(keys), tmp_path, 100, carry_rows=100)
    assert out["key"].tolist() == list(range(2500)) and stats.runs == 2


def test_the_first_row_of_a_key_is_kept(tmp_path):
    keys = np.array([4, 1, 4, 2, 1, 0, 2, 4], dtype=np.int64)
    for carry, fan_in, size in [(1, 2, 1), (2, 2, 3), (100, 8, 8)]:
        out, stats = _sorted(_table(keys), tmp_path, size, carry_rows=carry, fan_in=fan_in)
        assert out["key"].tolist() == [0, 1, 2, 4]
        assert out["position"].tolist() == [5, 1, 3, 0]      # the first occurrence in input order
        assert stats.rows_out == 4


def test_nothing_in_nothing_out(tmp_path):
    out, stats = _sorted(_table(np.array([], dtype=np.int64)), tmp_path, 10)
    assert len(out) == 0 and stats.runs == 0


def test_a_failing_writer_leaves_no_temporary_file(tmp_path):
    def fail(keys, chunk):
        raise OSError("disk full")

    frame = _table(np.random.default_rng(1).permutation(1000))
    with pytest.raises(OSError):
        sort_chunks(_chunks(frame, 50), fail, tmp_path, carry_rows=20, fan_in=2)
    assert list(tmp_path.iterdir()) == []
