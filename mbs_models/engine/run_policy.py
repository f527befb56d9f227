"""The run policy: what a run may be asked, how long it may run, and why it ended.

* Arguments and bounds (:func:`_check_arguments`, :func:`_check_bounds`): a scene with more than
  :data:`MAX_ABSORBERS` absorbers, an end time beyond :data:`MAX_END_TIME`, a run split into more than
  :data:`MAX_SEGMENTS` segments or an adaptive one whose time scales need more steps than its budget
  (:mod:`mbs_models.engine.guard`) is refused before solving (SceneError naming the key).
* :class:`RunPolicy`: the settings, the end time, the metrics to prove final (``stop_when_final``; an early stop
  only where energy bounds exist, :func:`~mbs_models.engine.energy_bounds.dissipative`) and the rest watch's
  tolerance (``stop_at_rest``, adaptive solvers only).
* :func:`conclude`: once the driver solved, why the run ended (:class:`~mbs_models.stop_reason.StopReason`),
  which metrics are final, the histories (the rest state held to the end time) -- a
  :class:`~mbs_models.engine.result_builder.RunRecord`; :func:`early_stop_trusted`: an early stop stands only if
  the solution's energy never rose by more than the bounds' slack (else the run is re-solved to the end time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Sequence

from ..errors import SceneError
from ..results.result import Result
from ..scene import Scene
from ..stop_reason import StopReason
from . import stability
from .accuracy import SolverSettings, solver_settings_for
from .energy_bounds import ENERGY_SLACK, dissipative, largest_energy_rise
from .finality import FINAL_METRICS, FinalityTracker, check_metric_names
from .guard import StepBudget
from .mechanism import Mechanism
from .rest import CHECK_INTERVAL, RestWatch
from .result_builder import RunRecord
from .time_scales import check_time_scales

if TYPE_CHECKING:
    from .driver import Solve

#: Longest simulated time accepted, in s.
MAX_END_TIME = 1.0e4
#: Most absorbers a scene may have: Exudyn's cost per step grows with the square of the bodies (measured ~0.5 ms
#: a step at 100 absorbers, 37 ms at 1 000), and so do the energy bounds set up before the solve.
MAX_ABSORBERS = 100
#: Segments a run may be split into at most (:func:`~mbs_models.engine.driver.segment_plan`: one per point of a pulse's table per shot):
#: each restarts the solver (~0.2 ms), so this many cost some 20-30 s.
MAX_SEGMENTS = 100_000


def _check_bounds(mechanism: Mechanism, settings: SolverSettings, end_time: float,
                  tracker: FinalityTracker | None, rest: RestWatch | None) -> None:
    """Refuse before solving (SceneError naming the scene key) a run split into more than :data:`MAX_SEGMENTS`
    segments, or an adaptive one whose always-acting time scales need more steps than its budget
    (:mod:`mbs_models.engine.time_scales`) over the time it surely integrates: the whole window, its first
    :data:`~mbs_models.engine.rest.CHECK_INTERVAL` where it may stop at rest, nothing where it may stop once
    its metrics are final (the budget still bounds it)."""
    segments = 1 + sum(1 for t in mechanism.breakpoints if t < end_time)
    if segments > MAX_SEGMENTS:
        pulse = mechanism.scene.firing.pulse if mechanism.scene.firing is not None else None
        key = "burst.shots" if pulse is None else f"firing.pulse.{'file' if pulse.file is not None else 'times'}"
        raise SceneError(key, f"the run would be split into {segments} segments (the solve restarts at every shot "
                              f"and every point of a pulse's table, for every shot), more than {MAX_SEGMENTS}: "
                              "use a pulse table with fewer points or fewer shots, or a shorter end time")
    if settings.adaptive and tracker is None:
        horizon = end_time if rest is None else min(end_time, CHECK_INTERVAL)
        check_time_scales(mechanism, StepBudget.for_run(end_time, mechanism.sensor_count), horizon)


def _check_arguments(scene: Scene, end_time: float, impact_threshold: float) -> None:
    """SceneError naming the argument: not a Scene, too many absorbers, an end time or impact threshold out of range."""
    if not isinstance(scene, Scene):
        raise SceneError("scene", f"must be a Scene, got {type(scene).__name__}")
    if len(scene.absorbers) > MAX_ABSORBERS:
        raise SceneError("absorber", f"the scene has {len(scene.absorbers)} absorbers, more than the {MAX_ABSORBERS} "
                                     "a run accepts (the cost of a step grows with the square of their number)")
    if isinstance(end_time, bool) or not isinstance(end_time, (int, float)) or not math.isfinite(end_time) \
            or not 0.0 < end_time <= MAX_END_TIME:
        raise SceneError("end_time", f"must be a number of seconds in (0, {MAX_END_TIME:g}], got {end_time!r}")
    if isinstance(impact_threshold, bool) or not isinstance(impact_threshold, (int, float)) \
            or not math.isfinite(impact_threshold) or impact_threshold < 0:
        raise SceneError("impact_threshold", f"must be a force >= 0 N, got {impact_threshold!r}")


@dataclass(frozen=True)
class RunPolicy:
    """How one run is to go: ``settings`` (the solver), ``end_time`` (s, requested), ``impact_threshold`` (N);
    ``requested`` the metrics to prove final, ``early_stop`` whether the run may stop once they are (asked for
    and the scene has energy bounds), ``rest_tolerance`` (m and m/s) the rest watch's (None: no stop at rest).
    ``mechanism``: the scene's :class:`~mbs_models.engine.mechanism.Mechanism` built to decide ``early_stop``, not
    used by any solve yet (None where none was built): the driver's first solve takes it rather than building
    the same again.
    """

    settings: SolverSettings
    end_time: float
    impact_threshold: float
    requested: tuple[str, ...]
    early_stop: bool
    rest_tolerance: float | None
    mechanism: Mechanism | None = field(default=None, compare=False, repr=False)

    @classmethod
    def of(cls, scene: Scene, end_time: float, accuracy: str | SolverSettings, user_functions: str | None,
           impact_threshold: float, stop_when_final: Sequence[str], stop_at_rest: bool) -> "RunPolicy":
        """The policy of :func:`~mbs_models.simulate`'s arguments; SceneError naming a bad one, or a fixed step
        unsafe for the scene (:func:`~mbs_models.engine.stability.check_settings`)."""
        _check_arguments(scene, end_time, impact_threshold)
        if not isinstance(stop_at_rest, bool):
            raise SceneError("stop_at_rest", f"must be True or False, got {stop_at_rest!r}")
        requested = check_metric_names(stop_when_final)
        settings = solver_settings_for(accuracy, user_functions)
        rest_tolerance = settings.absolute_tolerance if stop_at_rest and settings.adaptive else None  # (as asked for)
        stability.check_settings(scene, settings, float(end_time))  # unsafe steps: SceneError before solving
        mechanism = Mechanism(scene) if requested else None  # (whether the scene has energy bounds)
        return cls(settings=settings, end_time=float(end_time), impact_threshold=float(impact_threshold),
                   requested=requested, early_stop=bool(requested) and dissipative(mechanism),
                   rest_tolerance=rest_tolerance, mechanism=mechanism)


def stop_reason(policy: RunPolicy, solve: "Solve", re_solved: bool) -> StopReason:
    """Why the run ``solve`` ended (``re_solved``: it is the re-solve of an early stop the energy check refused)."""
    if re_solved:
        return StopReason.ENERGY_CHECK
    if solve.tracker is not None and solve.tracker.done:
        return StopReason.METRICS_FINAL
    if solve.rest is not None and solve.rest.time is not None:
        return StopReason.AT_REST
    if policy.requested and not policy.early_stop:
        return StopReason.NO_ENERGY_BOUND
    return StopReason.END_TIME


def conclude(policy: RunPolicy, solve: "Solve", scene: Scene, started: float, wall_started: float,
             re_solved: bool = False) -> RunRecord:
    """The record of a run the driver solved: why it ended, its window, which metrics are final.

    At rest, the rest state is held to the end time (within the tolerance of the solution,
    :meth:`~mbs_models.engine.rest.RestWatch.hold`); stopped once final, the tracker checks every other metric at
    the last state too (all of them proven final there are reported) and the window ends at the simulated end.
    ``started``, ``wall_started``: ``time.perf_counter()`` (s) at the start of this solve and of the call
    (an energy check's re-solve is part of the call that asked for the early stop).
    """
    reason = stop_reason(policy, solve, re_solved)
    samples, mechanism, rest = solve.samples, solve.mechanism, solve.rest
    at_rest = rest is not None and rest.time is not None
    if at_rest:
        samples = rest.hold(samples)
    final = FINAL_METRICS
    stopped = reason is StopReason.METRICS_FINAL
    if stopped:  # which other metrics are final too: all of them are checked at the last state
        tracker = solve.tracker
        tracker.observe_last(float(samples.time[-1]), [float(samples.positions[b.name][-1]) for b in mechanism.bodies],
                             [float(samples.velocities[b.name][-1]) for b in mechanism.bodies])
        final = tuple(n for n in FINAL_METRICS if n in tracker.final)
    return RunRecord(scene=scene, settings=solve.settings, mechanism=mechanism, samples=samples,
                     impact_threshold=policy.impact_threshold, requested_end_time=policy.end_time,
                     end_time=solve.simulated_end if stopped else policy.end_time, stop_reason=reason,
                     final_metrics=final, rest_time=rest.time if at_rest else None,
                     rest_tolerance=rest.tolerance if at_rest else None, steps=solve.steps,
                     started=started, assembled=solve.assembled, solved=solve.solved, wall_started=wall_started)


def early_stop_trusted(result: Result, solve: "Solve") -> bool:
    """True unless ``result`` stopped once its metrics were final while its mechanical energy (less the work of
    the inputs, above the bounds' energy floor) rose by more than :data:`~mbs_models.engine.energy_bounds.ENERGY_SLACK`
    somewhere: the bounds assume it never rises, so such an early stop is not trusted."""
    if result.stop_reason is not StopReason.METRICS_FINAL:
        return True
    mechanical = result.kinetic_energy_history + result.stored_energy_history
    if result.work_histories:
        mechanical = mechanical - result.work_history  # what never increases once the inputs are counted
    floor = solve.tracker.bounds.energy_floor  # the energy's lower bound (a preload's well)
    return not largest_energy_rise(mechanical - floor) > ENERGY_SLACK
