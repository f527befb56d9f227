"""The full grid of a sweep: every combination of the values given to dotted scene keys.

``make_grid(scene, {"absorber.mass": "100,500,1000", "contact.gap": "0:0.12:13"})`` checks the keys against
the scene (:func:`~mbs_models.scene.overrides.check_keys`), reads text specs
(:func:`~mbs_models.scene.overrides.parse_spec`) and returns a :class:`Grid`: its points in a fixed
order (the first key varies slowest, as nested loops over the keys in the order given).

A value that no point of the grid accepts (``contact.gap = -0.01``, a string where a number belongs) is
bad input: :func:`check_values` raises its :class:`~mbs_models.errors.SceneError` before anything runs.
A value that only some combinations refuse is a failed point of the sweep, recorded in its row.
"""

from __future__ import annotations

import itertools
import math
import numbers
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

from ..errors import SceneError
from ..scene import Scene
from ..scene.io import _toml_value
from ..scene.overrides import apply_overrides, check_keys, parse_spec


@dataclass(frozen=True)
class Grid:
    """``keys`` (dotted scene keys, in the order given) and the ``values`` of each (tuples, in order)."""

    keys: tuple[str, ...]
    values: tuple[tuple[Any, ...], ...]

    def __len__(self) -> int:
        return math.prod(len(v) for v in self.values)

    def points(self) -> list[dict[str, Any]]:
        """Every point as ``{key: value}``, the first key varying slowest."""
        return [dict(zip(self.keys, combination)) for combination in itertools.product(*self.values)]

    def labels(self) -> list[tuple]:
        """Every point's parameter values as they stand in the table (:func:`column_values`), in point order."""
        return list(itertools.product(*(column_values(values) for values in self.values)))


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


def make_grid(scene: Scene, params: Mapping[str, Sequence[Any] | str]) -> Grid:
    """The grid of ``params`` (dotted key -> values, or a text spec ``100,500,1000`` / ``START:STOP:COUNT``)
    over ``scene``; keys, specs and values are checked (:func:`check_values`)."""
    if not isinstance(params, Mapping) or not params:
        raise SceneError("params", "give at least one parameter: {dotted key: values}")
    keys = check_keys(scene, list(params))
    values = []
    for key in keys:
        spec = params[key]
        items = parse_spec(spec, key) if isinstance(spec, str) else spec
        if isinstance(items, (str, bytes)) or not isinstance(items, Sequence) and not hasattr(items, "__iter__"):
            raise SceneError(key, f"must be a sequence of values or a spec, got {type(spec).__name__}")
        items = [_normalise(v, key) for v in items]
        if not items:
            raise SceneError(key, "no values given")
        labels = column_values(items)
        for i, label in enumerate(labels):
            if label in labels[:i]:
                raise SceneError(key, f"value {label!r} given twice")
        values.append(tuple(items))
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


__all__ = ["Grid", "make_grid", "check_values", "column_values"]
