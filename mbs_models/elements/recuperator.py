"""The recuperator: a gas spring between the ground and the barrel that returns the barrel to battery.

Table (version 2)::

    [recuperator]                  # gas spring returning the barrel
    initial_pressure = 4.0e6       # p0, Pa: the gas pressure at battery (x = 0): the preload p0 A
    piston_area = 0.006            # A, m^2
    gas_volume = 0.008             # V0, m^3 at battery
    polytropic_exponent = 1.3      # n: 1 isothermal ... 1.67 (5/3, adiabatic monatomic gas); nitrogen 1.4

**Law.**  The piston compresses the gas by ``A x`` as the barrel recoils, polytropically
(``p V^n = p0 V0^n``), so the force, positive pushing the barrel towards -x (to battery), is::

    F(d) = p0 A (V0 / (V0 - A d))^n            d = x_M (N; m; defined for d < V0 / A)

a connector ground -> barrel (DESIGN.md's convention: ``F > 0`` pushes ``b`` = the barrel towards -x and
the ground towards +x, so the mount feels ``+F``).  It never vanishes: ``F(0) = p0 A`` is the *preload*
that holds the barrel in battery (see "Initial state" below).  With ``r = V0 / (V0 - A d)``,
``dr/dd = A r^2 / V0``, the stored energy ``U(d) = integral_0^d F`` is::

    U(d) = p0 V0 / (n - 1) (r^(n-1) - 1)        (n != 1; dU/dd = p0 V0 r^(n-2) A r^2 / V0 = p0 A r^n)
    U(d) = p0 V0 ln r = -p0 V0 ln(1 - A d / V0)  (n = 1, isothermal)

evaluated as ``p0 V0 expm1((n - 1) ln r) / (n - 1)`` with ``ln r = -log1p(-A d / V0)`` (no cancellation
for small d).  U is increasing and convex, negative for d < 0 (the gas expands beyond battery), and grows
without bound as ``d -> V0/A``: the gas spring cannot be bottomed out by any finite energy.  It stores and
never dissipates energy.  Its tangent stiffness is ``dF/dd = n p0 A^2 / V0 r^(n+1)``.

**Bounds** (the early stop, :mod:`mbs_models.engine.energy_bounds`): the potential is not the quadratic
form ``k d^2 / 2`` of a linear spring and not >= 0 (:attr:`RecuperatorConnector.quadratic_potential` is
False); the early stop bounds the barrel from the potential well this connector forms with the stops
(see there).  The force bound is ``F(d_max)`` (F is positive and increasing).  The *linear stiffness*
used by the stability checks (:mod:`mbs_models.engine.stability`, linearised time scales) is the
tangent stiffness at the largest stroke the scene can reach: the smaller of the recoil stop's position
and the stroke ``U^-1(E0)`` at which the recuperator alone would have stored the initial kinetic
energy E0 -- the stiffest the gas spring gets.

**Initial state: holding in battery.**  The preload presses the barrel against the battery stop, so the
barrel starts at rest in static equilibrium there rather than at x = 0: at ``x0 = position - p_s`` where
the battery stop's static penetration ``p_s`` balances the net load on the barrel::

    F_stop(p_s) = F(x0) + k x0 - M g sin(elevation)     (the recoil spring k, if any; gravity: a [cradle])

(``F(x0)`` is the preload ``p0 A`` up to the gas's expansion by ``A p_s``; every connector between the
ground and the barrel enters with its force at rest, :func:`held_position`).  Bodies mounted on the
barrel (absorbers of model (i)) ride with it: they start at x0 too, so every connector between them
and the barrel starts exactly as in a scene without preload (an actuator unloaded, a contact open by its
gap); bodies tied to the ground (absorbers of model (ii)) start at their own rest position x = 0, where
their actuators are unloaded, and their contact with the barrel opens by ``|x0|`` more.  Every body is
then at rest in equilibrium (the barrel's weight is the only gravity term here: the absorbers' own
weights belong to the cradle's element).  With a shot the barrel leaves this state at v0.

**Scene errors** (one line, naming the key): a preload that cannot return the barrel to battery against
gravity and friction, ``p0 A <= M g (sin(elevation) + mu cos(elevation))`` (``recuperator.initial_pressure``;
only with a ``[cradle]`` table); a preload with no ``[battery_stop]`` to rest on (``battery_stop``); a gas
volume that the stroke to the recoil stop would exhaust, ``V0 <= A * recoil_stop.position``
(``recuperator.gas_volume``).  Without a recoil stop no check is needed: the energy bound of the stroke,
``x_max = U^-1(E)``, is below ``V0 / A`` for every finite energy E, since U diverges there.

Building block: :func:`add_recuperator` adds the gas spring between two markers of your own Exudyn system.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..errors import SceneError
from .barrel import BARREL, free_recoil_energy, shot_keys
from .connector import GROUND, Connector
from .ops import Ops
from .table import Rule, Table, check_derived, ieee_power

#: Polytropic exponents accepted: from isothermal (1) to the adiabatic exponent of a monatomic ideal gas
#: (5/3, rounded up to 1.67); nitrogen, the usual recuperator gas, is 1.4 adiabatic.
POLYTROPIC_RANGE = (1.0, 1.67)


@dataclass(frozen=True)
class Recuperator(Table):
    """The gas spring returning the barrel to battery, ``F = p0 A (V0 / (V0 - A x_M))^n`` (module docstring).

    Attributes
    ----------
    initial_pressure: p0 in Pa (> 0), the gas pressure at battery; ``p0 A`` is the preload (N).
    piston_area: A in m^2 (> 0).
    gas_volume: V0 in m^3 (> 0), the gas volume at battery; it must exceed ``A`` times the stroke to a
        recoil stop.
    polytropic_exponent: n in [1, 1.67]: 1 isothermal, 1.4 adiabatic nitrogen, 5/3 adiabatic monatomic gas.
    """

    initial_pressure: float
    piston_area: float
    gas_volume: float
    polytropic_exponent: float
    TABLE: ClassVar[str] = "recuperator"
    ORDER: ClassVar[int] = 50
    SINCE_VERSION: ClassVar[int] = 2
    RULES: ClassVar = {"initial_pressure": Rule(0.0, strict=True, unit="Pa"),
                       "piston_area": Rule(0.0, strict=True, unit="m^2"),
                       "gas_volume": Rule(0.0, strict=True, unit="m^3"),
                       "polytropic_exponent": Rule(POLYTROPIC_RANGE[0], maximum=POLYTROPIC_RANGE[1])}
    KEY_UNITS: ClassVar = {"polytropic_exponent": "1"}

    # ------------------------------------------------------------------ the law in plain numbers
    @property
    def preload(self) -> float:
        """``p0 A`` in N: the force at battery (x = 0)."""
        return self.initial_pressure * self.piston_area

    @property
    def exhausted_at(self) -> float:
        """``V0 / A`` in m: the stroke at which the gas volume would vanish (the law's singularity)."""
        return self.gas_volume / self.piston_area

    def force(self, d: float) -> float:
        """``F(d) = p0 A (V0 / (V0 - A d))^n`` in N at the stroke ``d`` (m, < V0/A); inf where it overflows."""
        return self.preload * self._ratio_power(d, self.polytropic_exponent)

    def stored_energy(self, d):
        """``U(d)`` in J (numpy or float; module docstring): ``p0 V0 expm1((n-1) ln r) / (n-1)``, ``p0 V0 ln r``."""
        p0, V0, n = self.initial_pressure, self.gas_volume, self.polytropic_exponent
        log_r = -np.log1p(-self.piston_area * np.asarray(d, dtype=float) / V0)
        if n == 1.0:
            return p0 * V0 * log_r
        return p0 * V0 / (n - 1.0) * np.expm1((n - 1.0) * log_r)

    def stroke_at_energy(self, energy: float) -> float:
        """The stroke d (m) with ``U(d) = energy`` (J): the inverse of the increasing U; -inf below its range."""
        p0, V0, n = self.initial_pressure, self.gas_volume, self.polytropic_exponent
        if n == 1.0:
            log_r = energy / (p0 * V0)
        else:
            base = 1.0 + (n - 1.0) * energy / (p0 * V0)
            if base <= 0.0:
                return -math.inf
            log_r = math.log(base) / (n - 1.0)
        return -self.exhausted_at * math.expm1(-log_r)  # d = V0/A (1 - 1/r)

    def tangent_stiffness(self, d: float) -> float:
        """``dF/dd = n p0 A^2 / V0 (V0 / (V0 - A d))^(n+1)`` in N/m; inf where it overflows."""
        return self.polytropic_exponent * self.preload * self.piston_area / self.gas_volume * self._ratio_power(
            d, self.polytropic_exponent + 1.0)

    def _ratio_power(self, d: float, exponent: float) -> float:
        """``(V0 / (V0 - A d))^exponent``: inf where it overflows or the gas volume ``V0 - A d`` rounds to 0 (Python's
        float arithmetic raises instead)."""
        remaining = self.gas_volume - self.piston_area * d
        return ieee_power(self.gas_volume / remaining, exponent) if remaining > 0.0 else math.inf

    def __post_init__(self):
        super().__post_init__()
        keys = {f"{self.TABLE}.initial_pressure": self.initial_pressure, f"{self.TABLE}.piston_area": self.piston_area,
                f"{self.TABLE}.gas_volume": self.gas_volume}
        check_derived(keys, "the preload p0 A", self.preload, "N", positive=True)
        check_derived(keys, "the energy scale p0 V0", self.initial_pressure * self.gas_volume, "J", positive=True)
        check_derived(keys, "the stroke that would exhaust the gas V0 / A", self.exhausted_at, "m", positive=True)
        check_derived(keys, "the stiffness at battery n p0 A^2 / V0", self.tangent_stiffness(0.0), "N/m", positive=True)

    # ------------------------------------------------------------------ scene checks
    def check_in_scene(self, scene, key: str) -> None:
        """The preload must hold the barrel in battery (against gravity and friction, on a battery stop) and
        the gas must outlast the stroke to a recoil stop (module docstring, "Scene errors"); the force and the
        stiffness at the stroke the barrel's free-recoil energy reaches must be finite (the stroke
        :meth:`connectors` linearises at is no longer)."""
        keys = {f"{key}.initial_pressure": self.initial_pressure, f"{key}.piston_area": self.piston_area,
                f"{key}.gas_volume": self.gas_volume, **shot_keys(scene)}
        stroke = max(self.stroke_at_energy(free_recoil_energy(scene)), 0.0)
        check_derived(keys, "the gas spring's force at the stroke U^-1(E) reaching the free-recoil energy E = "
                            "M (shots v0)^2 / 2", self.force(stroke), "N")
        check_derived(keys, "the gas spring's stiffness at the stroke reaching the free-recoil energy",
                      self.tangent_stiffness(stroke), "N/m")
        mass = scene.barrel.mass
        cradle = getattr(scene, "cradle", None)
        if cradle is not None:
            g, angle = float(cradle.gravity), math.radians(float(cradle.elevation))
            mu = float(getattr(cradle, "friction_coefficient", 0.0) or 0.0)
            resisting = mass * g * (math.sin(angle) + mu * math.cos(angle))
            if self.preload <= resisting:
                raise SceneError(f"{key}.initial_pressure",
                                 f"the preload p0 A = {self.preload:.6g} N cannot return the barrel to battery against "
                                 f"gravity and friction M g (sin + mu cos) = {resisting:.6g} N (barrel.mass = {mass:g} "
                                 f"kg, cradle.gravity = {g:g} m/s^2, cradle.elevation = {float(cradle.elevation):g} deg, "
                                 f"cradle.friction_coefficient = {mu:g}); raise p0 or A")
        if getattr(scene, "battery_stop", None) is None:
            raise SceneError("battery_stop", f"missing: the recuperator's preload p0 A = {self.preload:.6g} N pushes "
                                             "the barrel to battery and needs a [battery_stop] to rest on")
        recoil_stop = getattr(scene, "recoil_stop", None)
        if recoil_stop is not None and self.gas_volume <= self.piston_area * recoil_stop.position:
            raise SceneError(f"{key}.gas_volume",
                             f"V0 = {self.gas_volume:.6g} m^3 would be exhausted by the stroke to the recoil stop: "
                             f"A x = {self.piston_area * recoil_stop.position:.6g} m^3 at x = "
                             f"{recoil_stop.position:g} m; V0 must exceed it")

    # ------------------------------------------------------------------ the element
    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list[Connector]:
        """The gas spring ground -> barrel, linearised (stability checks) at the largest stroke it can reach."""
        stroke = self.stroke_at_energy(scene.initial_kinetic_energy)
        recoil_stop = getattr(scene, "recoil_stop", None)
        if recoil_stop is not None:
            stroke = min(stroke, recoil_stop.position)
        return [RecuperatorConnector(name, name, self, stroke=max(stroke, 0.0))]

    def initial_positions(self, scene, name: str, bodies, connectors) -> dict[str, float]:
        """Holding in battery: the barrel at :func:`held_position`, the bodies riding on it (no connector to
        the ground) with it; the others stay at x = 0 (module docstring)."""
        x0 = held_position(scene, connectors)
        tied = {c.a for c in connectors if c.b == GROUND} | {c.b for c in connectors if c.a == GROUND}
        return {body.name: x0 for body in bodies if body.name == BARREL or body.name not in tied}


def gravity_load(scene) -> float:
    """The barrel's weight along the recoil axis, ``M g sin(elevation)`` in N (positive: towards +x, the
    recoil direction of an elevated gun), from a ``[cradle]`` table if the scene has one; else 0."""
    cradle = getattr(scene, "cradle", None)
    if cradle is None:
        return 0.0
    return scene.barrel.mass * float(cradle.gravity) * math.sin(math.radians(float(cradle.elevation)))


#: Brent's method's iterations for the held position: bisecting the bracket (at most 1 km) down to 1e-300 m takes
#: about 1010 halvings, Brent's method at most a few times its bisection count.
_MAX_ITERATIONS = 4000


def held_position(scene, connectors) -> float:
    """The barrel's static equilibrium x0 (m) on what holds it at battery.

    The net static force on the barrel (N, positive towards +x) with every body at rest is
    ``f(x) = M g sin(elevation) - sum_{ground -> barrel} F(x, 0) + sum_{barrel -> ground} F(-x, 0)`` over the
    connectors between the ground and the barrel (their laws at rest: the recuperator's preload, the
    stops' elastic force ``k p^n``, a recoil spring's ``k x``).  f is decreasing; f(0) < 0 when the preload
    exceeds the load (checked with the scene), so the root lies at x <= 0: bracketed by doubling steps
    down from 0 and solved with Brent's method to round-off (f's residual there is ~1e-16 of the preload).
    """
    from scipy.optimize import brentq

    load = gravity_load(scene)
    ground = [c for c in connectors if {c.a, c.b} == {GROUND, BARREL}]

    def f(x: float) -> float:
        total = load
        for c in ground:
            total += -c.python_force(x, 0.0) if c.a == GROUND else c.python_force(-x, 0.0)
        return total

    high, f_high = 0.0, f(0.0)
    if f_high >= 0.0:
        return 0.0
    step = 1e-9
    while True:
        low = -step
        f_low = f(low)
        if f_low > 0.0:
            break
        high, f_high = low, f_low
        step *= 2.0
        if step > 1e3:
            raise SceneError("battery_stop", "nothing holds the barrel against the recuperator's preload (p0 A: "
                                             "recuperator.initial_pressure x recuperator.piston_area) within 1 km of "
                                             "battery: the battery stop is too soft for it")
    root, status = brentq(f, low, high, xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=_MAX_ITERATIONS,
                          full_output=True, disp=False)
    if not status.converged:
        raise SceneError("recuperator.gas_volume", f"the static equilibrium in battery is not resolved in double "
                                                   f"precision ({status.flag} in [{low:g}, {high:g}] m): the gas "
                                                   f"spring's force falls from the preload within V0 / A")
    return float(root)


class RecuperatorConnector(Connector):
    """The gas spring as a connector ground -> barrel: ``F(d) = p0 A (V0 / (V0 - A d))^n`` (d = x_M).

    ``stroke`` (m) is where :attr:`linear_stiffness` linearises it (module docstring).
    """

    needs_user_function = True
    #: F increases with d and does not depend on d'
    monotone = True
    #: F does not depend on d': nothing dissipated
    dissipates = False

    def __init__(self, name: str, element: str, recuperator: Recuperator, *, stroke: float = 0.0):
        super().__init__(name, element, GROUND, BARREL)
        self.recuperator = recuperator
        self.preload = recuperator.preload
        self.gas_volume, self.piston_area = recuperator.gas_volume, recuperator.piston_area
        self.exponent = recuperator.polytropic_exponent
        self.stroke = float(stroke)

    def law(self, d, rate, ops: Ops):
        """``p0 A (V0 / (V0 - A d))^n`` (N), over ``ops``."""
        return self.preload * ops.power(self.gas_volume / (self.gas_volume - self.piston_area * d), self.exponent)

    @property
    def coordinate_range(self) -> tuple[float, float]:
        """d (m) where the law is defined: below ``V0 / A``."""
        return -math.inf, self.recuperator.exhausted_at

    # ------------------------------------------------------------------ energy (closed forms)
    def stored_energy(self, d):
        """``U(d)`` in J (module docstring)."""
        return self.recuperator.stored_energy(d)

    def python_stored_energy(self, d: float) -> float:
        """``U(d)`` in J on a float: ``p0 V0 expm1((n-1) ln r) / (n-1)`` (``p0 V0 ln r`` for n = 1)."""
        r = self.recuperator
        if d >= r.exhausted_at:
            return math.inf
        log_r = -math.log1p(-self.piston_area * d / self.gas_volume)
        if self.exponent == 1.0:
            return r.initial_pressure * self.gas_volume * log_r
        return r.initial_pressure * self.gas_volume / (self.exponent - 1.0) * math.expm1((self.exponent - 1.0) * log_r)

    def tangent_stiffness(self, d: float) -> float:
        """``n p0 A^2 / V0 (V0 / (V0 - A d))^(n+1)`` in N/m (:meth:`Recuperator.tangent_stiffness`)."""
        return self.recuperator.tangent_stiffness(d)

    # ------------------------------------------------------------------ bounds
    @property
    def linear_stiffness(self) -> float:
        """The tangent stiffness ``n p0 A^2 / V0 r^(n+1)`` (N/m) at :attr:`stroke`: for the stability checks
        only (it is not a quadratic potential: :attr:`quadratic_potential` is False)."""
        return self.recuperator.tangent_stiffness(self.stroke)

    def force_bound(self, d_bound: float, rate_bound: float, energy: float) -> float:
        """``F(d_bound)`` (N): F is positive and increasing, so ``|F| <= F(d_max)``; inf at or beyond V0/A."""
        if not d_bound < self.recuperator.exhausted_at:
            return math.inf
        return self.recuperator.force(d_bound)


def add_recuperator(mbs, marker_ground, marker_barrel, recuperator: Recuperator,
                    user_functions: str = "symbolic") -> RecuperatorConnector:
    """Add the recuperator's gas spring between two coordinate markers of your own Exudyn system.

    The force ``p0 A (V0 / (V0 - A d))^n`` with ``d = x_barrel - x_ground`` pushes the barrel towards -x
    (``user_functions``: ``"symbolic"`` or ``"python"``).  It never vanishes: a barrel at x = 0 with nothing to
    hold it is pushed forward by ``p0 A``; start it in equilibrium against your battery stop (see
    :func:`held_position`).  Returns the connector (``.index`` is the Exudyn item; keep it as long as ``mbs``).
    """
    connector = RecuperatorConnector(Recuperator.TABLE, Recuperator.TABLE, recuperator)
    connector.add_items(mbs, marker_ground, marker_barrel, user_functions)
    return connector
