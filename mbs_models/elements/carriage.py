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
    T   = -(k_h (x_s - x_s0) + c_h u_s)   while p > 0     (a dug-in spade; x_s0 its static x), else 0
          (x_s0: where it last touched down, with anchor = "touchdown")

Gravity ``g`` (the ``[cradle]`` value, 9.81 without it) pulls every body vertically.  The gun starts at rest
in the static equilibrium of the whole gun on its supports with the axis bodies held where the 1-D model starts
them (:func:`static_equilibrium`).

This module holds the tables, their checks and the planar geometry both the engine and the outputs use; the
engine assembles them (:mod:`mbs_models.engine.planar`), the reference writes its own equations
(``validation/reference/planar``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..errors import SceneError
from .contact_laws import LAW_FIELDS, LAW_KEY_UNITS, LAW_RULES, LawFields, OnsetCapture, law_force
from .ops import Ops, SymbolicVariables
from .table import Rule, Table, check_choice, check_derived, check_number, ieee_power

#: Default regularisation velocity of a support's Coulomb friction (m/s), as the cradle's.
DEFAULT_SUPPORT_FRICTION_VELOCITY = 1.0e-4
#: Where a spade's horizontal anchor sits: its static x for good, or where it last touched the ground.
ANCHORS = ("rest", "touchdown")
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
    friction_coefficient: mu (>= 0) of Coulomb friction against the point's horizontal velocity; not with
        the spade's keys below (neither: frictionless).
    horizontal_stiffness, horizontal_damping: k_h (N/m), c_h (N s/m) of a dug-in spade anchored at the point's
        static x while its normal force is > 0; not with ``friction_coefficient``.
    friction_velocity: v_reg (m/s, > 0; default 1e-4): the friction is ``mu N u / v_reg`` below it.
    anchor: where a spade's anchor is: ``"rest"`` (default, DESIGN.md: its static x, for good) or ``"touchdown"``
        (where it last touched the ground: after a jump the spade digs in where it lands).
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
    anchor: str = "rest"
    TABLE: ClassVar[str] = "support"
    SINCE_VERSION: ClassVar[int] = 2
    RULES: ClassVar = {**LAW_RULES, "friction_coefficient": Rule(0.0),
                       "friction_velocity": Rule(0.0, strict=True, unit="m/s"),
                       "horizontal_stiffness": Rule(0.0, unit="N/m"),
                       "horizontal_damping": Rule(0.0, unit="N s/m")}
    KEY_UNITS: ClassVar = {**LAW_KEY_UNITS, "name": "text", "position": "[m, m]", "friction_coefficient": "1",
                           "anchor": "text"}
    CHOICES: ClassVar = {**LawFields.CHOICES, "anchor": ANCHORS}

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise SceneError(f"{self.TABLE}.name", f"must be a name of letters, digits and _ (not starting with a "
                                                   f"digit), got {self.name!r}")
        object.__setattr__(self, "position", _point(f"{self.TABLE}.position", self.position))
        super().__post_init__()
        check_choice(f"{self.TABLE}.anchor", self.anchor, ANCHORS, "anchor")
        if self.anchor != "rest" and not (self.horizontal_stiffness or self.horizontal_damping):
            raise SceneError(f"{self.TABLE}.anchor", "is a spade's (it places the horizontal anchor): give "
                                                     "horizontal_stiffness or horizontal_damping, or drop it")
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
    KEY_UNITS: ClassVar = {"center_of_mass": "[m, m]", "trunnion": "[m, m]"}

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

    #: The carriage's mass over the recoiling masses, and its inertia over ``m_c L^2`` (``L``: the largest distance
    #: of a support or the trunnion from its CG), must lie within these bounds: beyond them the gun's mass matrix
    #: is singular to double precision (a unit slip, never a carriage).
    MASS_RATIO = (1e-9, 1e12)

    def check_in_scene(self, scene, key: str) -> None:
        """Gravity > 0 (the supports carry the gun's weight); the weight and each support's static penetration
        representable; the carriage's mass and inertia within :attr:`MASS_RATIO` of the recoiling parts'."""
        gravity = gravity_of(scene)
        if not gravity > 0.0:
            raise SceneError("cradle.gravity", f"must be > 0 m/s^2 on a carriage (the supports carry the gun's "
                                               f"weight), got {gravity:g}")
        axis = scene.barrel.mass + sum(a.mass for a in scene.absorbers)
        keys = {f"{key}.mass": self.mass, "barrel.mass": scene.barrel.mass, "cradle.gravity": gravity}
        weight = check_derived(keys, "the gun's weight g (m_c + sum m)", gravity * (self.mass + axis), "N",
                               positive=True)
        check_derived(keys, "the inverse of the gun's weight 1 / (g (m_c + sum m)) (the stability margin divides by "
                            "the static loads)", 1.0 / weight, "1/N", positive=True)
        low, high = self.MASS_RATIO
        if not low <= self.mass / axis <= high:
            raise SceneError(f"{key}.mass", f"must be within [{low:g}, {high:g}] times the recoiling mass "
                                            f"({axis:g} kg), got {self.mass:g} kg")
        points = {f"{key}.support.{i}.position": s.position for i, s in enumerate(self.support)}
        points[f"{key}.trunnion"] = self.trunnion
        arm = max(max(math.hypot(p[0] - self.center_of_mass[0], p[1] - self.center_of_mass[1])
                      for p in points.values()), 1e-3)
        far = max(points, key=lambda k: math.hypot(*points[k]))
        moment = check_derived({f"{key}.mass": self.mass, f"{key}.center_of_mass": max(map(abs, self.center_of_mass)),
                                far: max(map(abs, points[far]))},
                               "the carriage's inertia about its farthest point m_c L^2", self.mass * ieee_power(arm, 2),
                               "kg m^2", positive=True)
        if not low <= self.inertia / moment <= high:
            raise SceneError(f"{key}.inertia", f"must be within [{low:g}, {high:g}] times m_c L^2 = "
                                               f"{moment:g} kg m^2 (L = {arm:g} m, the largest "
                                               f"distance of a support or the trunnion from the CG), got "
                                               f"{self.inertia:g}")
        for i, s in enumerate(self.support):
            check_derived({f"{key}.support.{i}.stiffness": s.stiffness, f"{key}.mass": self.mass},
                          "the support's penetration under the whole weight (W / k)^(1/n)",
                          ieee_power(weight / s.stiffness, 1.0 / s.law_exponent), "m")

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




# ================================================================================================ the support law
def support_normal_force(support: Support, height, height_rate, ops: Ops, lam=None):
    """N (N, >= 0): the support's contact law at penetration ``p = -height`` (m) and rate ``p' = -height_rate``;
    ``lam`` (s/m): a restitution law's ``chi / max(v-, floor)`` of the episode (captured at its touch-down)."""
    return law_force(-height, -height_rate, support.law, support.stiffness, support.law_exponent, 0.0, ops,
                     damping_factor=support.damping_factor if support.law == "hunt-crossley" else None,
                     damping=support.damping or 0.0, lam=lam)


def support_tangential_force(support: Support, normal, x, x_rate, anchor: float, ops: Ops, height=None):
    """T (N, + = forward) on the carriage at the support: ``-mu N sat(u / v_reg)`` (Coulomb, regularised),
    ``-(k_h (x - x0) + c_h u)`` while ``p = -height > 0`` (a dug-in spade anchored at ``anchor`` = x0, m), else 0; ``x`` (m) and ``x_rate`` (u, m/s) are the
    point's horizontal position and velocity, ``height`` (m) its y."""
    if support.friction > 0.0:
        s = x_rate / support.friction_velocity
        return -support.friction * normal * ops.select(s > 1.0, 1.0, ops.select(s < -1.0, -1.0, s))
    if support.anchored:
        spring = (support.horizontal_stiffness or 0.0) * (x - anchor) + (support.horizontal_damping or 0.0) * x_rate
        return -ops.select(height < 0.0, spring, 0.0)
    return 0.0 * normal


def support_stored_energy(support: Support, height, x, anchor: float):
    """Elastic energy (J) of a support (numpy): the normal law's ``k p^(n+1) / (n+1)`` and, for a spade,
    ``k_h (x - x0)^2 / 2`` while ``p > 0`` (``anchor`` = x0: a number, or an array at the samples)."""
    p = np.maximum(-np.asarray(height, dtype=float), 0.0)
    n = support.law_exponent
    energy = support.stiffness * p ** (n + 1.0) / (n + 1.0)
    if support.anchored and support.horizontal_stiffness:
        energy = energy + np.where(p > 0.0, 0.5 * support.horizontal_stiffness * (np.asarray(x) - anchor) ** 2, 0.0)
    return energy


def onset_capture(support: Support, static_load: float) -> OnsetCapture | None:
    """A restitution law's capture of ``v-`` at each touch-down (the absorbers' contacts' :class:`OnsetCapture`,
    on the penetration ``p = -y``), started at rest on the ground under ``static_load`` (N); None for the other
    laws."""
    if not support.contact_law.restitution:
        return None
    capture = OnsetCapture(support.restitution_factor, support.impact_velocity_floor, 0.0)
    capture.start(support.static_penetration(static_load), 0.0)
    return capture


class AnchorCapture(SymbolicVariables):
    """A ``touchdown`` spade's anchor (m), captured at the step starts of a solve: while the point is off the
    ground (``height >= 0``) the anchor follows its x, so that it stays where the point last touched down (to
    within the point's horizontal travel in the step that lands).  :attr:`history` holds ``(time, anchor)`` at
    every change, for the forces between and at the samples (:meth:`anchor_at`)."""

    def __init__(self, anchor: float):
        self.anchor = float(anchor)
        self.history: list[tuple[float, float]] = [(0.0, self.anchor)]
        self._variable = None  # the symbolic variable, if any

    def observe(self, t: float, x: float, height: float) -> None:
        """The point's x (m) and height (m) at the step start ``t`` (s)."""
        if height < 0.0 or x == self.anchor:
            return
        self.anchor = float(x)
        self.history.append((float(t), self.anchor))
        if self._variable is not None:
            self._variable.SetValue(self.anchor)

    def anchor_at(self, t) -> np.ndarray:
        """The anchor (m) in force at times ``t`` (s): the value set at the last step start before t."""
        times = np.array([h[0] for h in self.history])
        values = np.array([h[1] for h in self.history])
        index = np.clip(np.searchsorted(times, np.asarray(t, dtype=float), side="left") - 1, 0, len(values) - 1)
        return values[index]


# ================================================================================================ statics
@dataclass(frozen=True)
class AxisBody:
    """A body on the recoil axis as the planar model sees it: name, mass (kg), its own inertia (kg m^2) and its
    coordinate at t = 0 (m, rearward from battery)."""

    name: str
    mass: float
    inertia: float = 0.0
    position: float = 0.0


@dataclass(frozen=True)
class StaticState:
    """The gun at rest on its supports: carriage frame offset ``(0, height)`` (m) and ``pitch`` (rad), each
    support's ``loads`` (N, by name) and ``anchors`` (its static x, m: a spade's anchor)."""

    height: float
    pitch: float
    loads: dict
    anchors: dict


def world_point(offset_x: float, offset_y: float, pitch: float, point) -> tuple[float, float]:
    """``(X, Y) + R(pitch) point`` (m): a carriage-frame point in the ground frame."""
    rx, ry = rotate(pitch, point)
    return offset_x + rx, offset_y + ry


def static_equilibrium(carriage: Carriage, elevation: float, gravity: float, bodies) -> StaticState:
    """:func:`_static_equilibrium` of the bodies as a tuple: computed once per gun (the assembly and the
    post-processing of a run both need it; the tables are frozen, the result is read only)."""
    return _static_equilibrium(carriage, float(elevation), float(gravity), tuple(bodies))


@functools.lru_cache(maxsize=64)
def _static_equilibrium(carriage: Carriage, elevation: float, gravity: float, bodies) -> StaticState:
    """The static equilibrium of the gun on its supports (DESIGN.md "Initial state"): the axis ``bodies``
    (:class:`AxisBody`) held at their ``position``, the carriage at ``X = 0`` (no horizontal force acts at rest:
    friction and an unstretched spade give none) and at the height ``Y`` and pitch ``phi`` where

        sum_i N_i = g (m_c + sum_j m_j),      sum_i x_i N_i = g (m_c x_c + sum_j m_j x_j)

    (vertical forces and moments about the origin; ``N_i = k_i p_i^n_i`` at the penetrations ``p_i = -y_i`` of
    the support points, ``x_i``, ``x_c``, ``x_j`` ground-frame abscissae).  Solved by Newton's method
    (:func:`scipy.optimize.root`) from the rigid-support loads (the lever rule of the two outermost supports);
    SceneError if no equilibrium with every load finite exists (a support carrying all the weight at a
    penetration beyond its law, never here for positive stiffnesses)."""
    from scipy.optimize import root

    masses = [(carriage.mass, carriage.center_of_mass)]
    masses += [(b.mass, axis_point(carriage, elevation, b.position)) for b in bodies]
    weight = gravity * sum(m for m, _ in masses)
    supports = carriage.supports

    def residual(z):
        height, pitch = z
        force = moment = 0.0
        for s in supports:
            x, y = world_point(0.0, height, pitch, s.position)
            load = s.stiffness * ieee_power(max(-y, 0.0), s.law_exponent)
            force += load
            moment += x * load
        for m, point in masses:
            x, _ = world_point(0.0, height, pitch, point)
            moment -= gravity * m * x
        return [(force - weight) / max(weight, 1.0), moment / max(weight, 1.0)]

    # a start: the two outermost supports carry the weight by the lever rule, at the penetration of each law
    xs = sorted(supports, key=lambda s: s.position[0])
    rear, front = xs[0], xs[-1]
    x_cg = sum(m * world_point(0.0, 0.0, 0.0, p)[0] for m, p in masses) / max(sum(m for m, _ in masses), 1e-300)
    span = front.position[0] - rear.position[0]
    share = min(max((x_cg - rear.position[0]) / span, 0.05), 0.95)
    p_front = front.static_penetration(weight * share)
    p_rear = rear.static_penetration(weight * (1.0 - share))
    pitch0 = -(p_front - p_rear) / span if share < 1 else 0.0
    height0 = -p_rear - rear.position[1] - rear.position[0] * pitch0
    with np.errstate(all="ignore"):
        solution = root(residual, [height0, pitch0], method="hybr", options={"xtol": 1e-14})
        height, pitch = (float(v) for v in solution.x)
        check = residual(solution.x)
    if not (math.isfinite(height) and math.isfinite(pitch) and all(math.isfinite(c) for c in check)) or \
            (not solution.success and max(abs(check[0]), abs(check[1])) > 1e-9):
        raise SceneError("carriage.support", f"no static equilibrium of the gun on its supports was found "
                                             f"({' '.join(str(solution.message).split())})")
    loads, anchors = {}, {}
    for s in supports:
        x, y = world_point(0.0, height, pitch, s.position)
        loads[s.name] = float(s.stiffness * max(-y, 0.0) ** s.law_exponent)
        anchors[s.name] = float(x)
    return StaticState(height=height, pitch=pitch, loads=loads, anchors=anchors)


__all__ = ["Carriage", "Support", "AxisBody", "AnchorCapture", "ANCHORS", "onset_capture", "StaticState", "axis_point", "elevation_of", "gravity_of", "rotate",
           "world_point", "static_equilibrium", "support_normal_force", "support_tangential_force",
           "support_stored_energy", "DEFAULT_SUPPORT_FRICTION_VELOCITY", "LAW_FIELDS"]
