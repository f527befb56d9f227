"""Cubic Hermite interpolation between output samples, of one quantity or of several at once.

On a sample interval [t0, t1] with h = t1 - t0 and s = (t - t0) / h, a quantity y with derivative
dy is interpolated as

    y(t) = (2 s^3 - 3 s^2 + 1) y0 + (s^3 - 2 s^2 + s) h dy0 + (-2 s^3 + 3 s^2) y1 + (s^3 - s^2) h dy1,

which is fourth-order accurate in h (position from velocity, velocity from acceleration); its derivative

    y'(t) = 6 (s^2 - s) (y0 - y1) / h + (3 s^2 - 4 s + 1) dy0 + (3 s^2 - 2 s) dy1

(:meth:`HermiteStack.derivative`: an acceleration between samples from the velocity's interpolant) is
third-order accurate, dy0 and dy1 at the ends.  The basis
polynomials depend only on t, so :class:`HermiteStack` computes them once for all the quantities
sampled at the same times (every body's position and velocity) and evaluates each quantity with the
same floating-point operations, in the same order, as :func:`hermite` does for one.
"""

from __future__ import annotations

from contextlib import nullcontext

import numpy as np


def hermite(t0, t1, y0, y1, dy0, dy1, t):
    """Evaluate the cubic Hermite interpolant on [t0, t1] at ``t`` (arrays broadcast)."""
    h = t1 - t0
    s = (t - t0) / h
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * h * dy0
            + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * h * dy1)


def _basis(t0, t1, t):
    """The four basis polynomials of :func:`hermite` at ``t``, the derivative ones times h."""
    h = t1 - t0
    s = (t - t0) / h
    s2, s3 = s * s, s * s * s
    return 2 * s3 - 3 * s2 + 1, (s3 - 2 * s2 + s) * h, -2 * s3 + 3 * s2, (s3 - s2) * h


def _derivative_basis(t0, t1, t):
    """The four basis polynomials of the derivative of :func:`hermite` at ``t``, in :func:`_apply`'s order."""
    h = t1 - t0
    s = (t - t0) / h
    s2 = s * s
    return 6 * (s2 - s) / h, 3 * s2 - 4 * s + 1, 6 * (s - s2) / h, 3 * s2 - 2 * s


def _apply(basis, y0, y1, dy0, dy1):
    """``b0 y0 + b1 dy0 + b2 y1 + b3 dy1``, summed in :func:`hermite`'s order."""
    b0, b1, b2, b3 = basis
    return b0 * y0 + b1 * dy0 + b2 * y1 + b3 * dy1


def _combine(t0, t1, t, y0, y1, dy0, dy1):
    """:func:`hermite` with the basis computed once and broadcast over leading axes of the values."""
    return _apply(_basis(t0, t1, t), y0, y1, dy0, dy1)


#: :meth:`HermiteStack.at_fractions` evaluates all quantities in one pass up to this many values (quantities x
#: fractions x intervals), one quantity at a time beyond (chosen by timing both ways: the one pass is faster for
#: the few hundred samples of an early-stopped run, the loop for long runs of many quantities).
AT_ONCE_ELEMENTS = 2 ** 15


