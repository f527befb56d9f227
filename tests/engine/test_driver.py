"""The driver (mbs_models.engine.driver): Exudyn's settings per solver, the pre-step function, Ctrl-C."""

from __future__ import annotations

import pytest

from mbs_models import SolverSettings, model_ii, simplified_model, simulate


def _every_shipped_scene():
    from mbs_models import load_scene
    from mbs_models.scenes import list_scenes, scene_path

    return [pytest.param(load_scene(scene_path(name)), id=name) for name in list_scenes()]


@pytest.mark.parametrize("solver", ["DOPRI5", "ODE23"])
@pytest.mark.parametrize("scene", _every_shipped_scene())
def test_first_same_as_last_solvers_skip_the_end_of_step_evaluation_bit_identically(
        scene, solver, monkeypatch, assert_results_identical):
    """DOPRI5's and ODE23's last stage is the end-of-step state, so the engine does not let Exudyn evaluate the
    forces again after each step; every shipped scene (shots, breech pulses: loads in time, segmented runs) gives
    the Result of the run that does, exactly."""
    import mbs_models.engine.driver as engine

    settings = SolverSettings(solver=solver, relative_tolerance=1e-6, absolute_tolerance=1e-8, max_step=5e-3)
    assert solver in engine.FIRST_SAME_AS_LAST_SOLVERS
    skipping = simulate(scene, 1.5, settings)
    monkeypatch.setattr(engine, "FIRST_SAME_AS_LAST_SOLVERS", ())
    assert_results_identical(skipping, simulate(scene, 1.5, settings))


def test_other_solvers_keep_exudyns_end_of_step_accelerations():
    """RK44's last stage is not the end-of-step state: Exudyn evaluates the accelerations after each step."""
    from mbs_models.engine.accuracy import solver_settings_for
    from mbs_models.engine.simulation import exudyn_simulation_settings

    fixed = exudyn_simulation_settings(SolverSettings(solver="RK44", step=1e-4), 1.0)
    assert fixed.timeIntegration.explicit.computeEndOfStepAccelerations
    standard = exudyn_simulation_settings(solver_settings_for("standard"), 1.0)
    assert not standard.timeIntegration.explicit.computeEndOfStepAccelerations


def test_ctrl_c_during_a_solve_is_a_keyboard_interrupt_not_a_failed_solve(monkeypatch):
    """Exudyn reports an interrupt inside the solve as its own error; simulate raises KeyboardInterrupt."""
    import mbs_models.engine.driver as engine

    original = engine._pre_step_function

    def interrupted_after_50_steps(*args):
        function, calls = original(*args), []

        def pre_step(mbs, t):
            calls.append(t)
            if len(calls) == 50:
                raise KeyboardInterrupt
            return function(mbs, t)

        pre_step.new_solve = function.new_solve
        return pre_step

    monkeypatch.setattr(engine, "_pre_step_function", interrupted_after_50_steps)
    for scene in (simplified_model(), model_ii(1000.0, 0.0)):
        with pytest.raises(KeyboardInterrupt):
            simulate(scene, 1.0)


def test_an_error_caused_by_an_interrupt_is_recognised_down_its_chain():
    from mbs_models.engine.driver import _interrupted

    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as interrupt:
            raise SystemError("returned a result with an exception set") from interrupt
    except SystemError as error:
        assert _interrupted(error)
    assert not _interrupted(RuntimeError("a user function failed"))


def test_solves_run_with_exudyns_throw_on_ctrl_c_and_restore_it(monkeypatch):
    """Exudyn's default (False) only asks a solve to stop after its current step, which a step rejected for ever at
    the minimum step size never ends (DESIGN.md, Exudyn notes); the engine's solves throw at once."""
    import exudyn

    import mbs_models.engine.driver as engine

    original, seen = engine._pre_step_function, []

    def spying(*args):
        function = original(*args)

        def pre_step(mbs, t):
            seen.append(exudyn.special.solver.throwErrorWithCtrlC)
            return function(mbs, t)

        pre_step.new_solve = function.new_solve
        return pre_step

    monkeypatch.setattr(engine, "_pre_step_function", spying)
    before = exudyn.special.solver.throwErrorWithCtrlC
    simulate(simplified_model(), 0.5)
    assert seen and all(seen) and exudyn.special.solver.throwErrorWithCtrlC == before


def test_a_diverged_adaptive_solve_is_re_solved_with_a_quarter_of_the_max_step(monkeypatch):
    """The realistic base with a damper 3000x the paper's: a 20 ms trial step from the
    slow phase into it reaches states where the battery stop's force is not finite, and Exudyn accepts it (its error
    estimate is NaN).  The run is re-solved with max_step / 4 and then agrees with the independent reference (the
    cradle's friction regularisation is the residual, ~1e-5: DESIGN.md, "Inclined cradle")."""
    from dataclasses import replace
    from pathlib import Path

    import mbs_models.engine.driver as driver
    from mbs_models.engine.accuracy import ACCURACY_PRESETS
    from mbs_models.scene.io import load_scene
    from mbs_models.studies.brake_design import PAPER_DAMPER
    from validation.reference import solve_reference

    base = load_scene(Path(__file__).resolve().parents[2] / "scripts" / "realistic_base.toml")
    scene = base.with_changes(recoil_brake=None, recoil_damper=replace(
        PAPER_DAMPER, recoil=PAPER_DAMPER.recoil * 3e3, counter_recoil=PAPER_DAMPER.counter_recoil * 3e3))
    solves = []
    original = driver._solve
    monkeypatch.setattr(driver, "_solve", lambda assembly, settings, *a, **k: (solves.append(settings.max_step),
                                                                               original(assembly, settings, *a, **k))[1])
    result = simulate(scene, 0.5, "standard")
    preset = ACCURACY_PRESETS["standard"].max_step
    assert result.settings.max_step == preset / 4 and preset in solves
    ref = solve_reference(scene, 0.5)
    assert result.max_barrel_displacement == pytest.approx(ref.max_barrel_displacement, rel=1e-4)
    assert result.peak_support_force == pytest.approx(ref.peak_support_force, rel=1e-4)


