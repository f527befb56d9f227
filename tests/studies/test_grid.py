"""The grid of a sweep (mbs_models.studies.grid): every combination in a fixed order, values checked."""

from __future__ import annotations

import itertools
import types

import numpy as np
import pandas as pd
import pytest

from mbs_models import SceneError, model_i
from mbs_models.studies.grid import MAX_POINTS, GridTooLarge, column_values, make_grid


def test_full_grid_first_key_slowest():
    grid = make_grid(model_i(), {"absorber.mass": "100,500", "contact.gap": [0.0, 0.01, 0.02]})
    assert len(grid) == grid.size == 6 and grid.shape == (2, 3)
    expected = [{"absorber.mass": m, "contact.gap": g} for m in (100, 500) for g in (0.0, 0.01, 0.02)]
    assert list(grid.points()) == expected
    assert [grid.point(i) for i in range(6)] == expected
    labels = list(grid.labels())
    assert labels[1] == grid.label(1) == (100.0, 0.01) and isinstance(labels[1][0], float)
    with pytest.raises(IndexError):
        grid.point(6)


def test_points_and_labels_are_generators_and_indices_decode_any_grid():
    """A grid of 10^8 points is never made point by point: its points are generated lazily, and point i is
    the i-th combination of nested loops (the first key slowest) -- here checked at the ends and at digits of
    the mixed radix (3, 1000, 2000): index = 2000 (1000 a + b) + c."""
    grid = make_grid(model_i(), {"absorber.mass": "1,2,3", "contact.gap": "0:0.1:1000",
                                 "absorber.contact.stiffness": "1e6:1e8:2000"}, max_points=None)
    assert grid.size == 6_000_000 and grid.strides == (2_000_000, 2000, 1)
    assert isinstance(grid.points(), types.GeneratorType) and not isinstance(grid.labels(), (list, tuple))
    first = list(itertools.islice(grid.points(), 3))
    assert first == [grid.point(i) for i in range(3)]
    for a, b, c in [(0, 0, 0), (2, 999, 1999), (1, 0, 1999), (1, 1, 0), (2, 517, 1234)]:
        point = grid.point(2000 * (1000 * a + b) + c)
        assert point == {"absorber.mass": grid.values[0][a], "contact.gap": grid.values[1][b],
                         "absorber.contact.stiffness": grid.values[2][c]}


def test_indices_encode_table_rows_back():
    grid = make_grid(model_i(), {"absorber.mass": "100,500", "contact.gap": [0.0, 0.01, 0.02]})
    columns = [pd.Series([500.0, 100.0, 500.0, 7.0]), pd.Series([0.02, 0.0, 0.05, 0.0])]
    assert grid.indices(columns).tolist() == [5, 0, -1, -1]      # 3 (500 kg) + 2 (20 mm); not points: -1


def test_more_points_than_allowed_are_refused_before_any_value_is_made():
    import tracemalloc

    tracemalloc.start()
    try:
        with pytest.raises(GridTooLarge) as info:   # 10^12 values of one key would fill any memory
            make_grid(model_i(), {"absorber.mass": "1:1000:10000", "contact.gap": "0:0.1:1000000000000"})
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 10_000_000   # bytes: no value list was made (10^12 floats would be 8 TB)
    error = info.value
    assert isinstance(error, SceneError) and error.key == "large" and error.size == 10**16
    assert "10,000,000,000,000,000 points (10,000 x 1,000,000,000,000)" in str(error)
    assert f"more than the {MAX_POINTS:,}" in str(error) and "large=True" in str(error)
    assert "--large" in str(error.with_flag("--large", "--large"))


def test_the_limit_is_the_count_of_points():
    make_grid(model_i(), {"absorber.mass": "1:1000:1000", "contact.gap": "0:0.1:1000"})   # 10^6: allowed
    with pytest.raises(GridTooLarge):
        make_grid(model_i(), {"absorber.mass": "1:1000:1000", "contact.gap": "0:0.1:1001"})
    with pytest.raises(GridTooLarge):
        make_grid(model_i(), {"absorber.mass": "1,2,3", "contact.gap": [0.0, 0.01]}, max_points=5)
    assert make_grid(model_i(), {"contact.gap": "0:0.1:1001"}, max_points=None).size == 1001


def test_ranges_and_numpy_values():
    grid = make_grid(model_i(), {"contact.gap": "0:0.12:13", "absorber.mass": np.array([100.0, 500.0])})
    assert len(grid) == 26
    assert all(type(v) is float for v in grid.values[1])


def test_column_values_have_one_type_per_column():
    assert column_values([500, 0.5]) == [500.0, 0.5] and type(column_values([500])[0]) is float
    assert column_values([True, False]) == [True, False]
    assert column_values(["flores", "hertz"]) == ["flores", "hertz"]
    assert column_values([2e-4, [[0.0, 3e-4], [0.3, 1e-4]]]) == ["0.0002", "[[0.0, 0.0003], [0.3, 0.0001]]"]


@pytest.mark.parametrize("params, key, needle", [
    ({}, "params", "at least one"),
    ({"contact.gapp": [0.0]}, "contact.gapp", "did you mean"),
    ({"contact.gap": "0:1"}, "contact.gap", "START:STOP:COUNT"),
    ({"contact.gap": []}, "contact.gap", "no values"),
    ({"contact.gap": [0.0, 0.0]}, "contact.gap", "given twice"),
    ({"contact.gap": [0.0, -0.01]}, "contact.gap", ">= 0 m"),               # no point accepts -0.01
    ({"absorber.mass": "100,heavy"}, "absorber.mass", "must be a number"),
    ({"contact.gap": [float("nan")]}, "contact.gap", "finite"),
])
def test_bad_grids(params, key, needle):
    with pytest.raises(SceneError) as info:
        make_grid(model_i(), params)
    assert info.value.key == key and needle in info.value.message


def test_a_value_only_some_points_refuse_is_no_bad_input():
    # restitution is not a field of hunt-crossley, but is one of flores: the point (hunt-crossley, 0.5) fails
    grid = make_grid(model_i(), {"contact.law": ["hunt-crossley", "flores"], "contact.restitution": [0.5]})
    assert len(grid) == 2
