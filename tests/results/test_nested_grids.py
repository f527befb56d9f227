"""Batched nested-grid searches (mbs_models.results.nested_grids) against the one-bracket searches they replace.

``one_bracket_maximum`` (here) and ``one_bracket_crossing`` (a fixture of conftest.py) are the scalar searches as the post-processing ran
them before issue #11 (copied here as the reference): the batched searches must give the same bits.
"""

from __future__ import annotations

import numpy as np
import pytest

from mbs_models.results.nested_grids import (
    first_true,
    first_true_search,
    function_maxima,
    maxima_search,
    run,
    uniform_grids,
)


def one_bracket_maximum(f, lo, hi, points=65, levels=4):
    for _ in range(levels):
        grid = np.linspace(lo, hi, points)
        values = np.asarray(f(grid), dtype=float)
        j = int(np.argmax(values))
        lo, hi = grid[max(j - 1, 0)], grid[min(j + 1, points - 1)]
    best_value, best_time = float(values[j]), float(grid[j])
    if 0 < j < points - 1:
        y0, y1, y2 = values[j - 1], values[j], values[j + 1]
        curvature = y0 - 2 * y1 + y2
        if curvature < 0:
            shift = 0.5 * (y0 - y2) / curvature
            step = grid[1] - grid[0]
            t_vertex = grid[j] + shift * step
            value = float(f(np.array([t_vertex]))[0])
            if value > best_value:
                best_value, best_time = value, float(t_vertex)
    return best_value, best_time


def wiggly(t):
    """A smooth function with many local maxima (s -> arbitrary units)."""
    return np.sin(37.0 * t) + 0.3 * np.cos(211.0 * t + 0.4) + 0.05 * np.sin(1723.0 * t)


@pytest.fixture
def brackets():
    rng = np.random.default_rng(11)
    lo = np.sort(rng.uniform(0.0, 10.0, 40))
    width = rng.choice([1e-2, 1e-4, 1e-7, 3e-9], size=40)
    return lo, lo + width


def test_uniform_grids_are_linspace_row_by_row(brackets):
    lo, hi = brackets
    lo, hi = np.append(lo, [2.5, 1e-310]), np.append(hi, [2.5, 3e-310])  # an empty bracket, a denormal step
    for points in (2, 65, 129):
        grids = uniform_grids(lo, hi, points)
        for i in range(len(lo)):
            assert np.array_equal(grids[i], np.linspace(lo[i], hi[i], points)), (points, i)


def test_function_maxima_equal_the_one_bracket_search(brackets):
    lo, hi = brackets
    values, times = function_maxima(wiggly, lo, hi)
    for i in range(len(lo)):
        assert (values[i], times[i]) == one_bracket_maximum(wiggly, lo[i], hi[i]), i


def test_function_maxima_find_a_known_peak():
    values, times = function_maxima(lambda t: -(t - 0.3217) ** 2, np.array([0.2, 0.3]), np.array([0.4, 0.33]))
    np.testing.assert_allclose(times, 0.3217, atol=1e-9)
    np.testing.assert_allclose(values, 0.0, atol=1e-15)


def test_first_true_equals_the_one_bracket_search(brackets, one_bracket_crossing):
    lo, hi = brackets
    indicator = lambda t: wiggly(t) > 0.2
    found = first_true(indicator, lo, hi)
    for i in range(len(lo)):
        assert found[i] == one_bracket_crossing(indicator, lo[i], hi[i]), i


def test_first_true_finds_a_switch():
    switch = np.array([0.123456789, 0.7])
    found = first_true(lambda t: t >= np.repeat(switch, t.size // 2), np.array([0.1, 0.65]), np.array([0.2, 0.71]))
    np.testing.assert_allclose(found, switch, atol=1e-9)


def test_searches_in_lockstep_give_what_each_gives_alone(brackets):
    lo, hi = brackets
    calls = []

    def evaluate(times, parts):
        calls.append(len(parts))
        return [wiggly(times[part]) for _, part in parts]

    maxima, crossings = run(evaluate, [maxima_search(lo, hi), first_true_search(lambda v: v > 0.2, lo[:7], hi[:7])])
    alone = function_maxima(wiggly, lo, hi)
    assert np.array_equal(maxima[0], alone[0]) and np.array_equal(maxima[1], alone[1])
    assert np.array_equal(crossings, first_true(lambda t: wiggly(t) > 0.2, lo[:7], hi[:7]))
    assert calls[:4] == [2, 2, 2, 2] and len(calls) == 5  # four shared levels, then the maxima's vertices
