"""The inclined cradle: gravity along the recoil axis and Coulomb friction of the barrel on its slide.

Table (version 2)::

    [cradle]                       # the barrel slides on a cradle inclined by the gun's elevation
    elevation = 30.0               # theta, degrees, in [-90, 90] (negative: depression)
    gravity = 9.81                 # g, m/s^2, >= 0 (default 9.81)
    friction_coefficient = 0.05    # mu, >= 0 (default 0: no friction)
    friction_velocity = 1.0e-4     # v_reg, m/s, > 0 (default 1e-4): the friction law's regularisation

Positions are positive in the recoil direction, which on an elevated gun points backwards and *down* the
cradle, so gravity pulls the barrel (mass M) along the recoil axis with

    F_g = M g sin(theta)                   (N; < 0 for a depressed gun: towards battery)

a constant external :class:`~mbs_models.elements.connector.Load` ``gravity`` on the barrel (Exudyn's
``LoadCoordinate``, no user function).  It is not transmitted through the mount along the axis (it is the
Earth's pull, not a connector), and its work ``W = F_g (x_M(t) - x_M(0))`` enters the energy balance
(``kinetic + stored + dissipated - work = initial energy``).

The normal force on the slide is the barrel's weight only, ``N = M g cos(theta)`` (>= 0): absorbers
riding on the barrel, the recoil forces and the cradle's own dynamics do not add to it.  Coulomb friction
opposes the sliding velocity ``v_M`` with the magnitude ``mu N`` and *sticks* at ``v_M = 0`` while the
other forces on the barrel stay within ``mu N`` (DESIGN.md, "Inclined cradle").  It is a connector
``cradle`` ground -> barrel (``d = x_M``, ``d' = v_M``), so it counts in the force on the mount (``+F``).

The friction law: regularised, linear-saturated (Exudyn's own)
---------------------------------------------------------------
The engine uses Exudyn's ``ObjectConnectorCoordinateSpringDamperExt`` in its regularised mode
(``dynamicFrictionForce = mu N``, ``frictionProportionalZone = v_reg``; built in, C++, no user function,
no data node)::

    F(v) = mu N v / v_reg          for |v| <= v_reg
    F(v) = mu N sign(v)            otherwise               (exactly Coulomb outside the band)

Dissipated power ``F v >= 0``; ``|F| <= mu N`` (the early stop's force bound); the law is a damper of
``c = mu N / v_reg`` (N s/m) in the band, which the stability checks of fixed-step solvers are told
(:attr:`CradleFriction.linear_damping`).  Sticking is represented by *creep*: under a sub-threshold net
force ``F_net`` (|F_net| < mu N) the barrel slides at ``v = v_reg F_net / (mu N)``, i.e. at most
``v_reg``.  Stated tolerance (tested): **a stuck barrel creeps by at most ``v_reg`` times the time it
is stuck** (0.1 mm per second at the default), and the dissipated energy differs from exact Coulomb
by at most ``mu N v_reg`` times that time.  A reversal (v crosses 0 with the other forces ``f``,
``r = |f| / (mu N) > 1``) crosses the band in ``tau ln((r+1)/(r-1))`` instead of exact Coulomb's
``2 tau r / (r^2 - 1)`` (``tau = M v_reg / (mu N)``): the motion after it is late by ``tau h(r)``,
``h(r) = |ln((r+1)/(r-1)) - 2 r / (r^2 - 1)|`` (a velocity offset ``v_reg (r - 1) h(r)``).  Every
difference from exact Coulomb is O(v_reg) (the tests measure it against the reference and check that a
4 times smaller ``friction_velocity`` makes it 4 times smaller).

Why this law (measured on Exudyn 1.13.6; ``scripts/friction_study.py`` reproduces every number)
------------------------------------------------------------------------------------------------
Against exact Coulomb (an event-driven solution with sticking), M = 5600 kg, v0 = 0.6909 m/s:

(a) a block sliding on a 10 deg incline, mu = 0.3 (sub-threshold: F_g / (mu N) = 0.59), which stops at
    t = 0.578 s, x = 0.19976 m and must stay there; creep = displacement in the 1 s after the stop (steps and
    errors do not depend on the machine, wall times do):

    ============================  ==========  =======  ======  ===============  ===========
    law                           solver      steps    time    x(stop) error    creep in 1 s
    ============================  ==========  =======  ======  ===============  ===========
    Exudyn regularised, 1e-4 m/s  DOPRI5      8924     56 ms   +2.0e-9 m        +5.9e-5 m
    Exudyn regularised, 1e-4 m/s  ODE23       11832    39 ms   +2.0e-9 m        +5.9e-5 m
    Exudyn regularised, 1e-4 m/s  GenAlpha    15799    33 ms   +2.6e-9 m        +5.9e-5 m
                                  h = 1e-4
    Exudyn regularised, 1e-5 m/s  DOPRI5      87749    496 ms  +2.0e-11 m       +5.9e-6 m
    our tanh(v / 1e-4), symbolic  DOPRI5      5897     43 ms   +5.4e-9 m        +6.7e-5 m
    Exudyn bristle, k = 1e9 N/m   DOPRI5      398      2 ms    -3.1e-9 m        -7.0e-6 m
    Exudyn bristle, k = 1e7 N/m   DOPRI5      410      2 ms    -1.2e-7 m        -7.0e-4 m
    ============================  ==========  =======  ======  ===============  ===========

(b) free recoil of the simplified model (k = 27500 N/m, c = 6239 N s/m) with friction, 10 s, DOPRI5 at
    the ``standard`` tolerances; errors of the max displacement, of x(10 s), and the largest |x error|:

    =======================  ===========================  ==========================  =======================
    law                      mu = 0.05, level (sticks     mu = 0.6, level (stops at   30 deg, mu = 0.05 (sticks
                             at 1.95 s)                   0.108 s and stays)          at 2.77 s)
    =======================  ===========================  ==========================  =======================
    Exudyn regularised 1e-4  12392 steps; 6e-10 / 5.6e-4  176048 steps (~1 s);        9914 steps; 2e-10 / 2.2e-4
                             / 5.6e-4 m                   7e-10 / 3.0e-5 / 3.0e-5 m   / 2.2e-4 m
    Exudyn bristle 1e9       2073 steps; 3e-9 / 6e-7      2116 steps; 3e-10 / 3.7e-5  2080 steps; 9e-10 / 3e-6
                             / 1.9e-4 m                   / 3.7e-5 m                  / 9.8e-5 m
    =======================  ===========================  ==========================  =======================

The implicit GeneralizedAlpha (fixed h = 1e-4 s) gives the same creep (it is the law's, not the solver's);
on the 30 deg case it had to cut its step (289099 steps instead of 100000: Newton at the band's kinks).

Exudyn's *bristle* mode (``frictionProportionalZone = 0``, a ``NodeGenericData`` holding the stick/slip
state and the last sticking position, switched after each step) is cheaper while stuck and does not creep,
but it is not a force law ``F(d, d')``: its force depends on hidden state, so the generic post-processing
(forces between steps, the support force and its refined peak, dissipated energy by quadrature), the early
stop's observed forces and the reference comparison could not evaluate it; it delays every reversal by a
bristle time ~sqrt(M / k_stick) (the 1.9e-4 m above), and it stores elastic energy in a stick spring that
would need its own bookkeeping.  The regularised mode is a stateless law that every part of the engine
evaluates as it evaluates the recoil damper, and it is exactly Coulomb outside ``|v| < v_reg``.  Its
linear-saturated form beats a ``tanh`` (which deviates from Coulomb up to ~3 v_reg and needs a user
function: 2.5x the time per step while stuck).  ``v_reg = 1e-4 m/s`` keeps the creep at the tenth of a
millimetre per second (a barrel's stroke is 0.1-1 m) at a cost: while stuck DOPRI5's step is limited to
``~3.3 M v_reg / (mu N)`` s by the band's damper (~1.3e3 steps per stuck second at mu = 0.05, ~1.8e4 at
mu = 0.6); ten times smaller costs ten times more steps.

Both the engine and the reference (exact Coulomb, :mod:`validation.reference.terms.cradle`) read this
table; ``mu = 0`` (or ``N = 0``) adds no friction connector and ``sin(theta) = 0`` no load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from .barrel import BARREL, free_recoil_speed, shot_keys
from .connector import GROUND, Connector, Load
from .ops import NUMPY_OPS, Ops
from .table import Rule, Table, check_derived

#: Default regularisation velocity of the friction law (m/s): see the module docstring.
DEFAULT_FRICTION_VELOCITY = 1.0e-4
#: Default gravitational acceleration (m/s^2).
DEFAULT_GRAVITY = 9.81


@dataclass(frozen=True)
class Cradle(Table):
    """The inclined cradle: gravity ``M g sin(theta)`` along the recoil axis and Coulomb friction ``mu M g cos(theta)``.

    Attributes
    ----------
    elevation: theta in degrees, in [-90, 90]: the gun's elevation (negative: depression).
    gravity: g in m/s^2 (>= 0), default 9.81.
    friction_coefficient: mu (>= 0), default 0 (no friction).
    friction_velocity: v_reg in m/s (> 0), default 1e-4: the friction force is ``mu N v / v_reg`` below it.
    """

    elevation: float
    gravity: float = DEFAULT_GRAVITY
    friction_coefficient: float = 0.0
    friction_velocity: float = DEFAULT_FRICTION_VELOCITY
    TABLE: ClassVar[str] = "cradle"
    ORDER: ClassVar[int] = 70
    SINCE_VERSION: ClassVar[int] = 2
    RULES: ClassVar = {"elevation": Rule(-90.0, unit="degrees", maximum=90.0),
                       "gravity": Rule(0.0, unit="m/s^2"),
                       "friction_coefficient": Rule(0.0),
                       "friction_velocity": Rule(0.0, strict=True, unit="m/s")}
    KEY_UNITS: ClassVar = {"friction_coefficient": "1"}

    # ------------------------------------------------------------------ derived quantities
    def weight_along(self, mass: float) -> float:
        """``M g sin(theta)`` in N: gravity's pull on a mass ``mass`` (kg) along the recoil axis."""
        return mass * self.gravity * math.sin(math.radians(self.elevation))

    def friction_force(self, mass: float) -> float:
        """``mu N = mu M g cos(theta)`` in N (>= 0): the Coulomb friction force of a sliding mass ``mass`` (kg).
        ``cos(+-90 deg)`` is taken as exactly 0 (no normal force on a vertical cradle)."""
        cosine = 0.0 if abs(self.elevation) == 90.0 else math.cos(math.radians(self.elevation))
        return self.friction_coefficient * mass * self.gravity * cosine

    def check_in_scene(self, scene, key: str) -> None:
        """The barrel's weight along the axis ``M g sin``, the friction ``mu M g cos``, the law's slope in its band
        ``mu N / v_reg`` and the free-recoil speed in units of ``v_reg`` (what the law divides) must be finite."""
        mass = scene.barrel.mass
        keys = {"barrel.mass": mass, f"{key}.gravity": self.gravity}
        check_derived(keys, "the barrel's weight along the recoil axis M g sin(elevation)", self.weight_along(mass), "N")
        keys[f"{key}.friction_coefficient"] = self.friction_coefficient
        friction = check_derived(keys, "the friction force mu M g cos(elevation)", self.friction_force(mass), "N")
        if friction > 0.0:
            keys[f"{key}.friction_velocity"] = self.friction_velocity
            check_derived(keys, "the friction law's slope mu N / friction_velocity", friction / self.friction_velocity,
                          "N s/m")
            check_derived({**keys, **shot_keys(scene)}, "the free-recoil speed over friction_velocity (shots v0 / v_reg)",
                          free_recoil_speed(scene) / self.friction_velocity)

    # ------------------------------------------------------------------ the element
    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list[Connector]:
        """The friction ``cradle`` ground -> barrel (none if ``mu N = 0``)."""
        force = self.friction_force(scene.barrel.mass)
        if force <= 0.0:
            return []
        return [CradleFriction(name, name, GROUND, BARREL, force, self.friction_velocity)]

    def loads(self, scene, name: str) -> list[Load]:
        """Gravity on the barrel, ``M g sin(theta)`` (none if it is 0; none on a carriage, where gravity pulls every
        body vertically in the planar model: :mod:`mbs_models.elements.carriage`)."""
        if getattr(scene, "carriage", None) is not None:
            return []
        force = self.weight_along(scene.barrel.mass)
        if force == 0.0:
            return []
        return [Load("gravity", name, BARREL, constant=force)]


