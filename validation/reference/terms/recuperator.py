"""Term of ``[recuperator]``: connector ``recuperator`` ground -> barrel, a gas spring returning the barrel.

DESIGN.md ("Bodies and connectors", "Initial state: holding in battery").  The gas (pressure p0 in Pa and
volume V0 in m^3 at battery, piston area A in m^2) is compressed polytropically (exponent n) by the stroke
``d = x_M``, so the force, positive pushing the barrel towards -x, is::

    F(d) = p0 A r^n,          r = V0 / (V0 - A d)         (N; defined for d < V0 / A)

Its potential ``U(d) = integral_0^d F`` (with ``dr/dd = A r^2 / V0``)::

    U = p0 V0 (r^(n-1) - 1) / (n - 1)      (n != 1),        U = p0 V0 ln r      (n = 1)

(computed with ``ln r = log1p(A d / (V0 - A d))`` and ``expm1``); ``dF/dt = n p0 A^2 / V0 r^(n+1) d'``.  It
stores energy and dissipates none; ``|F| <= F(|d|_max)`` (F is positive and increasing).  Its potential is
not a linear spring's and is negative for d < 0, so the early stop bounds it with the barrel's stops
(``nonlinear_potential``: :mod:`validation.reference.finality`).

Initial state: the preload ``p0 A`` presses the barrel against its battery stop, so the barrel starts at
rest at the static equilibrium x0 of the connectors between the ground and the barrel, each with its force
at rest (``static_force``: the stop's ``k p^n``, a recoil spring's ``k x``, this ``F``), and the barrel's
weight along the axis ``M g sin(elevation)`` of a ``[cradle]`` table (towards +x)::

    M g sin(elevation) - sum_{ground -> barrel} F_c(x0) + sum_{barrel -> ground} F_c(-x0) = 0

solved with Brent's method on a bracket found by doubling steps down from x = 0 (the preload wins there;
the stops' forces grow without bound).  The bodies with no connector to the ground (absorbers mounted on
the barrel) start at x0 with it; the others at 0.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ..model import BARREL, GROUND, Connector, Equations, ReferenceModelError

TABLES = ("recuperator",)


class GasSpring(Connector):
    """``F = p0 A (V0 / (V0 - A d))^n`` between ``a`` and ``b`` (module docstring)."""

    stores_energy = True
    dissipates = False
    nonlinear_potential = True

    def __init__(self, name: str, a: str, b: str, pressure: float, area: float, volume: float, exponent: float):
        super().__init__(name, a, b)
        self.pressure, self.area = float(pressure), float(area)
        self.volume, self.exponent = float(volume), float(exponent)
        self.preload = self.pressure * self.area
        self.d_limit = self.volume / self.area

    def law(self, d, rate, state=None):
        """``F = p0 A (V0 / (V0 - A d))^n`` (N); inf at or beyond ``d = V0 / A`` (floats or arrays)."""
        if np.ndim(d) == 0 and np.ndim(rate) == 0:
            return self.static_force(d) if self.volume - self.area * d > 0.0 else math.inf
        d = np.asarray(d, dtype=float) + 0.0 * np.asarray(rate, dtype=float)
        room = self.volume - self.area * d
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return np.where(room > 0.0, self.preload * (self.volume / np.where(room > 0.0, room, 1.0)) ** self.exponent,
                            np.inf)

    def equations(self, state) -> Equations:
        """``F = p0 A (V0 / (V0 - A d))^n``; no dissipated power.  A trial state of the solver beyond the gas
        volume (``V0 - A d <= 0``, never an accepted one: the scene's checks keep the stroke inside it) gets an
        infinite force, so that the step is rejected, instead of the complex power of a negative ratio."""
        return Equations("""
            {F} = {preload} * ratio_power({V0}, {V0} - {A} * ({xb} - {xa}), {n})""",
                         dict(preload=self.preload, V0=self.volume, A=self.area, n=self.exponent))

    def _ratio(self, d):
        return self.volume / (self.volume - self.area * d)

    def _ratio_power(self, d: float, exponent: float) -> float:
        """``r^exponent`` (d a float): inf where it overflows near ``V0 / A`` (Python's float power raises)."""
        try:
            return self._ratio(d) ** exponent
        except OverflowError:
            return math.inf

    def force_rate(self, state, d, rate, acceleration):
        """``dF/dt = n p0 A^2 / V0 r^(n+1) d'`` (N/s)."""
        return self.exponent * self.preload * self.area / self.volume * self._ratio_power(d, self.exponent + 1.0) * rate

    def stored_energy(self, d):
        """``U(d)`` (J; module docstring).  A gas expanded so far that ``A d / (V0 - A d)`` rounds to -1 has
        ``ln r = -inf``: U is its limit, ``-p0 V0 / (n - 1)`` (-inf for n = 1), without a warning."""
        with np.errstate(divide="ignore"):
            log_r = np.log1p(self.area * d / (self.volume - self.area * d))
        if self.exponent == 1.0:
            return self.pressure * self.volume * log_r
        return self.pressure * self.volume * np.expm1((self.exponent - 1.0) * log_r) / (self.exponent - 1.0)

    def static_force(self, d: float) -> float:
        """``F(d)`` (N): the law has no rate."""
        return self.preload * self._ratio_power(d, self.exponent)

    def force_bound(self, d_bound: float, rate_bound: float, penetration_bound: float) -> float:
        """``F(d_bound)`` (N); inf at or beyond ``V0 / A``."""
        return self.static_force(d_bound) if d_bound < self.d_limit else math.inf


def weight_along_the_axis(scene) -> float:
    """``M g sin(elevation)`` (N, towards +x) of a ``[cradle]`` table (elevation in degrees), 0 without one."""
    cradle = getattr(scene, "cradle", None)
    if cradle is None:
        return 0.0
    return float(scene.barrel.mass) * float(cradle.gravity) * math.sin(float(cradle.elevation) * math.pi / 180.0)


def hold_in_battery(builder) -> None:
    """Set the initial positions of the barrel and of the bodies riding on it (module docstring)."""
    load = weight_along_the_axis(builder.scene)
    holding = [c for c in builder.connectors if {c.a, c.b} == {GROUND, BARREL}]

    def net_force(x: float) -> float:
        return load + sum(c.static_force(-x) if c.a == BARREL else -c.static_force(x) for c in holding)

    upper = 0.0
    if net_force(upper) >= 0.0:
        return
    lower = -1e-9
    while net_force(lower) <= 0.0:
        upper, lower = lower, 2.0 * lower
        if lower < -1e3:
            raise ReferenceModelError("recuperator: nothing holds the barrel against the preload within 1 km")
    # bisecting 1 km down to xtol = 1e-300 m takes about 1010 halvings: Brent's method at most a few times that
    x0, status = brentq(net_force, lower, upper, xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=4000,
                        full_output=True, disp=False)
    if not status.converged:
        raise ReferenceModelError(f"recuperator: the static equilibrium in battery is not resolved ({status.flag})")
    grounded = {c.b for c in builder.connectors if c.a == GROUND} | {c.a for c in builder.connectors if c.b == GROUND}
    for body in builder.bodies:
        if body.name == BARREL or body.name not in grounded:
            builder.positions[body.name] = x0


def build(builder, key: str, table) -> None:
    """The gas spring ground -> barrel and the hold in battery of its preload."""
    builder.add_connector(GasSpring(key, GROUND, BARREL, table.initial_pressure, table.piston_area, table.gas_volume,
                                    table.polytropic_exponent))
    builder.add_finisher(hold_in_battery)
