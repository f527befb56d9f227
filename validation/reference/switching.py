"""Switching surfaces: which side of each the state is on at a restart, and the events that end a segment.

The integrator (:mod:`validation.reference.solver`) keeps the right-hand side smooth inside a segment by
fixing a :class:`~validation.reference.model.Mode`; a segment ends at the first switching surface the
state crosses (a terminal ``solve_ivp`` event located by root finding on the dense output), and the next
mode is chosen at that state (:class:`Restart`).  A quantity sitting on its switching surface is
classified by the direction the state is heading: the crossing direction of the event that stopped the
previous segment (``hints``), or the sign of its time derivatives (:func:`heading`).

Connectors are classified in two passes (``Connector.classify_pass``): first those decided on the
accelerations *without* their own force (contacts: does the free motion close the gap?), each against
the others' provisional states; then those decided on the accelerations of the classified mode
(velocity-sign switches such as the recoil damper's branch).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from .model import Model, Mode

#: |g| below these (m, 1, m/s) counts as "on the switching surface" when no event says so.
TOL_POS, TOL_S, TOL_VEL = 1e-14, 1e-14, 1e-14


def heading(g, dg, ddg=0.0, tol=TOL_POS) -> bool:
    """Is ``g`` (with derivatives ``dg``, ``ddg``) positive or about to become positive?"""
    if abs(g) > tol:
        return g > 0
    if abs(dg) > TOL_VEL:
        return dg > 0
    return ddg > 0


class NonFiniteEvent(FloatingPointError):
    """A switching function evaluated to NaN inside ``solve_ivp``'s event location: the solve fails
    (:class:`~validation.reference.solver.ReferenceSolveError`), no root is sought in it."""


def sided(g, t_start: float, positive: bool, window: float = 0.0):
    """Terminal event from ``g(t, y)`` watching the crossing that leaves the ``positive`` side.

    For ``t_start <= t <= t_start + window`` the function reports the classified side (a tiny value of
    that sign if ``g`` says otherwise): a surface the state has just left is re-armed only once ``g`` has
    moved clear of round-off noise, so noise in the dense output right after the restart, or a return
    within the first step, is not mistaken for a crossing at ``t_start``.  Until ``g`` has been seen on
    the classified side, an exact 0 counts as that side too: a state resting on its surface (a barrel at
    rest against a battery stop at 0: ``g`` is 0 for ever) is not crossing it.  (Once the state has left
    the surface an exact 0 is a root like any other: root finding may land on one.)
    """
    sign = 1.0 if positive else -1.0
    seen = [False]  # has g been seen strictly on the classified side?

    def fun(t, y):
        value = g(t, y)
        if value != value:  # NaN: the dense output left the finite numbers (a diverging solution)
            raise NonFiniteEvent(f"a switching function is NaN at t = {t:.9g} s")
        if sign * value > 0:
            seen[0] = True
        elif t - t_start <= window or (value == 0 and not seen[0]):
            return sign * 1e-300
        return value
    fun.terminal = True
    fun.direction = -sign
    fun.raw, fun.sign, fun.t_start, fun.window = g, sign, t_start, window
    return fun


def rearm_window(value: float, rate: float | None, noise: float, positive: bool) -> float:
    """Time (s) for a function sitting on its surface (``|value| <= noise``) to clear 100 noise levels."""
    if abs(value) > noise or rate is None or not (rate > 0) == positive or rate == 0:
        return 0.0
    with np.errstate(over="ignore"):  # a rate too small for double precision: the window's cap
        return min(100.0 * noise / abs(rate), 1e-8)


def missed_crossing(dense, funcs, names, t0: float, t1: float):
    """Earliest crossing inside ``(t0, t1)`` that solve_ivp's step-end sign checks missed.

    solve_ivp only compares event signs at step ends, so a surface left and re-entered within one step
    (a short separation or a grazing contact) goes unseen.  The dense output is scanned on the steps
    subdivided 8 times; returns ``(t, name)`` of the first such crossing, or None.
    """
    ts = np.asarray(dense.ts, dtype=float)
    ts = np.unique(np.concatenate(([t0], ts[(ts > t0) & (ts < t1)], [t1])))
    tg = np.concatenate(((ts[:-1, None] + np.diff(ts)[:, None] * np.arange(8)[None, :] / 8).ravel(), [t1]))
    yg = dense(tg)
    found = None
    for fun, name in zip(funcs, names):
        g = fun.sign * np.broadcast_to(fun.raw(tg, yg), tg.shape)
        wrong = (g < -1e-12 * np.max(np.abs(g))) & (tg > t0 + fun.window)
        wrong[0] = wrong[-1] = False
        if wrong.any():
            j = int(np.argmax(wrong))
            try:
                tr = brentq(lambda s: fun(s, dense(s)), tg[j - 1], tg[j], xtol=1e-16, maxiter=200)
            except ValueError:  # g at tg[j-1] is within round-off of the surface already
                tr = float(tg[j - 1])
            if found is None or tr < found[0]:
                found = (tr, name)
    return found


class Restart:
    """The choice of mode at a restart at time ``t`` (s) from state ``y``.

    ``hints``: ``"<connector>.<event>" -> bool`` for the events that stopped the previous segment (True:
    the surface was crossed upwards, the function is now positive); ``previous``: the previous segment's
    mode (None at t = 0).  :attr:`mode` is the classified mode (with the loads' pieces from ``t`` on);
    :meth:`events` the segment's events.  A restart after a time event (a shot's velocity jump, a load's
    breakpoint) has no hints: every connector is classified from the state, as after any event.
    """

    def __init__(self, model: Model, t: float, y: np.ndarray, hints: dict[str, bool], previous: Mode | None):
        self.model, self.t, self.y, self.previous = model, t, y, previous
        self._hints = hints
        self.s = np.asarray(y)[:model.axis_states].tolist() + [0.0, 0.0]  # the axis' state, then the ground
        x = [abs(v) for v in self.s[0:2 * model.n_bodies:2]]
        v = [abs(w) for w in self.s[1:2 * model.n_bodies:2]]
        #: round-off levels of positions (m) and velocities (m/s)
        self.position_scale = max([1.0] + x)
        self.velocity_noise = 1e-15 * max([1.0] + v)
        #: the pieces of the loads' laws on [t, next breakpoint)
        self.pieces = model.load_pieces(t)
        connectors = model.connectors
        self.states = [c.provisional(self.s, self.previous_state(c)) for c in connectors]
        for stage in (1, 2):
            for j, c in enumerate(connectors):
                if c.classify_pass == stage:
                    self.states[j] = c.classify(self)
        self.mode = Mode(model.names, tuple(self.states), self.pieces)

    # ------------------------------------------------------------------ what connectors ask while classifying
    def hints_for(self, connector) -> dict[str, bool]:
        """The hints of one connector, by event name."""
        prefix = connector.name + "."
        return {k[len(prefix):]: v for k, v in self._hints.items() if k.startswith(prefix)}

    def previous_state(self, connector):
        """The connector's state in the previous segment (None at t = 0)."""
        return None if self.previous is None else self.previous.states[connector.index]

    def _evaluate(self, omit=None):
        return self.model.evaluate(Mode(self.model.names, tuple(self.states), self.pieces), self.y, omit=omit,
                                   t=self.t)

    def free_relative_acceleration(self, connector) -> float:
        """d'' (m/s^2) of ``connector`` without its own force, the others in their current states."""
        return self.model.relative_acceleration(connector, self._evaluate(omit=connector.index))

    def relative_acceleration(self, connector) -> float:
        """d'' (m/s^2) of ``connector`` with every connector in its current state."""
        return self.model.relative_acceleration(connector, self._evaluate())

    def position_noise(self, offset: float = 0.0) -> float:
        """Round-off level (m) of a position difference minus ``offset``."""
        return 1e-15 * max(self.position_scale, abs(offset))

    def force_function(self, connector):
        """``(t, y) -> raw force`` (N) of ``connector`` in the classified mode, on a state or a batch (the
        time matters for a constraint force under a load)."""
        model, mode, j = self.model, self.mode, connector.index
        return lambda t, y: model.evaluate(mode, y, t=t).forces[j]

    # ------------------------------------------------------------------ the segment's events
    def events(self):
        """Terminal event functions of the segment starting here, and their names ``<connector>.<event>``.

        Each connector gives ``(event, g, positive, rate, noise)``: ``rate`` is dg/dt at the start in the
        new mode (None if not available), ``noise`` the round-off level of ``g``, both used for re-arming.
        """
        #: dy/dt at the restart in the new mode (velocities, accelerations, powers)
        self.dy = self.model.rhs(self.mode)(self.t, self.y)
        funcs, names = [], []
        #: names of the events across which the right-hand side is only C^1
        self.rough = {f"{c.name}.{event}" for c, state in zip(self.model.connectors, self.mode.states)
                      for event in c.rough_events(state)}
        for c, state in zip(self.model.connectors, self.mode.states):
            for event, g, positive, rate, noise in c.events(state, self):
                window = rearm_window(float(g(self.t, self.y)), rate, noise, positive)
                funcs.append(sided(g, self.t, positive, window))
                names.append(f"{c.name}.{event}")
        return funcs, names
