"""One point of a sweep: a scene with dotted-key overrides, simulated, as one tidy row of scalars.

:func:`simulate_scene` is the one place where a sweep calls :func:`~mbs_models.simulate` (the scene-list
sweeps of :mod:`.sweep` and the grid sweeps both go through it).  :func:`evaluate_point` applies the
overrides (:func:`~mbs_models.scene.overrides.apply_overrides`), simulates and returns the row: the
parameters, every scalar metric (:func:`metric_columns`, with those the elements declare), ``wall_time`` (s), ``status`` (``"ok"`` or the
error's class) and ``error`` (its message on one line, None when ok).  Whatever goes wrong at a point is
recorded in its row, and the sweep goes on: a :class:`~mbs_models.errors.SceneError` (an invalid
combination of values), a :class:`~mbs_models.errors.SimulationError` (a failed solve) and any other
exception (an ``OverflowError`` of an extreme value, a ``MemoryError``, a ``RecursionError``, a bug: one
point must not end a sweep of thousands), raised while the scene is built, solved or its row made; a
metric that is not a finite number is a SimulationError (a NaN must never pass as a result).
``KeyboardInterrupt`` and ``SystemExit`` do end the sweep.

A point whose worker process dies (a crash in the solver, the out-of-memory killer) cannot report
anything: the backend runs it again (:mod:`.backends`), and :func:`lost_batch` gives the rows of a point
whose worker died each time -- status :data:`WORKER_DIED`.

Everything here is module-level and picklable: worker processes and Dask workers receive the base scene,
the overrides and the :class:`PointSettings`, build their own model and send back plain rows.
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

from ..elements.declaration import ABSORBER, END_STOP, elements_with
from ..engine.accuracy import SolverSettings
from ..results import element_outputs
from ..results.carriage import CARRIAGE_METRICS
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
#: Per absorber (scenes with several elements whose role is an absorber), as ``absorber.N.<metric>``.
ABSORBER_METRICS = ("peak_contact_force", "max_absorber_velocity", "impacts")
#: Per end stop (an element whose role is an end stop), as ``<element name>.<metric>``.
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
#: ``status`` of a point whose worker process died every time it ran it (:func:`lost_batch`).
WORKER_DIED = "WorkerDied"
#: The longest ``error`` message kept (characters; a longer one is cut, ending in "...").
MAX_ERROR_LENGTH = 1000
#: Characters an ``error`` message does not keep (a NUL would make its row unreadable).
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


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
    """Element names of the scene's end stops (the elements whose role is
    :data:`~mbs_models.elements.declaration.END_STOP`)."""
    return elements_with(scene, END_STOP)


def metric_columns(scene: Scene) -> list[str]:
    """The metric columns of a sweep over ``scene`` (its overrides change values, never the elements)."""
    columns = list(SCALAR_METRICS)
    absorbers = elements_with(scene, ABSORBER)
    if len(absorbers) > 1:
        columns += [f"absorber.{i}.{m}" for i in range(len(absorbers)) for m in ABSORBER_METRICS]
    columns += [f"{stop}.{m}" for stop in _stops(scene) for m in STOP_METRICS]
    columns += element_outputs.sweep_columns(scene)  # the metrics elements declare (``<element>.<name>``)
    if getattr(scene, "carriage", None) is not None:  # the planar model: stability and each support's least load
        columns += list(CARRIAGE_METRICS)
        columns += [f"support.{s.name}.min_normal_force" for s in scene.carriage.supports]
    return columns + list(RUN_COLUMNS)


def result_row(result, scene: Scene) -> dict[str, Any]:
    """The metric columns (:func:`metric_columns`) of one result."""
    row: dict[str, Any] = {name: getattr(result, name) for name in SCALAR_METRICS}
    row["impacts"] = None if result.impacts is None else len(result.impacts)
    if len(elements_with(scene, ABSORBER)) > 1:
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
    row.update(element_outputs.sweep_row(result))
    if result.carriage is not None:
        row.update(result.carriage.metrics())
        row.update((f"support.{name}.min_normal_force", output.min_normal_force)
                   for name, output in result.carriage.supports.items())
    row.update(initial_velocity=scene.initial_velocity, end_time=result.end_time,
               stop_reason=str(result.stop_reason), steps=result.steps)  # the StopReason's text: tables hold strings
    return row


def evaluate_point(scene: Scene, overrides: Mapping[str, Any], settings: PointSettings = PointSettings()) -> dict:
    """The row of one point: ``overrides`` (dotted key -> value) applied to ``scene``, simulated.

    Keys of the row: the override keys (their values as given), :func:`metric_columns`, then
    ``wall_time`` (s: the solve's, or the time to fail), ``status`` and ``error``.  Any exception (module
    docstring) gives the row of a failed point: every metric None, ``status`` the exception's class,
    ``error`` its message on one line (:func:`error_text`).
    """
    row: dict[str, Any] = dict(overrides)
    start = time.perf_counter()
    try:
        point_scene = apply_overrides(scene, overrides)
        result = simulate_scene(point_scene, settings)
        metrics = checked_metrics(result_row(result, point_scene))
        wall_time = float(result.wall_time)
    except Exception as exc:  # noqa: BLE001 - every failure of one point is its row (module docstring)
        name = type(exc).__name__
        return failed_row(scene, overrides, name if name.isidentifier() else "Exception", error_text(exc),
                          time.perf_counter() - start)
    row.update(metrics)
    row.update(wall_time=wall_time if math.isfinite(wall_time) and wall_time >= 0 else time.perf_counter() - start,
               status="ok", error=None)
    return row


def failed_row(scene: Scene, overrides: Mapping[str, Any], status: str, error: str, wall_time: float) -> dict:
    """The row of a failed point: the overrides, every metric None, ``wall_time`` (s), ``status``, ``error``."""
    row: dict[str, Any] = dict(overrides)
    row.update({column: None for column in metric_columns(scene)})
    row.update(wall_time=wall_time, status=status, error=error)
    return row


def error_text(exc: BaseException) -> str:
    """The message of ``exc`` as one line for the ``error`` column: its lines joined with "; ", double quotes
    made single (a table's ``error`` cell is always quoted: a row cut short shows), other control characters
    spaces, what UTF-8 cannot hold replaced, at most :data:`MAX_ERROR_LENGTH` characters; the class name if
    it has no message (or cannot give one)."""
    try:
        text = str(exc)
    except Exception:  # noqa: BLE001 - a broken __str__ must not end the sweep either
        text = ""
    text = "; ".join(line.strip() for line in text.splitlines() if line.strip()).replace('"', "'")
    text = _CONTROL.sub(" ", text).encode("utf-8", "replace").decode("utf-8")
    if len(text) > MAX_ERROR_LENGTH:
        text = text[:MAX_ERROR_LENGTH - 3] + "..."
    return text or type(exc).__name__


def checked_metrics(row: dict[str, Any]) -> dict[str, Any]:
    """``row`` (a result's metric columns, :func:`result_row`) with every value a plain number or None: a count
    a whole number >= 0, any other metric a finite float, ``stop_reason`` text; SimulationError naming the
    first metric that is not (a NaN or an infinity is a failed solve, never a result)."""
    from ..errors import SimulationError

    checked: dict[str, Any] = {}
    for name, value in row.items():
        if value is None:
            checked[name] = None
        elif name in TEXT_COLUMNS:
            checked[name] = str(value)
        elif name in COUNT_COLUMNS or name.rsplit(".", 1)[-1] in COUNT_COLUMNS:
            number = float(value)
            if isinstance(value, bool) or not math.isfinite(number) or number != int(number) or number < 0:
                raise SimulationError(f"{name}: the result's count is {value!r}, not a whole number >= 0")
            checked[name] = int(value)
        else:
            number = float(value)
            if not math.isfinite(number):
                raise SimulationError(f"{name}: the result's value is {number!r}, not a finite number")
            checked[name] = number
    return checked


def evaluate_batch(task: tuple[Scene, PointSettings, Sequence[tuple[int, Mapping[str, Any]]]]
                   ) -> list[tuple[int, dict]]:
    """``[(index, evaluate_point(scene, overrides, settings)) for index, overrides in points]``: the unit of
    work a backend sends to a worker (several points per task amortise its overhead)."""
    scene, settings, points = task
    return [(index, evaluate_point(scene, overrides, settings)) for index, overrides in points]


def split_batch(task: tuple) -> list[tuple]:
    """A task of :func:`evaluate_batch` as one task per point: what a backend retries, point by point, when the
    worker running the task died."""
    scene, settings, points = task
    return [(scene, settings, [point]) for point in points]


def lost_batch(task: tuple, reason: str) -> list[tuple[int, dict]]:
    """The result of a task of :func:`evaluate_batch` whose worker died each time it ran (``reason`` says how):
    each point a failed row of status :data:`WORKER_DIED`."""
    scene, _settings, points = task
    return [(index, failed_row(scene, overrides, WORKER_DIED, reason, 0.0)) for index, overrides in points]


__all__ = ["PointSettings", "simulate_scene", "evaluate_point", "evaluate_batch", "metric_columns", "result_row",
           "failed_row", "error_text", "checked_metrics", "split_batch", "lost_batch", "SCALAR_METRICS",
           "STATUS_COLUMNS", "COUNT_COLUMNS", "TEXT_COLUMNS", "WORKER_DIED", "MAX_ERROR_LENGTH"]
