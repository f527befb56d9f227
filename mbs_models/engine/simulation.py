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
  (:mod:`mbs_models.engine.finality`); the result says so (``stop_reason``, ``requested_end_time``)
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

The work is split by job: the driver solves (:mod:`mbs_models.engine.driver`: segments, the re-solves), the run
policy decides (:mod:`mbs_models.engine.run_policy`: arguments and bounds, the early stop, the stop at rest, why the
run ended: :class:`~mbs_models.stop_reason.StopReason`), and the Result is built once from the run's record
(:mod:`mbs_models.engine.result_builder`).  This module is the entry point and re-exports what callers used from it.
"""

from __future__ import annotations

import time as _time
from typing import Sequence

from ..results.result import Result
from ..scene import Scene
from .accuracy import SolverSettings
from .driver import (FIRST_SAME_AS_LAST_SOLVERS, FRESH_MODELS, MAX_CONTACT_RETRIES,  # noqa: F401 (re-exported)
                     MAX_FIXED_STEP_SAMPLES, OBSERVE_EVERY, STEPS_PER_LOAD_WINDOW, FreshModels, drive,
                     exudyn_simulation_settings, segment_plan)
from .result_builder import build_result
from .run_policy import (MAX_ABSORBERS, MAX_END_TIME, MAX_SEGMENTS, RunPolicy,  # noqa: F401 (re-exported)
                         _check_arguments, _check_bounds, conclude, early_stop_trusted)
from .unit_slips import warn_unit_slips


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
    stop_when_final: metric names among :data:`~mbs_models.engine.finality.FINAL_METRICS`
        (``"max_barrel_displacement"``, ``"peak_contact_force"``, ``"max_absorber_velocity"``,
        ``"impacts"``).  The solve stops as soon as energy bounds prove that none of them can change
        before ``end_time`` (:mod:`mbs_models.engine.finality`); the result then covers
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
        and gives the safe limit), or the run is beyond a bound (the validation pages, "Limits"): a spring or damper too
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


def simulate_with(models: FreshModels, scene: Scene, end_time: float = 10.0,
                  accuracy: str | SolverSettings = "standard", *, user_functions: str | None = None,
                  impact_threshold: float = 1000.0, stop_when_final: Sequence[str] = (),
                  stop_at_rest: bool = True) -> Result:
    """:func:`simulate` with the Exudyn systems of ``models`` (:class:`FreshModels` or a
    :class:`~mbs_models.engine.reuse.Simulator`): the same contract."""
    return _run(models, scene, end_time, accuracy, user_functions, impact_threshold, stop_when_final, stop_at_rest)


def _run(models: FreshModels, scene: Scene, end_time: float, accuracy: str | SolverSettings,
         user_functions: str | None, impact_threshold: float, stop_when_final: Sequence[str], stop_at_rest: bool,
         wall_started: float | None = None) -> Result:
    """One run: the policy of the arguments, the driver's solve, the record and the Result built from it.

    An early stop whose energy check fails (:func:`~mbs_models.engine.run_policy.early_stop_trusted`) is re-solved
    to the end time with the settings it ended with (``wall_started``: the first solve's start; the Result's wall
    time covers both).
    """
    policy = RunPolicy.of(scene, end_time, accuracy, user_functions, impact_threshold, stop_when_final, stop_at_rest)
    started = _time.perf_counter()
    solve = drive(models, scene, policy)
    re_solved = wall_started is not None
    record = conclude(policy, solve, scene, started, started if wall_started is None else wall_started, re_solved)
    result = build_result(record)
    if not early_stop_trusted(result, solve):
        # the solution's energy rose by more than the bounds' slack: do not trust the early stop
        return _run(models, scene, end_time, solve.settings, None, impact_threshold, (), stop_at_rest, started)
    return result
