"""Term of ``[recoil_brake]``: connector ``recoil_brake`` ground -> barrel, the hydraulic throttling brake.

DESIGN.md, "Recoil brake".  With ``d = x_M`` (m) and ``d' = v_M`` (m/s)::

    F = rho A^3 d'|d'| / (2 (Cd a(d))^2)        (N; opposes d': F d' >= 0)

``A`` the piston area, ``a`` the orifice area (m^2), ``Cd`` the discharge coefficient, ``rho`` the fluid density
(kg/m^3).  ``a(d)`` is a number or piecewise linear through (stroke, area) pairs, constant before the first
and after the last stroke; while ``d' < 0`` the counter-recoil area (same forms) replaces it when given.
Dissipated power ``F d'`` (W); no stored energy.

Discrete state (:class:`BrakeState`), so that each segment's right-hand side is a polynomial of the state:

* the **branch**: recoiling (``d' > 0``: ``F = +K(d) d'^2``) or returning (``F = -K(d) d'^2``), ``K = rho A^3 /
  (2 Cd^2 a^2)``.  ``d'|d'|`` is only C^1 at ``d' = 0`` (and the area may switch there), so ``d' = 0`` is a
  switching surface (event ``v``) with or without a counter-recoil area.  At a restart on it the branch
  follows the sign of ``d''`` in the classified mode (the brake's force is 0 there on either branch), or the
  crossing direction if ``d'' = 0``;
* the **piece** of the active area table the stroke is on: ``0`` before the first stroke point, ``i`` between
  points ``i-1`` and ``i``, ``n`` after the last (``a`` is only C^0 at a stroke point); always 0 for a constant
  area.  Each stroke point
  bounding the piece is a switching surface (event ``x<i>``: ``d = stroke_i``); at a restart on one, the side is
  the crossing direction, or the direction ``d'`` (then ``d''``) is heading.

Energy bound: ``|F| <= rho A^3 |d'|max^2 / (2 Cd^2 a_min^2)``, ``a_min`` the smallest area of either table over
the strokes ``|d| <= |d|max``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model import BARREL, GROUND, Connector, Equations
from ..switching import TOL_VEL, heading

TABLES = ("recoil_brake",)


def points_of(area) -> tuple[tuple[float, float], ...]:
    """(stroke m, area m^2) pairs of a scene area: a number is one constant pair."""
    if isinstance(area, (int, float)):
        return ((0.0, float(area)),)
    return tuple((float(x), float(a)) for x, a in area)


def interpolate(points, d: float) -> float:
    """The piecewise-linear area (m^2) through ``points`` at stroke ``d`` (m), constant outside."""
    if d <= points[0][0]:
        return points[0][1]
    for (x0, a0), (x1, a1) in zip(points, points[1:]):
        if d <= x1:
            return a0 + (a1 - a0) * (d - x0) / (x1 - x0)
    return points[-1][1]


@dataclass(frozen=True)
class BrakeState:
    """The brake's state in one segment: ``recoil`` (True: d' > 0 branch) and ``piece`` (0 .. n, module
    docstring) of that branch's area table."""

    recoil: bool
    piece: int


