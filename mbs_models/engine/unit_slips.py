"""Every unit slip of a scene, and the :class:`~mbs_models.errors.UnitWarning` for each.

Two sources, one list: magnitudes implausible for a recoil mechanism (a barrel mass in tonnes, a pulse in
ms or kN: :mod:`mbs_models.scene.plausibility`) and contacts that can never close (a gap or stop position
in mm: :mod:`mbs_models.engine.reach`).  Each finding names its scene key; :func:`simulate
<mbs_models.engine.simulation.simulate>` warns of each before it solves (``warnings.warn`` with
:class:`~mbs_models.errors.UnitWarning`), :func:`~mbs_models.studies.sweep.run_sweep` and
:func:`~mbs_models.studies.optimise.optimise` of those at the corners of their grid or bounds
(:func:`grid_unit_slips`) before the first point, and the ``recoil`` command prints each as one line on
stderr.
Nothing is clamped or refused: the run goes on with the values as given.
"""

from __future__ import annotations

import functools
import itertools
import warnings
from typing import Any, Mapping, Sequence

from ..errors import UnitWarning
from ..scene import Scene
from ..scene.plausibility import implausible_magnitudes
from .reach import contacts_out_of_reach


#: Scenes whose findings :func:`unit_slips` keeps (the most recently used): a loop of runs of a few scenes.
CACHED_SCENES = 64


def unit_slips(scene: Scene) -> list:
    """The findings of ``scene`` (each with ``key`` and ``message()``): its implausible magnitudes, then its
    contacts out of reach; [] for a plausible scene.

    The findings depend on the scene's values alone (frozen tables) and are immutable: those of the last
    :data:`CACHED_SCENES` scenes are kept (by equality of the scenes: the same values), so that a loop of
    ``simulate`` calls on the same scenes checks each once; a scene that cannot be hashed is checked anew."""
    try:
        return list(_cached_unit_slips(scene))
    except TypeError:  # an unhashable value in a table (a plugin element's list)
        return _unit_slips(scene)


def _unit_slips(scene: Scene) -> list:
    """:func:`unit_slips` computed anew."""
    return [*implausible_magnitudes(scene), *contacts_out_of_reach(scene)]


@functools.lru_cache(maxsize=CACHED_SCENES)
def _cached_unit_slips(scene: Scene) -> tuple:
    return tuple(_unit_slips(scene))


def grid_unit_slips(scene: Scene, grid: Mapping[str, Sequence[Any]]) -> list:
    """The findings of a sweep or a design space: ``scene`` with the overrides ``grid`` (dotted key -> its
    values, or an optimisation's (low, high)) at every corner of the grid -- each key at its smallest and its
    largest number (a key without numbers at its first value) -- the first finding per scene key.  A unit
    slip grows with the magnitude it scales, so the corners show it; a corner the scene refuses is skipped
    (the sweep records it as a failed point)."""
    from ..errors import SceneError
    from ..scene.overrides import apply_overrides

    keys, choices = list(grid), []
    for values in grid.values():
        numbers = [float(v) for v in values if isinstance(v, (int, float)) and not isinstance(v, bool)]
        choices.append(sorted({min(numbers), max(numbers)}) if numbers else list(values)[:1])
    found: dict[str, object] = {}
    for corner in itertools.product(*choices):
        try:
            changed = apply_overrides(scene, dict(zip(keys, corner)))
        except SceneError:
            continue
        for finding in unit_slips(changed):
            found.setdefault(finding.key, finding)
    return list(found.values())


def warn_unit_slips(scene: Scene, stacklevel: int = 2, *, grid: Mapping[str, Sequence[Any]] | None = None
                    ) -> list[str]:
    """``warnings.warn(message, UnitWarning)`` for every finding of :func:`unit_slips` (of
    :func:`grid_unit_slips` with ``grid``); returns the messages.  ``stacklevel`` as for
    :func:`warnings.warn`, counted from the caller of this function."""
    findings = unit_slips(scene) if grid is None else grid_unit_slips(scene, grid)
    messages = [finding.message() for finding in findings]
    for message in messages:
        warnings.warn(message, UnitWarning, stacklevel=stacklevel + 1)
    return messages


__all__ = ["unit_slips", "grid_unit_slips", "warn_unit_slips"]
