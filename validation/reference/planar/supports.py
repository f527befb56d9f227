"""The supports: unilateral contacts of carriage points with the ground, with friction or a dug-in spade.

DESIGN.md, "The recoil axis on a carriage".  A support at carriage point ``r`` is at ``P = (X, Y) + R r``:
height ``y_s``, horizontal velocity ``u_s``.  Its force on the carriage, ``(T, N)`` in the ground frame:

* normal: the contact law of its table (DESIGN.md "Contact laws", the reference's :class:`~..terms.contact_laws.Law`)
  with penetration ``p = -y_s`` and rate ``p' = -y_s'``: 0 while ``p <= 0``; while ``p > 0`` (an episode, ``v-``
  its onset rate) ``N = k p^n (1 + a p')`` (a: lambda, ``chi / max(v-, floor)``, 0) or ``k p + c p'``
  (Kelvin-Voigt), clipped to ``N >= 0``;
* tangential, Coulomb regularised: ``T = -mu N sat(u_s / v_reg)``, ``sat`` clipping to [-1, 1] (three smooth
  branches: ``u_s < -v_reg``, ``|u_s| <= v_reg``, ``u_s > v_reg``);
* or a dug-in spade: ``T = -(k_h (x_s - x_s0) + c_h u_s)`` while the point is in the ground, ``p > 0``, whatever
  N (also while the normal law is clipped to 0), 0 otherwise; ``x_s0`` the anchor: the point's x in the initial
  static equilibrium (``anchor = "rest"``) or where it last touched down, its x at the event ``p = 0`` rising
  (``anchor = "touchdown"``); or none (frictionless).

Discrete state (:class:`SupportMode`): the normal contact's :class:`~..terms.contact_laws.ContactMode` (``on``:
the law acts; ``off`` and ``penetrated``: clipped; ``penetrated``: ``p > 0``, a spade holds; ``stick``: a spade
sliding on the ground, below), the friction branch ``slip`` (-1, 0, +1) and a spade's ``anchor`` x_s0.  Switching
surfaces (events): ``p = 0`` (touch / leave the ground: the spade's force switches there), the clipping surface
while penetrated (``1 + a p' = 0`` or ``p + (c/k) p' = 0``: N reaches 0; nothing else switches there) and
``u_s = +-v_reg`` (the friction's branches).

A spade's force switches on ``p = 0``, so that surface can hold the motion from both sides (Filippov): in the
ground the spade's force lifts the point out (``p'' < 0`` with N = 0 at p = p' = 0), off it the weight presses it
back (``p'' > 0``): a spade landing away from its anchor (``rest``) with its spring stretched.  Then the spade
*slides on the ground* (phase ``stick``): ``p = 0``, ``N = 0`` and its horizontal force is the share ``alpha``
(0 <= alpha <= 1) of its force in the ground that keeps ``p'' = 0`` (a multiplier of the planar equations,
:mod:`.model`); it ends where alpha reaches 0 (the point leaves the ground) or 1 (it digs in), events ``a0`` and
``a1``.  At a restart on the ground (``|p|`` below :data:`GROUND_POSITION` and ``|p'|`` below
:data:`GROUND_TIME` times ``|p''|`` on either side: it would cross and come back within that time) the spade slides
iff ``p'' > 0`` off the ground and ``p'' < 0`` in it.

Energy: stored ``k max(p, 0)^(n+1) / (n+1)`` plus, for a spade in the ground or sliding on it,
``k_h (x_s - x_s0)^2 / 2``; dissipated power ``(N - k p^n) p' - T u_s`` minus the spade spring's rate.  When a
spade leaves the ground its spring's energy leaves the balance at once (and one anchored at rest takes its energy
back at a touch-down away from its anchor): the solver adds it to the support's dissipated energy there
(:meth:`Support.anchor_energy`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..terms.contact_laws import OFF, ON, STICK, ContactMode, Law
from ..switching import TOL_POS, TOL_S, heading

#: A point within this distance (m) of the ground, and whose rate would carry it across and back within
#: ``GROUND_TIME`` (s) on either side, is on the ground: there a spade whose force pushes it out slides on it.
GROUND_POSITION, GROUND_TIME = 1e-12, 1e-9


@dataclass(frozen=True)
class SupportMode:
    """A support's discrete state in one segment: its normal ``contact`` state, the friction branch ``slip``
    (-1: ``u < -v_reg``, 0: ``|u| <= v_reg``, +1: ``u > v_reg``; 0 without friction) and a spade's ``anchor``
    x_s0 (m; None for a support without one)."""

    contact: ContactMode
    slip: int = 0
    anchor: float | None = None

    @property
    def holding(self) -> bool:
        """Does the normal law act (N > 0 possible)?"""
        return self.contact.phase == ON

    @property
    def in_ground(self) -> bool:
        """Is the point in the ground (p > 0; its normal law acting or clipped): a spade holds."""
        return self.contact.phase == ON or self.contact.penetrated

    @property
    def sliding(self) -> bool:
        """Does a spade slide on the ground (p = 0, N = 0, a share of its force: module docstring)?"""
        return self.contact.phase == STICK

    @property
    def spring_stored(self) -> bool:
        """Is a spade's spring energy stored (in the ground or sliding on it)?"""
        return self.in_ground or self.sliding


