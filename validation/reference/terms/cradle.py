"""Term of ``[cradle]``: gravity along the inclined cradle and *exact* Coulomb friction with sticking.

DESIGN.md, "Inclined cradle".  With the elevation theta (degrees), g (m/s^2), mu and the barrel's mass M:

* gravity: a constant load ``M g sin(theta)`` (N) on the barrel, positive in the recoil direction (down
  the cradle of an elevated gun); it does no work through the mount (no support force);
* friction: a connector ``cradle`` ground -> barrel (``d = x_M``, ``d' = v_M``) of magnitude
  ``mu N``, ``N = M g cos(theta)`` (the barrel's weight only), exact Coulomb with three modes:

  - ``slip+`` (v_M > 0): ``F = +mu N`` (pushes the barrel back); ``slip-`` (v_M < 0): ``F = -mu N``;
    surface ``v_M = 0``;
  - ``stick``: ``v_M = 0`` held by ``F = f_M``, the sum of every other force on the barrel (a
    constraint, evaluated after the others: the barrel's acceleration is exactly 0), as long as
    ``|F| <= mu N``; surfaces ``F = +mu N`` (then ``slip+``) and ``F = -mu N`` (``slip-``).

  At a restart on ``v_M = 0`` the mode follows the force ``f = M a_free`` that the other forces would
  give the barrel without friction: ``stick`` if ``|f| <= mu N``, else ``slip`` in the direction of f
  (a crossing of ``F = +-mu N`` out of ``stick`` slips in the direction it crossed).
  Dissipated power ``F v_M`` (>= 0: F has the sign of v_M, and v_M = 0 while stuck); ``|F| <= mu N``
  (the early stop's force bound); no potential.

``mu N = 0`` adds no connector, ``sin(theta) = 0`` no load.  On a carriage (``[carriage]``, DESIGN.md "The recoil
axis on a carriage") the load is not added: the planar model (:mod:`validation.reference.planar`) pulls every
body vertically; the friction keeps ``N = M g cos(theta)``.  The engine regularises the same law
(:mod:`mbs_models.elements.cradle`); the difference is the creep its regularisation allows.  The
sliding mode of the ``compression_only`` reading is another constraint on the barrel: the two together
are not modelled (ReferenceModelError).
"""

from __future__ import annotations

import math

import numpy as np

from ..model import BARREL, GROUND, ConstantLoad, Connector, Equations, ReferenceModelError
from ..switching import TOL_VEL

TABLES = ("cradle",)

#: Machine epsilon (the relative round-off of a time).
_EPS = 2.220446049250313e-16
#: Friction modes.
SLIP_FORWARD, SLIP_BACKWARD, STICK = "slip+", "slip-", "stick"