class RecoilBrake(Connector):
    """``F = rho A^3 d'|d'| / (2 Cd^2 a(d)^2)`` between ``a`` and ``b`` (module docstring)."""

    dissipates = True
    stores_energy = False
    classify_pass = 2

    def __init__(self, name: str, a: str, b: str, piston_area: float, orifice_area, discharge_coefficient: float,
                 fluid_density: float, counter_recoil_orifice_area=None):
        super().__init__(name, a, b)
        #: rho A^3 / (2 Cd^2) in kg m
        self.coefficient = float(fluid_density) * float(piston_area) ** 3 / (2.0 * float(discharge_coefficient) ** 2)
        self.recoil_points = points_of(orifice_area)
        self.counter_points = self.recoil_points if counter_recoil_orifice_area is None else \
            points_of(counter_recoil_orifice_area)

    def points(self, recoil: bool):
        """The area table of a branch."""
        return self.recoil_points if recoil else self.counter_points

    def piece_area(self, state: BrakeState) -> tuple[float, float, float]:
        """``(a0, slope, x0)`` with ``a = a0 + slope (d - x0)`` on the state's piece (m^2, m^2/m, m)."""
        points = self.points(state.recoil)
        n = len(points)
        if state.piece == 0:
            return points[0][1], 0.0, 0.0
        if state.piece >= n:
            return points[-1][1], 0.0, 0.0
        (x0, a0), (x1, a1) = points[state.piece - 1], points[state.piece]
        return a0, (a1 - a0) / (x1 - x0), x0

    # ------------------------------------------------------------------ the law
    def law(self, d, rate, state=None):
        """``F = rho A^3 d'|d'| / (2 (Cd a(d))^2)`` (N), a(d) of the branch of d''s sign (floats or arrays)."""
        if np.ndim(d) == 0 and np.ndim(rate) == 0:
            area = interpolate(self.points(rate > 0), d)
            return self.coefficient * rate * abs(rate) / (area * area)
        d = np.asarray(d, dtype=float) + 0.0 * np.asarray(rate, dtype=float)
        rate = np.asarray(rate, dtype=float) + 0.0 * d
        recoil, counter = (np.interp(d, [x for x, _ in points], [a for _, a in points])
                           for points in (self.recoil_points, self.counter_points))
        area = np.where(rate > 0, recoil, counter)
        return self.coefficient * rate * np.abs(rate) / (area * area)

    def equations(self, state: BrakeState) -> Equations:
        """``F = +-K d'^2`` with ``K = coefficient / a(d)^2`` on the piece; dissipated power ``F d'``."""
        sign = 1.0 if state.recoil else -1.0
        a0, slope, x0 = self.piece_area(state)
        if slope == 0.0:
            return Equations("""
                rate = {vb} - {va}
                {F} = {k} * rate * rate
                {P} = {F} * rate""", dict(k=sign * self.coefficient / (a0 * a0)))
        return Equations("""
            rate = {vb} - {va}
            area = {a0} + {slope} * ({xb} - {xa} - {x0})
            {F} = {k} * rate * rate / (area * area)
            {P} = {F} * rate""", dict(k=sign * self.coefficient, a0=a0, slope=slope, x0=x0))

    def force_rate(self, state: BrakeState, d, rate, acceleration):
        """dF/dt (N/s) = +-coefficient d' (2 d'' a - 2 d'^2 slope) / a^3."""
        sign = 1.0 if state.recoil else -1.0
        a0, slope, x0 = self.piece_area(state)
        area = a0 + slope * (d - x0)
        return sign * self.coefficient * rate * (2.0 * acceleration * area - 2.0 * rate * rate * slope) / area ** 3

    # ------------------------------------------------------------------ modes
    def _piece(self, recoil: bool, d: float, rate: float, acceleration: float, hints: dict) -> int:
        """How many stroke points of the branch's table the state is at or above (by the hint of a crossing,
        else heading: d, then d', then d'')."""
        points = self.points(recoil)
        if len(points) == 1:  # a constant area: one piece
            return 0
        piece = 0
        for i, (x, _) in enumerate(points):
            name = f"x{i}"
            above = hints[name] if name in hints else heading(d - x, rate, acceleration,
                                                              tol=1e-15 * max(1.0, abs(x)))
            piece += bool(above)
        return piece

    def provisional(self, s, previous):
        """The branch of the velocity's sign and the piece of the displacement (previous branch at v = 0)."""
        d, rate = s[self.ib] - s[self.ia], s[self.ib + 1] - s[self.ia + 1]
        recoil = rate > 0 if rate != 0 else (previous.recoil if previous is not None else True)
        points = self.points(recoil)
        return BrakeState(recoil, 0 if len(points) == 1 else sum(d >= x for x, _ in points))

    def classify(self, restart) -> BrakeState:
        """The branch and the piece at a restart (module docstring)."""
        s = restart.s
        d, rate = s[self.ib] - s[self.ia], s[self.ib + 1] - s[self.ia + 1]
        hints = restart.hints_for(self)
        acceleration = restart.relative_acceleration(self)
        recoil = rate > 0
        if "v" in hints or abs(rate) <= TOL_VEL:
            recoil = acceleration > 0 if acceleration != 0 else hints.get("v", rate >= 0)
        previous = restart.previous_state(self)
        if previous is not None and self.points(previous.recoil) is not self.points(recoil):
            # a stroke hint names a point of the other branch's table
            hints = {k: v for k, v in hints.items() if not k.startswith("x")}
        return BrakeState(bool(recoil), self._piece(recoil, d, rate, acceleration, hints))

    def events(self, state: BrakeState, restart):
        """``v``: d' = 0; ``x<i>``: d = stroke_i for the stroke points bounding the piece."""
        d_of, rate_of, dy = self.d_of, self.rate_of, restart.dy
        items = [("v", lambda t, y: rate_of(y), state.recoil, rate_of(dy), restart.velocity_noise)]
        points = self.points(state.recoil)
        for i, positive in ((state.piece - 1, True), (state.piece, False)):
            if 0 <= i < len(points) and len(points) > 1:
                x = points[i][0]
                items.append((f"x{i}", lambda t, y, x=x: d_of(y) - x, positive, d_of(dy), restart.position_noise(x)))
        return items

    # ------------------------------------------------------------------ bounds
    def smallest_area(self, d_bound: float) -> float:
        """The smallest area (m^2) of either table at strokes ``|d| <= d_bound`` (m)."""
        out = math.inf
        for points in (self.recoil_points, self.counter_points):
            inside = [a for x, a in points if abs(x) <= d_bound]
            ends = [interpolate(points, -d_bound), interpolate(points, d_bound)] if math.isfinite(d_bound) \
                else [points[0][1], points[-1][1]]
            out = min(out, *inside, *ends)
        return out

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        """``coefficient |d'|max^2 / a_min^2`` (N)."""
        if rate_bound == 0.0:
            return 0.0
        return self.coefficient * rate_bound ** 2 / self.smallest_area(d_bound) ** 2


def areas_at(table, elevation: float):
    """(recoil area, counter-recoil area or None) of a brake table at ``elevation`` (degrees), DESIGN.md: the first
    ``[[recoil_brake.band]]`` whose ``up_to`` is at least the elevation gives its areas (its counter-recoil area,
    or the brake's); no such band, the brake's own."""
    for band in getattr(table, "band", ()) or ():
        if elevation <= band.up_to:
            counter = band.counter_recoil_orifice_area
            return band.orifice_area, table.counter_recoil_orifice_area if counter is None else counter
    return table.orifice_area, table.counter_recoil_orifice_area


def build(builder, key: str, table) -> None:
    """The brake ground -> barrel, with the areas of the scene's elevation."""
    cradle = getattr(builder.scene, "cradle", None)
    recoil, counter = areas_at(table, cradle.elevation if cradle is not None else 0.0)
    builder.add_connector(RecoilBrake("recoil_brake", GROUND, BARREL, table.piston_area, recoil,
                                      table.discharge_coefficient, table.fluid_density, counter))


__all__ = ["BrakeState", "RecoilBrake", "TABLES", "build", "interpolate", "points_of"]
