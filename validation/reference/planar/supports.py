"""The supports: unilateral contacts of carriage points with the ground, with friction or a dug-in spade.

DESIGN.md, "The recoil axis on a carriage".  A support at carriage point ``r`` is at ``P = (X, Y) + R r``:
height ``y_s``, horizontal velocity ``u_s``.  Its force on the carriage, ``(T, N)`` in the ground frame:

* normal: the contact law of its table (DESIGN.md "Contact laws", the reference's :class:`~..terms.contact_laws.Law`)
  with penetration ``p = -y_s`` and rate ``p' = -y_s'``: 0 while ``p <= 0``; while ``p > 0`` (an episode, ``v-``
  its onset rate) ``N = k p^n (1 + a p')`` (a: lambda, ``chi / max(v-, floor)``, 0) or ``k p + c p'``
  (Kelvin-Voigt), clipped to ``N >= 0``;
* tangential, Coulomb regularised: ``T = -mu N sat(u_s / v_reg)``, ``sat`` clipping to [-1, 1] (three smooth
  branches: ``u_s < -v_reg``, ``|u_s| <= v_reg``, ``u_s > v_reg``);
* or a dug-in spade: ``T = -(k_h (x_s - x_s0) + c_h u_s)`` while ``N > 0`` (x_s0: the point's x in the initial
  static equilibrium), 0 otherwise; or none (frictionless).

Discrete state (:class:`SupportMode`): the normal contact's :class:`~..terms.contact_laws.ContactMode` (``on``:
the law acts; ``off`` and ``penetrated``: clipped) and the friction branch ``slip`` (-1, 0, +1).  Switching
surfaces (events): ``p = 0`` (touch / leave the ground), the clipping surface while penetrated (``1 + a p' = 0``
or ``p + (c/k) p' = 0``: N reaches 0; the spade lets go there too) and ``u_s = +-v_reg`` (the friction's
branches).

A spade's law switches its horizontal force off where N reaches 0, so the clipping surface can hold the motion
from both sides (Filippov): holding, the spade's force lifts the spade off the surface's far side (N would
become < 0); let go, the weight presses it back (N would become > 0).  Then the spade *slides on the surface*
(phase ``stick``): ``N = 0`` and the horizontal force is the share ``alpha`` (0 <= alpha <= 1) of the holding
force that keeps the surface's rate 0 (a multiplier of the planar equations, :mod:`.model`); it ends where alpha
reaches 0 (it lets go) or 1 (it holds again), events ``a0`` and ``a1``.  At a restart on the surface the spade
slides iff the surface's rate is > 0 let go and < 0 holding.

Energy: stored ``k max(p, 0)^(n+1) / (n+1)`` plus, for a spade holding, ``k_h (x_s - x_s0)^2 / 2``; dissipated
power ``(N - k p^n) p' - T u_s`` (+ ``c_h u_s^2`` is ``-T u_s`` minus the spring's rate for a spade).  When a spade
lets go (or takes hold again) its spring's energy leaves (or enters) the balance at once: the solver adds it to
the support's dissipated energy there (:meth:`Support.anchor_energy`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..terms.contact_laws import OFF, ON, STICK, ContactMode, Law
from ..switching import TOL_POS, TOL_S, heading


@dataclass(frozen=True)
class SupportMode:
    """A support's discrete state in one segment: its normal ``contact`` state and the friction branch ``slip``
    (-1: ``u < -v_reg``, 0: ``|u| <= v_reg``, +1: ``u > v_reg``; 0 without friction)."""

    contact: ContactMode
    slip: int = 0

    @property
    def holding(self) -> bool:
        """Does the normal law act (N > 0 possible, a spade holds)?"""
        return self.contact.phase == ON

    @property
    def sliding(self) -> bool:
        """Does a spade slide on its clipping surface (N = 0, a share of its horizontal force, module docstring)?"""
        return self.contact.phase == STICK

    @property
    def anchored(self) -> bool:
        """Is a spade's spring engaged (holding or sliding): its energy is stored."""
        return self.contact.phase in (ON, STICK)


