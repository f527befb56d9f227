"""A tabulated damper between the ground and the barrel: a measured force-velocity characteristic F(v).

Tables (version 2; an array: several may act together, each with its own ``name``)::

    [[tabulated_damper]]
    name = "buffer"                           # identifier: the key of its energy and outputs
    points = [[-0.5, -7000.0], [0.0, 0.0], [0.3, 1900.0], [1.0, 6200.0]]   # (velocity m/s, force N)
    # file = "damper.csv"                     # or a CSV "velocity,force" beside the scene file

**Law** (:mod:`.characteristic`): ``F(v)`` piecewise linear through the points, ``v = v_M`` the barrel's
velocity (m/s), a connector ground -> barrel (``d' = v_M``: ``F > 0`` opposes a recoiling barrel and pushes
the mount in the recoil direction).  Beyond the table the end segments are extrapolated linearly, and a run that
leaves the table is told so (:class:`~.characteristic.TableRangeWarning` naming the key).  Dissipated power
``F(v) v >= 0`` (W); no stored energy.  A user function (symbolic by default).

**Rules** (SceneError naming the key): at least 2 points, finite, velocities strictly increasing; the table lists
``(0, 0)`` (no force at rest); every point is passive, ``F_i v_i >= 0`` (a damper that pushes the way it moves
would inject energy); the end segments' slopes are >= 0, so that the extrapolation stays passive too.  Then
every segment is passive (its ends are on the same side of v = 0, or one is the rest point).

**Bounds**: ``|F| <= max |F|`` over ``|v| <= v_max`` (at the ends or a point inside).  The stability checks
linearise it with its steepest segment (N s/m).  A table reaching beyond 100 m/s (:data:`MAX_VELOCITY`) gets a
UnitWarning naming the key (velocities in mm/s?).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ..errors import SceneError
from .barrel import BARREL
from .characteristic import Characteristic, CharacteristicTable, warn_outside
from .connector import GROUND, Connector
from .ops import NUMPY_OPS, Ops

#: The fastest plausible velocity (m/s) a damper table reaches: free-recoil velocities stay below 30 m/s
#: (DESIGN.md "Unit slips"); a table in mm/s reaches 1000 times further.
MAX_VELOCITY = 100.0
#: The units of a point.
UNITS = ("velocity m/s", "force N")


@dataclass(frozen=True)
class TabulatedDamper(CharacteristicTable):
    """A damper ground -> barrel with a tabulated characteristic F(v) (module docstring).

    Attributes
    ----------
    name: identifier of the element (its energy and outputs).
    points: ``[[v m/s, F N], ...]``, at least 2, v strictly increasing, with (0, 0), passive.
    file: instead of ``points``, a CSV file ``velocity,force`` (one header line), relative to the scene file.
    """

    TABLE: ClassVar[str] = "tabulated_damper"
    KEY_UNITS: ClassVar = {**CharacteristicTable.KEY_UNITS, "points": "[[m/s, N], ...]"}
    ORDER: ClassVar[int] = 45
    COLUMNS: ClassVar[str] = "velocity,force"
    UNITS: ClassVar[tuple[str, str]] = UNITS
    MAX_EXTENT: ClassVar[float] = MAX_VELOCITY
    QUANTITY, UNIT, SLIP = "velocity", "m/s", "velocities in mm/s?"

    def check_pairs(self, pairs, where: str, item) -> None:
        """The rest point (0, 0) listed; passive (F v >= 0) at every point and on the extrapolated end segments."""
        if (0.0, 0.0) not in pairs:
            raise SceneError(where, "must list the rest point [0.0, 0.0]: a damper has no force at rest (F(0) = 0)")
        for i, (v, f) in enumerate(pairs):
            if f * v < 0:
                raise SceneError(item(i), f"must be passive, F v >= 0 (F of the sign of v): got F = {f:g} N at "
                                          f"v = {v:g} m/s")
        slopes = Characteristic(pairs).slopes
        for i, slope in ((0, slopes[0]), (len(pairs) - 1, slopes[-1])):
            if slope < 0:
                raise SceneError(item(i), f"the end segment's slope must be >= 0 N s/m (it is extrapolated beyond the "
                                          f"table, where a falling force would turn active), got {slope:g} N s/m")


class TabulatedDamperConnector(Connector):
    """The tabulated damper as a connector ground -> barrel (d' = v_M), a user function."""

    stores_energy = False   # F(d, 0) = F(0) = 0: the table passes through (0, 0)

    def __init__(self, name: str, element: str, damper: TabulatedDamper, key: str = TabulatedDamper.TABLE):
        super().__init__(name, element, GROUND, BARREL)
        self.damper, self.key = damper, key
        self.characteristic = Characteristic(damper.pairs)

    def law(self, d, rate, ops: Ops):
        """F(rate) (N) over ``ops``."""
        return self.characteristic.law(rate, ops)

    def force(self, d, rate, t=None):
        return self.characteristic.force(rate) + 0.0 * d

    def python_force(self, d: float, rate: float) -> float:
        return float(self.characteristic.force(rate))

    def dissipated_energy(self, quadrature, d_nodes, rate_nodes, times_nodes, stored):
        """``F(v) v`` integrated (J), >= 0.  A run whose velocity left the table gets a
        :class:`~.characteristic.TableRangeWarning`."""
        warn_outside(self.characteristic, rate_nodes, self.key, "velocity", "m/s")
        return quadrature(self.characteristic.law(rate_nodes, NUMPY_OPS) * rate_nodes)

    @property
    def linear_damping(self) -> float:
        """The steepest segment's slope (N s/m): the stiffest linearisation (stability checks)."""
        return self.characteristic.steepest_slope

    def force_bound(self, d_bound: float, rate_bound: float, energy: float) -> float:
        """``max |F|`` over ``|v| <= rate_bound`` (N)."""
        return self.characteristic.largest_magnitude(-rate_bound, rate_bound)


def add_tabulated_damper(mbs, marker_ground, marker_barrel, damper: TabulatedDamper,
                         user_functions: str = "symbolic") -> TabulatedDamperConnector:
    """Add a tabulated damper F(d') between two coordinate markers of your own Exudyn system (``d'`` the rate of
    the second marker's displacement from the first); returns the connector (``.index`` is the Exudyn item)."""
    connector = TabulatedDamperConnector(damper.name, damper.name, damper)
    connector.add_items(mbs, marker_ground, marker_barrel, user_functions)
    return connector


TabulatedDamper.CONNECTOR = TabulatedDamperConnector
