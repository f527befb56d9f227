"""``simulate(scene, end_time, accuracy)``: the one entry point to run a scene with Exudyn.

Contract
--------
* The scene is assembled with only the items its elements call for (:mod:`mbs_models.engine.assembly`).
* ``accuracy`` is a preset name (``"draft"``, ``"standard"`` default, ``"reference"``) or explicit
  :class:`~mbs_models.engine.accuracy.SolverSettings`.
* The return value is a complete :class:`~mbs_models.results.result.Result`, or a
  :class:`~mbs_models.errors.SimulationError` is raised: a solver that fails, stops before
  ``end_time``, or produces NaN/inf never yields a result.  The one exception is asked for:
  ``stop_when_final`` stops the solve once energy bounds prove the named metrics final
  (:mod:`mbs_models.engine.final_metrics`); the result says so (``stop_reason``, ``requested_end_time``)
  and holds None for every metric not proven final.  A run longer than 100 s that energy bounds prove at
  rest stops there too (:mod:`mbs_models.engine.rest`); its result still covers ``[0, end_time]``, holding
  the rest state from ``rest_time`` on (``stop_reason == "at_rest"``).  Bad arguments raise
  :class:`~mbs_models.errors.SceneError` naming the argument.
* Numerical safety (:mod:`mbs_models.engine.stability`): a fixed step that is unstable for the scene or
  would step over an impact is refused before solving (SceneError, key ``step``, with the safe
  limit); an adaptive solver that stepped over a whole (grazing) contact is re-run with a smaller
  ``max_step`` (the result's ``settings`` say which); a solve whose energy balance is off by more
  than 10 % of the initial energy raises SimulationError.
* Bounds (:mod:`mbs_models.engine.guard`, :mod:`mbs_models.engine.time_scales`): every adaptive solve has a
  step budget and a cap on its stored samples (SimulationError once spent); a scene whose linear springs and
  dampers alone need more steps than the budget, with more than :data:`MAX_ABSORBERS` absorbers, or split into
  more than :data:`MAX_SEGMENTS` segments is refused before solving (SceneError naming the key); Ctrl-C during a
  solve raises KeyboardInterrupt.
* The Exudyn model is released after every run (no growth over thousands of runs); a
  :class:`~mbs_models.engine.reuse.Simulator` keeps it for the next scene of the same structure instead
  (:func:`simulate_with`), with bit-identical results.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import replace
from typing import Sequence

import exudyn
import numpy as np

from ..errors import SceneError, SimulationError
from ..results.postprocess import Samples, analyse
from ..results.result import Result
from ..scene import Scene
from . import stability
from .accuracy import MIN_RELATIVE_TOLERANCE, SolverSettings, solver_settings_for
from .assembly import Assembly, assemble
from .final_metrics import (ENERGY_SLACK, FINAL_METRICS, STOP_AT_REST, STOP_END_TIME, STOP_ENERGY_CHECK,
                            STOP_METRICS_FINAL, STOP_NO_BOUND, FinalityTracker, check_metric_names, dissipative,
                            largest_energy_rise)
from .guard import StepBudget, sample_cap
from .mechanism import Mechanism
from .unit_slips import warn_unit_slips
from .rest import CHECK_INTERVAL, RestWatch
from .time_scales import check_time_scales, time_scale_hint

#: Longest simulated time accepted, in s.
MAX_END_TIME = 1.0e4
#: Most absorbers a scene may have: Exudyn's cost per step grows with the square of the bodies (measured ~0.5 ms
#: a step at 100 absorbers, 37 ms at 1 000), and so do the energy bounds set up before the solve.
MAX_ABSORBERS = 100
#: Re-solves (with max_step / 4 each) when an adaptive solver stepped over a whole contact.
MAX_CONTACT_RETRIES = 3
#: The finality tracker (stop_when_final) is shown the state at every this-many-th step: an observed step's
#: pre-step call (reading the state, the bounds) costs ~10 us inside a solve, a step ~5 us (README, cost
#: section; scripts/bench_prestep.py).  Changing it changes when early stops happen (not bit-identical).
OBSERVE_EVERY = 4
#: Most output samples kept for fixed-step solvers (output is thinned beyond this, and beyond
#: :func:`~mbs_models.engine.guard.sample_cap` for a scene with many sensors).
MAX_FIXED_STEP_SAMPLES = 1_000_000
#: Explicit solvers whose last stage is the end-of-step state ("first same as last": the last row of the
#: Butcher tableau is the weights and its node is 1; Exudyn 1.13's DOPRI5 and ODE23, CSolverExplicit.cpp).
#: Their last stage's acceleration is the end-of-step acceleration, bit for bit, so Exudyn need not
#: evaluate the forces once more after each step (``computeEndOfStepAccelerations``; a seventh of
#: DOPRI5's force evaluations, about a fifth of the solve).  A test compares both ways on every shipped
#: scene, exactly.
FIRST_SAME_AS_LAST_SOLVERS = ("DOPRI5", "ODE23")


def _check_arguments(scene: Scene, end_time: float, impact_threshold: float) -> None:
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


def exudyn_simulation_settings(settings: SolverSettings, end_time: float, start_time: float = 0.0):
    """Translate :class:`SolverSettings` into Exudyn ``SimulationSettings`` for a run from ``start_time``
    (s, default 0) to ``end_time`` (s)."""
    ss = exudyn.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = float(end_time)
    if start_time:
        ti.startTime = float(start_time)
    span = float(end_time) - float(start_time)
    ti.verboseMode = 0
    ss.show.statistics = False
    ss.show.computationTime = False
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = 0.0  # every step: extrema are refined between step ends
    if settings.solver in FIRST_SAME_AS_LAST_SOLVERS:  # the last stage already holds a(t + h)
        ti.explicit.computeEndOfStepAccelerations = False
    if settings.adaptive:
        ti.automaticStepSize = True
        ti.numberOfSteps = max(1, math.ceil(span / settings.max_step))
        ti.relativeTolerance = settings.relative_tolerance
        ti.absoluteTolerance = settings.absolute_tolerance
        ti.minimumStepSize = min(1e-12, settings.max_step)
    else:
        ti.automaticStepSize = False
        steps = max(1, math.ceil(span / settings.step - 1e-9))
        ti.numberOfSteps = steps
        if steps > MAX_FIXED_STEP_SAMPLES:
            ss.solution.sensors.writePeriod = span / MAX_FIXED_STEP_SAMPLES
        if settings.implicit:
            ti.newton.relativeTolerance = 1e-10
            ti.newton.absoluteTolerance = 1e-12
    return ss


class _BudgetSpent(Exception):
    """Stops Exudyn from the pre-step function once the step budget is spent."""


class _StepSizeStalled(SimulationError):
    """The step guard stopped an adaptive solve (see :func:`_absolute_tolerance_settings`)."""


def _absolute_tolerance_settings(settings: SolverSettings) -> SolverSettings | None:
    """Equivalent adaptive settings that dodge Exudyn's error-scale bug; None if already used.

    Exudyn 1.13's explicit solvers scale each coordinate's error by ``atol + max(y0, y1) * rtol``
    (CSolverExplicit.cpp) -- a signed maximum, not ``max(|y0|, |y1|)``.  The scale is 0 where a
    coordinate passes ``-atol/rtol``: the presets all have atol/rtol = 0.01, so a velocity of
    -0.01 m/s.  Usually the solver hurries past; in a stiff persistent contact the step collapses to
    its minimum and Exudyn re-tries it for ever (measured: three scenes found by the property tests
    stall exactly at v = -0.01, -0.1 or -0.001 m/s for atol/rtol = 0.01, 0.1, 0.001).  The re-solve
    uses (almost) pure absolute control, ``atol' = atol + rtol`` (the old tolerance at |y| = 1 m,
    1 m/s) with the smallest ``rtol`` accepted, which moves the singular value to ``-atol'/rtol'``,
    beyond -100 m/s.
    """
    if settings.relative_tolerance <= MIN_RELATIVE_TOLERANCE:
        return None
    return replace(settings, relative_tolerance=MIN_RELATIVE_TOLERANCE,
                   absolute_tolerance=settings.absolute_tolerance + settings.relative_tolerance)


def _pre_step_function(assembly: Assembly, budget: StepBudget | None, tracker: FinalityTracker | None):
    """Exudyn pre-step function: the step budget (raises when spent), the contacts' onset capture and
    the finality tracker.

    The budget *raises* when spent: returning False is ignored while Exudyn's DOPRI5 is stuck
    re-trying one step at its minimum step size (measured: model (ii) with m = 1 kg, k_c = 1e12 at
    rtol <= 1e-10 never passes t = 0.4924 s).  Contacts whose law needs the onset rate ``v-`` see the
    state at the start of every step (Exudyn's current coordinates; ``t`` is the end of the step
    about to be taken, so the start is ``t - currentStepSize``).  The tracker is shown the state at the
    start of every :data:`OBSERVE_EVERY`-th step; the function returns False once every requested metric
    is final: Exudyn then completes that step and stops, so the output ends one step after the state
    that proved finality.

    The function is Python called by Exudyn at every step, so it does at each step only what that step
    needs, everything else is looked up once here: one step counter serves the budget (which it calls only
    at :attr:`~mbs_models.engine.guard.StepBudget.next_check`) and the tracker's cadence; the state is read
    only for the captures or an observed step, and passed on as it is where Exudyn's coordinates are the
    bodies in body order (else reordered).  With the budget alone (most adaptive solves) the function only
    counts: one Python call, an increment and a comparison per step (~0.2 us; README, "Limits").
    """
    data = assembly.mbs.systemData
    read_positions, read_velocities = data.GetODE2Coordinates, data.GetODE2Coordinates_t
    mechanism = assembly.mechanism
    order = [assembly.coordinates[body.name] for body in mechanism.bodies]
    in_body_order = order == list(range(len(order))) and data.ODE2Size() == len(order)
    captures = []
    for contact in mechanism.capturing_contacts:
        ia = None if contact.a == "ground" else assembly.coordinates[contact.a]
        ib = None if contact.b == "ground" else assembly.coordinates[contact.b]
        captures.append((contact.capture, ia, ib))
    observe = tracker.observe if tracker is not None else None
    steps = 0  # calls so far (all segments of a run): the budget's step count and the tracker's cadence
    next_check = budget.next_check if budget is not None else math.inf
    solver = []  # Exudyn's time-integration state, cached on the first call of each solve

    def count(mbs, t):  # the budget alone (every adaptive solve): the least a step can pay
        nonlocal steps, next_check
        steps += 1
        if steps >= next_check:
            if not budget.advance(steps, t):
                raise _BudgetSpent(f"step budget spent at t = {t:.6g} s")
            next_check = budget.next_check
        return True

    def pre_step(mbs, t):
        nonlocal steps, next_check
        steps += 1
        if steps >= next_check:  # between checkpoints the budget would only count
            if not budget.advance(steps, t):
                raise _BudgetSpent(f"step budget spent at t = {t:.6g} s")
            next_check = budget.next_check
        q = v = None
        if captures:
            q = read_positions(copy=False).tolist()
            v = read_velocities(copy=False).tolist()
            if not solver:
                solver.append(mbs.sys["dynamicSolver"].it)
            t_start = t - solver[0].currentStepSize
            for capture, ia, ib in captures:
                d = (q[ib] if ib is not None else 0.0) - (q[ia] if ia is not None else 0.0)
                rate = (v[ib] if ib is not None else 0.0) - (v[ia] if ia is not None else 0.0)
                capture.observe(t_start, d, rate)
        if observe is None or steps % OBSERVE_EVERY:
            return True
        if q is None:
            q = read_positions(copy=False).tolist()
            v = read_velocities(copy=False).tolist()
        if in_body_order:
            return not observe(t, q, v)
        return not observe(t, [q[i] for i in order], [v[i] for i in order])

    function = count if budget is not None and not captures and observe is None else pre_step
    function.new_solve = solver.clear  # a segmented run calls it before each segment's solve
    return function


def _solve(assembly: Assembly, settings: SolverSettings, end_time: float,
           tracker: FinalityTracker | None = None, start_time: float = 0.0,
           run: dict | None = None) -> tuple[int, float]:
    """Run Exudyn from ``start_time`` to ``end_time`` (s); return the number of steps and the simulated end time.

    The solve ends at ``end_time``, or earlier only when ``tracker`` proved every requested metric
    final.  Raise SimulationError on any failure (including any other early stop).  ``run`` carries
    what the segments of one run share (the step budget and the pre-step function); None: a run of one
    segment.
    """
    mbs = assembly.mbs
    ss = exudyn_simulation_settings(settings, end_time, start_time)
    kept = sample_cap(len(assembly.sensors))
    if not settings.adaptive and ss.timeIntegration.numberOfSteps > kept:  # many sensors: fewer samples each
        ss.solution.sensors.writePeriod = max(ss.solution.sensors.writePeriod, (end_time - start_time) / kept)
    first_step = min((c.first_step_limit for c in assembly.mechanism.connectors), default=math.inf)
    if settings.adaptive and first_step < settings.max_step:  # else Exudyn starts with max_step
        ss.timeIntegration.initialStepSize = first_step
    solver_type = getattr(exudyn.DynamicSolverType, settings.solver)
    run = {} if run is None else run
    if "budget" not in run:
        run["budget"] = None
        if settings.adaptive:  # every adaptive solve: bounded steps and stored samples (engine/guard.py)
            run["budget"] = StepBudget.for_run(run.get("end_time", end_time), len(assembly.sensors))
        if run["budget"] is not None or tracker is not None or assembly.mechanism.capturing_contacts:
            run["pre_step"] = _pre_step_function(assembly, run["budget"], tracker)
            mbs.SetPreStepUserFunction(run["pre_step"])
    elif "pre_step" in run:
        run["pre_step"].new_solve()
    budget = run["budget"]
    print_to_console = exudyn.config.printToConsole
    exudyn.config.printToConsole = False  # Exudyn's own failure banner; we raise with the reason instead
    special = exudyn.special.solver
    throw_with_ctrl_c = special.throwErrorWithCtrlC
    special.throwErrorWithCtrlC = True  # Ctrl-C stops the solve at once, not after a step that may never end
    try:
        success = mbs.SolveDynamic(ss, solverType=solver_type)
    except Exception as exc:  # Exudyn wraps user-function exceptions in its own error types
        if _interrupted(exc):
            raise KeyboardInterrupt from None
        if budget is not None and budget.exhausted_at is not None:
            raise _StepSizeStalled(_budget_explanation(budget, settings, assembly, run, end_time)) from None
        message = " ".join(str(exc).split())
        raise SimulationError(f"Exudyn {settings.solver} failed: {message[:500]}") from exc
    finally:
        exudyn.config.printToConsole = print_to_console
        special.throwErrorWithCtrlC = throw_with_ctrl_c
    iteration = mbs.sys["dynamicSolver"].it
    if budget is not None and budget.exhausted_at is not None:
        raise _StepSizeStalled(_budget_explanation(budget, settings, assembly, run, end_time))
    if not success:
        raise SimulationError(f"Exudyn {settings.solver} reported failure at t = {iteration.currentTime:.6g} s")
    stopped_final = tracker is not None and tracker.done
    if iteration.currentTime < end_time * (1.0 - 1e-9) and not stopped_final:
        raise SimulationError(f"Exudyn {settings.solver} stopped early at t = {iteration.currentTime:.6g} s "
                              f"of {end_time:g} s")
    return int(iteration.currentStepIndex), float(iteration.currentTime)


def _interrupted(error: BaseException) -> bool:
    """True if ``error`` (what Exudyn raised) stems from a KeyboardInterrupt: Ctrl-C during the solve, which Exudyn
    reports as its own error (a failed user function, a SystemError) with the interrupt as the cause."""
    seen, pending = set(), [error]
    while pending:
        error = pending.pop()
        if error is None or id(error) in seen:
            continue
        if isinstance(error, KeyboardInterrupt):
            return True
        seen.add(id(error))
        pending += [error.__cause__, error.__context__]
    return False


def _budget_explanation(budget: StepBudget, settings: SolverSettings, assembly: Assembly, run: dict,
                        end_time: float) -> str:
    """The SimulationError message of a solve the budget stopped, with what in the scene is that fast (the usual
    hint, the chattering contact, where the estimates overflow on extreme values)."""
    try:
        hint = time_scale_hint(assembly.mechanism)
    except (ArithmeticError, ValueError):
        hint = None
    return budget.explanation(settings.solver, run.get("end_time", end_time), hint)


def _initial_accelerations(assembly: Assembly, t: float = 0.0) -> dict[str, float]:
    """Accelerations (m/s^2) of each body at the initial state, from Exudyn's own force evaluation.

    Exudyn's explicit solvers record the acceleration sensors at t = 0 as 0 (nothing is evaluated
    before the first step); the Hermite interpolation of the velocity on the first step -- and so the
    dissipated energy and refined extrema there -- needs the true value.  Call before solving.
    """
    mbs, data = assembly.mbs, assembly.mbs.systemData
    lhs = np.zeros(data.ODE2Size())
    mass = np.zeros((data.ODE2Size(), data.ODE2Size()))
    try:
        for i in range(data.NumberOfObjects()):
            index = exudyn.ObjectIndex(i)
            ltg = list(data.GetObjectLTGODE2(i))
            if not ltg:
                continue
            applies = mbs.ComputeItem(index)
            if exudyn.ComputeItemType.MassMatrix in applies:
                mass[np.ix_(ltg, ltg)] += np.asarray(mbs.ComputeItem(index, exudyn.ComputeItemType.MassMatrix))
            if exudyn.ComputeItemType.ODE2LHS in applies:
                lhs[ltg] += np.asarray(mbs.ComputeItem(index, exudyn.ComputeItemType.ODE2LHS), dtype=float)
    except Exception as exc:  # a user function that raises at the initial state
        if _interrupted(exc):
            raise KeyboardInterrupt from None
        message = " ".join(str(exc).split())
        raise SimulationError(f"evaluating the forces at t = 0 failed: {message[:500]}") from exc
    rhs = -lhs
    for load in assembly.mechanism.loads:  # external loads at t (the objects' LHS does not hold them)
        rhs[data.GetNodeLTGODE2(assembly.nodes[load.body])[0]] += float(load.force(np.array([t]))[0])
    accelerations = np.linalg.solve(mass, rhs)
    return {body: float(accelerations[data.GetNodeLTGODE2(node)[0]]) for body, node in assembly.nodes.items()}


def _stored(assembly: Assembly, name: str) -> np.ndarray:
    return np.asarray(assembly.mbs.GetSensorStoredData(assembly.sensors[name]), dtype=float)


def _read_segment(assembly: Assembly, settings: SolverSettings, start_time: float = 0.0,
                  initial_accelerations: dict[str, float] | None = None) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The sensors of the last solve: (time s, values by sensor name), duplicate time stamps dropped;
    SimulationError for NaN/inf."""
    columns = {name: _stored(assembly, name) for name in assembly.sensors}
    for body, value in (initial_accelerations or {}).items():
        data = columns[f"{body}_acceleration"]
        if len(data) and data[0, 0] == start_time:
            data[0, 1] = value  # Exudyn records 0 at the start (see _initial_accelerations)
    for name, data in columns.items():
        if not np.isfinite(data).all():
            first = int(np.flatnonzero(~np.all(np.isfinite(data), axis=1))[0])
            raise SimulationError(f"Exudyn {settings.solver} produced a non-finite {name.replace('_', ' ')} at "
                                  f"t = {data[first, 0]:.6g} s (the solve diverged; try a smaller step or "
                                  "tighter tolerance)")
    time = columns["barrel_position"][:, 0]
    later = time[1:] > time[:-1]
    rows = slice(None) if later.all() else np.concatenate([[True], later])  # drop duplicate time stamps, if any
    return (np.ascontiguousarray(time[rows]),
            {name: np.ascontiguousarray(data[rows, 1]) for name, data in columns.items()})


