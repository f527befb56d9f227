"""A measured characteristic: a force tabulated against one variable, piecewise linear, from a scene table.

The building block of the tabulated elements (:mod:`.tabulated_spring`: force against displacement,
:mod:`.tabulated_damper`: force against velocity).  A characteristic is ``n >= 2`` points ``(s_i, F_i)`` with
strictly increasing ``s`` (m or m/s) and forces F (N), given inline (``points = [[s, F], ...]``) or as a CSV
file of two columns after one header line (``file = "spring.csv"``, relative to the scene file).  Between the
points F is linear; **beyond the table the end segments are extrapolated linearly** (the law is continuous
everywhere, so a solver stepping past an end point meets no cliff)::

    F(s) = F_i + k_i (s - s_i),   k_i = (F_(i+1) - F_i) / (s_(i+1) - s_i),   i the segment of s
                                   (i = 0 below s_0, i = n - 2 above s_(n-1))

Its integral from 0, exact (piecewise quadratic), with ``C_i = integral_0^(s_i) F`` (trapezoids)::

    integral_0^s F = C_i + F_i (s - s_i) + k_i (s - s_i)^2 / 2

The largest |F| over an interval lies at an end of the interval or at a point inside it.  A run whose variable
left the table is told so by a :class:`TableRangeWarning` naming the key (the elements check the samples of
the run they are given in post-processing).

The force law over the backend ops is :func:`~.ops.piecewise_linear` (constant outside the table) plus the
end segments' extrapolation ``k_0 min(s - s_0, 0) + k_(n-2) max(s - s_(n-1), 0)``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ..errors import SceneError
from ..inputs import read_two_columns
from .ops import Ops, piecewise_linear
from .table import Rule, Table, check_number

#: Points a characteristic may have at most: the symbolic user function is a chain of one selection per point.
MAX_POINTS = 2_000


class TableRangeWarning(UserWarning):
    """A run took a tabulated element's variable (displacement, velocity) beyond its table: the force there is
    the end segment's linear extrapolation, not a measured value.  The message names the key and both ranges."""


def read_pairs_file(path: Path, key: str, columns: str) -> list[list[float]]:
    """The ``(s, F)`` rows of a CSV file of two columns (``columns``, e.g. ``"displacement,force"``) after one
    header line: a regular UTF-8 text file within the input limits (:func:`~mbs_models.inputs.read_text_file`),
    at most :data:`MAX_POINTS` rows.  SceneError naming ``key`` otherwise."""
    too_many = SceneError(key, f"{path} has more than {MAX_POINTS} points: resample the characteristic")
    return [list(pair) for pair in read_two_columns(path, key, "characteristic file", columns, MAX_POINTS,
                                                    lambda: too_many)]


def resolve_points(table, key: str, columns: str, units: tuple[str, str]) -> tuple[tuple[float, float], ...]:
    """The points of a table with ``points`` (inline pairs) or ``file`` (a CSV beside the scene): exactly one of
    them; at least 2 pairs of finite numbers with strictly increasing first entries.  Errors name
    ``key.points.i`` (or ``key.file``) and the allowed values."""
    from .firing import SCENE_DIRECTORY

    if (table.points is None) == (table.file is None):
        raise SceneError(f"{key}.points", "give either points = [[s, F], ...] or file = \"name.csv\" (one of them)")
    where = f"{key}.points"
    if table.file is not None:
        if not isinstance(table.file, str) or not table.file:
            raise SceneError(f"{key}.file", "must be a file name (a string)")
        path = Path(table.file)
        if not path.is_absolute():
            path = (SCENE_DIRECTORY.get() or Path.cwd()) / path
        raw, where = read_pairs_file(path, f"{key}.file", columns), f"{key}.file"
    else:
        raw = table.points
    form = f"a list of at least 2 pairs [{units[0]}, {units[1]}], e.g. [[0.0, 0.0], [0.1, 2000.0]]"
    if isinstance(raw, (str, bytes)) or not isinstance(raw, (list, tuple)):
        raise SceneError(where, f"must be {form}, got {type(raw).__name__}")
    if len(raw) < 2:
        raise SceneError(where, f"needs at least 2 points, got {len(raw)}; must be {form}")
    if len(raw) > MAX_POINTS:
        raise SceneError(where, f"has {len(raw)} points, more than {MAX_POINTS}: resample the characteristic")
    pairs: list[tuple[float, float]] = []
    for i, pair in enumerate(raw):
        item = f"{where}.{i}" if table.file is None else where
        if isinstance(pair, (str, bytes)) or not isinstance(pair, (list, tuple)) or len(pair) != 2:
            raise SceneError(item, f"must be a pair [{units[0]}, {units[1]}] of 2 numbers, got {pair!r}")
        s = check_number(item, pair[0], Rule(unit=units[0]))
        force = check_number(item, pair[1], Rule(unit=units[1]))
        if pairs and not s > pairs[-1][0]:
            raise SceneError(item, f"the {units[0]} values must be strictly increasing: {s:g} after {pairs[-1][0]:g}")
        pairs.append((s, force))
    return tuple(pairs)


