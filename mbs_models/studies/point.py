"""One point of a sweep: a scene with dotted-key overrides, simulated, as one tidy row of scalars.

:func:`simulate_scene` is the one place where a sweep calls :func:`~mbs_models.simulate` (the scene-list
sweeps of :mod:`.sweep` and the grid sweeps both go through it).  :func:`evaluate_point` applies the
overrides (:func:`~mbs_models.scene.overrides.apply_overrides`), simulates and returns the row: the
parameters, every scalar metric (:func:`metric_columns`), ``wall_time`` (s), ``status`` (``"ok"`` or the
error's class) and ``error`` (its message, None when ok).  A :class:`~mbs_models.errors.SceneError` (an
invalid combination of values) or :class:`~mbs_models.errors.SimulationError` (a failed solve) is
recorded in the row; any other exception is a bug and propagates.

Everything here is module-level and picklable: worker processes and Dask workers receive the base scene,
the overrides and the :class:`PointSettings`, build their own model and send back plain rows.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

from ..engine.accuracy import SolverSettings
from ..errors import RecoilError
from ..scene import Scene
from ..scene.overrides import apply_overrides

#: Scalar metrics of every scene, in column order (SI units: m, s, N, m/s; ``impacts`` is a count).
SCALAR_METRICS = (
    "max_barrel_displacement", "time_of_max_barrel_displacement",
    "peak_support_force", "time_of_peak_support_force",
    "peak_contact_force", "time_of_peak_contact_force",
    "max_absorber_velocity", "time_of_max_absorber_velocity",
    "impacts",
)
#: Per absorber (scenes with several), as ``absorber.N.<metric>``.
ABSORBER_METRICS = ("peak_contact_force", "max_absorber_velocity", "impacts")
#: Per end stop (a contact with the ground that is no absorber), as ``<element name>.<metric>``.
STOP_METRICS = ("peak_contact_force", "impacts", "dissipated_energy")
#: Run information after the metrics: the barrel's initial velocity (m/s), the simulated end time (s, less
#: than asked with an early stop), why the run ended, the solver's steps.
RUN_COLUMNS = ("initial_velocity", "end_time", "stop_reason", "steps")
#: The last three columns of every row.
STATUS_COLUMNS = ("wall_time", "status", "error")
#: Columns holding counts (whole numbers; empty for a failed point).
COUNT_COLUMNS = ("impacts", "steps")
#: Columns holding text.
TEXT_COLUMNS = ("stop_reason", "status", "error")


@dataclass(frozen=True)
class PointSettings:
    """What every point of a sweep shares: ``end_time`` (s), ``accuracy`` (a preset name or
    :class:`SolverSettings`), ``stop_when_final`` (metrics whose proven-final value ends a run early: the
    others are then empty) and the ``impact_threshold`` (N)."""

    end_time: float = 10.0
    accuracy: str | SolverSettings = "standard"
    stop_when_final: tuple[str, ...] = ()
    impact_threshold: float = 1000.0


def simulate_scene(scene: Scene, settings: PointSettings):
    """The :class:`~mbs_models.Result` of one scene: the single call of ``simulate`` of every sweep.

    It runs on this process's :class:`~mbs_models.engine.reuse.Simulator`: the points of one structure
    reuse one assembled system per worker process, with the results of ``simulate`` bit for bit."""
    from ..engine.reuse import process_simulator

    return process_simulator().simulate(scene, settings.end_time, settings.accuracy,
                                        impact_threshold=settings.impact_threshold,
                                        stop_when_final=settings.stop_when_final)


def _stops(scene: Scene) -> list[str]:
    """Element names of the scene's end stops (contacts with the ground that are no absorbers)."""
    from ..elements.absorber import Absorber
    from ..elements.contact_laws import LawFields

    return [name for name, table in scene.elements()
            if isinstance(table, LawFields) and not isinstance(table, Absorber)]


def metric_columns(scene: Scene) -> list[str]:
    """The metric columns of a sweep over ``scene`` (its overrides change values, never the elements)."""
    columns = list(SCALAR_METRICS)
    if len(scene.absorbers) > 1:
        columns += [f"absorber.{i}.{m}" for i in range(len(scene.absorbers)) for m in ABSORBER_METRICS]
    columns += [f"{stop}.{m}" for stop in _stops(scene) for m in STOP_METRICS]
    return columns + list(RUN_COLUMNS)


def result_row(result, scene: Scene) -> dict[str, Any]:
    """The metric columns (:func:`metric_columns`) of one result."""
    row: dict[str, Any] = {name: getattr(result, name) for name in SCALAR_METRICS}
    row["impacts"] = None if result.impacts is None else len(result.impacts)
    if len(scene.absorbers) > 1:
        for i, entry in enumerate(result.absorbers()):
            for metric in ABSORBER_METRICS:
                value = entry[metric]
                row[f"absorber.{i}.{metric}"] = len(value) if metric == "impacts" and value is not None else value
    stops = {entry["element"]: entry for entry in result.stops()} if _stops(scene) else {}
    for stop in _stops(scene):
        entry = stops.get(stop, {})
        row[f"{stop}.peak_contact_force"] = entry.get("peak_contact_force")
        impacts = entry.get("impacts")
        row[f"{stop}.impacts"] = None if impacts is None else len(impacts)
        row[f"{stop}.dissipated_energy"] = entry.get("dissipated_energy")
    row.update(initial_velocity=scene.initial_velocity, end_time=result.end_time, stop_reason=result.stop_reason,
               steps=result.steps)
    return row


def evaluate_point(scene: Scene, overrides: Mapping[str, Any], settings: PointSettings = PointSettings()) -> dict:
    """The row of one point: ``overrides`` (dotted key -> value) applied to ``scene``, simulated.

    Keys of the row: the override keys (their values as given), :func:`metric_columns`, then
    ``wall_time`` (s: the solve's, or the time to fail), ``status`` and ``error``.
    """
    row: dict[str, Any] = dict(overrides)
    start = time.perf_counter()
    try:
        point_scene = apply_overrides(scene, overrides)
        result = simulate_scene(point_scene, settings)
    except RecoilError as exc:
        row.update({column: None for column in metric_columns(scene)})
        row.update(wall_time=time.perf_counter() - start, status=type(exc).__name__, error=str(exc))
        return row
    row.update(result_row(result, point_scene))
    row.update(wall_time=result.wall_time, status="ok", error=None)
    return row


def evaluate_batch(task: tuple[Scene, PointSettings, Sequence[tuple[int, Mapping[str, Any]]]]
                   ) -> list[tuple[int, dict]]:
    """``[(index, evaluate_point(scene, overrides, settings)) for index, overrides in points]``: the unit of
    work a backend sends to a worker (several points per task amortise its overhead)."""
    scene, settings, points = task
    return [(index, evaluate_point(scene, overrides, settings)) for index, overrides in points]


__all__ = ["PointSettings", "simulate_scene", "evaluate_point", "evaluate_batch", "metric_columns", "result_row",
           "SCALAR_METRICS", "STATUS_COLUMNS", "COUNT_COLUMNS", "TEXT_COLUMNS"]
