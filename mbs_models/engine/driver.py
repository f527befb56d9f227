"""The driver of a run: Exudyn solves a scene, in segments where it has shots or loads, re-solving as needed.

:func:`drive` is the one entry (:func:`mbs_models.engine.simulation.simulate` calls it): it assembles the scene
(from :class:`FreshModels` or a :class:`~mbs_models.engine.reuse.Simulator`), solves it from 0 to the end time
(:func:`_solve`; :func:`_run_segments` for a scene with shots, loads or a rest watch), reads the sensors into
:class:`~mbs_models.results.postprocess.Samples` (:mod:`mbs_models.engine.readout`), and re-solves a run that

* stepped over a whole contact with a smaller ``max_step`` (:func:`_settings_after_stepped_over_contacts`,
  at most :data:`MAX_CONTACT_RETRIES` times);
* only grazed a contact, with a maximum step above :data:`~mbs_models.engine.stability.GRAZING_MAX_STEP`
  (:func:`_settings_after_grazed_contacts`, once);
* diverged (NaN or inf in its output) with an adaptive solver, with ``max_step / 4`` (at most
  :data:`MAX_DIVERGENCE_RETRIES` times): a trial step as long as the maximum step, taken from a slow phase into a
  stiff one (a damper of a millisecond's time constant), can reach states where a law is not finite, and Exudyn
  accepts a step whose error estimate is NaN;
* stalled with a maximum step above :data:`~mbs_models.engine.stability.GRAZING_MAX_STEP`: once with that
  maximum step (a long accepted step can land where the step size then collapses: the planar jump of the hard
  cases at 20 ms);
* stalled on Exudyn's error-scale bug with absolute error control (:func:`_absolute_tolerance_settings`, once).

What it collected is a :class:`Solve`; what the run *means* (why it stopped, which metrics are final) is the run
policy's (:mod:`mbs_models.engine.run_policy`), the Result is built from both (:mod:`mbs_models.engine.result_builder`).
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, replace

import exudyn
import numpy as np

from ..errors import SimulationError
from ..results.postprocess import Samples
from ..scene import Scene
from . import stability
from .accuracy import MIN_RELATIVE_TOLERANCE, SolverSettings
from .assembly import Assembly, assemble
from .finality import FinalityTracker
from .guard import StepBudget, sample_cap
from .mechanism import Mechanism
from .readout import NonFiniteSolve, collect, read_segment
from .rest import RestWatch
from .run_policy import RunPolicy, _check_bounds
from .time_scales import time_scale_hint

#: Re-solves (with max_step / 4 each) when an adaptive solver stepped over a whole contact.
MAX_CONTACT_RETRIES = 3
#: Re-solves (with max_step / 4 each) when an adaptive solve diverged (NaN or inf in its output).
MAX_DIVERGENCE_RETRIES = 3
#: The finality tracker (stop_when_final) is shown the state at the start of a step once this many steps, or
#: :data:`OBSERVE_INTERVAL` of simulated time, passed since the last state it was shown, whichever comes first.
#: An observed step's pre-step call (reading the state, the bounds) costs about as much as a step, an unobserved
#: one a tenth of that (the performance pages; scripts/bench_prestep.py): the step count spares the short steps
#: of a contact, the interval keeps the stop within a step of the proof where the steps are long.  Changing
#: either changes when early stops happen (not bit-identical; the metrics do not move).
OBSERVE_EVERY = 16
#: See :data:`OBSERVE_EVERY` (s): the longest simulated time between two states shown to the finality tracker.
OBSERVE_INTERVAL = 0.05
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


def _simulation_settings(assembly: Assembly, settings: SolverSettings, end_time: float, start_time: float):
    """:func:`exudyn_simulation_settings` for a solve of ``assembly`` (with fewer samples per sensor for a fixed step
    past :func:`~mbs_models.engine.guard.sample_cap`), made once per system and key (a sweep's points solve the
    same system with the same settings; :attr:`Assembly.simulation_settings`).  The caller sets the initial step
    size at every solve."""
    key = (settings, float(end_time), float(start_time))
    ss = assembly.simulation_settings.get(key)
    if ss is None:
        ss = exudyn_simulation_settings(settings, end_time, start_time)
        kept = sample_cap(len(assembly.sensors))
        if not settings.adaptive and ss.timeIntegration.numberOfSteps > kept:  # many sensors: fewer samples each
            ss.solution.sensors.writePeriod = max(ss.solution.sensors.writePeriod, (end_time - start_time) / kept)
        if len(assembly.simulation_settings) >= 16:  # (a long optimisation's many end times: keep the latest)
            assembly.simulation_settings.clear()
        assembly.simulation_settings[key] = ss
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


def _pre_step_function(assembly: Assembly, budget: StepBudget | None, tracker: FinalityTracker | None,
                       specialise: bool = True):
    """Exudyn pre-step function: the step budget (raises when spent), the contacts' onset capture and
    the finality tracker.

    The budget *raises* when spent: returning False is ignored while Exudyn's DOPRI5 is stuck
    re-trying one step at its minimum step size (measured: model (ii) with m = 1 kg, k_c = 1e12 at
    rtol <= 1e-10 never passes t = 0.4924 s).  Contacts whose law needs the onset rate ``v-`` see the
    state at the start of every step (Exudyn's current coordinates; ``t`` is the end of the step
    about to be taken, so the start is ``t - currentStepSize``).  The tracker is shown the state at the
    start of a step once :data:`OBSERVE_EVERY` steps or :data:`OBSERVE_INTERVAL` s passed since the last
    one it was shown, whichever comes first; the function returns False once every requested metric is
    final: Exudyn then completes that step and stops, so the output ends one step after the state that
    proved finality.

    The function is Python called by Exudyn at every step, so it does at each step only what that step
    needs, everything else is looked up once here: one step counter serves the budget (which it calls only
    at :attr:`~mbs_models.engine.guard.StepBudget.next_check`) and the tracker's cadence; the state is read
    only for the captures or an observed step, and passed on as it is where Exudyn's coordinates are the
    bodies in body order (else reordered).  With the budget alone (most adaptive solves) the function only
    counts: one Python call, an increment and a comparison per step (the validation pages, "Limits"); with
    the budget and the tracker alone (a sweep's early stop) it counts and observes at that cadence.
    ``specialise=False``: the general function in every case (the same calls of the budget and the tracker).
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
    planar = assembly.planar if assembly.planar is not None and assembly.planar.captures else None
    if planar is not None:  # the carriage's touchdown anchors see the tree's state at every step start
        tree = list(data.GetNodeLTGODE2(planar.node))
    steps = 0  # calls so far (all segments of a run): the budget's step count and the tracker's cadence
    observe_step, observe_time = OBSERVE_EVERY, OBSERVE_INTERVAL  # the tracker's next state: by count or by time
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
        nonlocal steps, next_check, observe_step, observe_time
        steps += 1
        if steps >= next_check:  # between checkpoints the budget would only count
            if not budget.advance(steps, t):
                raise _BudgetSpent(f"step budget spent at t = {t:.6g} s")
            next_check = budget.next_check
        q = v = None
        if planar is not None:
            q = read_positions(copy=False).tolist()
            v = read_velocities(copy=False).tolist()
            if not solver:
                solver.append(mbs.sys["dynamicSolver"].it)
            planar.observe(t - solver[0].currentStepSize, [q[i] for i in tree], [v[i] for i in tree])
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
        if observe is None or (steps < observe_step and t < observe_time):
            return True
        observe_step, observe_time = steps + OBSERVE_EVERY, t + OBSERVE_INTERVAL
        if q is None:
            q = read_positions(copy=False).tolist()
            v = read_velocities(copy=False).tolist()
        if in_body_order:
            return not observe(t, q, v)
        return not observe(t, [q[i] for i in order], [v[i] for i in order])

    def count_and_observe(mbs, t):  # the budget and the tracker alone (a sweep's early stop): pre_step's work
        nonlocal steps, next_check, observe_step, observe_time
        steps += 1
        if steps >= next_check:
            if not budget.advance(steps, t):
                raise _BudgetSpent(f"step budget spent at t = {t:.6g} s")
            next_check = budget.next_check
        if steps < observe_step and t < observe_time:
            return True
        observe_step, observe_time = steps + OBSERVE_EVERY, t + OBSERVE_INTERVAL
        return not observe(t, read_positions(copy=False).tolist(), read_velocities(copy=False).tolist())

    if specialise and budget is not None and not captures and planar is None:
        if observe is None:
            function = count
        elif in_body_order:
            function = count_and_observe
        else:
            function = pre_step
    else:
        function = pre_step
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
    ss = _simulation_settings(assembly, settings, end_time, start_time)
    first_step = min((c.first_step_limit for c in assembly.mechanism.connectors), default=math.inf)
    # (0: Exudyn starts with max_step; set at every solve, the settings object being the system's for its key)
    ss.timeIntegration.initialStepSize = first_step if settings.adaptive and first_step < settings.max_step else 0.0
    solver_type = getattr(exudyn.DynamicSolverType, settings.solver)
    run = {} if run is None else run
    if "budget" not in run:
        run["budget"] = None
        if settings.adaptive:  # every adaptive solve: bounded steps and stored samples (engine/guard.py)
            run["budget"] = StepBudget.for_run(run.get("end_time", end_time), len(assembly.sensors))
        anchors = assembly.planar is not None and assembly.planar.captures
        if run["budget"] is not None or tracker is not None or assembly.mechanism.capturing_contacts or anchors:
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
    if assembly.planar is not None:
        data.SetTime(t)  # the tree's force user function depends on time (a breech pulse)
    size = data.ODE2Size()
    lhs = np.zeros(size)
    mass = np.zeros((size, size))
    masses = {body.name: body.mass for body in assembly.mechanism.bodies}
    try:
        for index, ltg, has_mass, has_lhs, body in _item_layout(assembly):
            if body is not None:  # a body's ObjectMass1D: mass matrix [m] (the mass it was given), no LHS
                mass[ltg[0], ltg[0]] += masses[body]
                continue
            if len(ltg) == 1:  # (most objects: one coordinate, no index arrays needed)
                k = ltg[0]
                if has_mass:
                    mass[k, k] += float(np.asarray(mbs.ComputeItem(index, exudyn.ComputeItemType.MassMatrix))[0, 0])
                if has_lhs:
                    lhs[k] += float(np.asarray(mbs.ComputeItem(index, exudyn.ComputeItemType.ODE2LHS))[0])
                continue
            if has_mass:
                mass[np.ix_(ltg, ltg)] += np.asarray(mbs.ComputeItem(index, exudyn.ComputeItemType.MassMatrix))
            if has_lhs:
                lhs[ltg] += np.asarray(mbs.ComputeItem(index, exudyn.ComputeItemType.ODE2LHS), dtype=float)
    except Exception as exc:  # a user function that raises at the initial state
        if _interrupted(exc):
            raise KeyboardInterrupt from None
        message = " ".join(str(exc).split())
        raise SimulationError(f"evaluating the forces at t = 0 failed: {message[:500]}") from exc
    rhs = -lhs
    planar = assembly.planar
    if planar is not None:  # the tree's force user function (supports, loads) is in its LHS, evaluated at t
        from .planar import CARRIAGE_COORDINATES
        ltg = list(data.GetNodeLTGODE2(planar.node))
        accelerations = np.linalg.solve(mass, rhs)
        out = {body: float(accelerations[ltg[k]]) for body, k in planar.body_coordinate.items()}
        out.update((name, float(accelerations[ltg[k]])) for k, name in enumerate(CARRIAGE_COORDINATES))
        return out
    for load in assembly.mechanism.loads:  # external loads at t (the objects' LHS does not hold them)
        rhs[assembly.coordinates[load.body]] += float(load.force(np.array([t]))[0])
    accelerations = np.linalg.solve(mass, rhs)
    return {body: float(accelerations[assembly.coordinates[body]]) for body in assembly.nodes}


def _item_layout(assembly: Assembly) -> list:
    """:attr:`Assembly.item_layout`, looked up on the first call for the system (the objects, their coordinates
    and what Exudyn computes for each do not change when a sweep refills the system with new numbers).

    A body's ``ObjectMass1D`` (:func:`~mbs_models.engine.assembly.add_body`) is marked with the body's name: its
    mass matrix is the body's mass and its LHS is 0 (Exudyn's ``ObjectMass1D`` has no force of its own), so
    nothing is asked of Exudyn for it (tests/engine/test_driver.py compares with asking)."""
    if not assembly.item_layout:
        data = assembly.mbs.systemData
        body_of = {int(index): body for body, index in assembly.masses.items()}
        for i in range(data.NumberOfObjects()):
            ltg = [int(k) for k in data.GetObjectLTGODE2(i)]
            if not ltg:
                continue
            index = exudyn.ObjectIndex(i)
            body = body_of.get(i) if len(ltg) == 1 and i in body_of \
                and assembly.mbs.GetObject(index)["objectType"] == "Mass1D" else None
            if body is not None:  # (nothing is asked of Exudyn for it: see above)
                assembly.item_layout.append((index, ltg, False, False, body))
                continue
            applies = assembly.mbs.ComputeItem(index)
            assembly.item_layout.append((index, ltg, exudyn.ComputeItemType.MassMatrix in applies,
                                         exudyn.ComputeItemType.ODE2LHS in applies, None))
    return assembly.item_layout


#: Steps at least per window where a load varies (a breech pulse): the step is limited to its length / this.
STEPS_PER_LOAD_WINDOW = 40


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
        segments.append(_ending_at(read_segment(assembly, settings, t0, accelerations), t1))
        if tracker is not None and tracker.done:
            break
        settled = rest.settle(t0, t1, segments[-1]) if rest is not None else None
        if settled is not None:
            segments[-1], simulated_end = settled, rest.time
            break
    return steps, simulated_end, collect(assembly, simulated_end, settings, segments=segments)


#: A segment's last output time within this (relative to max(1 s, its end)) of the segment's end is its end.
SEGMENT_END_ROUND_OFF = 1e-12


def _ending_at(segment: tuple, end: float) -> tuple:
    """A segment's ``(time, values)`` with its last time set to the segment's ``end`` (s) where it differs by round-off
    only: Exudyn sums its steps (``span / numberOfSteps`` each, where the maximum step binds), so a segment from 0.5 s
    to 0.75 s in 7 steps ends at 0.7499999999999999 s -- and the next, starting at 0.75 s with a shot's jump, would
    not share its time (the jump is a zero-length interval the post-processing recognises)."""
    time, values = segment
    if len(time) and time[-1] != end and abs(time[-1] - end) <= SEGMENT_END_ROUND_OFF * max(1.0, abs(end)):
        time = time.copy()
        time[-1] = end
    return time, values


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


def _settings_after_grazed_contacts(mechanism: Mechanism, samples: Samples, settings: SolverSettings
                                    ) -> SolverSettings | None:
    """Settings for a re-solve with ``max_step`` at most :data:`~mbs_models.engine.stability.GRAZING_MAX_STEP`
    if an adaptive solve with a larger one only grazed a contact (:func:`~mbs_models.engine.stability.grazed_contacts`);
    else None."""
    if not settings.adaptive or settings.max_step <= stability.GRAZING_MAX_STEP:
        return None
    if not stability.grazed_contacts(mechanism, samples.positions):
        return None
    return replace(settings, max_step=stability.GRAZING_MAX_STEP)


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


@dataclass(frozen=True)
class Solve:
    """What the driver collected from the last (accepted) solve of a run.

    ``settings``: the settings it ran with (after any re-solve); ``samples`` the sensors' histories up to
    ``simulated_end`` (s): the end time, or earlier where the tracker proved the metrics final or the rest watch
    proved rest; ``steps`` Exudyn's steps over all segments; ``tracker`` and ``rest`` the finality tracker and
    the rest watch of the solve (None where not asked for); ``assembled`` and ``solved``: ``time.perf_counter()``
    (s) once the system was assembled and once it was solved.
    """

    settings: SolverSettings
    mechanism: Mechanism
    samples: Samples
    steps: int
    simulated_end: float
    tracker: FinalityTracker | None
    rest: RestWatch | None
    assembled: float
    solved: float


def drive(models: FreshModels, scene: Scene, policy: RunPolicy) -> Solve:
    """Solve ``scene`` as ``policy`` says (its settings, end time, early stop, rest watch) with the systems of
    ``models``; re-solve while the solver stepped over a contact or stalled (module docstring).

    Before the first solve, a run the step budget would stop is refused (SceneError naming the key,
    :func:`~mbs_models.engine.run_policy._check_bounds`).
    """
    settings, end_time = policy.settings, policy.end_time
    attempt = diverged = 0
    checked = False
    while True:
        # fresh for every solve (contacts carry the onset capture of one solve); the first: the policy's, if built
        mechanism = policy.mechanism if not checked and policy.mechanism is not None else Mechanism(scene)
        tracker = FinalityTracker(mechanism, policy.requested, policy.impact_threshold) if policy.early_stop else None
        rest = RestWatch.of(mechanism, policy.rest_tolerance, end_time, tracker.bounds if tracker else None)
        if not checked:  # runs the budget would stop, refused before solving (SceneError naming the key)
            _check_bounds(mechanism, settings, end_time, tracker, rest)
            checked = True
        assembly = models.acquire(scene, settings.user_functions, mechanism)
        assembled = _time.perf_counter()
        failed = True
        try:
            if mechanism.breakpoints or mechanism.loads or rest is not None:
                steps, simulated_end, samples = _run_segments(assembly, settings, end_time, tracker, rest)
                solved = _time.perf_counter()
            else:
                initial_accelerations = _initial_accelerations(assembly)
                steps, simulated_end = _solve(assembly, settings, end_time, tracker)
                solved = _time.perf_counter()
                samples = collect(assembly, simulated_end, settings, initial_accelerations)
            failed = False
        except NonFiniteSolve as failure:
            if not settings.adaptive or diverged >= MAX_DIVERGENCE_RETRIES:
                again = f" (also with max_step = {settings.max_step:.3g} s)" if diverged else ""
                raise SimulationError(f"{failure}{again}") from None
            diverged += 1
            settings = replace(settings, max_step=settings.max_step / 4.0)
            continue
        except _StepSizeStalled as stalled:
            if settings.adaptive and settings.max_step > stability.GRAZING_MAX_STEP:
                # first with the fine max step (a long step can land where the step then collapses), then below
                settings = replace(settings, max_step=stability.GRAZING_MAX_STEP)
                continue
            retry = _absolute_tolerance_settings(settings) if settings.adaptive else None
            if retry is None:
                raise SimulationError(str(stalled)) from None
            settings = retry  # once: the re-solve with absolute error control (see the function)
            continue
        finally:
            models.release(assembly, failed)
        retry = _settings_after_stepped_over_contacts(mechanism, samples, settings, policy.impact_threshold, attempt)
        if retry is not None:
            attempt += 1
        else:
            retry = _settings_after_grazed_contacts(mechanism, samples, settings)
        if retry is None:
            break
        settings = retry
    return Solve(settings=settings, mechanism=mechanism, samples=samples, steps=steps, simulated_end=simulated_end,
                 tracker=tracker, rest=rest, assembled=assembled, solved=solved)
