"""The grid of a sweep (mbs_models.studies.grid): every combination in a fixed order, values checked."""

from __future__ import annotations

import numpy as np
import pytest

from mbs_models import SceneError, model_i
from mbs_models.studies.grid import column_values, make_grid


def test_full_grid_first_key_slowest():
    grid = make_grid(model_i(), {"absorber.mass": "100,500", "contact.gap": [0.0, 0.01, 0.02]})
    assert len(grid) == 6
    assert grid.points() == [{"absorber.mass": m, "contact.gap": g} for m in (100, 500) for g in (0.0, 0.01, 0.02)]
    assert grid.labels()[1] == (100.0, 0.01) and isinstance(grid.labels()[1][0], float)


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
