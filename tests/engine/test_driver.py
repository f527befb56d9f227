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
