"""The carriage: the gun's non-recoiling parts, resting on the ground through supports, in the vertical plane.

Tables (version 2; DESIGN.md "The recoil axis on a carriage")::

    [carriage]
    mass = 2000.0                   # m_c, kg: everything that does not recoil
    inertia = 1500.0                # I_c, kg m^2 about the carriage's own centre of mass
    center_of_mass = [2.4, 0.8]     # m, carriage frame (x forward, y up; the ground is y = 0)
    trunnion = [2.5, 1.0]           # m, carriage frame: the recoil axis passes through it
    barrel_center_of_mass = 0.0     # b, m along the axis from the trunnion to the recoiling parts' CG in battery
    barrel_inertia = 0.0            # I_M, kg m^2: the recoiling parts about their own CG
    [[carriage.support]]            # two or more points of the carriage that rest on the ground
    name = "spade"
    position = [0.0, 0.0]           # m, carriage frame
    law = "kelvin-voigt"            # the normal force: any contact law, penetration p = -y of the point
    stiffness = 5.0e8
    damping = 2.0e6
    horizontal_stiffness = 2.0e8    # a spade dug in: k_h, N/m ...
    horizontal_damping = 1.0e6      #   ... and c_h, N s/m, anchoring the point at its rest x while N > 0
    # friction_coefficient = 0.3    # or Coulomb friction mu N against the point's horizontal velocity,
    # friction_velocity = 1.0e-4    #   regularised (linear) below v_reg = friction_velocity (m/s)

Kinematics (generalised coordinates ``q = (X, Y, phi, x_1 .. x_n)``): the carriage frame is the ground frame
moved by ``(X, Y)`` and turned by ``phi`` (counter-clockwise, nose up); a point ``r`` of the carriage frame is at

    P(r) = (X, Y) + R(phi) r,          R(phi) = [[cos phi, -sin phi], [sin phi, cos phi]]

so the carriage's CG is at ``P(center_of_mass)``, and the axis body ``i`` (the barrel, each absorber), whose
coordinate ``x_i >= 0`` is measured rearward from battery, has its CG at ``P(trunnion + (b - x_i) e)`` with
``e = (cos theta, sin theta)`` (theta: the ``[cradle]`` elevation, 0 without it).  Each 1-D element keeps its law
and acts on the axis coordinates; its reaction goes into the carriage.  A support's force on the carriage, at
its point ``P(r_s)`` with height ``y_s`` and horizontal velocity ``u_s``, is

    N   = law(p, p'),  p = -y_s                           (>= 0; the contact law of the table)
    T   = -mu N sat(u_s / v_reg)                           (Coulomb, regularised: sat clips to [-1, 1])
    T   = -(k_h (x_s - x_s0) + c_h u_s)   while N > 0     (a dug-in spade; x_s0 its static x), else 0

Gravity ``g`` (the ``[cradle]`` value, 9.81 without it) pulls every body vertically.  The gun starts at rest
in the static equilibrium of the whole gun on its supports with the axis bodies held where the 1-D model starts
them (:func:`static_equilibrium`).

This module holds the tables, their checks and the planar geometry both the engine and the outputs use; the
engine assembles them (:mod:`mbs_models.engine.planar`), the reference writes its own equations
(``validation/reference/planar``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from ..errors import SceneError
from .contact_laws import LAW_FIELDS, LAW_RULES, LawFields
from .table import Rule, Table, check_number

#: Default regularisation velocity of a support's Coulomb friction (m/s), as the cradle's.
DEFAULT_SUPPORT_FRICTION_VELOCITY = 1.0e-4
#: Default gravitational acceleration (m/s^2) of a carriage scene without a ``[cradle]`` table.
DEFAULT_GRAVITY = 9.81


def _point(key: str, value) -> tuple[float, float]:
    """A point of the carriage frame: two finite numbers (m)."""
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise SceneError(key, f"must be a point [x, y] of two numbers in m, got {value!r}")
    return (check_number(f"{key}[0]", value[0], Rule(unit="m")), check_number(f"{key}[1]", value[1], Rule(unit="m")))


@dataclass(frozen=True)
class Support(LawFields, Table):
    """One point of the carriage resting on the ground (a wheel, a spade, a firing base).

    Attributes
    ----------
    name: unique among the supports (the key of its outputs: ``support.NAME.min_normal_force``).
    position: ``[x, y]`` in m, carriage frame.
    law, stiffness, exponent, damping_factor, restitution, damping, minimum_impact_velocity: the normal contact
        law with the ground (fields as every contact's), penetration ``p = -y`` of the point.
    friction_coefficient: mu (>= 0) of Coulomb friction against the point's horizontal velocity; or
    horizontal_stiffness, horizontal_damping: k_h (N/m), c_h (N s/m) of a dug-in spade anchored at the point's
        static x while its normal force is > 0.  Not both; neither: frictionless.
    friction_velocity: v_reg (m/s, > 0; default 1e-4): the friction is ``mu N u / v_reg`` below it.
    """

    name: str
    position: tuple
    stiffness: float
    law: str = "hunt-crossley"
    exponent: float | None = None
    damping_factor: float | None = None
    restitution: float | None = None
    damping: float | None = None
    minimum_impact_velocity: float | None = None
    friction_coefficient: float | None = None
    friction_velocity: float = DEFAULT_SUPPORT_FRICTION_VELOCITY
    horizontal_stiffness: float | None = None
    horizontal_damping: float | None = None
    TABLE: ClassVar[str] = "support"
    SINCE_VERSION: ClassVar[int] = 2
    RULES: ClassVar = {**LAW_RULES, "friction_coefficient": Rule(0.0),
                       "friction_velocity": Rule(0.0, strict=True, unit="m/s"),
                       "horizontal_stiffness": Rule(0.0, unit="N/m"),
                       "horizontal_damping": Rule(0.0, unit="N s/m")}

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise SceneError(f"{self.TABLE}.name", f"must be a name of letters, digits and _ (not starting with a "
                                                   f"digit), got {self.name!r}")
        object.__setattr__(self, "position", _point(f"{self.TABLE}.position", self.position))
        super().__post_init__()
        anchored = self.horizontal_stiffness is not None or self.horizontal_damping is not None
        if anchored and self.friction_coefficient is not None:
            raise SceneError(f"{self.TABLE}.friction_coefficient",
                             "give either friction_coefficient (Coulomb) or horizontal_stiffness/horizontal_damping "
                             "(a dug-in spade), not both")

    @property
    def anchored(self) -> bool:
        """True for a dug-in spade (a horizontal spring-damper while in contact)."""
        return bool(self.horizontal_stiffness) or bool(self.horizontal_damping)

    @property
    def friction(self) -> float:
        """mu (0 without friction)."""
        return self.friction_coefficient or 0.0

    @property
    def law_exponent(self) -> float:
        """n of the normal law (1 for kelvin-voigt)."""
        return 1.0 if self.law == "kelvin-voigt" else float(self.exponent)

    def static_penetration(self, load: float) -> float:
        """The penetration (m) at which the law's force at rest, ``k p^n``, carries ``load`` (N, >= 0)."""
        return (max(load, 0.0) / self.stiffness) ** (1.0 / self.law_exponent)


@dataclass(frozen=True)
class Carriage(Table):
    """The carriage on its supports: the recoil axis moves with it (module docstring).

    Attributes
    ----------
    mass: m_c in kg (> 0): everything that does not recoil (carriage, cradle, trails, wheels).
    inertia: I_c in kg m^2 (> 0) about the carriage's own centre of mass.
    center_of_mass: ``[x, y]`` m, carriage frame.
    trunnion: ``[x, y]`` m, carriage frame: the recoil axis passes through it at the ``[cradle]`` elevation.
    barrel_center_of_mass: b in m (default 0): along the axis from the trunnion to the recoiling parts' CG in
        battery (+ = forward).
    barrel_inertia: I_M in kg m^2 (>= 0, default 0): the recoiling parts about their own CG.
    support: the supports (``[[carriage.support]]``), two or more, not all at one x.
    """

    mass: float
    inertia: float
    center_of_mass: tuple
    trunnion: tuple
    barrel_center_of_mass: float = 0.0
    barrel_inertia: float = 0.0
    support: tuple = ()
    TABLE: ClassVar[str] = "carriage"
    ORDER: ClassVar[int] = 95
    SINCE_VERSION: ClassVar[int] = 2
    RULES: ClassVar = {"mass": Rule(0.0, strict=True, unit="kg"), "inertia": Rule(0.0, strict=True, unit="kg m^2"),
                       "barrel_center_of_mass": Rule(unit="m"), "barrel_inertia": Rule(0.0, unit="kg m^2")}
    NESTED_MANY: ClassVar = {"support": Support}

    def __post_init__(self):
        object.__setattr__(self, "center_of_mass", _point(f"{self.TABLE}.center_of_mass", self.center_of_mass))
        object.__setattr__(self, "trunnion", _point(f"{self.TABLE}.trunnion", self.trunnion))
        super().__post_init__()
        if len(self.support) < 2:
            raise SceneError(f"{self.TABLE}.support", f"needs at least two [[carriage.support]] tables (a wheel and "
                                                      f"a spade), got {len(self.support)}")
        names = [s.name for s in self.support]
        for i, name in enumerate(names):
            if name in names[:i]:
                raise SceneError(f"{self.TABLE}.support.{i}.name", f"{name!r} names two supports: give each its own")
        if len({s.position[0] for s in self.support}) < 2:
            raise SceneError(f"{self.TABLE}.support", "the supports all lie at one x: the carriage would tip over "
                                                      "(give them different x positions)")

    @property
    def supports(self) -> tuple[Support, ...]:
        """The supports, in the file's order."""
        return self.support

    # ------------------------------------------------------------------ the element
    def bodies(self, scene, name: str) -> list:
        """None on the recoil axis: the carriage is assembled by the planar engine."""
        return []

    def connectors(self, scene, name: str) -> list:
        return []


# ================================================================================================ geometry
def elevation_of(scene) -> float:
    """theta in rad: the ``[cradle]`` elevation (0 without it)."""
    return math.radians(scene.cradle.elevation) if scene.cradle is not None else 0.0


def gravity_of(scene) -> float:
    """g in m/s^2: the ``[cradle]`` value (9.81 without it)."""
    return scene.cradle.gravity if scene.cradle is not None else DEFAULT_GRAVITY


def rotate(angle: float, point) -> tuple[float, float]:
    """``R(angle) point`` (m)."""
    c, s = math.cos(angle), math.sin(angle)
    return (c * point[0] - s * point[1], s * point[0] + c * point[1])


def axis_point(carriage: Carriage, elevation: float, x: float) -> tuple[float, float]:
    """The carriage-frame point (m) of an axis body's CG at coordinate ``x`` (m, rearward from battery):
    ``trunnion + (b - x) e``, ``e = (cos theta, sin theta)``."""
    along = carriage.barrel_center_of_mass - x
    return (carriage.trunnion[0] + along * math.cos(elevation), carriage.trunnion[1] + along * math.sin(elevation))


__all__ = ["Carriage", "Support", "axis_point", "elevation_of", "gravity_of", "rotate",
           "DEFAULT_SUPPORT_FRICTION_VELOCITY", "LAW_FIELDS"]
