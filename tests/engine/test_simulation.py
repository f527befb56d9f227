"""simulate(): physics against closed forms, backends against each other, failures as errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

import mbs_models.elements.contact_laws as contact_laws
import mbs_models.elements.recoil_damper as recoil_damper
from mbs_models.elements.ops import PYTHON_OPS
from mbs_models import (ACCURACY_PRESETS, SceneError, SimulationError, SolverSettings, model_i, model_ii,
                        simplified_model, simulate)


def damped_oscillator_maximum(mass, stiffness, damping, v0):
    """First maximum of M x'' + c x' + k x = 0, x(0) = 0, x'(0) = v0 (underdamped).

    x(t) = v0/wd exp(-zeta wn t) sin(wd t); x'(t) = 0 where tan(wd t) = wd / (zeta wn).
    """
    wn = math.sqrt(stiffness / mass)
    zeta = damping / (2.0 * math.sqrt(stiffness * mass))
    assert zeta < 1.0
    wd = wn * math.sqrt(1.0 - zeta ** 2)
    t_max = math.atan2(wd, zeta * wn) / wd
    return v0 / wd * math.exp(-zeta * wn * t_max) * math.sin(wd * t_max), t_max


def test_simplified_model_matches_closed_form_maximum():
    v0 = 6.86 * 564 / 5600
    x_max, t_max = damped_oscillator_maximum(5600.0, 27500.0, 6239.0, v0)
    result = simulate(simplified_model(), 10.0)
    assert result.max_barrel_displacement == pytest.approx(x_max, rel=1e-6)
    assert result.time_of_max_barrel_displacement == pytest.approx(t_max, rel=1e-5)
    assert round(x_max, 4) == 0.2215  # the paper's Table 2 value for the simplified model


@pytest.mark.parametrize("factory", [model_i, model_ii], ids=["model-i", "model-ii"])
def test_python_and_symbolic_user_functions_agree(factory):
    scene = factory(500.0, 0.02)
    symbolic = simulate(scene, 3.0, user_functions="symbolic")
    python = simulate(scene, 3.0, user_functions="python")
    for name in ("max_barrel_displacement", "peak_contact_force", "max_absorber_velocity",
                 "time_of_max_barrel_displacement", "time_of_peak_contact_force"):
        assert getattr(python, name) == pytest.approx(getattr(symbolic, name), rel=1e-9), name
    assert len(python.time) == len(symbolic.time)
    np.testing.assert_allclose(python.barrel_position, symbolic.barrel_position, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(python.contact_force, symbolic.contact_force, rtol=1e-9, atol=1e-6)


@pytest.mark.parametrize("accuracy", list(ACCURACY_PRESETS))
def test_presets_run_and_report_complete_results(accuracy):
    result = simulate(model_ii(1000.0, 0.0), 2.0, accuracy)
    assert result.settings == ACCURACY_PRESETS[accuracy]
    assert result.time[0] == 0.0 and result.time[-1] == pytest.approx(2.0)
    assert np.all(np.diff(result.time) > 0)
    assert np.all(result.contact_force >= 0.0)
    assert result.impacts, "model (ii) at gap 0 is hit at once"
    assert result.peak_contact_force == pytest.approx(max(i.peak_force for i in result.impacts))
    for first, second in zip(result.impacts, result.impacts[1:]):
        assert first.end < second.start
    assert all(i.start <= i.time_of_peak_force <= i.end and i.peak_force > 1000.0 for i in result.impacts)


def test_simplified_result_has_no_contact_quantities():
    result = simulate(simplified_model(), 1.0)
    assert result.contact_force is None and result.absorber_position is None
    assert result.peak_contact_force is None and result.max_absorber_velocity is None
    assert result.impacts == []
    assert set(result.dissipated_energy) == {"recoil_damper"}


def test_refined_peak_beats_the_raw_sample_maximum():
    """At draft accuracy the refined peak is closer to a reference-accuracy peak than the raw samples."""
    scene = model_ii(1000.0, 0.0)
    truth = simulate(scene, 0.05, "reference").peak_contact_force
    draft = simulate(scene, 0.05, "draft")
    raw = float(draft.contact_force.max())
    assert abs(draft.peak_contact_force - truth) < abs(raw - truth)
    assert abs(draft.peak_contact_force - truth) / truth < 1e-3


def test_impact_threshold_filters_episodes():
    scene = model_ii(1000.0, 0.0)
    few = simulate(scene, 10.0, impact_threshold=20e3)
    many = simulate(scene, 10.0, impact_threshold=1e3)
    assert 0 < len(few.impacts) < len(many.impacts)
    assert all(i.peak_force > 20e3 for i in few.impacts)


def test_energy_is_accounted_for():
    result = simulate(model_i(1000.0, 0.04), 10.0)
    e0 = result.scene.initial_kinetic_energy
    assert np.max(np.abs(result.energy_error())) < 1e-3 * e0
    assert all(history[-1] >= 0 for history in result.dissipated_energy_history.values())
    # after 10 s almost everything has been dissipated
    assert result.total_dissipated_energy == pytest.approx(e0, rel=1e-3)


@pytest.mark.parametrize("kwargs, key", [
    ({"end_time": 0.0}, "end_time"), ({"end_time": -1.0}, "end_time"), ({"end_time": math.inf}, "end_time"),
    ({"end_time": 1e9}, "end_time"), ({"accuracy": "perfect"}, "accuracy"),
    ({"impact_threshold": -1.0}, "impact_threshold"), ({"user_functions": "fortran"}, "user_functions"),
])
def test_bad_arguments_are_scene_errors(kwargs, key):
    with pytest.raises(SceneError) as info:
        simulate(model_ii(), **kwargs)
    assert info.value.key == key


@pytest.mark.parametrize("settings, key", [
    (dict(solver="Euler"), "solver"), (dict(relative_tolerance=0.0), "relative_tolerance"),
    (dict(max_step=math.nan), "max_step"), (dict(solver="RK44", step=None), "step"),
    (dict(solver="RK44", step=5.0), "step"),
])
def test_bad_solver_settings(settings, key):
    with pytest.raises(SceneError) as info:
        SolverSettings(**settings)
    assert info.value.key == key


def test_exception_in_python_user_function_is_a_simulation_error(monkeypatch):
    def broken(*args, **kwargs):
        raise ZeroDivisionError("deliberate failure inside the contact law")

    monkeypatch.setattr(contact_laws, "law_force", broken)
    with pytest.raises(SimulationError, match="deliberate failure"):
        simulate(model_ii(), 0.1, user_functions="python")


def test_nan_from_user_function_is_a_simulation_error(monkeypatch):
    original = recoil_damper.recoil_damper_force

    def poisoned(velocity, damper, ops=PYTHON_OPS):
        value = original(velocity, damper, ops)
        return math.nan if velocity < 0 else value

    monkeypatch.setattr(recoil_damper, "recoil_damper_force", poisoned)
    with pytest.raises(SimulationError, match="non-finite"):
        simulate(simplified_model(), 2.0, user_functions="python")


def test_fixed_step_solver_runs():
    result = simulate(simplified_model(), 2.0, SolverSettings(solver="RK44", step=1e-3))
    x_max, _ = damped_oscillator_maximum(5600.0, 27500.0, 6239.0, 6.86 * 564 / 5600)
    assert result.max_barrel_displacement == pytest.approx(x_max, rel=1e-8)


def test_chattering_contact_fails_clearly_instead_of_running_for_hours():
    """compression_only on model (ii) sticks at maximum compression: the force switches every step."""
    from mbs_models import Conventions

    scene = model_ii(1000.0, 0.0, Conventions(compression_only=True))
    with pytest.raises(SimulationError, match="step budget"):
        simulate(scene, 1.0)


@pytest.mark.parametrize("factory", [simplified_model, model_ii])
def test_solver_that_stops_early_with_success_is_a_simulation_error(monkeypatch, factory):
    """Exudyn told to stop at half the end time returns success; that must not pass as a result."""
    import mbs_models.engine.driver as driver

    original = driver.exudyn_simulation_settings

    def stopping_halfway(settings, end_time, start_time=0.0):
        ss = original(settings, end_time, start_time)
        ss.timeIntegration.endTime = 0.5 * end_time
        return ss

    monkeypatch.setattr(driver, "exudyn_simulation_settings", stopping_halfway)
    with pytest.raises(SimulationError, match="stopped early at t = 0.5 s"):
        simulate(factory(), 1.0)


def test_the_docstring_example_of_simulate_holds():
    """help(simulate) shows an example: its printed numbers are the library's."""
    import doctest

    from mbs_models.engine import simulation

    finder = doctest.DocTestFinder()
    [test] = [t for t in finder.find(simulation.simulate, "simulate", globs={}) if t.examples]
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    runner.run(test)
    assert runner.summarize(verbose=False).failed == 0 and len(test.examples) >= 3


