"""Building block: a force tabulated against one variable ``u`` (the displacement d or the rate d').

DESIGN.md, "Tabulated spring and damper".  Points ``(u_0, F_0) ... (u_(n-1), F_(n-1))``, ``u`` strictly
increasing, ``n >= 2``.  The law is linear on each of the ``n + 1`` **pieces** of the u axis: piece 0 is
``u < u_0``, piece ``j`` (1 <= j <= n-1) is ``u_(j-1) <= u < u_j``, piece n is ``u >= u_(n-1)``; on piece j::

    F = A_j + K_j (u - B_j)

with ``(B_j, A_j, K_j)`` the start point, value and slope of the segment ``[u_(j-1), u_j]`` for the inner pieces,
and the first segment's (pieces 0 and 1) or the last segment's (pieces n-1 and n) line outside the table: the
end segments extend linearly.  The pieces are the discrete state of the connector: every table point bounding
the current piece is a switching surface (event ``u<i>``: ``u = u_i``), so each solver segment integrates one
linear law.  At a restart the piece is decided by the side of each point the state is on or heading to (the
crossing's hint, else u, then du/dt, then d^2u/dt^2).
"""

from __future__ import annotations

import math

import numpy as np

from ..switching import heading


class Table:
    """The pieces of a tabulated force (module docstring)."""

    def __init__(self, points):
        self.u = [float(p[0]) for p in points]
        self.f = [float(p[1]) for p in points]
        n = len(self.u)
        self.n = n
        segments = [(self.u[i], self.f[i], (self.f[i + 1] - self.f[i]) / (self.u[i + 1] - self.u[i]))
                    for i in range(n - 1)]
        #: piece j -> (B_j, A_j, K_j)
        self.pieces = [segments[0]] + segments + [segments[-1]]

    def piece_of(self, u: float) -> int:
        """The piece holding ``u`` (number of table points <= u)."""
        return sum(u >= x for x in self.u)

    def value(self, u: float) -> float:
        """F(u) (N) on a float."""
        start, value, slope = self.pieces[self.piece_of(u)]
        return value + slope * (u - start)

    def values(self, u) -> np.ndarray:
        """F(u) (N) on an array (each element on its own piece)."""
        u = np.asarray(u, dtype=float)
        j = np.searchsorted(np.array(self.u), u, side="right")
        start = np.array([p[0] for p in self.pieces])[j]
        value = np.array([p[1] for p in self.pieces])[j]
        slope = np.array([p[2] for p in self.pieces])[j]
        return value + slope * (u - start)

    def largest_magnitude(self, bound: float) -> float:
        """``max |F|`` (N) over ``|u| <= bound``: at ``+-bound`` or at a table point inside; an infinite bound
        gives inf unless the extended end segment on that side is flat."""
        inside = [abs(f) for x, f in zip(self.u, self.f) if -bound <= x <= bound]
        if math.isfinite(bound):
            return max(inside + [abs(self.value(-bound)), abs(self.value(bound))])
        if self.pieces[0][2] != 0.0 or self.pieces[-1][2] != 0.0:
            return math.inf
        return max(inside + [abs(self.f[0]), abs(self.f[-1])])

    def classify(self, u: float, du: float, ddu: float, hints: dict) -> int:
        """The piece at a restart (module docstring)."""
        piece = 0
        for i, x in enumerate(self.u):
            name = f"u{i}"
            above = hints[name] if name in hints else heading(u - x, du, ddu, tol=1e-15 * max(1.0, abs(x)))
            piece += bool(above)
        return piece

    def bounding(self, piece: int):
        """``(i, positive)`` of the table points bounding ``piece``: the lower one (the state is above it) and
        the upper one (below it)."""
        return [(i, positive) for i, positive in ((piece - 1, True), (piece, False)) if 0 <= i < self.n]
