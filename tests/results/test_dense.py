"""mbs_models/results/dense.py: histories on a fine grid from the step-end samples' interpolant and the laws."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from mbs_models import SceneError, SolverSettings, model_i, model_ii, simulate
from mbs_models.cli import _resolve_scene
from mbs_models.results.dense import INTERVAL_RANGE, check_interval, default_interval, dense_times
from mbs_models.results.histories import history_columns
from validation.studies.guarantee import TOLERANCES


def test_the_dense_times_keep_every_sample_and_split_longer_steps_evenly():
    """Steps of 2.5 ms and 7 ms at 1 ms are split into ceil(h / 1 ms) = 3 and 7 equal parts; the zero-length step
    of a shot and the 0.5 ms step get nothing; a step from the held rest state on gets nothing either."""
    time = np.array([0.0, 0.0025, 0.0025, 0.003, 0.01, 0.02])
    times, rows = dense_times(time, 1e-3, held_from=0.01)
    expected = np.concatenate([[0.0, 0.0025 / 3, 0.005 / 3], [0.0025, 0.0025, 0.003],
                               0.003 + 0.001 * np.arange(1, 7), [0.01, 0.02]])
    np.testing.assert_allclose(times, expected, rtol=0, atol=1e-18)
    assert list(rows) == [0, 3, 4, 5, 12, 13] and np.array_equal(times[rows], time)
    unheld, _ = dense_times(time, 1e-3)
    assert len(unheld) == len(times) + 9  # the last 10 ms step in 10 parts


@pytest.mark.parametrize("interval", [1e-3, 7e-4, 2.5e-5])
def test_no_gap_exceeds_the_interval(interval):
    """Random steps up to 20 ms: every gap at most the interval, up to the rounding of the times (a few ulp of
    the largest time, 1 s here: 1e-15 s)."""
    rng = np.random.default_rng(3)
    time = np.concatenate([[0.0], np.cumsum(rng.uniform(1e-5, 2e-2, 200))])
    times, rows = dense_times(time, interval)
    assert np.max(np.diff(times)) <= interval + 1e-15 and np.all(np.diff(times) > 0)
    assert np.array_equal(times[rows], time)


def test_the_default_interval_is_1_ms_finer_for_short_windows_and_coarser_for_very_long_ones():
    assert default_interval(10.0) == 1e-3 and default_interval(1000.0) == 1e-3
    assert default_interval(0.5) == 0.5 / 2000 and default_interval(1e4) == 1e4 / 1e6


@pytest.mark.parametrize("bad", [0.0, -1e-3, 2.0, 1e-6, math.nan, math.inf, "fast", None, True])
def test_an_interval_out_of_range_is_refused_on_one_line_naming_the_key_and_the_range(bad):
    with pytest.raises(SceneError) as error:
        check_interval(bad, key="--history-interval")
    message = str(error.value)
    assert message.startswith("--history-interval: ") and "\n" not in message
    assert f"from {INTERVAL_RANGE[0]:g} to {INTERVAL_RANGE[1]:g} s" in message


def test_an_interval_in_range_is_taken():
    assert check_interval(1e-5) == 1e-5 and check_interval(1) == 1.0 and check_interval("0.002") == 0.002


_RUNS: dict = {}


def _run(name: str):
    """A 1 s draft run of a shipped scene (or of the scene of every element), once for the module."""
    if name not in _RUNS:
        _RUNS[name] = simulate(_resolve_scene(name), 1.0, "draft")
    return _RUNS[name]


SCENES = ("model_ii", "burst", "contact_exact_restitution", "towed_howitzer_45", "breech_pulse", "end_stops")


@pytest.mark.parametrize("name", SCENES)
def test_at_the_samples_every_history_is_the_step_end_one_and_the_metrics_stay(name):
    """Every column of the history table at the sample rows is the step-end Result's, bit for bit (the same laws
    on the same samples in this process); the metrics, the time to battery and the summary are the step-end
    Result's; steps of 20 ms are filled to 1 ms."""
    result = _run(name)
    dense = result.densified(1e-3)
    times, rows = dense_times(result.time, 1e-3)
    assert np.array_equal(dense.time, times) and dense.step_ends is result
    assert np.max(np.diff(result.time)) > 5e-3 and np.max(np.diff(dense.time)) <= 1e-3 + 1e-15
    sampled, densified = history_columns(result), history_columns(dense)
    assert list(sampled) == list(densified)
    for column, values in sampled.items():
        assert np.array_equal(densified[column][rows], values), column
    assert dense.metrics() == result.metrics() and dense.time_to_battery == result.time_to_battery
    assert dense.summary() == result.summary()
    assert dense.densified(1e-3).time.shape == dense.time.shape  # again from the step ends, not the dense values


def test_a_densified_result_keeps_the_step_end_interpolant_for_state_at():
    result = _run("model_ii")
    t = np.linspace(0.0, 1.0, 777)
    for ours, theirs in zip(result.densified().state_at(t), result.state_at(t)):
        for name in theirs:
            assert np.array_equal(ours[name], theirs[name])