class HermiteStack:
    """Piecewise-cubic Hermite interpolants of Q quantities sampled at the same times.

    ``y`` and ``dy`` have shape (Q, samples); calls return shape (Q,) + the shape of the times.  The
    sample times and the values are kept as the rows of one table, so that a call gathers the samples
    on both sides of every time in two gathers (:meth:`chain` shares the rows that are values of one
    quantity and derivatives of another).
    """

    def __init__(self, time: np.ndarray, y: np.ndarray, dy: np.ndarray):
        time = np.asarray(time, dtype=float)
        y = np.asarray(y, dtype=float).reshape(-1, len(time))
        dy = np.asarray(dy, dtype=float).reshape(-1, len(time))
        self._set_table(np.concatenate([time[None, :], y, dy]), len(y), 1 + len(y))

    @classmethod
    def chain(cls, time: np.ndarray, levels: list[np.ndarray]) -> "HermiteStack":
        """The interpolants of a chain of quantities each the derivative of the one before, sampled as
        ``levels`` (each of shape (Q, samples); e.g. positions, velocities, accelerations): the values are
        every level but the last, their derivatives every level but the first (so velocities are
        interpolated from accelerations, positions from velocities), ``Q (len(levels) - 1)`` quantities."""
        time = np.asarray(time, dtype=float)
        rows = [np.asarray(level, dtype=float).reshape(-1, len(time)) for level in levels]
        stack = cls.__new__(cls)
        stack._set_table(np.concatenate([time[None, :]] + rows), sum(len(r) for r in rows[:-1]), 1 + len(rows[0]))
        return stack

    def _set_table(self, table: np.ndarray, count: int, first_derivative: int) -> None:
        """``table``: the times (row 0), the ``count`` values from row 1, their derivatives from row
        ``first_derivative``."""
        self._table = table
        self._values = slice(1, 1 + count)
        self._derivatives = slice(first_derivative, first_derivative + count)
        self.time, self.y, self.dy = table[0], table[self._values], table[self._derivatives]

    def _interval(self, t: np.ndarray) -> np.ndarray:
        """The index of the sample interval holding each time (bisection; the first or last beyond the ends)."""
        return np.minimum(np.maximum(np.searchsorted(self.time, t, side="right") - 1, 0), len(self.time) - 2)

    def __call__(self, t, quantities=None) -> np.ndarray:
        """Values at times ``t`` (s, any shape), the interval of each found by bisection.

        ``quantities``: indices of the quantities wanted (shape (len(quantities),) + the shape of ``t``), each
        the same floats as in the full result; None: all of them.  Only the samples of those quantities are
        gathered, so a call for a few quantities of a large stack costs what those few cost."""
        t = np.asarray(t, dtype=float)
        i = self._interval(t)
        if quantities is None:
            # take: the same gathers as indexing, several times faster along axis 1
            before, after = self._table.take(i, axis=1), self._table.take(i + 1, axis=1)
            values, derivatives = self._values, self._derivatives
        else:
            wanted = np.asarray(quantities, dtype=np.intp)
            rows = np.concatenate([[0], self._values.start + wanted, self._derivatives.start + wanted])
            rows = rows.reshape((-1,) + (1,) * i.ndim)
            before, after = self._table[rows, i[None]], self._table[rows, i[None] + 1]
            values, derivatives = slice(1, 1 + len(wanted)), slice(1 + len(wanted), 1 + 2 * len(wanted))
        return _combine(before[0], after[0], t, before[values], after[values], before[derivatives],
                        after[derivatives])

    def derivative(self, t, quantities=None) -> np.ndarray:
        """The interpolants' time derivatives at times ``t`` (s, any shape; module docstring), shaped as
        :meth:`__call__`'s values; at a sample time, the sampled derivative of the interval after it."""
        t = np.asarray(t, dtype=float)
        i = self._interval(t)
        count = self._values.stop - self._values.start
        wanted = np.arange(count) if quantities is None else np.asarray(quantities, dtype=np.intp)
        y, dy = self._table[self._values.start + wanted], self._table[self._derivatives.start + wanted]
        return _apply(_derivative_basis(self.time[i], self.time[i + 1], t), y[:, i], y[:, i + 1], dy[:, i], dy[:, i + 1])

    def at_fractions(self, fractions: np.ndarray) -> np.ndarray:
        """Values at ``t_i + f h_i`` for every fraction f and interval i: shape (Q, fractions, intervals).

        On a zero-length interval (a jump at a segment boundary, e.g. a shot) the value before the jump.
        The basis is computed once with the intervals as the last axis (long inner loops).  Up to
        :data:`AT_ONCE_ELEMENTS` values the quantities are evaluated together (fewer, longer operations);
        beyond, each on the basis in turn (small temporaries: one (Q, fractions, intervals) array of
        temporaries then costs more in fresh memory pages than in arithmetic).  Both ways do the same
        floating-point operations on every value.
        """
        t0, t1 = self.time[:-1], self.time[1:]
        f = np.asarray(fractions, dtype=float)[:, None]
        jump = not np.all(t1 > t0)
        with np.errstate(invalid="ignore", divide="ignore") if jump else nullcontext():
            basis = _basis(t0, t1, t0 + f * (t1 - t0))
        y, dy = self.y, self.dy
        if len(y) * f.shape[0] * len(t0) <= AT_ONCE_ELEMENTS:
            values = _apply(basis, y[:, None, :-1], y[:, None, 1:], dy[:, None, :-1], dy[:, None, 1:])
            return np.where(t1 > t0, values, y[:, None, :-1]) if jump else values
        out = np.empty((len(y), f.shape[0], len(t0)))
        for q in range(len(y)):
            values = _apply(basis, y[q, :-1], y[q, 1:], dy[q, :-1], dy[q, 1:])
            out[q] = np.where(t1 > t0, values, y[q, :-1]) if jump else values
        return out

    def on_intervals(self, fractions: np.ndarray) -> np.ndarray:
        """:meth:`at_fractions` laid out as (Q, intervals, fractions) (a transposed view)."""
        return self.at_fractions(fractions).transpose(0, 2, 1)


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