def _collect(assembly: Assembly, end_time: float, settings: SolverSettings,
             initial_accelerations: dict[str, float] | None = None, segments: list | None = None) -> Samples:
    """Read the sensors into :class:`Samples`; raise SimulationError for NaN/inf or missing output.

    ``segments``: the ``(time, values)`` of every segment of a segmented run (:func:`_run_segments`),
    joined in order; the sample at a segment boundary appears twice, before and after it (a velocity
    jump of a shot, a jump of the breech force): a zero-length interval the post-processing skips.
    """
    if segments is None:
        segments = [_read_segment(assembly, settings, 0.0, initial_accelerations)]
    if len(segments) == 1:
        time, values = segments[0]
    else:
        time = np.concatenate([t for t, _ in segments])
        values = {name: np.concatenate([v[name] for _, v in segments]) for name in assembly.sensors}
    if len(time) < 2:
        raise SimulationError(f"Exudyn {settings.solver} produced fewer than two output samples")
    if abs(time[-1] - end_time) > 1e-6 * max(1.0, end_time):
        raise SimulationError(f"Exudyn {settings.solver} output ends at t = {time[-1]:.6g} s, not at {end_time:g} s")
    bodies = [body.name for body in assembly.mechanism.bodies]
    return Samples(time=time, positions={b: values[f"{b}_position"] for b in bodies},
                   velocities={b: values[f"{b}_velocity"] for b in bodies},
                   accelerations={b: values[f"{b}_acceleration"] for b in bodies},
                   forces={c.name: values[f"{c.name}_force"] for c in assembly.mechanism.connectors
                           if c.records_force})


