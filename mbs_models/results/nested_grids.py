"""Nested-grid searches on many brackets at once: maxima of a function, first times an indicator turns True.

Each bracket ``[lo, hi]`` (s) is searched on a uniform grid of ``points`` times; the next level zooms on
the neighbours of the best (or first True) point; after ``levels`` levels the resolution is
``(hi - lo) / (points - 1)**levels``.  All brackets advance level by level together: the function is
called once per level on all brackets' times, whatever their number, so a run with hundreds of contact
episodes costs a handful of vectorised calls instead of hundreds of small ones; :func:`run` drives
several searches (maxima, crossings, of different functions of the same state) in lockstep, so they
share those calls too.

Each bracket's arithmetic is that of the one-bracket search (``np.linspace`` per bracket, ``argmax``
per row, the same parabola), element by element in float64, so the results are bit-identical to
searching the brackets one at a time.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def uniform_grids(lo: np.ndarray, hi: np.ndarray, points: int) -> np.ndarray:
    """``np.linspace(lo[i], hi[i], points)`` for every i, as rows of a ``(len(lo), points)`` array.

    The same operations as ``np.linspace`` on each pair: ``lo + i * ((hi - lo) / (points - 1))`` (or
    ``lo + (i / (points - 1)) * (hi - lo)`` where the step underflows to 0), the last point ``hi``.
    ``lo`` and ``hi`` are 1-D float arrays.
    """
    div = points - 1
    index = _indices(points)
    delta = hi - lo
    step = delta / div
    grid = index * step[:, None]
    if not step.all():  # numpy's special case for denormal steps (gh-5437), per row
        zero = step == 0
        grid[zero] = (index / div) * delta[zero, None]
    grid += lo[:, None]
    grid[:, -1] = hi
    return grid


_INDICES: dict[int, np.ndarray] = {}


def _indices(points: int) -> np.ndarray:
    """``np.arange(points, dtype=float)`` (the grid indices 0, 1, ..., points - 1), made once per size."""
    if points not in _INDICES:
        _INDICES[points] = np.arange(0, points, dtype=float)
    return _INDICES[points]


def maxima_search(lo: np.ndarray, hi: np.ndarray, points: int = 65, levels: int = 4):
    """Generator form of :func:`function_maxima`: yields arrays of times (s), is sent ``f`` on each
    (same shape), returns ``(values, times)``.  Run it with :func:`run` (alone or beside others)."""
    lo = np.asarray(lo, dtype=float)
    hi = np.asarray(hi, dtype=float)
    rows = np.arange(len(lo))
    first = rows * points  # each row's first point in the flattened grid
    for _ in range(levels):
        grid = uniform_grids(lo, hi, points)
        values = np.asarray((yield grid), dtype=float)
        j = values.argmax(axis=1)
        flat = grid.ravel()
        lo, hi = flat.take(first + np.maximum(j, 1) - 1), flat.take(first + np.minimum(j, points - 2) + 1)
    at_best = first + j
    best_value, best_time = values.ravel().take(at_best), grid.ravel().take(at_best)
    inner = rows[(j > 0) & (j < points - 1)]  # the best point has two neighbours
    ji = j[inner]
    y0, y1, y2 = values[inner, ji - 1], values[inner, ji], values[inner, ji + 1]
    curvature = y0 - 2 * y1 + y2
    vertex = curvature < 0
    if vertex.any():
        r = inner[vertex]
        shift = 0.5 * (y0[vertex] - y2[vertex]) / curvature[vertex]
        step = grid[r, 1] - grid[r, 0]
        t_vertex = grid[r, j[r]] + shift * step
        times = best_time.copy()  # one time per bracket: its vertex, or its best point again (value unused)
        times[r] = t_vertex
        value = np.asarray((yield times), dtype=float)[r]
        better = value > best_value[r]
        best_value[r[better]] = value[better]
        best_time[r[better]] = t_vertex[better]
    return best_value, best_time


def first_true_search(predicate: Callable[[np.ndarray], np.ndarray], t_false: np.ndarray, t_true: np.ndarray,
                      points: int = 129, levels: int = 4):
    """Generator form of :func:`first_true`: yields ``(brackets, points)`` arrays of times (s), is sent a
    function's values on them, of which ``predicate(values)`` is the indicator; returns the times."""
    a = np.asarray(t_false, dtype=float)
    b = np.asarray(t_true, dtype=float)
    first = np.arange(len(a)) * points  # each row's first point in the flattened grid
    for _ in range(levels):
        grid = uniform_grids(a, b, points)
        flags = np.array(predicate((yield grid)), dtype=bool)
        flags[:, -1] = True
        at_true = first + flags[:, 1:].argmax(axis=1) + 1
        flat = grid.ravel()
        a, b = flat.take(at_true - 1), flat.take(at_true)
    return 0.5 * (a + b)


