"""Parameter sweeps: a grid over dotted scene keys as one table, or a list of scenes; in parallel.

* :func:`run_sweep` (:mod:`.grid_sweep`; public as ``mbs_models.run_sweep``, ``recoil sweep`` on the
  command line): the full grid of values of dotted scene keys over one scene, one tidy row per point (a
  pandas DataFrame), written to CSV/Parquet as rows finish and resumable, streamed (memory independent of
  the grid's size); on a local process pool or a Dask cluster.  Its parts: :mod:`.grid` (the points),
  :mod:`.point` (one point as a row; the one call of ``simulate``), :mod:`.backends` (where points run),
  :mod:`.point_set` (the points a file holds), :mod:`.sweep_table` (the table's types and file),
  :mod:`.table_rows` (its rows written and read back, each checked), :mod:`.sweep_lock` (one sweep per
  file), :mod:`.table_sort` (the file put in grid order).
* :func:`run_scenes`, :func:`gap_sweep`, :func:`parallel_map`: many scenes (or any function) in worker
  processes, giving :class:`SweepPoint` objects (the validation studies use these).

Exudyn models cannot be pickled, so workers receive *scenes* (frozen dataclasses) and send back
scalars, never models or arrays.

    from mbs_models import model_i, run_sweep
    table = run_sweep(model_i(), {"absorber.mass": [100, 500, 1000], "contact.gap": "0:0.12:13"},
                      out="gaps.csv")
"""

from __future__ import annotations

import math
from concurrent.futures import Executor, Future
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Callable, Iterable, Iterator, Sequence, TypeVar

from ..engine.accuracy import SolverSettings
from ..errors import SceneError, SimulationError
from ..scene import Scene
from .backends import check_workers, default_workers, exit_with_parent, local_pool  # noqa: F401  (default_workers, exit_with_parent: public)

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
    from .point import PointSettings, error_text, simulate_scene

    scene, end_time, accuracy, stop_when_final = job
    try:
        result = simulate_scene(scene, PointSettings(end_time, accuracy, stop_when_final))
    except SimulationError as exc:
        return SweepPoint(scene, None, None, None, None, None, 0.0, error=str(exc))
    except Exception as exc:  # noqa: BLE001 - one scene must not end the sweep (as a grid point: studies.point)
        return SweepPoint(scene, None, None, None, None, None, 0.0, error=f"{type(exc).__name__}: {error_text(exc)}")
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
    is used.  A failed solve (or any other exception of one scene) does not stop the sweep: its point carries
    ``error`` instead of values.
    ``stop_when_final`` is passed to :func:`~mbs_models.simulate`: each run stops once the named
    metrics are proven final (the others are then None in its point).
    """
    return parallel_map(_run_one, sweep_jobs(scenes, end_time, accuracy, stop_when_final), workers=workers,
                        progress=progress)


def sweep_jobs(scenes: Sequence[Scene], end_time: float = 10.0, accuracy: str | SolverSettings = "standard",
               stop_when_final: Sequence[str] = ()) -> list[tuple]:
    """The jobs of :func:`run_scenes` (arguments checked here, so that bad input fails fast); run them with
    :func:`run_sweep_jobs` -- e.g. in chunks submitted to a pool of :func:`process_pool` beside other work."""
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
    return jobs


def run_sweep_jobs(jobs: Sequence[tuple]) -> list[SweepPoint]:
    """One :class:`SweepPoint` per job of :func:`sweep_jobs`, in order, in this process."""
    return [_run_one(job) for job in jobs]


class InlineExecutor(Executor):
    """An executor that runs each job in this process when it is submitted (``workers=1``)."""

    def submit(self, fn, /, *args, **kwargs) -> Future:
        future: Future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # noqa: BLE001 - handed to the caller through the future
            future.set_exception(exc)
        return future


@contextmanager
def process_pool(workers: int | None = None) -> Iterator[Executor]:
    """An executor of ``workers`` processes (default: all CPUs; forked where possible, so that workers start
    in milliseconds with this process's imports), or :class:`InlineExecutor` for ``workers=1``.

    One pool for many kinds of jobs lets independent studies share the CPUs instead of running one phase
    after the other; jobs start in the order they are submitted.
    """
    workers = check_workers(workers)
    if workers == 1:
        yield InlineExecutor()
        return
    with local_pool(workers) as pool:
        try:
            yield pool
        except BaseException:
            pool.shutdown(wait=True, cancel_futures=True)
            raise


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
    # small chunks: the last one is run by one worker while the others idle (32 per worker: < 1/32 of the work)
    chunk = max(1, math.ceil(len(items) / (workers * 32)))
    with local_pool(min(workers, len(items))) as pool:
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


# ================================================================================================ grid sweeps
from .grid_sweep import run_sweep  # noqa: E402  (public here: mbs_models.studies.sweep.run_sweep)
