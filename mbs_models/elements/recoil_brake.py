"""The hydraulic recoil brake between the ground and the barrel: oil throttled through an orifice.

Table ``[recoil_brake]`` (version 2)::

    [recoil_brake]                 # F = rho A^3 v|v| / (2 (Cd a(x))^2), opposing v
    piston_area = 0.012            # A, m^2 (effective), > 0
    orifice_area = 2.0e-4          # a, m^2 (> 0) -- a number, or a table of (stroke m, area m^2) pairs:
    # orifice_area = [[0.0, 3e-4], [0.3, 1e-4], [0.5, 0.5e-4]]   # piecewise linear in barrel displacement
    discharge_coefficient = 0.7    # Cd, in (0, 1]
    fluid_density = 870.0          # rho, kg/m^3, > 0
    counter_recoil_orifice_area = 1.0e-4   # optional: another area (number or table) while returning
    [[recoil_brake.band]]          # optional: a variable-recoil brake, its orifice switched with the elevation
    up_to = 45.0                   #   degrees: this band acts up to 45 (from the previous band's up_to)
    orifice_area = [[0.0, 3e-4], [0.6, 1e-4]]   # its area (number or table); counter_recoil_orifice_area too

The piston (area ``A``) pushes oil through the orifice (area ``a``) at ``A v / (Cd a)``; the pressure drop
``rho (A v / (Cd a))^2 / 2`` on the piston gives the force

    F = rho A^3 v |v| / (2 Cd^2 a(x)^2)        (N; v = v_M in m/s, x = x_M in m)

on the ground side (the barrel feels ``-F``): a quadratic damper opposing the motion, ``F v >= 0``.  A
table makes ``a(x)`` piecewise linear in the barrel displacement ``x``, constant before the first and after
the last stroke point; ``counter_recoil_orifice_area`` (same forms), when given, is the area while the barrel
returns (``v < 0``).  Dissipated power ``F v`` (W), no stored energy.  A connector ground -> barrel
(``d = x_M``, ``d' = v_M``), always a user function (symbolic by default).

Bounds: ``|F| <= rho A^3 |v|max^2 / (2 Cd^2 a_min^2)`` with ``a_min`` the smallest area the barrel can meet
(the early stop).  Linearised (the stability checks of fixed-step solvers): the tangent damping
``dF/dv = 2 K |v|`` (``K = rho A^3 / (2 Cd^2 a^2)``) at its largest, i.e. with the smallest area and the
largest speed the energy allows, ``|v| <= sqrt(2 E0 / M)``: the stiffest the brake can be during the run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, ClassVar

from ..errors import SceneError
from .barrel import BARREL, free_recoil_speed, shot_keys
from .connector import GROUND, Connector
from .ops import NUMPY_OPS, PYTHON_OPS, Ops, piecewise_linear
from .table import Rule, Table, check_derived, check_number, ieee_power

#: The two fields that take a number or a table of (stroke, area) pairs.
AREA_FIELDS = ("orifice_area", "counter_recoil_orifice_area")
_AREA = Rule(0.0, strict=True, unit="m^2")
#: The unit of an orifice-area key in the key reference: a number or a table of pairs.
AREA_UNIT = "m^2, or [[m, m^2], ...]"
_TABLE_FORM = "a number (m^2) or a table of (stroke m, area m^2) pairs, e.g. [[0.0, 3e-4], [0.3, 1e-4]]"


def check_area(key: str, value) -> float | tuple[tuple[float, float], ...]:
    """An orifice area (m^2, > 0) or a table of ``(stroke m, area m^2)`` pairs: at least one pair, each two
    finite numbers, strokes strictly increasing, areas > 0.  Returns the float or a tuple of float pairs;
    SceneError naming ``key`` (``key.i`` for pair i, 0-based) otherwise."""
    if isinstance(value, (list, tuple)):
        if not value:
            raise SceneError(key, f"an empty table: needs >= 1 (stroke m, area m^2) pair; must be {_TABLE_FORM}")
        pairs = []
        for i, pair in enumerate(value):
            item = f"{key}.{i}"
            if not isinstance(pair, (list, tuple)) or len(pair) != 2:
                raise SceneError(item, f"must be a pair [stroke m, area m^2] of 2 numbers, got {pair!r}")
            stroke = check_number(item, pair[0], Rule(unit="m"))
            area = check_number(item, pair[1], _AREA)
            if pairs and not stroke > pairs[-1][0]:
                raise SceneError(item, f"strokes must be strictly increasing: {stroke:g} m after {pairs[-1][0]:g} m")
            pairs.append((stroke, area))
        return tuple(pairs)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SceneError(key, f"must be {_TABLE_FORM}, got {type(value).__name__} {value!r}")
    return check_number(key, value, _AREA)


def area_points(area) -> tuple[tuple[float, float], ...]:
    """The area as (stroke m, area m^2) pairs (a number: one pair, a constant)."""
    return area if isinstance(area, tuple) else ((0.0, float(area)),)


def smallest_area(area, d_bound: float = math.inf) -> float:
    """The smallest orifice area (m^2) of ``area`` (number or pairs) over the strokes ``|x| <= d_bound`` (m):
    the piecewise-linear function's minimum lies at an end of the interval or at a stroke point inside."""
    points = area_points(area)
    if len(points) == 1:
        return points[0][1]
    candidates = [a for x, a in points if abs(x) <= d_bound]
    if math.isfinite(d_bound):
        candidates += [piecewise_linear(-d_bound, points, PYTHON_OPS), piecewise_linear(d_bound, points, PYTHON_OPS)]
    else:
        candidates += [points[0][1], points[-1][1]]
    return min(candidates)


