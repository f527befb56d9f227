"""A tabulated spring between the ground and the barrel: a measured force-displacement characteristic F(x).

Tables (version 2; an array: several may act together, each with its own ``name``)::

    [[tabulated_spring]]
    name = "main_spring"                      # identifier: the key of its energy and outputs
    points = [[0.0, 0.0], [0.1, 2400.0], [0.2, 5600.0], [0.3, 9600.0]]   # (displacement m, force N)
    # file = "spring.csv"                     # or a CSV "displacement,force" beside the scene file

**Law** (:mod:`.characteristic`): ``F(x)`` piecewise linear through the points, ``x = x_M`` the barrel's
displacement (m), a connector ground -> barrel (``d = x_M``: ``F > 0`` pushes the barrel towards battery and
the mount in the recoil direction).  Beyond the table the end segments are extrapolated linearly, and a run that
leaves the table is told so (:class:`~.characteristic.TableRangeWarning` naming the key).  Stored energy,
exact::

    U(x) = integral_0^x F = C_i + F_i (x - x_i) + k_i (x - x_i)^2 / 2     (x in segment i, slope k_i)

tangent stiffness ``k_i``; no dissipation.  A user function (symbolic by default).

**Rules** (SceneError naming the key): at least 2 points, finite, displacements strictly increasing; the table
lists the rest point ``(0, 0)`` (the barrel starts at rest at battery, x = 0, so the spring is relaxed there: a
preloaded spring needs a battery stop to hold it, which this element does not model -- use a
``[recuperator]`` for a preload); the force never decreases with x (``F_(i+1) >= F_i``: a spring whose force
falls as it is compressed is unstable, and the energy bounds of the early stop need a convex potential).  So
``U >= 0`` and convex, with ``U(0) = 0``.  Between the ground and the barrel only (a spring between the barrel
and an absorber would leave the early stop without its potential well: not supported).

**Bounds**: ``|F| <= max |F|`` over ``|x| <= x_max`` (at the ends or a point inside; F is monotone); the early
stop bounds x from the potential well this spring forms with the barrel's stops
(:mod:`mbs_models.engine.energy_bounds`: ``quadratic_potential`` is False).  The stability checks linearise it
with its steepest segment.  A table reaching beyond 5 m (:data:`MAX_STROKE`) gets a UnitWarning naming the key
(displacements in mm?).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ..errors import SceneError
from .barrel import BARREL
from .characteristic import Characteristic, CharacteristicTable, warn_outside
from .connector import GROUND, Connector
from .ops import Ops

#: The longest plausible stroke (m) a spring table reaches: real recoil strokes are below 1.5 m; a table in mm
#: reaches 1000 times further.
MAX_STROKE = 5.0
#: The units of a point.
UNITS = ("displacement m", "force N")


@dataclass(frozen=True)
class TabulatedSpring(CharacteristicTable):
    """A spring ground -> barrel with a tabulated characteristic F(x) (module docstring).

    Attributes
    ----------
    name: identifier of the element (its energy and outputs).
    points: ``[[x m, F N], ...]``, at least 2, x strictly increasing, with the point (0, 0), F non-decreasing.
    file: instead of ``points``, a CSV file ``displacement,force`` (one header line), relative to the scene file.
    """

    TABLE: ClassVar[str] = "tabulated_spring"
    KEY_UNITS: ClassVar = {**CharacteristicTable.KEY_UNITS, "points": "[[m, N], ...]"}
    ORDER: ClassVar[int] = 44
    COLUMNS: ClassVar[str] = "displacement,force"
    UNITS: ClassVar[tuple[str, str]] = UNITS
    MAX_EXTENT: ClassVar[float] = MAX_STROKE
    QUANTITY, UNIT, SLIP = "displacement", "m", "displacements in mm?"

    def check_pairs(self, pairs, where: str, item) -> None:
        """The rest point (0, 0) listed; F never decreasing with x."""
        if (0.0, 0.0) not in pairs:
            raise SceneError(where, "must list the rest point [0.0, 0.0]: the barrel starts at rest at x = 0 m, "
                                    "where the spring must be relaxed (a preload needs a [recuperator])")
        for i in range(1, len(pairs)):
            if pairs[i][1] < pairs[i - 1][1]:
                raise SceneError(item(i), f"the force must not decrease with x (>= {pairs[i - 1][1]:g} N), got "
                                          f"{pairs[i][1]:g} N at x = {pairs[i][0]:g} m")


class TabulatedSpringConnector(Connector):
    """The tabulated spring as a connector ground -> barrel (d = x_M), a user function."""

    monotone = True      # F non-decreasing in d (checked on the table), independent of the rate
    dissipates = False

    def __init__(self, name: str, element: str, spring: TabulatedSpring, key: str = TabulatedSpring.TABLE):
        super().__init__(name, element, GROUND, BARREL)
        self.spring, self.key = spring, key
        self.characteristic = Characteristic(spring.pairs)

    def law(self, d, rate, ops: Ops):
        """F(d) (N) over ``ops``."""
        return self.characteristic.law(d, ops)

    def force(self, d, rate, t=None):
        return self.characteristic.force(d) + 0.0 * rate

    def python_force(self, d: float, rate: float) -> float:
        return float(self.characteristic.force(d))

    @property
    def kinks(self) -> tuple[float, ...]:
        """The table's displacements (m): the force's slope jumps there."""
        return tuple(float(x) for x in self.characteristic.s)

    def stored_energy(self, d):
        """``U(d) = integral_0^d F`` (J), exact.  Given a run's samples (an array), a run that left the table gets
        a :class:`~.characteristic.TableRangeWarning`."""
        if getattr(d, "ndim", 0) >= 1 and getattr(d, "size", 0) > 1:
            warn_outside(self.characteristic, d, self.key, "displacement", "m")
        return self.characteristic.integral(d)

    def python_stored_energy(self, d: float) -> float:
        return float(self.characteristic.integral(d))

    @property
    def linear_stiffness(self) -> float:
        """The steepest segment's slope (N/m): for the stability checks only (not a quadratic potential)."""
        return self.characteristic.steepest_slope

    def force_bound(self, d_bound: float, rate_bound: float, energy: float) -> float:
        """``max |F|`` over ``|d| <= d_bound`` (N)."""
        return self.characteristic.largest_magnitude(-d_bound, d_bound)


def add_tabulated_spring(mbs, marker_ground, marker_barrel, spring: TabulatedSpring,
                         user_functions: str = "symbolic") -> TabulatedSpringConnector:
    """Add a tabulated spring F(d) between two coordinate markers of your own Exudyn system (``d`` the
    displacement of the second marker from the first); returns the connector (``.index`` is the Exudyn item)."""
    connector = TabulatedSpringConnector(spring.name, spring.name, spring)
    connector.add_items(mbs, marker_ground, marker_barrel, user_functions)
    return connector


TabulatedSpring.CONNECTOR = TabulatedSpringConnector