class Support:
    """One support of the carriage (module docstring), read from a ``[[carriage.support]]`` table as data;
    ``anchor``: the point's x in the static equilibrium (m)."""

    def __init__(self, table, anchor: float = 0.0):
        self.name = str(table.name)
        self.point = (float(table.position[0]), float(table.position[1]))
        self.law = Law.from_table(table)
        self.friction = float(table.friction_coefficient or 0.0)
        self.friction_velocity = float(table.friction_velocity)
        self.horizontal_stiffness = float(table.horizontal_stiffness or 0.0)
        self.horizontal_damping = float(table.horizontal_damping or 0.0)
        self.anchored = self.horizontal_stiffness > 0.0 or self.horizontal_damping > 0.0
        #: "rest" (x_s0 the static x for good) or "touchdown" (x_s0 where the point last touched down)
        self.anchor_rule = str(getattr(table, "anchor", "rest") or "rest")
        #: x_s0 (m) at t = 0: the point's x in the static equilibrium
        self.anchor = float(anchor)

    def __repr__(self) -> str:
        return f"Support({self.name!r} at {self.point})"

    # ------------------------------------------------------------------ kinematics
    def motion(self, geometry, carriage):
        """(x_s, y_s, u_s, w_s): the point's position and velocity (m, m/s) from the carriage's
        ``(X, Y, phi, X', Y', phi')`` (floats or arrays)."""
        X, Y, phi, dX, dY, dphi = carriage
        x, y = geometry.place(X, Y, phi, self.point)
        u, w = geometry.point_velocity(phi, dX, dY, dphi, self.point)
        return x, y, u, w

    # ------------------------------------------------------------------ the laws
    def static_force(self, penetration: float) -> float:
        """``k max(p, 0)^n`` (N): the normal force at rest."""
        return self.law.stiffness * max(penetration, 0.0) ** self.law.exponent

    def elastic(self, p):
        """``k sign(p) |p|^n`` (N): the law's spring, continued oddly to p < 0 (smooth across a segment's end)."""
        return self.law.stiffness * np.sign(p) * np.abs(p) ** self.law.exponent

    def normal(self, mode: SupportMode, p, rate):
        """N (N) in ``mode``: the law unclipped while ``on`` (the segment's smooth law), 0 otherwise."""
        if mode.contact.phase != ON:
            return 0.0 * p
        if self.law.kelvin_voigt:
            return self.law.stiffness * p + self.law.damping * rate
        return self.elastic(p) * (1.0 + mode.contact.factor * rate)

    def spade_force(self, anchor: float, x, u):
        """``-(k_h (x - x0) + c_h u)`` (N): a spade's horizontal force in the ground, anchored at x0 = ``anchor``."""
        return -(self.horizontal_stiffness * (x - anchor) + self.horizontal_damping * u)

    def tangential(self, mode: SupportMode, normal, x, u, share=0.0):
        """T (N) in ``mode`` from N (N), the point's x (m) and horizontal velocity u (m/s); a sliding spade's
        ``share`` (alpha) of its force."""
        if self.anchored:
            if mode.in_ground:
                return self.spade_force(mode.anchor, x, u)
            return share * self.spade_force(mode.anchor, x, u) if mode.sliding else 0.0 * u
        if self.friction == 0.0:
            return 0.0 * u
        if mode.slip:
            return -mode.slip * self.friction * normal
        return -self.friction * normal * u / self.friction_velocity

    def stored_energy(self, mode: SupportMode | None, p, x):
        """``k max(p, 0)^(n+1) / (n+1)`` plus a spade's ``k_h (x - x0)^2 / 2`` while in the ground or sliding (J)."""
        n = self.law.exponent
        out = self.law.stiffness * np.maximum(p, 0.0) ** (n + 1.0) / (n + 1.0)
        if self.anchored and mode is not None and mode.spring_stored:
            out = out + self.anchor_energy(mode.anchor, x)
        return out

    def anchor_energy(self, anchor: float, x):
        """``k_h (x - x0)^2 / 2`` (J): the spade's spring, anchored at x0 = ``anchor`` (m)."""
        return 0.5 * self.horizontal_stiffness * (x - anchor) ** 2

    def dissipated_power(self, mode: SupportMode, p, rate, normal, tangential, u, x):
        """``(N - k p^n) p' - T u`` (W), minus the spade spring's rate ``k_h (x - x0) u`` while it holds."""
        out = 0.0 * p
        if mode.contact.penetrated or mode.contact.phase == ON:
            out = (normal - self.elastic(p)) * rate
        out = out - tangential * u
        if self.anchored and mode.spring_stored:
            out = out - self.horizontal_stiffness * (x - mode.anchor) * u
        return out

    # ------------------------------------------------------------------ modes and events
    def provisional(self, p: float, rate: float) -> SupportMode:
        """At t = 0: the law acts iff p > 0 (the static equilibrium), friction in its linear branch, a spade
        anchored at its static x."""
        anchor = self.anchor if self.anchored else None
        if p <= 0.0:
            return SupportMode(ContactMode(OFF), 0, anchor)
        factor, onset = self._episode(rate, None)
        return SupportMode(ContactMode(ON, True, False, factor, onset), self._branch(0.0, 0.0, {}), anchor)

    def _episode(self, rate: float, previous: ContactMode | None):
        if previous is not None and previous.penetrated:
            return previous.factor, previous.onset_rate
        onset = max(rate, 0.0)
        return self.law.episode_factor(onset), onset

    def surface(self, p, rate, factor):
        """The clipping surface: ``p + (c/k) p'`` (m, Kelvin-Voigt) or ``1 + a p'``."""
        if self.law.kelvin_voigt:
            return p + self.law.damping / self.law.stiffness * rate
        return 1.0 + factor * rate

    def surface_rate(self, rate, acceleration, factor):
        if self.law.kelvin_voigt:
            return rate + self.law.damping / self.law.stiffness * acceleration
        return factor * acceleration

    def _branch(self, u: float, du: float, hints: dict) -> int:
        """The friction branch at a restart (0 without friction)."""
        if self.anchored or self.friction == 0.0:
            return 0
        v = self.friction_velocity
        if "u+" in hints:
            return 1 if hints["u+"] else 0
        if "u-" in hints:
            return 0 if hints["u-"] else -1
        if heading(u - v, du, tol=1e-15 * max(1.0, v)):
            return 1
        if heading(-(u + v), -du, tol=1e-15 * max(1.0, v)):
            return -1
        return 0

    def _anchor(self, previous: SupportMode | None, in_ground: bool, x: float) -> float | None:
        """x_s0 after a restart: ``touchdown`` moves it to the point's x where it touches the ground (enters it or
        slides on it)."""
        if not self.anchored:
            return None
        before = self.anchor if previous is None else previous.anchor
        entering = in_ground and previous is not None and not previous.spring_stored
        return float(x) if self.anchor_rule == "touchdown" and entering else before

    def classify(self, p: float, rate: float, free: float, u: float, du: float, hints: dict,
                 previous: SupportMode | None, x: float = 0.0, free_holding: float | None = None) -> SupportMode:
        """The state at a restart from ``p``, ``p'``, the free ``p''`` (this support's forces left out), the
        point's x, u and du/dt, the hints of the event that stopped the segment (``p``, ``s``, ``u+``, ``u-``,
        ``a0``, ``a1``: True if crossed upwards) and the previous state; ``free_holding``: a spade's ``p''`` with
        N = 0 and its whole force (whether it slides on the ground, module docstring)."""
        slip = self._branch(u, du, hints)
        if "a0" in hints:      # a sliding spade's share fell to 0: the point leaves the ground
            return SupportMode(ContactMode(OFF), slip, self._anchor(previous, False, x))
        if (self.anchored and free_holding is not None and "a1" not in hints and free > 0.0 > free_holding
                and abs(p) <= GROUND_POSITION and abs(rate) <= GROUND_TIME * min(free, -free_holding)):
            return SupportMode(ContactMode(STICK), slip, self._anchor(previous, True, x))
        entering = "a1" in hints or (hints["p"] if "p" in hints else heading(p, rate, free))
        if not entering:
            return SupportMode(ContactMode(OFF), slip, self._anchor(previous, False, x))
        anchor = self._anchor(previous, True, x)
        factor, onset = self._episode(rate, None if previous is None else previous.contact)
        acting = SupportMode(ContactMode(ON, True, False, factor, onset), slip, anchor)
        if not self.law.has_clipping_surface or "a1" in hints:
            return acting
        tol = TOL_POS if self.law.kelvin_voigt else TOL_S
        value = self.surface(p, rate, factor)
        above = hints["s"] if "s" in hints else heading(value, self.surface_rate(rate, free, factor), tol=tol)
        return acting if above else SupportMode(ContactMode(OFF, True, True, factor, onset), slip, anchor)

    def events(self, mode: SupportMode, motion, share=None) -> list[tuple]:
        """``(event, g(t, y), positive)`` of the surfaces watched in ``mode``; ``motion(y)`` gives
        ``(x_s, y_s, u_s, w_s)`` of a planar state or batch, ``share(t, y)`` a sliding spade's alpha."""
        if mode.sliding:
            return [("a0", share, True), ("a1", lambda t, y: share(t, y) - 1.0, False)]
        items = [("p", lambda t, y: -motion(y)[1], mode.contact.penetrated)]
        if mode.contact.penetrated and self.law.has_clipping_surface:
            factor, surface = mode.contact.factor, self.surface

            def clip(t, y):
                _, height, _, rise = motion(y)
                return surface(-height, -rise, factor)
            items.append(("s", clip, not mode.contact.clipped))
        if self.friction > 0.0 and not self.anchored:
            v = self.friction_velocity
            if mode.slip >= 0:
                items.append(("u+", lambda t, y: motion(y)[2] - v, mode.slip == 1))
            if mode.slip <= 0:
                items.append(("u-", lambda t, y: motion(y)[2] + v, mode.slip == 0))
        return items
