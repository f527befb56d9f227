"""The step budget that stops collapsing adaptive solves (mbs_models.engine.guard)."""

import pytest

from mbs_models.engine.guard import (MAX_STORED_VALUES, MINIMUM_STEP_BUDGET, STALL_WINDOW_STEPS, STALL_WINDOW_TIME,
                                     StepBudget, sample_cap, step_budget)


def test_budget_grows_with_end_time_and_has_a_floor():
    assert step_budget(0.001) == MINIMUM_STEP_BUDGET
    assert step_budget(100.0) > step_budget(10.0) >= MINIMUM_STEP_BUDGET


def test_budget_stops_after_max_steps_and_explains():
    budget = StepBudget(3)
    assert [budget(None, 0.1 * i) for i in range(1, 6)] == [True, True, True, False, False]
    assert budget.exhausted_at == 0.4
    assert "step budget of 3 steps" in budget.explanation("DOPRI5", 1.0)


def test_stall_is_detected_long_before_the_budget():
    from mbs_models.engine.guard import STALL_WINDOW_STEPS, STALL_WINDOW_TIME

    budget = StepBudget(10 * STALL_WINDOW_STEPS)
    step = 0.5 * STALL_WINDOW_TIME / STALL_WINDOW_STEPS  # (five times the collapse's mean step: not a collapse)
    results = [budget(None, i * step) for i in range(1, STALL_WINDOW_STEPS + 2)]
    assert results[STALL_WINDOW_STEPS - 2] is True and results[STALL_WINDOW_STEPS - 1] is False
    assert budget.stalled and "step size collapsed" in budget.explanation("DOPRI5", 1.0)


def test_steady_small_steps_are_not_a_stall():
    from mbs_models.engine.guard import STALL_WINDOW_STEPS, STALL_WINDOW_TIME

    budget = StepBudget(10 * STALL_WINDOW_STEPS)
    step = 2.0 * STALL_WINDOW_TIME / STALL_WINDOW_STEPS
    assert all(budget(None, i * step) for i in range(1, 3 * STALL_WINDOW_STEPS))
    assert not budget.stalled


@pytest.mark.parametrize("max_steps, step_of", [
    (3, lambda i: 0.1 * i),                                                   # spent after 3 steps
    (10 * STALL_WINDOW_STEPS, lambda i: 0.1 * STALL_WINDOW_TIME / STALL_WINDOW_STEPS * i),  # a stall
    (3 * STALL_WINDOW_STEPS + 7, lambda i: 2.0 * STALL_WINDOW_TIME / STALL_WINDOW_STEPS * i),  # spent, no stall
    (10 * STALL_WINDOW_STEPS, lambda i: STALL_WINDOW_TIME / STALL_WINDOW_STEPS
     * (2.0 * min(i, STALL_WINDOW_STEPS) + 0.1 * max(i - STALL_WINDOW_STEPS, 0))),  # a stall in the 2nd window
    (10 * STALL_WINDOW_STEPS, lambda i: STALL_WINDOW_TIME / STALL_WINDOW_STEPS
     * (2.0 * min(i, 5000) + 1e-3 * max(i - 5000, 0))),  # a collapse after 5000 steps
])
def test_advancing_at_the_checkpoints_only_is_calling_at_every_step(max_steps, step_of):
    """The pre-step function calls advance() only at next_check: the budget must end in the same state, at
    the same step, as one called at every step."""
    every, checkpoints = StepBudget(max_steps), StepBudget(max_steps)
    for i in range(1, max_steps + 2 * STALL_WINDOW_STEPS):
        expected = every(None, step_of(i))
        if i >= checkpoints.next_check:
            assert checkpoints.advance(i, step_of(i)) is expected
        else:  # between checkpoints a call only counts
            assert expected is True
        if not expected:
            break
    assert not expected
    assert (checkpoints.steps, checkpoints.exhausted_at, checkpoints.stalled) == \
        (every.steps, every.exhausted_at, every.stalled)


def test_the_sample_cap_divides_the_stored_values_among_the_sensors():
    assert sample_cap(7) == MAX_STORED_VALUES // 7
    assert sample_cap(3) * 3 <= MAX_STORED_VALUES < (sample_cap(3) + 1) * 3
    assert sample_cap(0) == MAX_STORED_VALUES and sample_cap(10 * MAX_STORED_VALUES) == 1