def _area_at(d, area, ops: Ops):
    points = area_points(area)
    return points[0][1] if len(points) == 1 else piecewise_linear(d, points, ops)


def recoil_brake_force(d, rate, brake: "RecoilBrake", ops: Ops = PYTHON_OPS):
    """The brake's force in N, ``rho A^3 v|v| / (2 Cd^2 a(x)^2)``, at barrel displacement ``d`` (m) and velocity
    ``rate`` (m/s), over ``ops``; positive opposes a positive velocity.  The counter-recoil area, if given,
    acts while ``rate < 0``."""
    area = _area_at(d, brake.orifice_area, ops)
    if brake.counter_recoil_orifice_area is not None:
        area = ops.select(rate < 0, _area_at(d, brake.counter_recoil_orifice_area, ops), area)
    return brake.coefficient * (rate * ops.absolute(rate)) / (area * area)


def _check_area_fields(table) -> None:
    """Check (and store as floats or tuples of pairs) a table's orifice areas: :func:`check_area` each."""
    for name in AREA_FIELDS:
        value = getattr(table, name)
        if value is not None or name == "orifice_area":
            object.__setattr__(table, name, check_area(f"{table.TABLE}.{name}", value))


def _area_mapping(out: dict[str, Any]) -> dict[str, Any]:
    """A table's TOML mapping with its area tables as lists of [stroke, area] lists."""
    for name in AREA_FIELDS:
        if isinstance(out.get(name), tuple):
            out[name] = [list(pair) for pair in out[name]]
    return out