def values_at(times: np.ndarray):
    """The trivial search: yields ``times``, returns the values it is sent (to run beside the others)."""
    return (yield np.asarray(times, dtype=float))


def run(evaluate: Callable[[np.ndarray, list[tuple[int, slice]]], list[np.ndarray]], searches: list) -> list:
    """Drive several searches in lockstep; return their results in order.

    At each round every unfinished search asks for values at an array of times, one row (or one time)
    per bracket, in the order of its brackets; ``evaluate`` gets all those times concatenated (1-D, s)
    and ``(search index, slice)`` of each search's part, and returns one array of values per part (each
    search, or each bracket, may evaluate a different function on the same interpolated state).  So a
    round costs one evaluation whatever the number of searches and brackets.
    """
    results: list = [None] * len(searches)
    requests = {}
    for index, search in enumerate(searches):
        try:
            requests[index] = next(search)
        except StopIteration as done:
            results[index] = done.value
    while requests:
        order = list(requests)
        sizes = [requests[i].size for i in order]
        ends = np.cumsum(sizes)
        parts = [(i, slice(int(e - n), int(e))) for i, e, n in zip(order, ends, sizes)]
        times = np.concatenate([requests[i].ravel() for i in order]) if len(order) > 1 else requests[order[0]].ravel()
        values = evaluate(times, parts)
        for i, part_values in zip(order, values):
            try:
                requests[i] = searches[i].send(np.reshape(part_values, requests[i].shape))
            except StopIteration as done:
                results[i] = done.value
                del requests[i]
    return results


def _alone(f: Callable[[np.ndarray], np.ndarray]):
    return lambda times, parts: [f(times[part]) for _, part in parts]


def function_maxima(f: Callable[[np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray,
                    points: int = 65, levels: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Maxima ``(values, times)`` of a continuous ``f(t)`` on each bracket ``[lo[i], hi[i]]`` (hi > lo).

    ``f`` maps a 1-D array of times (s) to an array of the same shape.  Nested uniform grids (each
    level keeps the best point's two neighbours), then a parabola through the best point and its
    neighbours: with curvature ``y0 - 2 y1 + y2 < 0`` its vertex ``t1 + (y0 - y2) / (2 (y0 - 2 y1 + y2)) dt``
    is evaluated and kept if it is larger.  Resolution ~ (hi - lo) / points**levels.
    """
    return run(_alone(f), [maxima_search(lo, hi, points, levels)])[0]


def first_true(indicator: Callable[[np.ndarray], np.ndarray], t_false: np.ndarray, t_true: np.ndarray,
               points: int = 129, levels: int = 4) -> np.ndarray:
    """Earliest time (s) in each ``(t_false[i], t_true[i]]`` where the boolean ``indicator`` turns True.

    ``indicator`` maps a 1-D array of times to booleans.  Each level keeps the bracket around the first
    True point after the left end (the right end counts as True), so the result, the midpoint of the
    last bracket, is within ``(t_true - t_false) / (points - 1)**levels / 2``; where the indicator is
    never True on a grid (it flips faster than the grid), the search closes on ``t_true``.
    """
    return run(_alone(indicator), [first_true_search(lambda flags: flags, t_false, t_true, points, levels)])[0]