#: Steps at least per window where a load varies (a breech pulse): the step is limited to its length / this.
STEPS_PER_LOAD_WINDOW = 40
#: Segments a run may be split into at most (:func:`segment_plan`: one per point of a pulse's table per shot):
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


def segment_plan(mechanism: Mechanism, end_time: float, settings: SolverSettings) -> list[tuple[float, float, SolverSettings]]:
    """``(start s, end s, settings)`` of each segment of a run: split at every shot and every jump or kink of
    a load (:attr:`Mechanism.breakpoints`: every point of a pulse's table); inside a load's window the
    adaptive ``max_step`` is at most the window's length / :data:`STEPS_PER_LOAD_WINDOW`, so that no pulse is
    stepped over."""
    cuts = [0.0] + [t for t in mechanism.breakpoints if t < end_time] + [float(end_time)]
    plan = []
    for t0, t1 in zip(cuts[:-1], cuts[1:]):
        segment_settings = settings
        for load in mechanism.loads:
            for w0, w1 in load.windows:
                if w0 < t1 and t0 < w1 and settings.adaptive:
                    limit = (w1 - w0) / STEPS_PER_LOAD_WINDOW
                    if limit < segment_settings.max_step:
                        segment_settings = replace(segment_settings, max_step=limit)
        plan.append((t0, t1, segment_settings))
    return plan