class Characteristic:
    """The piecewise-linear force through ``points`` ``((s_i, F_i), ...)``, extrapolated by its end segments
    (module docstring).  ``s`` in m or m/s, F in N."""

    def __init__(self, points):
        self.points = tuple((float(s), float(f)) for s, f in points)
        self.s = np.array([p[0] for p in self.points])
        self.f = np.array([p[1] for p in self.points])
        self.slopes = np.diff(self.f) / np.diff(self.s)
        # C_i = integral_0^(s_i) F, summed outward from 0 (exact for a linear F; no difference of two large
        # integrals from the table's first point, whose round-off would swamp U near 0)
        self.integral_at_points = np.array([self._from_zero(float(p)) for p in self.s])

    @property
    def low(self) -> float:
        return float(self.s[0])

    @property
    def high(self) -> float:
        return float(self.s[-1])

    def _segment(self, s):
        return np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, len(self.s) - 2)

    def _from_zero(self, s: float) -> float:
        """``integral_0^s F`` by trapezoids over the table's pieces between 0 and ``s`` (F is linear on each)."""
        nodes = [0.0, *(p for p in self.s if min(0.0, s) < p < max(0.0, s)), s]
        nodes = sorted(nodes) if s >= 0.0 else sorted(nodes, reverse=True)
        return math.fsum(0.5 * (self.force(b) + self.force(a)) * (b - a) for a, b in zip(nodes, nodes[1:]))

    def _anchors(self, s):
        """For each ``s``: the table point nearest to ``s`` on the way from 0 to ``s`` (index), or -1 for 0
        itself when no table point lies between them."""
        right = np.searchsorted(self.s, s, side="right") - 1          # last point <= s
        left = np.searchsorted(self.s, s, side="left")                # first point >= s
        n = len(self.s)
        positive = (s >= 0.0) & (right >= 0)
        positive &= self.s[np.clip(right, 0, n - 1)] >= 0.0
        negative = (s < 0.0) & (left < n)
        negative &= self.s[np.clip(left, 0, n - 1)] <= 0.0
        return np.where(positive, right, np.where(negative, left, -1))

    def force(self, s):
        """F(s) in N on floats or arrays (numpy), extrapolated linearly beyond the table."""
        s = np.asarray(s, dtype=float)
        i = self._segment(s)
        out = self.f[i] + self.slopes[i] * (s - self.s[i])
        return float(out) if out.ndim == 0 else out

    def law(self, s, ops: Ops):
        """F(s) over ``ops`` (the symbolic and Python user functions): :func:`~.ops.piecewise_linear` plus the
        end segments' extrapolation."""
        inside = piecewise_linear(s, self.points, ops)
        below = ops.select(s < self.low, float(self.slopes[0]) * (s - self.low), 0.0)
        above = ops.select(s > self.high, float(self.slopes[-1]) * (s - self.high), 0.0)
        return inside + below + above

    def integral(self, s):
        """``integral_0^s F`` (N m for a spring: J) on floats or arrays, exact (module docstring)."""
        s = np.asarray(s, dtype=float)
        k = self._anchors(s)
        anchor = np.where(k >= 0, self.s[np.clip(k, 0, None)], 0.0)
        at_anchor = np.where(k >= 0, self.integral_at_points[np.clip(k, 0, None)], 0.0)
        out = at_anchor + 0.5 * (self.force(anchor) + self.force(s)) * (s - anchor)  # F linear between them
        return float(out) if out.ndim == 0 else out

    def largest_magnitude(self, low: float, high: float) -> float:
        """``max |F|`` (N) over ``[low, high]``: at the ends or at a point inside; inf for an infinite end where
        an end segment is not flat."""
        candidates = [abs(f) for s, f in self.points if low <= s <= high]
        for end in (low, high):
            if math.isfinite(end):
                candidates.append(abs(self.force(end)))
            elif (end > 0 and self.slopes[-1] != 0) or (end < 0 and self.slopes[0] != 0):
                return math.inf
            else:
                candidates.append(abs(self.f[-1] if end > 0 else self.f[0]))
        return float(max(candidates))

    @property
    def steepest_slope(self) -> float:
        """The largest segment slope ``k_i`` (N/m or N s/m): the stiffest linearisation of the law."""
        return float(np.max(self.slopes))


