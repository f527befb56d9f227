"""The always-acting time scales and the up-front refusal of runs they make too long (mbs_models.engine.time_scales).

Expected rates are the closed forms of the module docstring worked by hand: ``sqrt(k / m)`` for a spring and
``c / (2 m)`` for a damper on the reduced mass of their ends; step counts ``duration x rate / 4``.
"""

from __future__ import annotations

import math

import pytest

from mbs_models import SceneError, load_scene, model_i, simplified_model, simulate
from mbs_models.engine import simulation
from mbs_models.engine.accuracy import solver_settings_for
from mbs_models.engine.guard import StepBudget
from mbs_models.engine.mechanism import Mechanism
from mbs_models.engine.rest import CHECK_INTERVAL, RestWatch
from mbs_models.engine.time_scales import always_acting_time_scales, check_time_scales, time_scale_hint
from mbs_models.scene.overrides import apply_overrides
from mbs_models.scenes import list_scenes, scene_path

M = 5600.0  # the paper's barrel, kg


def scales_of(scene):
    return {s.key: s for s in always_acting_time_scales(Mechanism(scene))}


def test_the_simplified_model_s_spring_and_damper_by_hand():
    scales = scales_of(simplified_model())
    assert set(scales) == {"recoil_spring.stiffness", "recoil_damper.counter_recoil"}  # the larger coefficient
    spring, damper = scales["recoil_spring.stiffness"], scales["recoil_damper.counter_recoil"]
    assert spring.rate == pytest.approx(math.sqrt(27500.0 / M), rel=1e-12) and spring.stiffness
    assert damper.rate == pytest.approx(14050.0 / (2 * M), rel=1e-12) and not damper.stiffness
    fastest_first = [s.key for s in always_acting_time_scales(Mechanism(simplified_model()))]
    assert fastest_first == ["recoil_spring.stiffness", "recoil_damper.counter_recoil"]  # 2.2 1/s, then 1.25 1/s


def test_an_absorber_on_the_barrel_moves_on_the_reduced_mass_and_its_faster_law_is_named():
    scales = scales_of(model_i(1000.0, 0.0))
    reduced = M * 1000.0 / (M + 1000.0)
    assert scales["absorber.stiffness"].rate == pytest.approx(math.sqrt(13500.0 / reduced), rel=1e-12)
    assert scales["absorber.stiffness"].mass == pytest.approx(reduced, rel=1e-12)
    damped = scales_of(model_i(1000.0, 0.0).with_changes(**{"absorber.damping": 1e7}))
    assert "absorber.stiffness" not in damped  # c / 2m = 5893 1/s beats sqrt(k / m) = 4 1/s
    assert damped["absorber.damping"].rate == pytest.approx(1e7 / (2 * reduced), rel=1e-12)


def test_several_absorbers_are_named_by_their_table_keys():
    scales = scales_of(load_scene(scene_path("two_absorbers")))
    front, rear = scales["absorber.0.stiffness"], scales["absorber.1.stiffness"]  # ground-mounted: their own mass
    assert front.rate == pytest.approx(math.sqrt(8100.0 / 600.0), rel=1e-12)
    assert rear.rate == pytest.approx(math.sqrt(5400.0 / 400.0), rel=1e-12)


@pytest.mark.parametrize("name, keys", [
    ("recoil_brake", {"recoil_spring.stiffness"}),  # the brake's v|v| is stiff only while fast
    ("cradle", {"recoil_spring.stiffness", "recoil_damper.counter_recoil"}),  # friction: only while stuck
    ("model_ii", {"recoil_spring.stiffness", "recoil_damper.counter_recoil", "absorber.stiffness"}),  # not the contact
])
def test_contacts_the_brake_and_friction_are_left_to_the_budget(name, keys):
    assert set(scales_of(load_scene(scene_path(name)))) == keys