def _run_segments(assembly: Assembly, settings: SolverSettings, end_time: float,
                  tracker: FinalityTracker | None, rest: RestWatch | None = None) -> tuple[int, float, Samples]:
    """Solve a scene with shots or pulses segment by segment (:func:`segment_plan`).

    At each segment's start the shots firing then add their velocity jumps to the state; each segment
    is one Exudyn solve from the previous one's end state.  ``rest``: the segments are cut into chunks
    too, and the solve ends once a chunk proves rest (:meth:`RestWatch.settle`; the samples then end at
    the rest time).  Returns (steps, simulated end time s, samples).
    """
    mechanism, data = assembly.mechanism, assembly.mbs.systemData
    run: dict = {"end_time": end_time}
    segments, steps, simulated_end = [], 0, 0.0
    plan = segment_plan(mechanism, end_time, settings)
    for k, (t0, t1, segment_settings) in enumerate(plan if rest is None else rest.split(plan)):
        if k:
            q = np.array(data.GetODE2Coordinates(), dtype=float)
            v = np.array(data.GetODE2Coordinates_t(), dtype=float)
            for t_shot, body, jump in mechanism.impulses:
                if t_shot == t0:
                    v[assembly.coordinates[body]] += jump
            for configuration in (exudyn.ConfigurationType.Initial, exudyn.ConfigurationType.Current):
                data.SetODE2Coordinates(q.tolist(), configuration=configuration)
                data.SetODE2Coordinates_t(v.tolist(), configuration=configuration)
        accelerations = _initial_accelerations(assembly, t0)
        for load in mechanism.loads:  # a pulse's piece of this segment
            load.start_segment(t0)
        n, simulated_end = _solve(assembly, segment_settings, t1, tracker, t0, run)
        steps += n
        segments.append(_read_segment(assembly, settings, t0, accelerations))
        if tracker is not None and tracker.done:
            break
        settled = rest.settle(t0, t1, segments[-1]) if rest is not None else None
        if settled is not None:
            segments[-1], simulated_end = settled, rest.time
            break
    return steps, simulated_end, _collect(assembly, simulated_end, settings, segments=segments)


