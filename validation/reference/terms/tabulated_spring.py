"""Term of ``[[tabulated_spring]]``: connector ``<name>`` ground -> barrel, ``F = F(x_M)`` tabulated.

DESIGN.md, "Tabulated spring and damper".  ``d = x_M`` (m); F (N) linear on each piece of the table, the end
segments extended (:mod:`.tabulated`).  Potential ``U(d) = integral_0^d F``: on a piece of slope K, from its
end x nearer to the rest point (0, 0), which the table lists, ``U(d) = U(x) + F(x) (d - x) + K (d - x)^2 / 2``,
with ``U`` at the table points summed segment by segment outward from the rest point.  ``dF/dt = K d'``.  No dissipation.  F never decreases
with d, so U is convex with U(0) = 0: the early stop bounds it with the barrel's stops as a potential well
(``nonlinear_potential``).  ``|F| <= max |F|`` over ``|d| <= |d|max``.
"""

from __future__ import annotations

import numpy as np

from ..model import BARREL, GROUND, Connector, Equations
from .tabulated import Table

TABLES = ("tabulated_spring",)


class TabulatedSpring(Connector):
    """``F = F(d)`` tabulated between ``a`` and ``b`` (module docstring); the state is the piece of d."""

    stores_energy = True
    dissipates = False
    nonlinear_potential = True
    classify_pass = 2

    def __init__(self, name: str, a: str, b: str, points):
        super().__init__(name, a, b)
        self.table = Table(points)
        u, f = self.table.u, self.table.f
        rest = u.index(0.0)
        # U at the table points: trapezoids outward from the rest point
        energy = [0.0] * len(u)
        for i in range(rest + 1, len(u)):
            energy[i] = energy[i - 1] + 0.5 * (f[i] + f[i - 1]) * (u[i] - u[i - 1])
        for i in range(rest - 1, -1, -1):
            energy[i] = energy[i + 1] - 0.5 * (f[i] + f[i + 1]) * (u[i + 1] - u[i])
        self._energy_at = dict(zip(u, energy))

    def law(self, d, rate, state=None):
        """``F(d)`` (N) from the table, each d on its own piece (floats or arrays)."""
        if np.ndim(d) == 0 and np.ndim(rate) == 0:
            return self.table.value(d)
        return self.table.values(np.asarray(d, dtype=float) + 0.0 * np.asarray(rate, dtype=float))

    @property
    def kinks(self) -> tuple[float, ...]:
        """The table's displacements (m): the slope of F jumps there."""
        return tuple(self.table.u)

    def equations(self, state) -> Equations:
        start, value, slope = self.table.pieces[state]
        return Equations("{F} = {A} + {K} * ({xb} - {xa} - {B})", dict(A=value, K=slope, B=start))

    def force_rate(self, state, d, rate, acceleration):
        return self.table.pieces[state][2] * rate

    def stored_energy(self, d):
        """U(d) in J (module docstring), on floats or arrays, from the end of d's piece nearer to the rest point:
        ``U(x) + F(x) (d - x) + K (d - x)^2 / 2`` with x the piece's right end left of 0, its left end right of 0
        (so that near 0 no large U(x) cancels: U(0) = 0 exactly)."""
        d_array = np.asarray(d, dtype=float)
        u, f = self.table.u, self.table.f
        rest = u.index(0.0)
        j = np.searchsorted(np.array(u), d_array, side="right")
        anchor_index = np.array([i if i <= rest else i - 1 for i in range(len(self.table.pieces))])[j]
        x = np.array(u)[anchor_index]
        force = np.array(f)[anchor_index]
        slope = np.array([p[2] for p in self.table.pieces])[j]
        base = np.array([self._energy_at[point] for point in u])[anchor_index]
        h = d_array - x
        out = base + force * h + 0.5 * slope * h * h
        return float(out) if out.ndim == 0 else out

    def static_force(self, d: float) -> float:
        return self.table.value(d)

    def provisional(self, s, previous):
        return self.table.piece_of(s[self.ib] - s[self.ia])

    def classify(self, restart) -> int:
        s = restart.s
        d, rate = s[self.ib] - s[self.ia], s[self.ib + 1] - s[self.ia + 1]
        return self.table.classify(d, rate, restart.relative_acceleration(self), restart.hints_for(self))

    def events(self, state, restart):
        d_of, dy = self.d_of, restart.dy
        return [(f"u{i}", lambda t, y, x=self.table.u[i]: d_of(y) - x, positive, d_of(dy),
                 restart.position_noise(self.table.u[i])) for i, positive in self.table.bounding(state)]

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        return self.table.largest_magnitude(d_bound)


def build(builder, key: str, table) -> None:
    """The spring ground -> barrel, named by the table's ``name``."""
    builder.add_connector(TabulatedSpring(table.name, GROUND, BARREL, table.pairs))
