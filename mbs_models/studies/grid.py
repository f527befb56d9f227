"""The full grid of a sweep: every combination of the values given to dotted scene keys.

``make_grid(scene, {"absorber.mass": "100,500,1000", "contact.gap": "0:0.12:13"})`` checks the keys against
the scene (:func:`~mbs_models.scene.overrides.check_keys`), reads text specs
(:func:`~mbs_models.scene.overrides.parse_spec`) and returns a :class:`Grid`: its points in a fixed
order (the first key varies slowest, as nested loops over the keys in the order given).  A grid is never
made point by point: :meth:`Grid.points` and :meth:`Grid.labels` are generators, :meth:`Grid.point` decodes
one grid index (``index = sum(position_k * stride_k)``, ``stride_k`` the product of the later keys'
counts) and :meth:`Grid.indices` encodes the parameter columns of a table back into indices; a grid of
10^8 points costs the memory of its keys' values (10^4 + 10^4 here), not of its points.

A grid of more than :data:`MAX_POINTS` points is refused (:class:`GridTooLarge`) unless asked for
(``make_grid(..., max_points=None)``; ``run_sweep(..., large=True)``, ``recoil sweep --large``), before any
value is generated: the size is the product of the counts (:func:`~mbs_models.scene.overrides.spec_size`).

A value that no point of the grid accepts (``contact.gap = -0.01``, a string where a number belongs) is
bad input: :func:`check_values` raises its :class:`~mbs_models.errors.SceneError` before anything runs.
A value that only some combinations refuse is a failed point of the sweep, recorded in its row.
"""

from __future__ import annotations

import itertools
import math
import numbers
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Iterator, Mapping, Sequence

import numpy as np

from ..errors import SceneError
from ..scene import Scene
from ..scene.io import _toml_value
from ..scene.overrides import apply_overrides, check_keys, parse_spec, spec_size

#: The most points a sweep runs without being asked for more (``large=True``, ``--large``): at the ~10 ms
#: of a 10 s run of the shipped models, 10^6 points are about 3 CPU hours and a table of a few hundred MB;
#: a grid beyond it is far more often a slip (a COUNT with zeros too many) than a plan.
MAX_POINTS = 1_000_000


def shape_text(shape: Sequence[int]) -> str:
    """``10,000 x 10,000``: the counts of a grid's keys."""
    return " x ".join(f"{n:,}" for n in shape)


class GridTooLarge(SceneError):
    """A grid of more points than allowed (key ``large``): its ``size``, ``shape`` and the ``limit``."""

    def __init__(self, size: int, shape: tuple[int, ...], limit: int, flag: str = "large=True"):
        self.size, self.shape, self.limit = size, tuple(shape), limit
        super().__init__("large", f"the grid has {size:,} points ({shape_text(shape)}), more than the {limit:,} "
                                  f"a sweep runs unless asked: give {flag} to run it anyway")

    def with_flag(self, key: str, flag: str) -> SceneError:
        """The same refusal naming ``flag`` (``--large``) under ``key``, for the command line."""
        error = GridTooLarge(self.size, self.shape, self.limit, flag)
        return SceneError(key, error.message)