class CoulombFriction(Connector):
    """Exact Coulomb friction ``mu N`` (N) between the ground ``a`` and a body ``b`` (module docstring)."""

    dissipates = True
    stores_energy = False
    classify_pass = 1

    def __init__(self, name: str, a: str, b: str, force: float):
        if a != GROUND or b == GROUND:
            raise ReferenceModelError(f"{name}: friction is modelled between the ground and a body")
        super().__init__(name, a, b)
        self.force = float(force)

    def law(self, d, rate, state=None):
        """``F = mu N sign(d')`` (N) while slipping (floats or arrays).  At d' = 0 the friction is the constraint
        force that holds the body (:meth:`equations` in ``stick``), anything in ``[-mu N, mu N]``: the law gives 0
        there, so that ``F(d, 0) = 0`` (no stored energy)."""
        if np.ndim(d) == 0 and np.ndim(rate) == 0:
            return math.copysign(self.force, rate) if rate != 0 else 0.0
        return self.force * np.sign(np.asarray(rate, dtype=float) + 0.0 * np.asarray(d, dtype=float))

    def equations(self, state) -> Equations:
        """``F = +-mu N`` while slipping; while stuck, the constraint ``F = f_b`` (every other force on b);
        the dissipated power ``F d'``."""
        if state == STICK:
            return Equations("""
                {F} = {fb} + 0.0
                {P} = {F} * ({vb} - {va})""", constraint=True)  # + 0.0: a copy (numpy rows are updated in place)
        return Equations("""
            {F} = {f}
            {P} = {f} * ({vb} - {va})""", dict(f=self.force if state == SLIP_FORWARD else -self.force))

    def force_rate(self, state, d, rate, acceleration):
        """0 while slipping; None while stuck (no closed form: the peak is found numerically)."""
        return None if state == STICK else 0.0 * rate

    def provisional(self, s, previous):
        """The previous mode, or at t = 0 the sign of the velocity (stuck at rest)."""
        if previous is not None:
            return previous
        rate = s[self.ib + 1] - s[self.ia + 1]
        return SLIP_FORWARD if rate > 0 else (SLIP_BACKWARD if rate < 0 else STICK)

    def classify(self, restart) -> str:
        """The mode at a restart (module docstring)."""
        hints = restart.hints_for(self)
        if "forward" in hints:        # left stick through F = +mu N
            return SLIP_FORWARD
        if "backward" in hints:       # through F = -mu N
            return SLIP_BACKWARD
        rate = restart.s[self.ib + 1] - restart.s[self.ia + 1]
        needed = self.mass_b * restart.free_relative_acceleration(self)  # the force that holds v = 0
        # on the surface v = 0 to within what the time's round-off allows at this acceleration (a restart
        # located by another connector's event, e.g. a stiff stop, lands 1e-16 s off: v ~ a 1e-16 s)
        noise = TOL_VEL + 8.0 * _EPS * max(1.0, abs(restart.t)) * (abs(needed) + self.force) / self.mass_b
        if "v" not in hints and abs(rate) > noise:
            return SLIP_FORWARD if rate > 0 else SLIP_BACKWARD
        if abs(needed) <= self.force:
            return STICK
        return SLIP_FORWARD if needed > 0 else SLIP_BACKWARD

    def events(self, state, restart):
        """``v = 0`` while slipping; ``F = +mu N`` and ``F = -mu N`` while stuck."""
        rate_of = self.rate_of
        if state != STICK:
            # a slide that starts on v = 0 (out of stick, or from rest) watches v - v(start): the round-off left
            # in v (either sign, ~1e-17 m/s) is not a crossing; the acceleration then grows from 0 as the force
            # that broke the stick keeps growing
            start = restart.s[self.ib + 1] - restart.s[self.ia + 1]
            offset = start if abs(start) <= restart.velocity_noise else 0.0
            return [("v", lambda t, y: rate_of(y) - offset, state == SLIP_FORWARD, rate_of(restart.dy),
                     restart.velocity_noise)]
        held = restart.force_function(self)
        limit = self.force
        return [("forward", lambda t, y: held(t, y) - limit, False, None, 0.0),
                ("backward", lambda t, y: held(t, y) + limit, True, None, 0.0)]

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        """``mu N`` (N)."""
        return self.force


def build(builder, key: str, table) -> None:
    """Gravity on the barrel and the friction ``cradle`` (module docstring), read from the table as data."""
    mass = float(builder.scene.barrel.mass)
    theta = math.radians(float(table.elevation))
    g, mu = float(table.gravity), float(table.friction_coefficient)
    normal = 0.0 if abs(float(table.elevation)) == 90.0 else mass * g * math.cos(theta)
    along = mass * g * math.sin(theta)
    if along != 0.0 and getattr(builder.scene, "carriage", None) is None:
        builder.add_load(ConstantLoad("gravity", BARREL, along))
    if mu * normal > 0.0:
        if builder.scene.conventions.compression_only:
            raise ReferenceModelError("[cradle] friction with the compression_only reading: two sliding modes on "
                                      "the barrel are not modelled")
        builder.add_connector(CoulombFriction(key, GROUND, BARREL, mu * normal))
