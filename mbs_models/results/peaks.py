"""Refining extrema and crossings between output samples with cubic Hermite interpolation.

Exudyn records the state at the end of each (adaptive) step.  A raw sample maximum of a 15 ms force
pulse is not its peak, so every reported extremum is refined on the piecewise-cubic Hermite
interpolant built from a quantity *and its time derivative* (position from velocity, velocity from
acceleration), which is fourth-order accurate in the step size.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .hermite import HermiteTrajectory, hermite  # noqa: F401  (re-exported: the interpolant of the refinements)
from .nested_grids import first_true, maxima_search, run, values_at


def run_bounds(flags: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(first, last)`` index arrays (inclusive) of the maximal runs of True in a 1-D boolean array."""
    active = np.asarray(flags, dtype=bool)
    edges = np.diff(active.astype(np.int8))
    first = np.flatnonzero(edges == 1) + 1
    last = np.flatnonzero(edges == -1)
    if len(active) and active[0]:
        first = np.concatenate([[0], first])
    if len(active) and active[-1]:
        last = np.concatenate([last, [len(active) - 1]])
    return first.astype(int), last.astype(int)


def runs_of_true(flags: np.ndarray) -> list[tuple[int, int]]:
    """``(first, last)`` indices (inclusive) of every maximal run of True in a 1-D boolean array.

    The contact episodes of a sampled force are ``runs_of_true(force > 0)``.
    """
    first, last = run_bounds(flags)
    return list(zip(first.tolist(), last.tolist()))


def run_argmax(values: np.ndarray, first: np.ndarray, last: np.ndarray) -> np.ndarray:
    """Index of the (first) largest of ``values[first[r]:last[r] + 1]`` for every run r (runs disjoint,
    increasing, values not NaN): ``np.argmax`` per run, in one pass over the samples of all runs."""
    if not len(first):
        return np.zeros(0, dtype=int)
    lengths = last - first + 1
    offsets = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    index = np.repeat(first - offsets, lengths) + np.arange(int(lengths.sum()))  # the samples of every run
    run = np.repeat(np.arange(len(first)), lengths)
    inside = values[index]
    largest = np.maximum.reduceat(inside, offsets)
    at_largest = np.flatnonzero(inside == largest[run])
    _, first_of_run = np.unique(run[at_largest], return_index=True)
    return index[at_largest[first_of_run]]


def refine_maximum(time: np.ndarray, y: np.ndarray, dy: np.ndarray) -> tuple[float, float]:
    """Global maximum ``(value, time)`` of the Hermite interpolant of ``y`` (derivative ``dy``).

    Every interval where the derivative turns from positive to non-positive holds a local maximum,
    and so do the two intervals beside the sample maximum; on each, the interpolant's derivative is
    a quadratic whose roots are solved exactly.  All local maxima are compared, not only the one
    next to the largest sample: with many near-equal peaks (a rattling absorber) the largest sample
    need not sit beside the largest peak.
    """
    time, y, dy = (np.asarray(a, dtype=float) for a in (time, y, dy))
    k = int(np.argmax(y))
    best_value, best_time = float(y[k]), float(time[k])
    candidate = (dy[:-1] > 0) & (dy[1:] <= 0)  # per interval: the derivative turns from positive
    candidate[max(k - 1, 0):k + 1] = True  # the intervals beside the sample maximum
    i = np.flatnonzero(candidate)
    h = time[i + 1] - time[i]
    nonempty = h > 0
    i, h = i[nonempty], h[nonempty]
    if not len(i):
        return best_value, best_time
    # y(s) = a s^3 + b s^2 + c s + d on s in [0, 1]
    y0, y1, d0, d1 = y[i], y[i + 1], dy[i] * h, dy[i + 1] * h
    a = 2 * y0 + d0 - 2 * y1 + d1
    b = -3 * y0 - 2 * d0 + 3 * y1 - d1
    c = d0
    # roots of 3a s^2 + 2b s + c without cancellation: q = -(B + sign(B) sqrt(B^2 - 4AC)) / 2
    A, B = 3 * a, 2 * b
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        disc = B * B - 4 * A * c
        q = -0.5 * (B + np.copysign(np.sqrt(np.where(disc >= 0, disc, np.nan)), B))
        for s in (q / A, c / q):
            value = ((a * s + b) * s + c) * s + y0
            value = np.where(np.isfinite(s) & (s >= 0.0) & (s <= 1.0) & np.isfinite(value), value, -np.inf)
            j = int(np.argmax(value))
            if value[j] > best_value:
                best_value, best_time = float(value[j]), float(time[i[j]] + s[j] * h[j])
    return best_value, best_time