# ------------------------------------------------------------------ bounds (issue #20): every run ends


def _contact_free_scenes():
    from mbs_models import load_scene
    from mbs_models.engine.mechanism import Mechanism
    from mbs_models.scenes import list_scenes, scene_path

    return [pytest.param(load_scene(scene_path(name)), id=name) for name in list_scenes()
            if not Mechanism(load_scene(scene_path(name))).contacts]


@pytest.mark.parametrize("scene", _contact_free_scenes())
def test_the_budget_of_a_scene_without_contact_changes_no_result(scene, monkeypatch, assert_results_identical):
    """Every adaptive solve now counts its steps in a pre-step function; without it (as before issue #20) every
    contact-free shipped scene gives the same Result, bit for bit."""
    import mbs_models.engine.run_policy as engine

    budgeted = simulate(scene, 3.0)
    assert budgeted.steps > 0
    monkeypatch.setattr(engine.StepBudget, "for_run", classmethod(lambda cls, end_time, sensors: None))
    monkeypatch.setattr(engine, "check_time_scales", lambda *args: None)
    assert_results_identical(budgeted, simulate(scene, 3.0))


def test_a_scene_without_contact_is_stopped_by_the_step_budget_naming_its_stiff_spring(monkeypatch):
    """The budget bounds contact-free solves too (a stiff spring the up-front check lets through, a budget of
    500 steps for the 2000 this run takes); the message names what is fast."""
    import mbs_models.engine.guard as guard
    import mbs_models.engine.run_policy as engine
    from mbs_models.scene.overrides import apply_overrides

    monkeypatch.setattr(guard, "MINIMUM_STEP_BUDGET", 500)
    monkeypatch.setattr(guard, "STEPS_PER_SIMULATED_SECOND", 0)
    monkeypatch.setattr(engine, "check_time_scales", lambda *args: None)
    with pytest.raises(SimulationError) as info:
        simulate(apply_overrides(simplified_model(), {"recoil_spring.stiffness": 1e11}), 1.0)
    message = str(info.value)
    assert "step budget of 500 steps" in message
    assert "recoil_spring.stiffness = 1e+11 N/m on 5600 kg gives a period of 0.0015 s" in message


