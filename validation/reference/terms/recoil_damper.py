"""Term of ``[recoil_damper]``: connector ``recoil_damper`` ground -> barrel, Eqs. (2)-(3) of the paper.

``F = c(v_M) v_M`` (N) with ``c = recoil`` while the barrel recoils (``v_M > 0``) and ``counter_recoil``
otherwise (N s/m); F is 0 at ``v_M = 0`` on either branch.  Dissipated power ``c v_M^2`` (W);
``dF/dt = c a_M``; bound ``|F| <= max(c) |v_M|_max``.  None if both coefficients are 0.

Discrete state (different coefficients only): the branch, True while recoiling.  Switching surface
``v_M = 0``; at a restart on it the branch follows the sign of ``a_M`` in the classified mode (the
damper's force is 0 there on either branch), or the crossing direction if ``a_M = 0``.
"""

from __future__ import annotations

import numpy as np

from ..model import BARREL, GROUND, Connector, Equations
from ..switching import TOL_VEL

TABLES = ("recoil_damper",)


class RecoilDamper(Connector):
    """The asymmetric damper ``F = c(d') d'`` between ``a`` and ``b`` (module docstring)."""

    dissipates = True
    stores_energy = False

    def __init__(self, name: str, a: str, b: str, recoil: float, counter_recoil: float):
        super().__init__(name, a, b)
        self.recoil, self.counter_recoil = float(recoil), float(counter_recoil)
        self.asymmetric = self.recoil != self.counter_recoil
        self.classify_pass = 2 if self.asymmetric else 0

    def coefficient(self, state) -> float:
        """c (N s/m) on the branch ``state`` (True or None: recoil)."""
        return self.counter_recoil if state is False else self.recoil

    def law(self, d, rate, state=None):
        """``F = c(d') d'`` (N): ``recoil`` for d' > 0, ``counter_recoil`` otherwise (floats or arrays)."""
        if np.ndim(rate) == 0 and np.ndim(d) == 0:
            return (self.recoil if rate > 0 else self.counter_recoil) * rate
        rate = np.asarray(rate, dtype=float) + 0.0 * np.asarray(d, dtype=float)
        return np.where(rate > 0, self.recoil, self.counter_recoil) * rate

    def equations(self, state) -> Equations:
        """``F = c d'``, dissipated power ``c d'^2``."""
        return Equations("""
            rate = {vb} - {va}
            {F} = {c} * rate
            {P} = {c} * rate ** 2""", dict(c=self.coefficient(state)))

    def force_rate(self, state, d, rate, acceleration):
        """dF/dt = c d'' (N/s)."""
        return self.coefficient(state) * acceleration

    def provisional(self, s, previous):
        """The branch of the velocity's sign (None when both coefficients are equal)."""
        return (s[self.ib + 1] - s[self.ia + 1]) > 0 if self.asymmetric else None

    def classify(self, restart) -> bool:
        """The branch at a restart (module docstring)."""
        rate = restart.s[self.ib + 1] - restart.s[self.ia + 1]
        recoil = rate > 0
        hints = restart.hints_for(self)
        if "v" in hints or abs(rate) <= TOL_VEL:
            acceleration = restart.relative_acceleration(self)
            recoil = acceleration > 0 if acceleration != 0 else hints.get("v", recoil)
        return bool(recoil)

    def events(self, state, restart):
        """``v = 0`` (the velocity's sign change) with different coefficients."""
        if not self.asymmetric:
            return []
        rate_of = self.rate_of
        return [("v", lambda t, y: rate_of(y), state, rate_of(restart.dy), restart.velocity_noise)]

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        """``max(c) |d'|_max`` (N)."""
        c = max(self.recoil, self.counter_recoil)
        return c * rate_bound if c > 0 else 0.0


def build(builder, key: str, table) -> None:
    """The damper ground -> barrel, unless both coefficients are 0."""
    if table.recoil > 0 or table.counter_recoil > 0:
        builder.add_connector(RecoilDamper("recoil_damper", GROUND, BARREL, table.recoil, table.counter_recoil))
