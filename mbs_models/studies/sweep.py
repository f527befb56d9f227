"""Parameter sweeps: many scenes, in parallel worker processes, with progress.

Exudyn models cannot be pickled, so workers receive *scenes* (frozen dataclasses) and send back
the scalar metrics of each run (:class:`SweepPoint`), never models or arrays.

    from mbs_models import model_i
    from mbs_models.studies.sweep import gap_sweep
    points = gap_sweep(model_i, absorber_mass=500.0, gaps=[0.0, 0.01, 0.02])
"""

from __future__ import annotations

import math
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Callable, Iterable, Sequence, TypeVar

from ..engine.accuracy import SolverSettings
from ..errors import SceneError, SimulationError
from ..scene import Scene
from .backends import check_workers, default_workers  # noqa: F401  (default_workers: public here before)

Progress = Callable[[int, int], None]
T = TypeVar("T")
R = TypeVar("R")


@dataclass(frozen=True)
class SweepPoint:
    """Scalar results of one scene of a sweep (SI units); ``error`` is set if its solve failed.

    With ``stop_when_final`` a run may end before the requested end time (``end_time`` is the
    simulated one, ``stop_reason`` says why); a metric not proven final is None, as in
    :class:`~mbs_models.results.result.Result`.  ``impacts`` is the number of impacts.
    """

    scene: Scene
    max_barrel_displacement: float | None
    time_of_max_barrel_displacement: float | None
    peak_contact_force: float | None
    max_absorber_velocity: float | None
    impacts: int | None
    wall_time: float
    error: str | None = None
    end_time: float | None = None
    stop_reason: str | None = None
    peak_support_force: float | None = None

    @property
    def gap(self) -> float | None:
        """The contact gap in m of the scene's one absorber (None without an absorber or with several)."""
        absorbers = self.scene.absorbers
        return absorbers[0].contact.gap if len(absorbers) == 1 else None


def _run_one(job: tuple[Scene, float, str | SolverSettings, tuple[str, ...]]) -> SweepPoint:
    from .point import PointSettings, simulate_scene

    scene, end_time, accuracy, stop_when_final = job
    try:
        result = simulate_scene(scene, PointSettings(end_time, accuracy, stop_when_final))
    except SimulationError as exc:
        return SweepPoint(scene, None, None, None, None, None, 0.0, error=str(exc))
    return SweepPoint(scene, result.max_barrel_displacement, result.time_of_max_barrel_displacement,
                      result.peak_contact_force, result.max_absorber_velocity,
                      None if result.impacts is None else len(result.impacts), result.wall_time,
                      end_time=result.end_time, stop_reason=result.stop_reason,
                      peak_support_force=result.peak_support_force)


def run_scenes(scenes: Sequence[Scene], end_time: float = 10.0, accuracy: str | SolverSettings = "standard", *,
              workers: int | None = None, progress: Progress | None = None,
              stop_when_final: Sequence[str] = ()) -> list[SweepPoint]:
    """Simulate every scene (in order) and return one :class:`SweepPoint` each.

    ``workers=1`` runs in this process; otherwise a process pool of ``workers`` (default: all CPUs)
    is used.  A failed solve does not stop the sweep: its point carries ``error`` instead of values.
    ``stop_when_final`` is passed to :func:`~mbs_models.simulate`: each run stops once the named
    metrics are proven final (the others are then None in its point).
    """
    scenes = list(scenes)
    if not all(isinstance(s, Scene) for s in scenes):
        raise SceneError("scenes", "every item of a sweep must be a Scene")
    from ..engine.final_metrics import check_metric_names
    stop_when_final = check_metric_names(stop_when_final)
    jobs = [(scene, end_time, accuracy, stop_when_final) for scene in scenes]
    if not jobs:
        return []
    # validate the shared arguments once, in this process, so that bad input fails fast
    from ..engine.simulation import _check_arguments
    from ..engine.accuracy import solver_settings_for
    _check_arguments(scenes[0], end_time, 0.0)
    solver_settings_for(accuracy)

    return parallel_map(_run_one, jobs, workers=workers, progress=progress)


def parallel_map(function: Callable[[T], R], items: Sequence[T], *, workers: int | None = None,
                 progress: Progress | None = None) -> list[R]:
    """``[function(item) for item in items]`` in worker processes, in order, with progress calls.

    ``function`` must be a module-level function and items picklable (scenes are; Exudyn models
    are not).  ``workers=1`` (or a single item) runs in this process.
    """
    items = list(items)
    workers = check_workers(workers)
    out: list[R] = []
    if workers == 1 or len(items) <= 1:
        for i, item in enumerate(items):
            out.append(function(item))
            if progress:
                progress(i + 1, len(items))
        return out
    chunk = max(1, math.ceil(len(items) / (workers * 8)))
    context = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn")
    with ProcessPoolExecutor(max_workers=min(workers, len(items)), mp_context=context) as pool:
        for i, value in enumerate(pool.map(function, items, chunksize=chunk)):
            out.append(value)
            if progress and ((i + 1) % max(1, len(items) // 20) == 0 or i + 1 == len(items)):
                progress(i + 1, len(items))
    return out


def gap_sweep(factory: Callable[..., Scene], absorber_mass: float, gaps: Iterable[float], end_time: float = 10.0,
              accuracy: str | SolverSettings = "standard", *, workers: int | None = None,
              progress: Progress | None = None, stop_when_final: Sequence[str] = ()) -> list[SweepPoint]:
    """Max barrel displacement etc. over gaps (m) for one model factory and absorber mass (Figs 4-5).

    ``stop_when_final=("max_barrel_displacement",)`` gives Figs 4-5 at a fraction of the cost: the
    same values, the other metrics None (see :func:`run_scenes`).
    """
    scenes = [factory(absorber_mass, float(gap)) for gap in gaps]
    return run_scenes(scenes, end_time, accuracy, workers=workers, progress=progress,
                     stop_when_final=stop_when_final)