def _settings_after_stepped_over_contacts(mechanism: Mechanism, samples: Samples, settings: SolverSettings,
                                          impact_threshold: float, attempt: int) -> SolverSettings | None:
    """None if the solver felt every contact; else settings for a re-solve with a smaller max_step.

    A fixed-step solver, or an adaptive one still stepping over contacts after
    :data:`MAX_CONTACT_RETRIES` re-solves, raises SimulationError (see :mod:`mbs_models.engine.stability`).
    """
    missed = []
    for contact in mechanism.contacts:
        missed += stability.stepped_over_contacts(
            contact, samples.time, mechanism.relative(contact, samples.positions),
            mechanism.relative(contact, samples.velocities), samples.forces[contact.name], impact_threshold)
    if not missed:
        return None
    missed.sort(key=lambda m: m.time)
    first = missed[0]
    shortest = min(m.duration for m in missed)
    what = (f"Exudyn {settings.solver} stepped over {len(missed)} contact(s) between two steps, the first at "
            f"t = {first.time:.6g} s (penetration {first.penetration:.3g} m, ~{first.peak_force:.3g} N, "
            f"lasting ~{first.duration:.3g} s)")
    if not settings.adaptive:
        raise SimulationError(f"{what}; use step <= {shortest / stability.STEPS_PER_CONTACT:.3g} s")
    if attempt >= MAX_CONTACT_RETRIES:
        raise SimulationError(f"{what} even with max_step = {settings.max_step:.3g} s")
    return replace(settings, max_step=min(settings.max_step, shortest) / 4.0)