def friction_law(rate, force: float, velocity: float, ops: Ops = NUMPY_OPS):
    """The regularised Coulomb force (N) at the sliding velocity ``rate`` (m/s): ``force * s`` with
    ``s = rate / velocity`` clipped to [-1, 1] (``force`` = mu N in N, ``velocity`` = v_reg in m/s)."""
    s = rate / velocity
    return force * ops.select(s > 1.0, 1.0, ops.select(s < -1.0, -1.0, s))


class CradleFriction(Connector):
    """Coulomb friction of the barrel on the cradle, regularised (module docstring): ``F = mu N sat(v / v_reg)``.

    ``friction_force`` is mu N (N), ``friction_velocity`` v_reg (m/s).  In Exudyn it is the built-in
    regularised friction of ``ObjectConnectorCoordinateSpringDamperExt`` (no user function).
    """

    sticks = True  # exact Coulomb holds the barrel anywhere its other forces stay within mu N
    needs_user_function = False  # Exudyn's built-in regularised friction (add_items)
    stores_energy = False        # F(d, 0) = 0
    monotone = True              # mu N sat(v / v_reg): non-decreasing in v, independent of d

    def __init__(self, name: str, element: str, a: str, b: str, friction_force: float, friction_velocity: float):
        super().__init__(name, element, a, b)
        self.friction_force = float(friction_force)
        self.friction_velocity = float(friction_velocity)

    def law(self, d, rate, ops: Ops):
        return friction_law(rate, self.friction_force, self.friction_velocity, ops)

    def add_items(self, mbs, marker_a, marker_b, user_functions: str = "symbolic"):
        """Exudyn's ``ObjectConnectorCoordinateSpringDamperExt`` with markers ``[marker_a, marker_b]``:
        ``dynamicFrictionForce = mu N``, ``frictionProportionalZone = v_reg`` (the same law, in C++)."""
        from exudyn.itemInterface import ObjectConnectorCoordinateSpringDamperExt

        self.index = mbs.AddObject(ObjectConnectorCoordinateSpringDamperExt(
            markerNumbers=[marker_a, marker_b], dynamicFrictionForce=self.friction_force,
            frictionProportionalZone=self.friction_velocity,
            visualization={"show": False, "drawSize": -1.0, "color": [-1.0, -1.0, -1.0, -1.0]}))
        return self.index

    def update_items(self, mbs, index, user_functions: str = "symbolic") -> None:
        """Write mu N and v_reg into ``index``, an item :meth:`add_items` made (an earlier point of a sweep)."""
        mbs.SetObjectParameter(index, "dynamicFrictionForce", self.friction_force)
        mbs.SetObjectParameter(index, "frictionProportionalZone", self.friction_velocity)
        self.index = index

    # ------------------------------------------------------------------ energy and bounds
    @property
    def dissipates(self) -> bool:
        return True

    def dissipated_energy(self, quadrature, d_nodes, rate_nodes, times_nodes, stored):
        """``F(v) v >= 0`` integrated (J)."""
        return quadrature(self.law(d_nodes, rate_nodes, NUMPY_OPS) * rate_nodes)

    @property
    def linear_damping(self) -> float:
        """``mu N / v_reg`` (N s/m): the law's slope in its band, what the stability checks linearise."""
        return self.friction_force / self.friction_velocity

    def force_bound(self, d_bound: float, rate_bound: float, energy: float) -> float:
        """``mu N`` (N), whatever the state."""
        return self.friction_force