class Support:
    """One support of the carriage (module docstring), read from a ``[[carriage.support]]`` table as data."""

    def __init__(self, table, anchor: float = 0.0):
        self.name = str(table.name)
        self.point = (float(table.position[0]), float(table.position[1]))
        self.law = Law.from_table(table)
        self.friction = float(table.friction_coefficient or 0.0)
        self.friction_velocity = float(table.friction_velocity)
        self.horizontal_stiffness = float(table.horizontal_stiffness or 0.0)
        self.horizontal_damping = float(table.horizontal_damping or 0.0)
        self.anchored = self.horizontal_stiffness > 0.0 or self.horizontal_damping > 0.0
        #: x_s0 (m): the spade's anchor, the point's x in the static equilibrium
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

    def spade_force(self, x, u):
        """``-(k_h (x - x0) + c_h u)`` (N): a holding spade's horizontal force."""
        return -(self.horizontal_stiffness * (x - self.anchor) + self.horizontal_damping * u)

    def tangential(self, mode: SupportMode, normal, x, u, share=0.0):
        """T (N) in ``mode`` from N (N), the point's x (m) and horizontal velocity u (m/s); a sliding spade's
        ``share`` (alpha) of its holding force."""
        if self.anchored:
            if mode.holding:
                return self.spade_force(x, u)
            return share * self.spade_force(x, u) if mode.sliding else 0.0 * u
        if self.friction == 0.0:
            return 0.0 * u
        if mode.slip:
            return -mode.slip * self.friction * normal
        return -self.friction * normal * u / self.friction_velocity

    def stored_energy(self, mode: SupportMode | None, p, x):
        """``k max(p, 0)^(n+1) / (n+1)`` plus a holding spade's ``k_h (x - x0)^2 / 2`` (J)."""
        n = self.law.exponent
        out = self.law.stiffness * np.maximum(p, 0.0) ** (n + 1.0) / (n + 1.0)
        if self.anchored and mode is not None and mode.anchored:
            out = out + self.anchor_energy(x)
        return out

    def anchor_energy(self, x):
        """``k_h (x - x0)^2 / 2`` (J): the spade's spring."""
        return 0.5 * self.horizontal_stiffness * (x - self.anchor) ** 2

    def dissipated_power(self, mode: SupportMode, p, rate, normal, tangential, u, x):
        """``(N - k p^n) p' - T u`` (W), minus the spade spring's rate ``k_h (x - x0) u`` while it holds."""
        out = 0.0 * p
        if mode.contact.penetrated or mode.contact.phase == ON:
            out = (normal - self.elastic(p)) * rate
        out = out - tangential * u
        if self.anchored and mode.anchored:
            out = out - self.horizontal_stiffness * (x - self.anchor) * u
        return out

    # ------------------------------------------------------------------ modes and events
    def provisional(self, p: float, rate: float) -> SupportMode:
        """At t = 0: the law acts iff p > 0 (the static equilibrium), friction in its linear branch."""
        if p <= 0.0:
            return SupportMode(ContactMode(OFF))
        factor, onset = self._episode(rate, None)
        return SupportMode(ContactMode(ON, True, False, factor, onset), self._branch(0.0, 0.0, {}))

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

    def classify(self, p: float, rate: float, free: float, u: float, du: float, hints: dict,
                 previous: SupportMode | None, free_holding: float | None = None) -> SupportMode:
        """The state at a restart from ``p``, ``p'``, the free ``p''`` (this support's forces left out), the
        point's u and du/dt, the hints of the event that stopped the segment (``p``, ``s``, ``u+``, ``u-``, ``a0``,
        ``a1``: True if crossed upwards) and the previous state; ``free_holding``: a spade's ``p''`` with N = 0 and
        its whole horizontal force (whether it slides on the clipping surface, module docstring)."""
        slip = self._branch(u, du, hints)
        if not (hints["p"] if "p" in hints else heading(p, rate, free)):
            return SupportMode(ContactMode(OFF), slip)
        factor, onset = self._episode(rate, None if previous is None else previous.contact)
        acting = ContactMode(ON, True, False, factor, onset)
        clipped = ContactMode(OFF, True, True, factor, onset)
        if not self.law.has_clipping_surface:
            return SupportMode(acting, slip)
        if "a0" in hints:      # a sliding spade's share fell to 0: it lets go
            return SupportMode(clipped, slip)
        if "a1" in hints:      # rose to 1: it holds
            return SupportMode(acting, slip)
        tol = TOL_POS if self.law.kelvin_voigt else TOL_S
        value = self.surface(p, rate, factor)
        if self.anchored and free_holding is not None and ("s" in hints or abs(value) <= tol):
            let_go = self.surface_rate(rate, free, factor)
            holding = self.surface_rate(rate, free_holding, factor)
            if let_go > 0.0 > holding:
                return SupportMode(ContactMode(STICK, True, False, factor, onset), slip)
        above = hints["s"] if "s" in hints else heading(value, self.surface_rate(rate, free, factor), tol=tol)
        return SupportMode(acting if above else clipped, slip)

    def sliding_condition(self, mode: SupportMode, rate):
        """``(A, B)`` with the clipping surface's rate ``A + B p''`` (p' = ``rate``): a sliding spade holds it at 0."""
        if self.law.kelvin_voigt:
            return rate, self.law.damping / self.law.stiffness
        return 0.0 * rate, mode.contact.factor

    def events(self, mode: SupportMode, motion, share=None) -> list[tuple]:
        """``(event, g(t, y), positive)`` of the surfaces watched in ``mode``; ``motion(y)`` gives
        ``(x_s, y_s, u_s, w_s)`` of a planar state or batch, ``share(t, y)`` a sliding spade's alpha."""
        items = [("p", lambda t, y: -motion(y)[1], mode.contact.penetrated)]
        if mode.sliding:
            items += [("a0", share, True), ("a1", lambda t, y: share(t, y) - 1.0, False)]
        elif mode.contact.penetrated and self.law.has_clipping_surface:
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