def simulate(scene: Scene, end_time: float = 10.0, accuracy: str | SolverSettings = "standard", *,
             user_functions: str | None = None, impact_threshold: float = 1000.0,
             stop_when_final: Sequence[str] = (), stop_at_rest: bool = True) -> Result:
    """Simulate ``scene`` from t = 0 to ``end_time`` (s) with Exudyn and return a :class:`Result`.

    Parameters
    ----------
    scene: the validated scene (see :func:`mbs_models.load_scene`, :func:`mbs_models.model_ii`).
    end_time: simulated time in s, in (0, 1e4]; the paper uses 10 s.
    accuracy: ``"draft"``, ``"standard"`` (default) or ``"reference"``, or a :class:`SolverSettings`.
    user_functions: override the settings' backend: ``"symbolic"`` (C++) or ``"python"``.
    impact_threshold: a contact episode counts as an impact when its peak force rises above the force the
        contact held at rest when it began (0, or at t = 0 an initial interference's ``k p^n``) by more than
        this (N).
    stop_when_final: metric names among :data:`~mbs_models.engine.final_metrics.FINAL_METRICS`
        (``"max_barrel_displacement"``, ``"peak_contact_force"``, ``"max_absorber_velocity"``,
        ``"impacts"``).  The solve stops as soon as energy bounds prove that none of them can change
        before ``end_time`` (:mod:`mbs_models.engine.final_metrics`); the result then covers
        ``[0, result.end_time]`` with ``result.requested_end_time`` = ``end_time``,
        ``result.stop_reason == "metrics_final"``, and every metric *not* proven final at the stop
        (with its time) is None (``impacts`` too), never a value of the shorter window.  Scenes that
        inject energy (``literal_lambda_sign``) have no bound and run to ``end_time``
        (``stop_reason == "end_time_no_energy_bound"``).  An early stop is trusted only if the run's
        energy-balance error stayed below the bounds' slack; otherwise the scene is re-solved to
        ``end_time`` (``stop_reason == "end_time_energy_check"``).  Empty (default): run to ``end_time``.
    stop_at_rest: a run longer than 100 s (:data:`~mbs_models.engine.rest.CHECK_INTERVAL`) of an adaptive
        solver stops once energy bounds prove every position within the settings' absolute tolerance (m) of
        the rest state and every velocity within it (m/s) for all later time (:mod:`mbs_models.engine.rest`):
        ``stop_reason == "at_rest"``, ``rest_time`` (s) the first output sample that proves it, and the
        histories hold the rest state from there to ``end_time`` (``end_time`` is the requested one).
        Scenes that never provably rest (undamped, a load that never ends, friction) run to ``end_time``.
        False: always integrate to ``end_time``.

    Returns
    -------
    Result (:class:`mbs_models.results.result.Result`), SI units throughout:

    * time histories at the solver's output steps: ``time`` (s); ``positions``, ``velocities``,
      ``accelerations`` per body name (``"barrel"`` and the absorbers; m, m/s, m/s^2); ``contacts`` per
      contact name (:class:`~mbs_models.results.result.ContactOutput`: force history N, peak, impacts);
      ``support_force`` (N, the force on the mount, positive in the recoil direction); energies per
      body/connector (``kinetic_energy_histories``, ``stored_energy_histories``,
      ``dissipated_energy_history``, ``work_histories``; J) and :meth:`~Result.energy_error`;
    * metrics, refined between samples: ``max_barrel_displacement`` (m) and its time,
      ``peak_support_force`` (N), ``peak_contact_force`` (N) and ``max_absorber_velocity`` (m/s) over all
      absorbers, each with its time; ``impacts`` (the absorbers' contact episodes that rise by more
      than ``impact_threshold`` above their force at rest, in time order); ``dissipated_energy`` (J per
      connector); :meth:`~Result.absorbers`, :meth:`~Result.stops`,
      :meth:`~Result.energy` per element; ``max_at_end_of_window`` (the maximum is the window's last
      instant, not a turning point);
    * the run: ``end_time`` and ``requested_end_time`` (s), ``stop_reason``, ``final_metrics``,
      ``settings``, ``steps``, ``wall_time`` (s); :meth:`~Result.metrics` (a JSON-ready dict, the keys of
      ``recoil run --json``) and :meth:`~Result.summary` (text).

    Metrics of effects the scene lacks are None (never 0 for "no absorber"); an absorber that is never
    touched has ``peak_contact_force == 0.0`` with no time.

    Example
    -------
    >>> from mbs_models import model_ii, simulate
    >>> result = simulate(model_ii(absorber_mass=1000.0, gap=0.0), end_time=2.0)
    >>> round(result.max_barrel_displacement, 4), round(result.time_of_max_barrel_displacement, 3)
    (0.1508, 0.508)
    >>> round(result.peak_contact_force / 1e3, 1), len(result.impacts)   # kN
    (123.3, 4)

    Raises
    ------
    SceneError: an argument is invalid, or a fixed step is unsafe for the scene (the message names it
        and gives the safe limit), or the run is beyond a bound (README, "Limits"): a spring or damper too
        stiff for the step budget (the message names the key and the largest value that fits), more than
        :data:`MAX_ABSORBERS` absorbers, more than :data:`MAX_SEGMENTS` segments.
    SimulationError: the solve failed, stopped early, produced non-finite values, stepped over a
        contact with a fixed step, does not balance energy (see :mod:`mbs_models.engine.stability`), or
        spent its step budget or its cap on stored samples (:mod:`mbs_models.engine.guard`).
    KeyboardInterrupt: Ctrl-C during the solve (at once, whatever the solver is doing).

    Warns
    -----
    UnitWarning (:mod:`mbs_models.errors`), before the solve: a magnitude implausible for a recoil
        mechanism (a barrel mass in tonnes, a pulse in ms or kN) or a contact that can never close (a gap
        in mm), naming the scene key (:mod:`mbs_models.engine.unit_slips`); the run goes on.
    stability.AccuracyWarning: a fixed step resolves impacts with fewer than 10 steps, or the energy
        balance is off by more than 1 % of the initial energy.
    """
    if isinstance(scene, Scene):  # anything else: simulate_with's SceneError
        _check_arguments(scene, end_time, impact_threshold)  # before the warnings: nothing to warn of a refusal
        warn_unit_slips(scene, stacklevel=2)
    return simulate_with(FRESH_MODELS, scene, end_time, accuracy, user_functions=user_functions,
                         impact_threshold=impact_threshold, stop_when_final=stop_when_final, stop_at_rest=stop_at_rest)


