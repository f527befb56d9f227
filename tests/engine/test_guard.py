"""The step budget that stops collapsing adaptive solves (mbs_models.engine.guard)."""

import pytest

from mbs_models.engine.guard import (MINIMUM_STEP_BUDGET, STALL_WINDOW_STEPS, STALL_WINDOW_TIME, StepBudget,
                                     step_budget)


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
    step = 0.1 * STALL_WINDOW_TIME / STALL_WINDOW_STEPS
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
