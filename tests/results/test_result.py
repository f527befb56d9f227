"""mbs_models/results/result.py: the end of the window and the summary's header."""

from __future__ import annotations

import pytest

from mbs_models import model_ii, simplified_model, simulate


def test_a_maximum_still_rising_at_the_end_of_the_window_is_flagged():
    short = simulate(simplified_model(), 0.05, "draft")
    assert short.barrel_velocity[-1] > 0 and short.time_of_max_barrel_displacement == short.time[-1]
    assert short.max_at_end_of_window is True
    assert short.maxima_at_end_of_window()[0] == "max_barrel_displacement"
    assert short.metrics()["max_at_end_of_window"] is True
    assert "not a turning point" in short.summary()


def test_a_turning_point_is_not_flagged():
    full = simulate(simplified_model(), 2.0, "draft")
    assert full.time_of_max_barrel_displacement < full.time[-1]
    assert full.max_at_end_of_window is False and full.maxima_at_end_of_window() == []
    assert "turning point" not in full.summary()


def test_an_unproven_maximum_has_no_flag():
    """Stopped at 0.45 s once the absorber's velocity is final: the barrel still moves out, and its maximum is
    None (not proven), not a value "at the end of the window"."""
    early = simulate(model_ii(1000.0, 0.0), 10.0, stop_when_final=("max_absorber_velocity",))
    assert early.max_barrel_displacement is None and early.barrel_velocity[-1] > 0
    assert early.max_at_end_of_window is None and "max_barrel_displacement" not in early.maxima_at_end_of_window()
    proven = simulate(model_ii(1000.0, 0.0), 10.0, stop_when_final=("peak_contact_force",))
    assert proven.max_barrel_displacement is not None and proven.max_at_end_of_window is False


def test_the_header_names_the_model_once_and_adds_it_where_the_name_lacks_it():
    scene = model_ii()
    assert simulate(scene, 0.05, "draft").summary().splitlines()[0].count("model (ii)") == 1
    renamed = scene.with_changes(name="my mechanism")
    assert simulate(renamed, 0.05, "draft").summary().splitlines()[0].startswith("my mechanism (model (ii)), ")


def test_a_run_at_rest_says_when_in_its_summary_and_metrics():
    """Stopped at rest: the header names the rest time, ``rest_note`` the proven bound, ``metrics()`` both; a run
    that did not rest has neither."""
    rested = simulate(simplified_model(), 200.0, "draft")
    header = rested.summary().splitlines()[0]
    assert f"200 s (at rest from {rested.rest_time:.6g} s)" in header
    assert rested.metrics()["rest_time"] == rested.rest_time and rested.metrics()["rest_tolerance"] == 1e-8
    assert rested.rest_note().startswith(f"at rest from t = {rested.rest_time:.6g} s (proven: every position within "
                                         "1e-08 m of its rest position and every velocity within 1e-08 m/s")
    assert not rested.maxima_at_end_of_window()
    short = simulate(simplified_model(), 2.0, "draft")
    assert short.rest_note() is None and "rest_time" not in short.metrics() and "at rest" not in short.summary()


def test_a_result_is_immutable_and_a_changed_copy_is_a_new_result():
    """Built once (issue #21): no attribute can be assigned after construction, neither the run's fields nor a
    contact's output; ``dataclasses.replace`` gives a copy and leaves the original as it was."""
    import dataclasses

    import pytest

    from mbs_models import StopReason

    result = simulate(model_ii(1000.0, 0.0), 0.3, "draft")
    assert result.stop_reason is StopReason.END_TIME and result.requested_end_time == result.end_time == 0.3
    for name, value in (("stop_reason", "metrics_final"), ("end_time", 0.1), ("max_barrel_displacement", 0.0),
                        ("wall_time", 0.0), ("final_metrics", ())):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(result, name, value)
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.contacts["contact"].peak_force = None
    longer = dataclasses.replace(result, requested_end_time=2.0)
    assert longer.requested_end_time == 2.0 and result.requested_end_time == 0.3
    assert dataclasses.replace(result, stop_reason="at_rest").stop_reason is StopReason.AT_REST  # read from its text
    with pytest.raises(ValueError):
        dataclasses.replace(result, stop_reason="stopped")


def test_state_at_gives_the_histories_at_any_sampling_interval_from_the_samples_interpolant():
    """On a 1 ms grid, the Hermite interpolant of a standard run's step-end samples (steps up to the preset's
    max step) follows the independent reference within 1e-6 of the peak position and velocity (the preset
    promises 1e-7 on the displacement's peak, 1e-5 on the absorbers' velocities); straight lines between the
    same samples do not (off by more than 1e-5): the densified output needs the interpolant, not small steps."""
    import numpy as np
    import pytest

    from mbs_models import model_i
    from validation.reference import solve_reference

    for scene in (model_ii(1000.0, 0.0), model_i(100.0, 0.04)):
        result = simulate(scene, 2.0)
        ref = solve_reference(scene, 2.0)
        t = np.arange(0.0, 2.0, 1e-3)
        positions, velocities = result.state_at(t)
        for ours, exact in ((positions["barrel"], ref.barrel_position(t)), (velocities["barrel"], ref.barrel_velocity(t))):
            assert np.max(np.abs(ours - exact)) <= 1e-6 * np.max(np.abs(exact))
        linear = np.interp(t, result.time, result.barrel_position)
        assert np.max(np.abs(linear - ref.barrel_position(t))) > 1e-5 * np.max(np.abs(ref.barrel_position(t)))
        # at the samples themselves: the samples
        distinct = np.flatnonzero(np.diff(result.time) > 0)[:50]
        at_samples, _ = result.state_at(result.time[distinct])
        assert np.array_equal(at_samples["absorber"], result.positions["absorber"][distinct])
        with pytest.raises(ValueError, match="state_at: times must lie in"):
            result.state_at([result.time[-1] + 1.0])


def test_a_single_shot_returns_to_battery_as_the_closed_form_says():
    """``time_to_battery``: the simplified model is a linear spring-damper on each side of its maximum, solved in
    closed form (tests/battery_return.py).  At ``standard`` the engine's metrics are within ~1e-7 (its claim);
    1e-6 leaves room for the crossing's refinement on the Hermite interpolant."""
    from battery_return import simplified_return

    scene = simplified_model()
    t_max, x_max, t_back = simplified_return(scene)
    result = simulate(scene, 5.0)
    assert result.max_barrel_displacement == pytest.approx(x_max, rel=1e-6)   # the closed form is this model's
    assert result.time_to_battery == pytest.approx(t_back, rel=1e-6)
    assert result.metrics()["time_to_battery"] == result.time_to_battery
    assert f"back in battery          {t_back:.5f} s" in result.summary()


def test_no_time_to_battery_before_the_barrel_is_back():
    """A window that ends before the return (the closed form's 1.79 s) gives None, not the window's end."""
    short = simulate(simplified_model(), 1.5, "draft")
    assert short.max_barrel_displacement is not None and short.time_to_battery is None
    assert "back in battery          not within the window" in short.summary()
    rising = simulate(simplified_model(), 0.05, "draft")          # the maximum is not a turning point yet
    assert rising.time_to_battery is None
