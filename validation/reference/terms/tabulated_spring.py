"""Term of ``[[tabulated_spring]]``: connector ``<name>`` ground -> barrel, ``F = F(x_M)`` tabulated.

DESIGN.md, "Tabulated spring and damper".  ``d = x_M`` (m); F (N) linear on each piece of the table, the end
segments extended (:mod:`.tabulated`).  Potential ``U(d) = integral_0^d F``: on piece j (start B, value A,
slope K) ``U(d) = U(B) + A (d - B) + K (d - B)^2 / 2``, with ``U`` at the table points summed segment by segment
from the rest point (0, 0), which the table lists.  ``dF/dt = K d'``.  No dissipation.  F never decreases
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

    def equations(self, state) -> Equations:
        start, value, slope = self.table.pieces[state]
        return Equations("{F} = {A} + {K} * ({xb} - {xa} - {B})", dict(A=value, K=slope, B=start))

    def force_rate(self, state, d, rate, acceleration):
        return self.table.pieces[state][2] * rate

    def stored_energy(self, d):
        """U(d) in J (module docstring), on floats or arrays."""
        d_array = np.asarray(d, dtype=float)
        j = np.searchsorted(np.array(self.table.u), d_array, side="right")
        start = np.array([p[0] for p in self.table.pieces])[j]
        value = np.array([p[1] for p in self.table.pieces])[j]
        slope = np.array([p[2] for p in self.table.pieces])[j]
        base = np.array([self._energy_at[p[0]] for p in self.table.pieces])[j]
        h = d_array - start
        out = base + value * h + 0.5 * slope * h * h
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