@dataclass(frozen=True)
class Grid:
    """``keys`` (dotted scene keys, in the order given) and the ``values`` of each (tuples, in order).

    Point ``index`` (0-based, the first key slowest) has the value ``values[k][position_k]`` of each key,
    ``position_k = (index // stride_k) % count_k``.
    """

    keys: tuple[str, ...]
    values: tuple[tuple[Any, ...], ...]

    @property
    def shape(self) -> tuple[int, ...]:
        """How many values each key has."""
        return tuple(len(v) for v in self.values)

    @property
    def size(self) -> int:
        """How many points (a Python int: exact however large)."""
        return math.prod(self.shape)

    def __len__(self) -> int:
        return self.size

    @cached_property
    def strides(self) -> tuple[int, ...]:
        """``stride_k``: the product of the counts of the keys after key k."""
        return tuple(math.prod(self.shape[k + 1:]) for k in range(len(self.shape)))

    @cached_property
    def cells(self) -> tuple[tuple[Any, ...], ...]:
        """Each key's values as table cells (:func:`column_values`)."""
        return tuple(tuple(column_values(values)) for values in self.values)

    def _positions(self, index: int) -> list[int]:
        if not 0 <= index < self.size:
            raise IndexError(f"grid index {index} out of range 0..{self.size - 1}")
        return [(index // stride) % count for stride, count in zip(self.strides, self.shape)]

    def point(self, index: int) -> dict[str, Any]:
        """Point ``index`` as ``{key: value}``."""
        return {key: values[p] for key, values, p in zip(self.keys, self.values, self._positions(index))}

    def label(self, index: int) -> tuple:
        """Point ``index``'s parameter values as they stand in the table (:func:`column_values`)."""
        return tuple(cells[p] for cells, p in zip(self.cells, self._positions(index)))

    def points(self) -> Iterator[dict[str, Any]]:
        """Every point as ``{key: value}``, the first key varying slowest (a generator)."""
        return (dict(zip(self.keys, combination)) for combination in itertools.product(*self.values))

    def labels(self) -> Iterator[tuple]:
        """Every point's parameter values as table cells, in point order (a generator)."""
        return itertools.product(*self.cells)

    def indices(self, columns: Sequence[Sequence[Any]]) -> np.ndarray:
        """The grid index (int64) of each row of a table given by its parameter ``columns`` (one array of cells
        per key, in key order); -1 for a row that is not a point of this grid."""
        import pandas as pd

        rows = len(columns[0]) if columns else 0
        index = np.zeros(rows, dtype=np.int64)
        outside = np.zeros(rows, dtype=bool)
        for cells, stride, column in zip(self.cells, self.strides, columns):
            position = pd.Index(list(cells)).get_indexer(pd.Index(column))
            outside |= position < 0
            index += position.astype(np.int64) * stride
        index[outside] = -1
        return index


def _is_number(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def column_values(values: Sequence[Any]) -> list[Any]:
    """One parameter's values as table cells, of one type per column: numbers as float, booleans as they are;
    otherwise text (strings as they are, any other value -- a table of pairs -- as its TOML text)."""
    if all(_is_number(v) for v in values):
        return [float(v) for v in values]
    if all(isinstance(v, bool) for v in values):
        return list(values)
    return [v if isinstance(v, str) else _toml_value(v) for v in values]


def _normalise(value: Any, key: str) -> Any:
    """Plain Python values (numpy scalars to float/int/bool); non-finite numbers refused."""
    if hasattr(value, "item") and not isinstance(value, (list, tuple, str)):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        raise SceneError(key, f"must be a finite number, got {value}")
    if isinstance(value, tuple):
        value = [_normalise(v, key) for v in value]
    elif isinstance(value, list):
        value = [_normalise(v, key) for v in value]
    return value


def _count(spec: Any, key: str) -> int | None:
    """How many values ``spec`` gives (None: not known without reading it -- an iterator)."""
    if isinstance(spec, str):
        return spec_size(spec, key)
    try:
        return len(spec)
    except TypeError:
        return None


def check_size(shape: Sequence[int], max_points: int | None) -> None:
    """:class:`GridTooLarge` if a grid of ``shape`` has more than ``max_points`` points (None: any size)."""
    size = math.prod(shape)
    if max_points is not None and size > max_points:
        raise GridTooLarge(size, tuple(shape), max_points)


def make_grid(scene: Scene, params: Mapping[str, Sequence[Any] | str], *,
              max_points: int | None = MAX_POINTS) -> Grid:
    """The grid of ``params`` (dotted key -> values, or a text spec ``100,500,1000`` / ``START:STOP:COUNT``)
    over ``scene``; keys, specs and values are checked (:func:`check_values`).  More than ``max_points``
    points (None: no limit) is :class:`GridTooLarge`, raised before any value is made."""
    if not isinstance(params, Mapping) or not params:
        raise SceneError("params", "give at least one parameter: {dotted key: values}")
    keys = check_keys(scene, list(params))
    counts = [_count(params[key], key) for key in keys]
    if None not in counts:
        check_size(counts, max_points)
    values = []
    for key in keys:
        spec = params[key]
        items = parse_spec(spec, key) if isinstance(spec, str) else spec
        if isinstance(items, (str, bytes)) or not isinstance(items, Sequence) and not hasattr(items, "__iter__"):
            raise SceneError(key, f"must be a sequence of values or a spec, got {type(spec).__name__}")
        items = [_normalise(v, key) for v in items]
        if not items:
            raise SceneError(key, "no values given")
        seen: set = set()
        for label in column_values(items):
            if label in seen:
                raise SceneError(key, f"value {label!r} given twice")
            seen.add(label)
        values.append(tuple(items))
    check_size([len(v) for v in values], max_points)
    grid = Grid(tuple(keys), tuple(values))
    check_values(scene, grid)
    return grid


def check_values(scene: Scene, grid: Grid) -> None:
    """Raise the SceneError of a value that every point with it refuses, naming its key (bad input)."""
    first = {key: values[0] for key, values in zip(grid.keys, grid.values)}
    for k, (key, values) in enumerate(zip(grid.keys, grid.values)):
        for value in values:
            try:
                apply_overrides(scene, {**first, key: value})
                continue
            except SceneError as exc:
                if exc.key != key:
                    continue
                error = exc
            others = [v for j, v in enumerate(grid.values) if j != k]
            other_keys = [kk for j, kk in enumerate(grid.keys) if j != k]
            if not any(_accepts(scene, {**dict(zip(other_keys, combination)), key: value})
                       for combination in itertools.product(*others)):
                raise error


def _accepts(scene: Scene, overrides: dict) -> bool:
    try:
        apply_overrides(scene, overrides)
    except SceneError:
        return False
    return True


__all__ = ["Grid", "GridTooLarge", "MAX_POINTS", "make_grid", "check_size", "check_values", "column_values",
           "shape_text"]
