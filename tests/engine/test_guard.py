"""The step budget that stops collapsing adaptive solves (mbs_models.engine.guard)."""

from mbs_models.engine.guard import MINIMUM_STEP_BUDGET, StepBudget, step_budget


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