def test_a_segment_ending_a_round_off_short_of_its_end_ends_at_it():
    """0.5 s + 7 steps of 0.25/7 s sum to 0.7499999999999999 s: the next segment (a shot at 0.75 s) must share the
    time, so the last time becomes 0.75 s; a segment stopped early (by the tracker) keeps its times."""
    import numpy as np

    from mbs_models.engine.driver import _ending_at

    steps = np.array([0.5] + [0.25 / 7] * 7)
    time = np.cumsum(steps)
    assert time[-1] != 0.75 and abs(time[-1] - 0.75) < 1e-15
    values = {"x": np.arange(8.0)}
    snapped, same = _ending_at((time, values), 0.75)
    assert snapped[-1] == 0.75 and np.array_equal(snapped[:-1], time[:-1]) and same is values
    assert time[-1] != 0.75  # the solver's array itself is not changed
    early = np.array([0.5, 0.6, 0.7])
    assert np.array_equal(_ending_at((early, values), 0.75)[0], early)


def test_the_specialised_pre_step_functions_stop_where_the_general_one_does(monkeypatch):
    """The pre-step function made for a run's case (the budget alone; the budget and the tracker) gives the runs of
    the general one: the same steps, early stops and values (Figs 4/5 points with and without the early stop)."""
    from mbs_models import model_i, model_ii, simulate
    from mbs_models.engine import driver

    runs = [(model(mass, gap), metrics) for model in (model_i, model_ii) for mass in (100.0, 1000.0)
            for gap in (0.0, 0.08) for metrics in ((), ("max_barrel_displacement",))]

    def outcomes():
        out = []
        for scene, metrics in runs:
            result = simulate(scene, 2.0, "standard", stop_when_final=metrics)
            out.append((result.end_time, result.steps, result.stop_reason, result.max_barrel_displacement,
                        result.peak_contact_force, result.barrel_position.tolist()))
        return out

    specialised = outcomes()
    general = driver._pre_step_function
    monkeypatch.setattr(driver, "_pre_step_function",
                        lambda assembly, budget, tracker: general(assembly, budget, tracker, specialise=False))
    assert outcomes() == specialised


def test_initial_accelerations_are_exudyns_own_where_its_mass_objects_are_not_asked():
    """The initial accelerations take a body's ObjectMass1D as its mass and no force (driver._item_layout): the same
    floats as asking Exudyn for every object's mass matrix and LHS, on every shipped 1-D scene and after a refill
    with other numbers."""
    import exudyn
    import numpy as np

    from mbs_models import load_scene
    from mbs_models.engine.assembly import assemble, refill
    from mbs_models.engine.driver import _initial_accelerations
    from mbs_models.engine.mechanism import Mechanism
    from mbs_models.scenes import list_scenes, scene_path

    def asking_exudyn(assembly):
        mbs, data = assembly.mbs, assembly.mbs.systemData
        size = data.ODE2Size()
        lhs, mass = np.zeros(size), np.zeros((size, size))
        for i in range(data.NumberOfObjects()):
            ltg = list(data.GetObjectLTGODE2(i))
            if not ltg:
                continue
            index = exudyn.ObjectIndex(i)
            applies = mbs.ComputeItem(index)
            if exudyn.ComputeItemType.MassMatrix in applies:
                mass[np.ix_(ltg, ltg)] += np.asarray(mbs.ComputeItem(index, exudyn.ComputeItemType.MassMatrix))
            if exudyn.ComputeItemType.ODE2LHS in applies:
                lhs[ltg] += np.asarray(mbs.ComputeItem(index, exudyn.ComputeItemType.ODE2LHS), dtype=float)
        rhs = -lhs
        for load in assembly.mechanism.loads:
            rhs[data.GetNodeLTGODE2(assembly.nodes[load.body])[0]] += float(load.force(np.array([0.0]))[0])
        a = np.linalg.solve(mass, rhs)
        return {body: float(a[data.GetNodeLTGODE2(node)[0]]) for body, node in assembly.nodes.items()}

    scenes = [load_scene(scene_path(name)) for name in list_scenes()]
    scenes = [scene for scene in scenes if scene.carriage is None]
    assert len(scenes) >= 15
    for scene in scenes:
        assembly = assemble(scene)
        try:
            assert _initial_accelerations(assembly) == asking_exudyn(assembly), scene.name
            other = scene.with_changes(**{"barrel.mass": scene.barrel.mass * 1.07})
            assembly = refill(assembly, other, Mechanism(other))
            assert _initial_accelerations(assembly) == asking_exudyn(assembly), scene.name
        finally:
            assembly.close()
