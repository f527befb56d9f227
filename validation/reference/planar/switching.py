"""The choice of mode at a restart of the planar model: the axis connectors as in 1-D, then the supports.

:class:`PlanarRestart` is the 1-D :class:`~validation.reference.switching.Restart` with the planar dynamics
answering what the connectors ask while they classify themselves:

* ``relative_acceleration(c)``: ``d''`` of connector c from the planar equations;
* ``free_relative_acceleration(c)``: ``d''`` without c's own force, expressed for the 1-D effective mass: the
  connectors read ``m_1D d''_free`` as the force that would hold ``d'' = 0`` (``m_1D = 1 / (1/m_a + 1/m_b)``),
  and in the planar model that force is ``d''_free / (G^T M^-1 G)`` (:mod:`.model`), so the value returned is
  ``d''_free (1/m_a + 1/m_b) / (G^T M^-1 G)`` -- of the same sign, the holding force exact;
* ``force_function(c)``: c's force in the classified mode (a constraint's multiplier included).

The supports are classified last (:meth:`.supports.Support.classify`) from their penetration, its rate and
its free acceleration (their own forces left out; for a spade also with its whole horizontal force and N = 0:
whether it slides on the ground), the point's x, horizontal velocity and acceleration and the hints
``support.NAME.<event>`` of the event that stopped the previous segment; their events are added to the
connectors' (a sliding spade's share alpha reaching 0 or 1).
"""

from __future__ import annotations

import numpy as np

from ..switching import Restart, rearm_window, sided
from .model import PlanarMode

#: Half-width (s) of the central difference that gives a support event's rate at a restart.
_RATE_STEP = 1e-9


def support_prefix(support) -> str:
    return f"support.{support.name}."


class PlanarRestart(Restart):
    """A restart of the planar model at ``t`` (s) from the planar state ``y`` (module docstring)."""

    def __init__(self, model, t: float, y: np.ndarray, hints: dict[str, bool], previous: PlanarMode | None):
        self.planar = model
        if previous is not None:
            self.support_states = list(previous.supports)
        else:
            self.support_states = []
            for s in model.supports:
                _, height, _, rise = model.support_motion(s)(y)
                self.support_states.append(s.provisional(-float(height), -float(rise)))
        super().__init__(model, t, y, hints, previous)
        for k, s in enumerate(model.supports):
            self.support_states[k] = self._classify_support(k, s)
        self.mode = self._planar_mode(self.states)

    def _planar_mode(self, states) -> PlanarMode:
        return PlanarMode(self.model.names, tuple(states), self.pieces, tuple(self.support_states))

    def _evaluate(self, omit=None, free_support=None):
        return self.planar.evaluate(self._planar_mode(self.states), self.y, omit=omit, t=self.t,
                                    free_support=free_support)

    # ------------------------------------------------------------------ what connectors ask
    def free_relative_acceleration(self, connector) -> float:
        free = self.model.relative_acceleration(connector, self._evaluate(omit=connector.index))
        G = np.zeros(self.planar.geometry.n)
        if connector.body_a is not None:
            G[3 + connector.body_a] += 1.0
        if connector.body_b is not None:
            G[3 + connector.body_b] -= 1.0
        X, Y, phi, *_ = self.planar.carriage(self.y)
        xs, _ = self.planar.axis_coordinates(self.y)
        M = self.planar.geometry.mass_matrix(np.array([phi]), [np.array([x]) for x in xs])[..., 0]
        return free * connector.inverse_reduced_mass / float(G @ np.linalg.solve(M, G))

    def relative_acceleration(self, connector) -> float:
        return self.model.relative_acceleration(connector, self._evaluate())

    def force_function(self, connector):
        planar, mode, j = self.planar, self.mode, connector.index
        return lambda t, y: planar.evaluate(mode, y, t=t).forces[j]

    # ------------------------------------------------------------------ the supports
    def _classify_support(self, k: int, support):
        motion = self.planar.support_motion(support)
        x, height, u, rise = motion(self.y)
        dy = self.planar.rhs(self._planar_mode(self.states))(self.t, self.y)
        du = self._rate(lambda y: motion(y)[2], dy)
        free = -self._rate(lambda y: motion(y)[3], self._derivative(free_support=k))
        free_holding = (-self._rate(lambda y: motion(y)[3], self._derivative(free_support=k, free_share=1.0))
                        if support.anchored else None)
        prefix = support_prefix(support)
        hints = {name[len(prefix):]: v for name, v in self._hints.items() if name.startswith(prefix)}
        previous = None if self.previous is None else self.previous.supports[k]
        return support.classify(-float(height), -float(rise), free, float(u), du, hints, previous, float(x),
                                free_holding)

    def _derivative(self, free_support=None, free_share=0.0):
        """dy/dt at the restart with the current states (``free_support``: that support's forces left out, a
        spade's but for ``free_share`` of it)."""
        ev = self.planar.evaluate(self._planar_mode(self.states), self.y, t=self.t, free_support=free_support,
                                  free_share=free_share)
        planar, slot = self.planar, self.planar.carriage_slot
        dy = np.zeros(planar.n_states)
        dy[slot:slot + 3] = self.y[slot + 3:slot + 6]
        dy[slot + 3:slot + 6] = ev.qdd[:3]
        for i in range(planar.axis.n_bodies):
            dy[2 * i], dy[2 * i + 1] = self.y[2 * i + 1], ev.qdd[3 + i]
        return dy

    def _share_function(self, k: int):
        """``(t, y) -> alpha`` of support k sliding in the classified mode (a state or a batch)."""
        planar, mode = self.planar, self.mode
        return lambda t, y: planar.evaluate(mode, y, t=t).shares[k]

    def _rate(self, g, dy) -> float:
        """d/dt of ``g(y)`` along ``dy`` at the restart (central difference over +-1 ns)."""
        h = _RATE_STEP
        return float((g(self.y + h * dy) - g(self.y - h * dy)) / (2.0 * h))

    def events(self):
        funcs, names = super().events()
        for k, s in enumerate(self.planar.supports):
            motion = self.planar.support_motion(s)
            for event, g, positive in s.events(self.mode.supports[k], motion, self._share_function(k)):
                value = float(g(self.t, self.y))
                rate = self._rate(lambda y: g(self.t, y), self.dy)
                noise = 1e-15 * max(1.0, abs(value))
                funcs.append(sided(g, self.t, positive, rearm_window(value, rate, noise, positive)))
                names.append(f"{support_prefix(s)}{event}")
        return funcs, names