@dataclass(frozen=True)
class BrakeBand(Table):
    """The orifice of a variable-recoil brake within a band of elevations (``[[recoil_brake.band]]``), the way a
    throttling rod's grooves are switched with elevation (the M109's at 45 degrees, references/recoil-data.md 1.1).

    Attributes
    ----------
    up_to: the band's highest elevation, degrees in [-90, 90]: the band acts from the previous band's ``up_to``
        (exclusive; -90 for the first) to this one (inclusive).
    orifice_area: the area (m^2) or table of (stroke m, area m^2) pairs in the band.
    counter_recoil_orifice_area: optional, the area while the barrel returns in the band (default: the brake's).
    """

    up_to: float
    orifice_area: Any
    counter_recoil_orifice_area: Any = None
    TABLE: ClassVar[str] = "band"
    SINCE_VERSION: ClassVar[int] = 2
    RULES: ClassVar = {"up_to": Rule(-90.0, unit="degrees", maximum=90.0)}
    KEY_UNITS: ClassVar = {name: AREA_UNIT for name in AREA_FIELDS}

    def __post_init__(self):
        super().__post_init__()
        _check_area_fields(self)

    def to_mapping(self) -> dict[str, Any]:
        out = _area_mapping(super().to_mapping())
        return out


@dataclass(frozen=True)
class RecoilBrake(Table):
    """Hydraulic recoil brake ``F = rho A^3 v|v| / (2 Cd^2 a(x)^2)`` (module docstring).

    Attributes
    ----------
    piston_area: A, the effective piston area in m^2 (> 0).
    orifice_area: a in m^2 (> 0), or a table of (stroke m, area m^2) pairs, piecewise linear in the barrel
        displacement (constant outside the table).
    discharge_coefficient: Cd, in (0, 1].
    fluid_density: rho in kg/m^3 (> 0).
    counter_recoil_orifice_area: optional, the area (number or table) while the barrel returns (v < 0).
    band: optional ``[[recoil_brake.band]]`` tables, ``up_to`` strictly increasing: at the scene's ``[cradle]``
        elevation the first band whose ``up_to`` is at least the elevation gives the orifice (and, if it has one,
        the counter-recoil orifice); above the last band, the areas above.  :meth:`at_elevation`.
    """

    piston_area: float
    orifice_area: Any
    discharge_coefficient: float
    fluid_density: float
    counter_recoil_orifice_area: Any = None
    band: tuple = ()
    TABLE: ClassVar[str] = "recoil_brake"
    NESTED_MANY: ClassVar = {"band": BrakeBand}
    ORDER: ClassVar[int] = 50
    SINCE_VERSION: ClassVar[int] = 2
    RULES: ClassVar = {"piston_area": Rule(0.0, strict=True, unit="m^2"),
                       "discharge_coefficient": Rule(0.0, strict=True, maximum=1.0),
                       "fluid_density": Rule(0.0, strict=True, unit="kg/m^3")}
    KEY_UNITS: ClassVar = {**{name: AREA_UNIT for name in AREA_FIELDS}, "discharge_coefficient": "1"}

    def __post_init__(self):
        super().__post_init__()
        _check_area_fields(self)
        for i in range(1, len(self.band)):
            if not self.band[i].up_to > self.band[i - 1].up_to:
                raise SceneError(f"{self.TABLE}.band.{i}.up_to", f"must exceed the previous band's up_to "
                                                               f"({self.band[i - 1].up_to:g} degrees): the bands "
                                                               f"cover the elevations in order, got {self.band[i].up_to:g}")
        self._check_representable()
        for band in self.band:
            self._banded(band)._check_representable()

    def _banded(self, band: BrakeBand) -> "RecoilBrake":
        """This brake with ``band``'s areas (its counter-recoil area, or this brake's) and no bands."""
        counter = band.counter_recoil_orifice_area
        return replace(self, orifice_area=band.orifice_area, band=(),
                       counter_recoil_orifice_area=self.counter_recoil_orifice_area if counter is None else counter)

    def at_elevation(self, elevation: float) -> "RecoilBrake":
        """The brake as it acts at ``elevation`` (degrees): the first band with ``up_to >= elevation``, else the
        brake's own areas (no band: itself)."""
        for band in self.band:
            if elevation <= band.up_to:
                return self._banded(band)
        return self if not self.band else replace(self, band=())

    def _check_representable(self) -> None:
        """Every factor of the law ``K(a) = rho A^3 / (2 Cd^2 a^2)`` finite and > 0 as the law computes it, for
        the smallest and the largest area: a brake double precision cannot represent is bad input."""
        A, cd = self.piston_area, self.discharge_coefficient
        keys = {f"{self.TABLE}.piston_area": A, f"{self.TABLE}.discharge_coefficient": cd,
                f"{self.TABLE}.fluid_density": self.fluid_density}
        check_derived(keys, "the cube of the piston area A^3", ieee_power(A, 3), "m^6", positive=True)
        check_derived(keys, "the square of the discharge coefficient Cd^2", ieee_power(cd, 2), positive=True)
        coefficient = check_derived(keys, "the coefficient rho A^3 / (2 Cd^2)", self.coefficient, "kg m", positive=True)
        for name in AREA_FIELDS:
            area = getattr(self, name)
            if area is None:
                continue
            areas = [a for _, a in area_points(area)]
            smallest = {**keys, f"{self.TABLE}.{name}": min(areas)}
            square = check_derived(smallest, "the square of the smallest orifice area a^2", ieee_power(min(areas), 2),
                                   "m^4", positive=True)
            check_derived(smallest, "the brake's coefficient rho A^3 / (2 Cd^2 a^2) at the smallest area",
                          coefficient / square, "kg/m^3")
            check_derived({**keys, f"{self.TABLE}.{name}": max(areas)},
                          "the brake's coefficient rho A^3 / (2 Cd^2 a^2) at the largest area",
                          coefficient / ieee_power(max(areas), 2), "kg/m^3", positive=True)

    def check_in_scene(self, scene, key: str) -> None:
        """The brake's largest force at the barrel's free-recoil speed, ``K(a_min) (shots v0)^2``, must be finite
        (with the areas of the scene's elevation)."""
        if self.band:
            banded = self.at_elevation(_elevation(scene))
            if banded is not self:
                banded.check_in_scene(scene, key)
                return
        area = self.smallest_area()
        keys = {f"{key}.piston_area": self.piston_area, f"{key}.discharge_coefficient": self.discharge_coefficient,
                f"{key}.fluid_density": self.fluid_density, f"{key}.orifice_area": area, **shot_keys(scene)}
        speed = free_recoil_speed(scene)
        check_derived(keys, "the brake's force at the barrel's free-recoil speed v, rho A^3 v^2 / (2 Cd^2 a_min^2)",
                      self.coefficient / ieee_power(area, 2) * ieee_power(speed, 2), "N")

    @property
    def coefficient(self) -> float:
        """``rho A^3 / (2 Cd^2)`` in kg m (times ``v|v| / a^2`` it is the force; :meth:`_check_representable` keeps
        the powers finite and > 0)."""
        return self.fluid_density * self.piston_area ** 3 / (2.0 * self.discharge_coefficient ** 2)

    def smallest_area(self, d_bound: float = math.inf) -> float:
        """The smallest area (m^2) either branch has at strokes ``|x| <= d_bound`` (m)."""
        areas = [smallest_area(self.orifice_area, d_bound)]
        if self.counter_recoil_orifice_area is not None:
            areas.append(smallest_area(self.counter_recoil_orifice_area, d_bound))
        return min(areas)

    def to_mapping(self) -> dict[str, Any]:
        """The TOML mapping: tables of pairs as lists of [stroke, area] lists."""
        out = _area_mapping(super().to_mapping())
        if not self.band:
            out.pop("band", None)
        return out

    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list[Connector]:
        """One brake ground -> barrel (with the areas of the scene's elevation, :meth:`at_elevation`)."""
        return [RecoilBrakeConnector(self.at_elevation(_elevation(scene)), scene)]


