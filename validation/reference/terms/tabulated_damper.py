"""Term of ``[[tabulated_damper]]``: connector ``<name>`` ground -> barrel, ``F = F(v_M)`` tabulated.

DESIGN.md, "Tabulated spring and damper".  ``d' = v_M`` (m/s); F (N) linear on each piece of the table, the
end segments extended (:mod:`.tabulated`): on piece j ``F = A + K (d' - B)``, ``dF/dt = K d''``.  Dissipated
power ``F d'`` (W, >= 0: the table is passive); no stored energy.  ``|F| <= max |F|`` over ``|d'| <= |d'|max``.
The pieces switch where d' crosses a table velocity (events on d'), decided at a restart on the accelerations of
the classified mode (F is continuous, so they do not depend on the piece chosen).
"""

from __future__ import annotations

import numpy as np

from ..model import BARREL, GROUND, Connector, Equations
from .tabulated import Table

TABLES = ("tabulated_damper",)


class TabulatedDamper(Connector):
    """``F = F(d')`` tabulated between ``a`` and ``b`` (module docstring); the state is the piece of d'."""

    dissipates = True
    stores_energy = False
    classify_pass = 2

    def __init__(self, name: str, a: str, b: str, points):
        super().__init__(name, a, b)
        self.table = Table(points)

    def law(self, d, rate, state=None):
        """``F(d')`` (N) from the table, each d' on its own piece (floats or arrays)."""
        if np.ndim(d) == 0 and np.ndim(rate) == 0:
            return self.table.value(rate)
        return self.table.values(np.asarray(rate, dtype=float) + 0.0 * np.asarray(d, dtype=float))

    def equations(self, state) -> Equations:
        start, value, slope = self.table.pieces[state]
        return Equations("""
            rate = {vb} - {va}
            {F} = {A} + {K} * (rate - {B})
            {P} = {F} * rate""", dict(A=value, K=slope, B=start))

    def force_rate(self, state, d, rate, acceleration):
        return self.table.pieces[state][2] * acceleration

    def provisional(self, s, previous):
        return self.table.piece_of(s[self.ib + 1] - s[self.ia + 1])

    def classify(self, restart) -> int:
        s = restart.s
        rate = s[self.ib + 1] - s[self.ia + 1]
        acceleration = restart.relative_acceleration(self)
        return self.table.classify(rate, acceleration, 0.0, restart.hints_for(self))

    def events(self, state, restart):
        rate_of, dy = self.rate_of, restart.dy
        return [(f"u{i}", lambda t, y, v=self.table.u[i]: rate_of(y) - v, positive, rate_of(dy),
                 restart.velocity_noise) for i, positive in self.table.bounding(state)]

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        return self.table.largest_magnitude(rate_bound)


def build(builder, key: str, table) -> None:
    """The damper ground -> barrel, named by the table's ``name``."""
    builder.add_connector(TabulatedDamper(table.name, GROUND, BARREL, table.pairs))