def test_a_run_gets_the_smaller_of_the_step_budget_and_the_sample_cap():
    few = StepBudget.for_run(1.0, 3)  # 200 000 steps < 3.3 million samples: the step budget binds
    assert (few.max_steps, few.capped) == (step_budget(1.0), False)
    many = StepBudget.for_run(1000.0, 7)  # 5e7 steps > 1.4 million samples: the cap binds
    assert (many.max_steps, many.capped) == (MAX_STORED_VALUES // 7, True)
    assert StepBudget(10).max_steps == 10 and not StepBudget(10).capped


def test_a_capped_budget_says_the_output_cap_stopped_it_and_what_to_change():
    budget = StepBudget(100, stored_samples=3)
    assert [budget(None, 0.1 * i) for i in range(1, 6)] == [True, True, True, False, False]
    text = budget.explanation("DOPRI5", 10.0, "Hint.")
    assert "cap of 3 samples" in text and "shorter window" in text and "step budget of" not in text
    assert text.endswith(". Hint.")


def test_the_explanation_ends_with_the_scene_s_hint_or_the_chattering_contact():
    budget = StepBudget(2)
    for i in range(1, 4):
        budget(None, 0.1 * i)
    assert budget.explanation("ODE23", 1.0, "The spring is stiff.").endswith("spent (mean step 0.15 s). "
                                                                           "The spring is stiff.")
    assert "chattering" in budget.explanation("ODE23", 1.0)


def test_a_collapse_is_stopped_after_the_shorter_window():
    """Steps of a tenth of the collapse's mean step: stopped after COLLAPSE_WINDOW_STEPS steps (not the stall's
    20 000), and the explanation names the shorter window."""
    from mbs_models.engine.guard import COLLAPSE_WINDOW_STEPS, COLLAPSE_WINDOW_TIME

    assert STALL_WINDOW_STEPS % COLLAPSE_WINDOW_STEPS == 0
    assert COLLAPSE_WINDOW_TIME / COLLAPSE_WINDOW_STEPS < STALL_WINDOW_TIME / STALL_WINDOW_STEPS  # a smaller mean step
    budget = StepBudget(10 * STALL_WINDOW_STEPS)
    step = 0.1 * COLLAPSE_WINDOW_TIME / COLLAPSE_WINDOW_STEPS
    results = [budget(None, i * step) for i in range(1, COLLAPSE_WINDOW_STEPS + 2)]
    assert results[COLLAPSE_WINDOW_STEPS - 2] is True and results[COLLAPSE_WINDOW_STEPS - 1] is False
    assert budget.stalled and budget.collapsed
    assert f"{COLLAPSE_WINDOW_STEPS} steps advanced less than {COLLAPSE_WINDOW_TIME:g} s" in \
        budget.explanation("DOPRI5", 1.0)


def test_steps_between_the_collapse_and_the_stall_are_left_to_the_stall_window():
    """A mean step between the two windows' (3e-8 s): not a collapse; the stall window stops it, as before."""
    from mbs_models.engine.guard import COLLAPSE_WINDOW_STEPS, COLLAPSE_WINDOW_TIME

    step = 3.0 * COLLAPSE_WINDOW_TIME / COLLAPSE_WINDOW_STEPS
    assert step < STALL_WINDOW_TIME / STALL_WINDOW_STEPS
    budget = StepBudget(10 * STALL_WINDOW_STEPS)
    results = [budget(None, i * step) for i in range(1, STALL_WINDOW_STEPS + 2)]
    assert all(results[:STALL_WINDOW_STEPS - 1]) and results[STALL_WINDOW_STEPS - 1] is False
    assert budget.stalled and not budget.collapsed
    assert f"{STALL_WINDOW_STEPS} steps advanced less than" in budget.explanation("DOPRI5", 1.0)


def _outcome(scene, end_time: float, accuracy: str, **options):
    """How a run ends: ("ok", stop reason, steps, max barrel displacement) or ("failed", stalled or not)."""
    import warnings

    from mbs_models import simulate
    from mbs_models.errors import SimulationError

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            result = simulate(scene, end_time, accuracy, **options)
        except SimulationError as error:
            return ("failed", "step size collapsed" in str(error))
    return ("ok", result.stop_reason, result.steps, result.max_barrel_displacement)


def _every_case():
    """(name, scene, end time, accuracy, options): the hard cases and the 19 paper cases at every preset, and
    every reading of the convention study as ``recoil paper`` runs it (standard, stopped once final)."""
    from validation.studies.conventions import STUDIED_METRICS, convention_jobs
    from validation.studies.hard_cases import HARD_CASES
    from validation.studies.precision import paper_cases

    for accuracy in ("draft", "standard", "reference"):
        for case in HARD_CASES:
            yield f"{case.name} {accuracy}", case.scene, case.end_time, accuracy, {}
        for name, scene in paper_cases():
            yield f"{name} {accuracy}", scene, 10.0, accuracy, {}
    for index, key, scene in convention_jobs():
        yield f"reading {index} {key}", scene, 10.0, "standard", {"stop_when_final": STUDIED_METRICS}


@pytest.mark.slow
def test_every_hard_and_paper_case_ends_as_without_the_collapse_window(monkeypatch):
    """The collapse window only stops sooner what the stall window stopped: every hard case, paper case and
    reading of the paper ends the same way with it and without it (the same stop reason, steps and maximum; or
    failed as a stalled step both ways)."""
    import mbs_models.engine.guard as guard

    differ, collapsed = [], 0
    for name, scene, end_time, accuracy, options in _every_case():
        now = _outcome(scene, end_time, accuracy, **options)
        with monkeypatch.context() as patch:
            patch.setattr(guard, "COLLAPSE_WINDOW_TIME", 0.0)  # never a collapse: the stall window alone
            before = _outcome(scene, end_time, accuracy, **options)
        collapsed += now[0] == "failed"
        if now != before:
            differ.append((name, now, before))
    assert not differ
    assert collapsed >= 5  # the compression_only reading's model (ii) cases at least (the window is exercised)


def test_the_compression_only_reading_is_stopped_by_the_collapse_window():
    """The paper's ``compression_only`` reading on model (ii) (a contact that switches off at every step while the
    springs push the bodies together: the step collapses to 1e-10 to 8e-9 s, measured) fails after 2000 steps of the
    first solve and 2000 of the re-solve with absolute error control, each well inside the stall window's 20 000."""
    from mbs_models import Conventions, model_ii, simulate
    from mbs_models.engine.guard import COLLAPSE_WINDOW_STEPS, COLLAPSE_WINDOW_TIME
    from mbs_models.errors import SimulationError

    scene = model_ii(1000.0, 0.0, Conventions(compression_only=True))
    with pytest.raises(SimulationError, match=f"the step size collapsed: {COLLAPSE_WINDOW_STEPS} steps advanced "
                                              f"less than {COLLAPSE_WINDOW_TIME:g} s"):
        simulate(scene, 10.0, "standard", stop_when_final=("max_barrel_displacement",))