def warn_outside(characteristic: Characteristic, values, key: str, what: str, unit: str) -> None:
    """A :class:`TableRangeWarning` naming ``key`` if any of ``values`` (a run's samples) lies beyond the table."""
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        return
    lowest, highest = float(np.min(values)), float(np.max(values))
    if lowest < characteristic.low or highest > characteristic.high:
        warnings.warn(f"{key}: the run's {what} reached [{lowest:.4g}, {highest:.4g}] {unit}, beyond the table's "
                      f"[{characteristic.low:g}, {characteristic.high:g}] {unit}: the force there is the end segment "
                      f"extrapolated linearly; extend the table", TableRangeWarning, stacklevel=3)


def implausible_extent(characteristic: Characteristic, key: str, limit: float, what: str, unit: str,
                       slip: str) -> list[tuple[str, str]]:
    """``[(key, one line)]`` if the table reaches beyond ``|s| = limit`` (a unit slip, ``slip``), else []."""
    extent = max(abs(characteristic.low), abs(characteristic.high))
    if extent <= limit:
        return []
    return [(key, f"{key} reaches a {what} of {extent:g} {unit} (plausible: up to {limit:g} {unit}); {slip}")]


def check_name(key: str, name) -> str:
    """A tabulated element's ``name``: an identifier (a letter, then letters, digits or ``_``), not ``barrel`` or
    ``ground``."""
    import re

    if not isinstance(name, str) or not re.match(r"^[A-Za-z][A-Za-z0-9_]*$", name) or name in ("barrel", "ground"):
        raise SceneError(f"{key}.name", f"must be an identifier (a letter, then letters, digits or _), not barrel "
                                        f"or ground; got {name!r}")
    return name


def scene_key(scene, table, default: str) -> str:
    """``table``'s key in ``scene`` (``tabulated_spring`` or ``tabulated_spring.1``)."""
    return next((key for key, other in scene.tables() if other is table), default)


@dataclass(frozen=True)
class CharacteristicTable(Table):
    """The scene table of a tabulated characteristic (a base: :mod:`.tabulated_spring`, :mod:`.tabulated_damper`).

    Fields ``name``, ``points`` (inline pairs) or ``file`` (a CSV beside the scene); a subclass names its TABLE,
    ``COLUMNS`` (the CSV header), ``UNITS`` (of a point), the plausible extent ``MAX_EXTENT`` with its
    ``QUANTITY``, ``UNIT`` and ``SLIP`` hint (a UnitWarning beyond it), its ``CONNECTOR`` class, and its own
    rules in :meth:`check_pairs`.
    """

    name: str
    points: Any = None
    file: str | None = None
    MANY: ClassVar[bool] = True
    KEY_UNITS: ClassVar = {"name": "text", "file": "text (a path)"}
    SINCE_VERSION: ClassVar[int] = 2
    COLUMNS: ClassVar[str] = ""
    UNITS: ClassVar[tuple[str, str]] = ("", "")
    MAX_EXTENT: ClassVar[float] = math.inf
    QUANTITY: ClassVar[str] = ""
    UNIT: ClassVar[str] = ""
    SLIP: ClassVar[str] = ""
    CONNECTOR: ClassVar[type] = type(None)

    def __post_init__(self):
        super().__post_init__()
        key = self.TABLE
        check_name(key, self.name)
        pairs = resolve_points(self, key, self.COLUMNS, self.UNITS)
        where = self._where(key)
        self.check_pairs(pairs, where, lambda i: where if self.file is not None else f"{where}.{i}")
        if self.file is None:
            object.__setattr__(self, "points", pairs)
        object.__setattr__(self, "_pairs", pairs)

    def _where(self, key: str) -> str:
        return f"{key}.file" if self.file is not None else f"{key}.points"

    def check_pairs(self, pairs, where: str, item) -> None:
        """The element's own rules on its points (SceneError naming ``where``, or ``item(i)`` for point i)."""

    @property
    def pairs(self) -> tuple[tuple[float, float], ...]:
        """The points as given inline or read from the file."""
        return self._pairs

    def to_mapping(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name}
        if self.file is not None:
            out["file"] = self.file
        else:
            out["points"] = [list(p) for p in self.pairs]
        return out

    def implausible(self, key: str) -> list[tuple[str, str]]:
        """A table reaching beyond ``MAX_EXTENT`` (a UnitWarning: ``mbs_models.scene.plausibility``)."""
        return implausible_extent(Characteristic(self.pairs), self._where(key), self.MAX_EXTENT, self.QUANTITY,
                                  self.UNIT, self.SLIP)

    def bodies(self, scene, name: str) -> list:
        return []

    def connectors(self, scene, name: str) -> list:
        return [self.CONNECTOR(self.name, name, self, scene_key(scene, self, self.TABLE))]