def test_a_spring_too_stiff_for_the_window_is_refused_with_its_period_the_steps_and_the_largest_that_fits():
    scene = apply_overrides(simplified_model(), {"recoil_spring.stiffness": 1e19})
    budget = StepBudget.for_run(0.5, 3)  # 200 000 steps
    with pytest.raises(SceneError) as info:
        check_time_scales(Mechanism(scene), budget, 0.5)
    assert info.value.key == "recoil_spring.stiffness"
    message = info.value.message
    assert "period of 1.5e-07 s" in message  # 2 pi sqrt(5600 / 1e19) = 1.487e-7 s
    assert "at least 5.3e+06 steps" in message  # 0.5 s x 4.226e7 1/s / 4
    assert "200000 steps" in message and "at most 1.43e+16 N/m fits" in message  # 5600 (4 x 2e5 / 0.5)^2
    largest = M * (4.0 * 200_000 / 0.5) ** 2
    check_time_scales(Mechanism(apply_overrides(simplified_model(), {"recoil_spring.stiffness": 0.999 * largest})),
                      budget, 0.5)  # just below: accepted
    with pytest.raises(SceneError):
        check_time_scales(Mechanism(apply_overrides(simplified_model(), {"recoil_spring.stiffness": 1.001 * largest})),
                          budget, 0.5)


def test_a_damper_too_stiff_is_refused_by_simulate_before_any_solve(monkeypatch):
    def no_solve(*args, **kwargs):
        raise AssertionError("assembled: the refusal must come first")

    monkeypatch.setattr(simulation.FreshModels, "acquire", no_solve)
    scene = apply_overrides(simplified_model(), {"recoil_damper.recoil": 1e30})
    with pytest.raises(SceneError) as info:
        simulate(scene, 0.5)
    assert info.value.key == "recoil_damper.recoil" and "time constant of 1.1e-26 s" in info.value.message  # 2M/c
    assert "at most 1.79e+10 N s/m fits" in info.value.message  # 2 x 5600 x (4 x 2e5 / 0.5)


def test_a_run_that_may_stop_at_rest_or_once_final_is_counted_over_what_it_surely_integrates():
    """A spring of period ~1 ms on a 1e4-s window: 2.5e7 steps over the window (more than the 1.4 million samples
    of model (ii)'s seven sensors), 2.5e5 over the first rest check: refused only where the run cannot stop."""
    scene = apply_overrides(load_scene(scene_path("model_ii")), {"recoil_spring.stiffness": M * 5000.0 ** 2})
    mechanism = Mechanism(scene)
    settings = solver_settings_for("standard", None)
    rest = RestWatch.of(mechanism, settings.absolute_tolerance, 1e4)
    assert rest is not None
    simulation._check_bounds(mechanism, settings, 1e4, None, rest)  # over its first CHECK_INTERVAL: fits
    with pytest.raises(SceneError) as info:
        simulation._check_bounds(mechanism, settings, 1e4, None, None)  # no rest stop: the whole window
    assert info.value.key == "recoil_spring.stiffness" and "samples a run may store" in info.value.message
    assert 5000.0 * CHECK_INTERVAL / 4.0 < StepBudget.for_run(1e4, mechanism.sensor_count).max_steps


@pytest.mark.parametrize("name", list_scenes())
def test_no_shipped_scene_is_refused_over_long_windows(name):
    mechanism = Mechanism(load_scene(scene_path(name)))
    for end_time in (0.1, 10.0, 1e4):
        check_time_scales(mechanism, StepBudget.for_run(end_time, mechanism.sensor_count), end_time)


def test_the_hint_names_what_may_be_stiff():
    stiff = Mechanism(apply_overrides(simplified_model(), {"recoil_spring.stiffness": 1e11}))
    assert "recoil_spring.stiffness = 1e+11 N/m on 5600 kg gives a period of 0.0015 s" in time_scale_hint(stiff)
    plain = time_scale_hint(Mechanism(load_scene(scene_path("recoil_brake"))))
    assert plain.startswith("No linear spring or damper of the scene is that fast") and "(here: recoil_brake)" in plain
    assert "(here: cradle)" in time_scale_hint(Mechanism(load_scene(scene_path("cradle"))))
    assert "chattering" in time_scale_hint(Mechanism(load_scene(scene_path("model_ii"))))
