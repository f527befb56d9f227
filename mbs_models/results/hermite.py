"""Cubic Hermite interpolation between output samples, of one quantity or of several at once.

On a sample interval [t0, t1] with h = t1 - t0 and s = (t - t0) / h, a quantity y with derivative
dy is interpolated as

    y(t) = (2 s^3 - 3 s^2 + 1) y0 + (s^3 - 2 s^2 + s) h dy0 + (-2 s^3 + 3 s^2) y1 + (s^3 - s^2) h dy1,

which is fourth-order accurate in h (position from velocity, velocity from acceleration).  The basis
polynomials depend only on t, so :class:`HermiteStack` computes them once for all the quantities
sampled at the same times (every body's position and velocity) and evaluates each quantity with the
same floating-point operations, in the same order, as :func:`hermite` does for one.
"""

from __future__ import annotations

import numpy as np


def hermite(t0, t1, y0, y1, dy0, dy1, t):
    """Evaluate the cubic Hermite interpolant on [t0, t1] at ``t`` (arrays broadcast)."""
    h = t1 - t0
    s = (t - t0) / h
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * h * dy0
            + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * h * dy1)


def _combine(t0, t1, t, y0, y1, dy0, dy1):
    """:func:`hermite` with the basis computed once and broadcast over leading axes of the values."""
    h = t1 - t0
    s = (t - t0) / h
    s2, s3 = s * s, s * s * s
    b0 = 2 * s3 - 3 * s2 + 1
    b1 = (s3 - 2 * s2 + s) * h
    b2 = -2 * s3 + 3 * s2
    b3 = (s3 - s2) * h
    return b0 * y0 + b1 * dy0 + b2 * y1 + b3 * dy1


class HermiteStack:
    """Piecewise-cubic Hermite interpolants of Q quantities sampled at the same times.

    ``y`` and ``dy`` have shape (Q, samples); calls return shape (Q,) + the shape of the times.
    """

    def __init__(self, time: np.ndarray, y: np.ndarray, dy: np.ndarray):
        self.time = np.asarray(time, dtype=float)
        self.y = np.asarray(y, dtype=float).reshape(-1, len(self.time))
        self.dy = np.asarray(dy, dtype=float).reshape(-1, len(self.time))

    def __call__(self, t) -> np.ndarray:
        """Values at times ``t`` (s, any shape), the interval of each found by bisection."""
        t = np.asarray(t, dtype=float)
        i = np.minimum(np.maximum(np.searchsorted(self.time, t, side="right") - 1, 0), len(self.time) - 2)
        j = i + 1  # take: the same gathers as indexing, several times faster along axis 1
        return _combine(self.time.take(i), self.time.take(j), t, self.y.take(i, axis=1), self.y.take(j, axis=1),
                        self.dy.take(i, axis=1), self.dy.take(j, axis=1))

    def on_intervals(self, fractions: np.ndarray) -> np.ndarray:
        """Values at ``t_i + f h_i`` for every interval i and fraction f: shape (Q, intervals, fractions).

        On a zero-length interval (a jump at a segment boundary, e.g. a shot) the value before the jump.
        """
        t0, t1 = self.time[:-1, None], self.time[1:, None]
        f = np.asarray(fractions, dtype=float)[None, :]
        y0, y1 = self.y[:, :-1, None], self.y[:, 1:, None]
        dy0, dy1 = self.dy[:, :-1, None], self.dy[:, 1:, None]
        if np.all(t1 > t0):
            return _combine(t0, t1, t0 + f * (t1 - t0), y0, y1, dy0, dy1)
        with np.errstate(invalid="ignore", divide="ignore"):
            values = _combine(t0, t1, t0 + f * (t1 - t0), y0, y1, dy0, dy1)
        return np.where(t1 > t0, values, y0)


class HermiteTrajectory:
    """Piecewise-cubic Hermite interpolant of a sampled quantity ``y`` with derivative ``dy``."""

    def __init__(self, time: np.ndarray, y: np.ndarray, dy: np.ndarray):
        self.time = np.asarray(time, dtype=float)
        self.y = np.asarray(y, dtype=float)
        self.dy = np.asarray(dy, dtype=float)
        self._stack = HermiteStack(self.time, self.y, self.dy)

    def __call__(self, t):
        return self._stack(t)[0]

    def on_intervals(self, fractions: np.ndarray) -> np.ndarray:
        """Values at ``t_i + f h_i`` for every interval i and fraction f: shape (intervals, fractions)."""
        return self._stack.on_intervals(fractions)[0]
