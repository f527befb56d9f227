"""Building block: the linear spring-damper ``F = k d + c d'`` (recoil spring, absorber actuators).

With ``d = x_b - x_a`` (m) and ``d' = v_b - v_a`` (m/s) (DESIGN.md, "Bodies and connectors"):

* force ``F = k d + c d'`` (N), k in N/m, c in N s/m;
* stored energy ``U = k d^2 / 2`` (J); dissipated power ``F d' - dU/dt = c d'^2`` (W);
* ``dF/dt = k d' + c d''``; at rest ``F = k d``;
* energy bounds: the spring enters the quadratic form with ``k``; ``|F| <= k |d|_max + c |d'|_max``.
"""

from __future__ import annotations

from ..model import Connector, Equations


class LinearSpringDamper(Connector):
    """``F = k d + c d'`` between ``a`` and ``b``; no discrete state."""

    def __init__(self, name: str, a: str, b: str, stiffness: float = 0.0, damping: float = 0.0):
        super().__init__(name, a, b)
        self.stiffness, self.damping = float(stiffness), float(damping)
        self.dissipates = self.damping > 0
        self.stores_energy = self.stiffness > 0

    def law(self, d, rate, state=None):
        """``F = k d + c d'`` (N)."""
        return self.stiffness * d + self.damping * rate

    def equations(self, state) -> Equations:
        """``F = k d + c d'``; the dissipated power ``c d'^2``."""
        k, c = self.stiffness, self.damping
        if c == 0.0:
            return Equations("{F} = {k} * ({xb} - {xa})", dict(k=k))
        if k == 0.0:
            return Equations("""
                rate = {vb} - {va}
                {F} = {c} * rate
                {P} = {c} * rate ** 2""", dict(c=c))
        return Equations("""
            rate = {vb} - {va}
            {F} = {k} * ({xb} - {xa}) + {c} * rate
            {P} = {c} * rate ** 2""", dict(k=k, c=c))

    def force_rate(self, state, d, rate, acceleration):
        """dF/dt = k d' + c d'' (N/s)."""
        return self.stiffness * rate + self.damping * acceleration

    def stored_energy(self, d):
        """U = k d^2 / 2 (J)."""
        return 0.5 * self.stiffness * d ** 2

    def static_force(self, d: float) -> float:
        """k d (N)."""
        return self.stiffness * d

    @property
    def linear_stiffness(self) -> float:
        return self.stiffness

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        """``k |d|_max + c |d'|_max`` (N); a zero coefficient adds nothing, even to an infinite bound."""
        return sum(coefficient * bound for coefficient, bound in ((self.stiffness, d_bound), (self.damping, rate_bound))
                   if coefficient > 0)
