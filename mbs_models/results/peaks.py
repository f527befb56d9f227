"""Refining extrema and crossings between output samples with cubic Hermite interpolation.

Exudyn records the state at the end of each (adaptive) step.  A raw sample maximum of a 15 ms force
pulse is not its peak, so every reported extremum is refined on the piecewise-cubic Hermite
interpolant built from a quantity *and its time derivative* (position from velocity, velocity from
acceleration), which is fourth-order accurate in the step size.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

def hermite(t0, t1, y0, y1, dy0, dy1, t):
    """Evaluate the cubic Hermite interpolant on [t0, t1] at ``t`` (arrays broadcast)."""
    h = t1 - t0
    s = (t - t0) / h
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * h * dy0
            + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * h * dy1)


class HermiteTrajectory:
    """Piecewise-cubic Hermite interpolant of a sampled quantity ``y`` with derivative ``dy``."""

    def __init__(self, time: np.ndarray, y: np.ndarray, dy: np.ndarray):
        self.time = np.asarray(time, dtype=float)
        self.y = np.asarray(y, dtype=float)
        self.dy = np.asarray(dy, dtype=float)

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        i = np.clip(np.searchsorted(self.time, t, side="right") - 1, 0, len(self.time) - 2)
        return hermite(self.time[i], self.time[i + 1], self.y[i], self.y[i + 1], self.dy[i], self.dy[i + 1], t)

    def on_intervals(self, fractions: np.ndarray) -> np.ndarray:
        """Values at ``t_i + f h_i`` for every interval i and fraction f: shape (intervals, fractions)."""
        t0, t1 = self.time[:-1, None], self.time[1:, None]
        f = np.asarray(fractions, dtype=float)[None, :]
        if np.all(t1 > t0):
            return hermite(t0, t1, self.y[:-1, None], self.y[1:, None], self.dy[:-1, None], self.dy[1:, None],
                           t0 + f * (t1 - t0))
        # zero-length intervals (a jump at a segment boundary, e.g. a shot): the value before the jump
        with np.errstate(invalid="ignore", divide="ignore"):
            values = hermite(t0, t1, self.y[:-1, None], self.y[1:, None], self.dy[:-1, None], self.dy[1:, None],
                             t0 + f * (t1 - t0))
        return np.where(t1 > t0, values, self.y[:-1, None])


def runs_of_true(flags: np.ndarray) -> list[tuple[int, int]]:
    """``(first, last)`` indices (inclusive) of every maximal run of True in a 1-D boolean array.

    The contact episodes of a sampled force are ``runs_of_true(force > 0)``.
    """
    active = np.asarray(flags, dtype=bool)
    if not active.any():
        return []
    edges = np.diff(active.astype(np.int8))
    starts = list(np.flatnonzero(edges == 1) + 1)
    ends = list(np.flatnonzero(edges == -1))
    if active[0]:
        starts.insert(0, 0)
    if active[-1]:
        ends.append(len(active) - 1)
    return [(int(i0), int(i1)) for i0, i1 in zip(starts, ends)]


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
    h = np.diff(time)
    near_sample_max = [i for i in (k - 1, k) if 0 <= i < len(h)]
    i = np.union1d(np.flatnonzero((dy[:-1] > 0) & (dy[1:] <= 0)), near_sample_max).astype(int)
    i = i[h[i] > 0]
    if not len(i):
        return best_value, best_time
    # y(s) = a s^3 + b s^2 + c s + d on s in [0, 1]
    y0, y1, d0, d1 = y[i], y[i + 1], dy[i] * h[i], dy[i + 1] * h[i]
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
                best_value, best_time = float(value[j]), float(time[i[j]] + s[j] * h[i[j]])
    return best_value, best_time


def refine_function_maximum(f: Callable[[np.ndarray], np.ndarray], time: np.ndarray, k: int,
                            points: int = 65, levels: int = 4) -> tuple[float, float]:
    """Maximum ``(value, time)`` of a continuous function ``f(t)`` near sample ``k``.

    ``f`` takes an array of times.  It is searched over [t_{k-1}, t_{k+1}] on nested uniform grids
    (each level zooms on the best point's neighbours), then a parabola through the best three
    points gives the final estimate: a few vectorised calls, resolution ~ h / points**levels.
    """
    lo = time[max(k - 1, 0)]
    hi = time[min(k + 1, len(time) - 1)]
    if hi <= lo:
        return float(f(np.array([time[k]]))[0]), float(time[k])
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


def refine_crossing(indicator: Callable[[np.ndarray], np.ndarray], t_false: float, t_true: float,
                    points: int = 129, levels: int = 4) -> float:
    """Earliest time in (t_false, t_true] where the boolean ``indicator(times)`` turns True.

    Nested uniform grids: each level keeps the bracket around the first True point, so the
    resolution is (t_true - t_false) / (points - 1)**levels.  If the indicator is never True on a
    grid (it flips back and forth faster than the grid), ``t_true`` is returned.
    """
    a, b = t_false, t_true
    for _ in range(levels):
        grid = np.linspace(a, b, points)
        flags = np.asarray(indicator(grid), dtype=bool)
        flags[-1] = True
        j = int(np.argmax(flags[1:])) + 1  # first True after the left end
        a, b = grid[j - 1], grid[j]
    return float(0.5 * (a + b))