def test_a_result_crossing_processes_keeps_its_laws():
    """Pickled (a report's runs come back from worker processes), a run whose contact captured its onset rate
    (a symbolic variable while it solved) densifies to the same histories."""
    result = _run("contact_exact_restitution")
    assert any(getattr(c, "capture", None) is not None for c in result.mechanism.connectors)
    back = pickle.loads(pickle.dumps(result))
    for column, values in history_columns(result.densified()).items():
        assert np.array_equal(history_columns(back.densified())[column], values), column


def test_a_contact_force_between_samples_is_its_law_on_the_interpolated_state():
    """Model (i)'s contact (gap 0, impact at t = 0): between the samples the force is Hunt-Crossley's
    ``k p^n (1 + lambda p')``, ``p = (x_M - x_m) - gap`` (DESIGN.md), written out here on the interpolated state."""
    result = simulate(model_i(1000.0, 0.0), 0.5, "draft")
    dense = result.densified(1e-4)
    _, rows = dense_times(result.time, 1e-4)
    inner = np.setdiff1d(np.arange(len(dense.time)), rows)
    contact = result.scene.absorber.contact
    p = dense.barrel_position[inner] - dense.absorber_position[inner] - contact.gap
    rate = dense.barrel_velocity[inner] - dense.absorber_velocity[inner]
    expected = np.where(p > 0, contact.stiffness * np.maximum(p, 0.0) ** contact.exponent
                        * (1.0 + contact.damping_factor * rate), 0.0)
    assert np.count_nonzero(expected) > 20
    np.testing.assert_allclose(np.maximum(dense.contact_force[inner], 0.0), np.maximum(expected, 0.0),
                               rtol=1e-12, atol=1e-9 * result.peak_contact_force)


@pytest.mark.parametrize("scene", [model_ii(1000.0, 0.0), model_i(100.0, 0.0)], ids=["ii-m1000", "i-m100"])
def test_between_the_samples_the_histories_follow_a_run_with_1_ms_steps(scene):
    """In the steps of 10 ms and more of a ``standard`` run (20 ms at most), the dense histories match a run with
    the same tolerances and a 1 ms maximum step (its own densified histories every 0.1 ms, linearly interpolated:
    off by ~h^2 a''/8, below 1e-9 of the peaks) within the preset's guarantee (``TOLERANCES["standard"]``): each
    run's trajectory is within half the ``metric`` bound of the exact one (the maximum step's rule, accuracy.md),
    so two runs differ by at most ``metric`` relative to the peak position and velocity; forces by at most
    ``force`` of their peak (their laws on those states); energies by twice ``energy`` of the initial energy (each
    run's balance within ``energy``).  Straight chords between the same samples miss the position bound."""
    bounds = TOLERANCES["standard"]
    coarse = simulate(scene, 3.0, "standard")
    fine = simulate(scene, 3.0, SolverSettings(relative_tolerance=1e-9, absolute_tolerance=1e-11, max_step=1e-3))
    dense, reference = coarse.densified(1e-3), fine.densified(1e-4)
    times, rows = dense_times(coarse.time, 1e-3)
    step = np.minimum(np.searchsorted(coarse.time, times, side="right") - 1, len(coarse.time) - 2)
    between = np.ones(len(times), dtype=bool)
    between[rows] = False
    between &= np.diff(coarse.time)[step] >= 1e-2
    assert np.count_nonzero(between) > 1000
    ours, theirs, sampled = history_columns(dense), history_columns(reference), history_columns(coarse)
    initial = theirs["kinetic energy [J]"][0]

    def error(column, values):
        expected = np.interp(times[between], reference.time, theirs[column])
        return np.max(np.abs(values[between] - expected))

    checked = 0
    for column, values in ours.items():
        if column.endswith(("position [m]", "velocity [m/s]")):
            bound = bounds["metric"] * np.max(np.abs(theirs[column]))
        elif column.endswith("force [N]"):
            bound = bounds["force"] * max(np.max(np.abs(theirs[column])), 1.0)
        elif column.endswith("[J]"):
            bound = 2 * bounds["energy"] * initial
        else:
            continue  # time; accelerations (the velocity interpolant's derivative) are not in the guarantee
        assert error(column, values) <= bound, column
        checked += 1
    assert checked >= 15
    chords = np.interp(times, coarse.time, sampled["barrel position [m]"])
    assert error("barrel position [m]", chords) > bounds["metric"] * np.max(np.abs(theirs["barrel position [m]"]))


def test_a_run_at_rest_is_not_filled_where_the_rest_state_is_held():
    """Stopped at rest, the histories hold the rest state from ``rest_time`` to the end: nothing is inserted
    there (the rows do not grow with the end time); before it, gaps of at most the interval."""
    from mbs_models import simplified_model

    result = simulate(simplified_model(), 200.0, "draft")
    assert result.rest_time is not None
    dense = result.densified(1e-3)
    before = dense.time <= result.rest_time
    assert np.max(np.diff(dense.time[before])) <= 1e-3 + 1e-13
    assert np.count_nonzero(~before) == np.count_nonzero(result.time > result.rest_time)


def test_densifying_is_left_to_the_outputs():
    """``simulate`` returns the step-end samples (sweeps and metrics never pay for densifying)."""
    result = _run("model_ii")
    assert result.step_ends is None and np.array_equal(result.time, result.samples.time)