class FreshModels:
    """Where :func:`simulate_with` gets its Exudyn systems: a new :func:`~mbs_models.engine.assembly.assemble`
    for every solve, closed after it.  :class:`mbs_models.engine.reuse.Simulator` keeps them instead."""

    def acquire(self, scene: Scene, user_functions: str, mechanism: Mechanism) -> Assembly:
        """An assembled system of ``scene`` (with ``mechanism``'s connectors bound to it), ready to solve."""
        return assemble(scene, user_functions, mechanism)

    def release(self, assembly: Assembly, failed: bool) -> None:
        """The solve with ``assembly`` is over (``failed``: it raised)."""
        assembly.close()


FRESH_MODELS = FreshModels()


def simulate_with(models: FreshModels, scene: Scene, end_time: float = 10.0,
                  accuracy: str | SolverSettings = "standard", *, user_functions: str | None = None,
                  impact_threshold: float = 1000.0, stop_when_final: Sequence[str] = (),
                  stop_at_rest: bool = True) -> Result:
    """:func:`simulate` with the Exudyn systems of ``models`` (:class:`FreshModels` or a
    :class:`~mbs_models.engine.reuse.Simulator`): the same contract."""
    _check_arguments(scene, end_time, impact_threshold)
    if not isinstance(stop_at_rest, bool):
        raise SceneError("stop_at_rest", f"must be True or False, got {stop_at_rest!r}")
    requested = check_metric_names(stop_when_final)
    settings = solver_settings_for(accuracy, user_functions)
    rest_tolerance = settings.absolute_tolerance if stop_at_rest and settings.adaptive else None  # (as asked for)
    stability.check_settings(scene, settings, float(end_time))  # unsafe steps: SceneError before solving
    early_stop = bool(requested) and dissipative(scene)
    t_start = _time.perf_counter()
    attempt = 0
    checked = False
    while True:
        mechanism = Mechanism(scene)  # fresh: contacts carry the onset capture of one solve
        tracker = FinalityTracker(mechanism, requested, impact_threshold) if early_stop else None
        rest = RestWatch.of(mechanism, rest_tolerance, float(end_time), tracker.bounds if tracker else None)
        if not checked:  # runs the budget would stop, refused before solving (SceneError naming the key)
            _check_bounds(mechanism, settings, float(end_time), tracker, rest)
            checked = True
        assembly = models.acquire(scene, settings.user_functions, mechanism)
        t_assembled = _time.perf_counter()
        failed = True
        try:
            if mechanism.breakpoints or mechanism.loads or rest is not None:
                steps, simulated_end, samples = _run_segments(assembly, settings, float(end_time), tracker, rest)
                t_solved = _time.perf_counter()
            else:
                initial_accelerations = _initial_accelerations(assembly)
                steps, simulated_end = _solve(assembly, settings, float(end_time), tracker)
                t_solved = _time.perf_counter()
                samples = _collect(assembly, simulated_end, settings, initial_accelerations)
            failed = False
        except _StepSizeStalled as stalled:
            retry = _absolute_tolerance_settings(settings) if settings.adaptive else None
            if retry is None:
                raise SimulationError(str(stalled)) from None
            settings = retry  # once: the re-solve with absolute error control (see the function)
            continue
        finally:
            models.release(assembly, failed)
        retry = _settings_after_stepped_over_contacts(mechanism, samples, settings, float(impact_threshold), attempt)
        attempt += 1
        if retry is None:
            break
        settings = retry
    stopped = tracker is not None and tracker.done
    at_rest = rest is not None and rest.time is not None
    if at_rest:  # the rest state held to the end time (within the tolerance of the solution: rest.py)
        samples = rest.hold(samples)
    final = FINAL_METRICS
    if stopped:  # which other metrics are final too: all of them are checked at the last state
        tracker.observe_last(float(samples.time[-1]), [float(samples.positions[b.name][-1]) for b in mechanism.bodies],
                             [float(samples.velocities[b.name][-1]) for b in mechanism.bodies])
        final = tuple(n for n in FINAL_METRICS if n in tracker.final)
    metrics = analyse(mechanism, samples, float(impact_threshold), final)  # unproven ones: not computed
    result = _result(scene, settings, mechanism, samples, metrics, float(impact_threshold))
    for name in ("max_barrel_displacement", "max_absorber_velocity", "peak_contact_force", "peak_support_force"):
        value = getattr(result, name)
        if value is not None and not math.isfinite(value):
            raise SimulationError(f"post-processing produced a non-finite {name.replace('_', ' ')}")
    energy_error = (result.kinetic_energy_history + result.stored_energy_history
                    + sum(result.dissipated_energy_history.values()) - mechanism.initial_energy())
    mechanical = result.kinetic_energy_history + result.stored_energy_history
    scale = mechanism.energy_scale()  # the mechanism at hand: building another solves a preload's equilibrium again
    if result.work_histories:
        work = result.work_history
        energy_error = energy_error - work
        mechanical = mechanical - work  # what never increases once the inputs are counted
        scale += float(np.max(np.abs(work)))
    stability.check_energy_balance(scene, samples.time, energy_error, f"Exudyn {settings.label()}", scale)
    floor = tracker.bounds.energy_floor if stopped else 0.0  # the energy's lower bound (a preload's well)
    if stopped and largest_energy_rise(mechanical - floor) > ENERGY_SLACK:
        # the solution's energy rose by more than the bounds' slack: do not trust the early stop
        result = simulate_with(models, scene, end_time, settings, impact_threshold=impact_threshold,
                               stop_at_rest=stop_at_rest)
        result.stop_reason = STOP_ENERGY_CHECK
        result.wall_time = _time.perf_counter() - t_start
        return result
    if stopped:
        result.stop_reason = STOP_METRICS_FINAL
        result.end_time = simulated_end
        result.final_metrics = final
        _drop_unproven(result, final)
    else:
        result.stop_reason = STOP_NO_BOUND if requested and not early_stop else STOP_END_TIME
        result.end_time = float(end_time)
        if at_rest:
            result.stop_reason, result.rest_time, result.rest_tolerance = STOP_AT_REST, rest.time, rest.tolerance
    result.requested_end_time = float(end_time)
    result.steps = steps
    t_end = _time.perf_counter()
    result.wall_time = t_end - t_start
    result.timings = {"assembly": t_assembled - t_start, "solve": t_solved - t_assembled, "postprocess": t_end - t_solved}
    return result