def test_stored_samples_are_capped_and_a_run_beyond_the_cap_fails_saying_so(monkeypatch):
    """Model (ii) stores seven sensors; with room for 100 samples a 2 s draft run (some 140 steps) fails naming the
    cap, with room for 2000 it passes holding fewer samples than the cap."""
    import mbs_models.engine.guard as guard

    scene = model_ii(1000.0, 0.0)
    monkeypatch.setattr(guard, "MAX_STORED_VALUES", 7 * 2000)
    result = simulate(scene, 2.0, "draft")
    assert 100 < len(result.time) <= 2000 and result.steps <= 2000
    monkeypatch.setattr(guard, "MAX_STORED_VALUES", 7 * 100)
    with pytest.raises(SimulationError, match="reached its cap of 100 samples"):
        simulate(scene, 2.0, "draft")


def test_a_fixed_step_run_with_many_sensors_is_thinned_to_the_cap(monkeypatch):
    import mbs_models.engine.guard as guard

    monkeypatch.setattr(guard, "MAX_STORED_VALUES", 3 * 500)  # the simplified model: three sensors
    result = simulate(simplified_model(), 2.0, SolverSettings(solver="RK44", step=1e-3))  # 2000 steps
    assert len(result.time) <= 501 and result.time[-1] == pytest.approx(2.0)


@pytest.mark.parametrize("key, value", [("recoil_brake.discharge_coefficient", 1e-30),
                                        ("recoil_brake.orifice_area", 1e-30),
                                        ("recoil_brake.fluid_density", 1e300)])
def test_a_brake_absurdly_stiff_fails_clearly_within_the_budget(key, value):
    """Issue #20: these ran for ever (Ctrl-C ended them as a failed solve); now the budget's stall window stops them
    (two solves of 20 000 steps at most) with a message pointing at the brake and extreme values."""
    from mbs_models import load_scene
    from mbs_models.scene.overrides import apply_overrides
    from mbs_models.scenes import scene_path

    with pytest.raises(SimulationError) as info:
        simulate(apply_overrides(load_scene(scene_path("recoil_brake")), {key: value}), 0.5)
    assert "step size collapsed" in str(info.value) and "recoil brake's v|v|" in str(info.value)


#: The extreme values issue #20 reported (each ran without end, or ended in an unclear error).
REPORTED_EXTREMES = [("firing.muzzle_velocity", 1e30), ("recoil_spring.stiffness", 1e19),
                     ("cradle.friction_coefficient", 1e300), ("recoil_damper.recoil", 1e30),
                     ("recoil_brake.orifice_area", 1e-30), ("recoil_brake.discharge_coefficient", 1e-30),
                     ("recoil_brake.fluid_density", 1e300), ("absorber.damping", 1e30),
                     ("absorber.stiffness", 1e19)]


def _reported_extremes():
    """Each reported value on each shipped scene that has its table."""
    from mbs_models import load_scene
    from mbs_models.scenes import list_scenes, scene_path

    cases = []
    for name in list_scenes():
        scene = load_scene(scene_path(name))
        tables = {key for key, _ in scene.tables()}
        cases += [pytest.param(name, key, value, id=f"{name}-{key}") for key, value in REPORTED_EXTREMES
                  if key.split(".")[0] in tables]
    return cases


@pytest.mark.slow
@pytest.mark.parametrize("name, key, value", _reported_extremes())
def test_every_reported_extreme_ends_within_a_bound(name, key, value):
    """Each value issue #20 reported, on each shipped scene that has its table: a result, a SceneError (the scene's or
    before the solve) or a one-line SimulationError -- never a run without end (a generous 60 s, a guard, not a speed test)."""
    import time
    import warnings

    from mbs_models import load_scene
    from mbs_models.scene.overrides import apply_overrides
    from mbs_models.scenes import scene_path

    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:  # the scene itself may refuse the value (SceneError)
            result = simulate(apply_overrides(load_scene(scene_path(name)), {key: value}), 0.5)
            assert np.all(np.isfinite(result.time))
        except (SceneError, SimulationError) as error:
            assert str(error).strip() and "\n" not in str(error)
    assert time.perf_counter() - start < 60.0