def maxima_near_samples(time: np.ndarray, ks: np.ndarray, points: int = 65, levels: int = 4):
    """The searches for the maxima of a function near each sample ``ks[i]``, and how to read them.

    Returns ``(searches, brackets, assemble)``: generators for :func:`~mbs_models.results.nested_grids.run`
    (a :func:`~mbs_models.results.nested_grids.maxima_search` over [t_{k-1}, t_{k+1}] for every k whose
    bracket is not empty; the value at ``t_k`` itself where it is, equal times at a jump), the indices
    into ``ks`` of each search's brackets (increasing), and ``assemble(results)`` -> ``(values, times)``
    arrays in the order of ``ks``.  A sample at a segment boundary appears twice (a largest sample is the
    first of the two): the bracket then ends at the next later sample, ``t_{k+2}``, not at ``t_k`` again.
    """
    time = np.asarray(time, dtype=float)
    ks = np.asarray(ks, dtype=int)
    lo = time[np.maximum(ks - 1, 0)]
    hi = time[np.minimum(np.searchsorted(time, time[ks], side="right"), len(time) - 1)]
    open_ = hi > lo
    searches, brackets, kinds = [], [], []
    if open_.any():
        searches.append(maxima_search(lo[open_], hi[open_], points, levels))
        brackets.append(np.flatnonzero(open_))
        kinds.append("open")
    if not open_.all():
        searches.append(values_at(time[ks[~open_]]))
        brackets.append(np.flatnonzero(~open_))
        kinds.append("closed")

    def assemble(results) -> tuple[np.ndarray, np.ndarray]:
        values = np.empty(len(ks))
        times = np.empty(len(ks))
        for kind, result in zip(kinds, results):
            if kind == "open":
                values[open_], times[open_] = result
            else:
                times[~open_] = time[ks[~open_]]
                values[~open_] = np.asarray(result, dtype=float)
        return values, times

    return searches, brackets, assemble


def refine_function_maxima(f: Callable[[np.ndarray], np.ndarray], time: np.ndarray, ks: np.ndarray,
                           points: int = 65, levels: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Maxima ``(values, times)`` of a continuous ``f(t)`` near each sample ``ks[i]``, all at once.

    ``f`` maps a 1-D array of times to an array of that shape.  Each is searched over
    [t_{k-1}, t_{k+1}] by :func:`~mbs_models.results.nested_grids.maxima_search` (nested uniform
    grids, then a parabola through the best three points): ``levels + 1`` calls of ``f`` in all,
    resolution ~ h / points**levels.  Where the bracket is empty (equal times at a jump) the value is
    ``f(t_k)`` at ``t_k``.
    """
    searches, _, assemble = maxima_near_samples(time, ks, points, levels)
    return assemble(run(lambda times, parts: [f(times[part]) for _, part in parts], searches))


def refine_function_maximum(f: Callable[[np.ndarray], np.ndarray], time: np.ndarray, k: int,
                            points: int = 65, levels: int = 4) -> tuple[float, float]:
    """Maximum ``(value, time)`` of a continuous function ``f(t)`` near sample ``k``.

    ``f`` takes a 1-D array of times.  It is searched over [t_{k-1}, t_{k+1}] on nested uniform grids
    (each level zooms on the best point's neighbours), then a parabola through the best three
    points gives the final estimate: a few vectorised calls, resolution ~ h / points**levels.
    (:func:`refine_function_maxima` with one sample.)
    """
    values, times = refine_function_maxima(lambda t: np.reshape(f(np.ravel(t)), np.shape(t)), time, [k],
                                           points, levels)
    return float(values[0]), float(times[0])


def refine_crossing(indicator: Callable[[np.ndarray], np.ndarray], t_false: float, t_true: float,
                    points: int = 129, levels: int = 4) -> float:
    """Earliest time in (t_false, t_true] where the boolean ``indicator(times)`` turns True.

    Nested uniform grids: each level keeps the bracket around the first True point, so the
    resolution is (t_true - t_false) / (points - 1)**levels.  If the indicator is never True on a
    grid (it flips back and forth faster than the grid), ``t_true`` is returned.
    (:func:`~mbs_models.results.nested_grids.first_true` with one bracket.)
    """
    found = first_true(lambda t: np.reshape(indicator(np.ravel(t)), np.shape(t)), np.array([t_false], dtype=float),
                       np.array([t_true], dtype=float), points, levels)
    return float(found[0])