def _largest(candidates) -> tuple[float | None, float | None]:
    """(value, time) with the largest value, the earliest on ties; (None, None) if there is none."""
    candidates = [c for c in candidates if c[0] is not None]
    if not candidates:
        return None, None
    return max(candidates, key=lambda c: (c[0], -(c[1] if c[1] is not None else 0.0)))


def _result(scene: Scene, settings: SolverSettings, mechanism: Mechanism, samples: Samples, metrics,
            impact_threshold: float) -> Result:
    """The Result of a solve: histories, the version-1 metrics over all absorbers, per-element outputs."""
    absorber_contacts = [metrics.contacts[c.name] for c in mechanism.absorber_contacts if c.name in metrics.contacts]
    has_absorbers = bool(mechanism.absorber_contacts)
    peak = time_of_peak = None
    impacts = None
    if has_absorbers and absorber_contacts:
        peak, time_of_peak = _largest((c.peak_force, c.time_of_peak_force) for c in absorber_contacts)
        if peak == 0.0:
            time_of_peak = None
        if all(c.impacts is not None for c in absorber_contacts):
            impacts = sorted((i for c in absorber_contacts for i in c.impacts), key=lambda i: i.start)
    elif not has_absorbers:
        impacts = []
    v_max, t_v = _largest(metrics.max_velocity.values()) if metrics.max_velocity else (None, None)
    energies = metrics.energies
    element_of = {body.name: body.element or body.name for body in mechanism.bodies}
    element_of.update({c.name: c.element for c in mechanism.connectors})
    element_of.update({load.name: load.element for load in mechanism.loads})
    return Result(
        scene=scene, settings=settings, end_time=float(samples.time[-1]), time=samples.time,
        positions=samples.positions, velocities=samples.velocities, accelerations=samples.accelerations,
        contacts=metrics.contacts, support_force=metrics.support_force,
        max_barrel_displacement=metrics.max_barrel_displacement,
        time_of_max_barrel_displacement=metrics.time_of_max_barrel_displacement,
        peak_contact_force=peak, time_of_peak_contact_force=time_of_peak,
        max_absorber_velocity=v_max, time_of_max_absorber_velocity=t_v,
        impacts=impacts, impact_threshold=impact_threshold,
        dissipated_energy={name: float(history[-1]) for name, history in energies.dissipated.items()},
        peak_support_force=metrics.peak_support_force, time_of_peak_support_force=metrics.time_of_peak_support_force,
        max_velocities=dict(metrics.max_velocity), dissipated_energy_history=energies.dissipated,
        stored_energy_histories=energies.stored, kinetic_energy_histories=energies.kinetic, element_of=element_of,
        work_histories=energies.work, shots=metrics.shots)


def _drop_unproven(result: Result, final: tuple[str, ...]) -> None:
    """Set every metric not proven final (and its time) to None: a shorter window's value is no result."""
    if "max_barrel_displacement" not in final:
        result.max_barrel_displacement = result.time_of_max_barrel_displacement = None
    if "peak_contact_force" not in final:
        result.peak_contact_force = result.time_of_peak_contact_force = None
        for contact in result.contacts.values():
            contact.peak_force = contact.time_of_peak_force = None
    if "max_absorber_velocity" not in final:
        result.max_absorber_velocity = result.time_of_max_absorber_velocity = None
        result.max_velocities = {name: (None, None) for name in result.max_velocities}
    if "impacts" not in final:
        result.impacts = None
        for contact in result.contacts.values():
            contact.impacts = None
    if "peak_support_force" not in final:
        result.peak_support_force = result.time_of_peak_support_force = None