def _elevation(scene) -> float:
    """The scene's ``[cradle]`` elevation (degrees; 0 without a cradle)."""
    cradle = getattr(scene, "cradle", None)
    return cradle.elevation if cradle is not None else 0.0


class RecoilBrakeConnector(Connector):
    """The brake as a connector ground -> barrel (d = x_M, d' = v_M), a user function.

    ``scene`` (optional) gives the largest barrel speed for :attr:`linear_damping`; without it (a building
    block in a caller's own system) the linearisation is unknown and reported as 0.
    """

    needs_user_function = True
    #: ``F(d, 0) = 0``: the brake only dissipates
    stores_energy = False

    def __init__(self, brake: RecoilBrake, scene=None):
        super().__init__(RecoilBrake.TABLE, RecoilBrake.TABLE, GROUND, BARREL)
        self.brake = brake
        self._scene = scene
        self._largest_speed = None

    def law(self, d, rate, ops: Ops):
        return recoil_brake_force(d, rate, self.brake, ops)

    @property
    def dissipates(self) -> bool:
        return True

    def dissipated_energy(self, quadrature, d_nodes, rate_nodes, times_nodes, stored):
        """``F v`` integrated (J), >= 0."""
        return quadrature(recoil_brake_force(d_nodes, rate_nodes, self.brake, NUMPY_OPS) * rate_nodes)

    def force_bound(self, d_bound: float, rate_bound: float, energy: float) -> float:
        """``rho A^3 |v|max^2 / (2 Cd^2 a_min^2)`` (N), a_min over the strokes ``|x| <= d_bound``."""
        if rate_bound == 0.0:
            return 0.0
        return self.brake.coefficient * rate_bound ** 2 / self.brake.smallest_area(d_bound) ** 2

    def largest_speed(self) -> float:
        """``sqrt(2 E0 / M)`` (m/s): the barrel's speed can never exceed what the initial energy E0 (J: kinetic
        plus what the other elements store at t = 0, an initial interference) gives it; 0 without a scene."""
        scene = self._scene
        if scene is None:
            return 0.0
        if self._largest_speed is not None:
            return self._largest_speed
        energy = scene.initial_kinetic_energy
        for name, table in scene.elements():
            if table is self.brake:
                continue
            for connector in table.connectors(scene, name):
                if connector.stores_energy:
                    energy += float(connector.stored_energy(0.0))
        self._largest_speed = math.sqrt(2.0 * max(energy, 0.0) / scene.barrel.mass)
        return self._largest_speed

    @property
    def linear_damping(self) -> float:
        """The tangent damping ``dF/dv = 2 K |v|`` (N s/m) at its largest during the run: the smallest area
        and the largest speed (:meth:`largest_speed`), the stiffest linearisation a fixed step must survive."""
        return 2.0 * self.brake.coefficient / self.brake.smallest_area() ** 2 * self.largest_speed()

    @property
    def first_step_limit(self) -> float:
        """``M / (2 K_max |v|max)`` (s): the time constant of the brake at its stiffest (:attr:`linear_damping`).

        A brake far stiffer than the solver's maximum step (areas of 1 % of the example's: a time constant of
        ~1e-5 s) would otherwise be met with a 5 ms first step, in which ``v|v|`` grows without bound and the
        error estimate with it; inf without a scene or without motion."""
        damping = self.linear_damping
        return self._scene.barrel.mass / damping if damping > 0 else math.inf


def add_recoil_brake(mbs, marker_ground, marker_barrel, brake: RecoilBrake,
                     user_functions: str = "symbolic") -> RecoilBrakeConnector:
    """Add the hydraulic recoil brake between two coordinate markers of your own Exudyn system.

    The force ``rho A^3 v|v| / (2 Cd^2 a(x)^2)`` with ``x`` the displacement and ``v`` the rate of
    ``x_barrel - x_ground`` (:func:`recoil_brake_force`), a user function (``"symbolic"`` or ``"python"``).
    Returns the connector (``.index`` is the Exudyn item; keep it as long as ``mbs``).
    """
    connector = RecoilBrakeConnector(brake)
    connector.add_items(mbs, marker_ground, marker_barrel, user_functions)
    return connector
