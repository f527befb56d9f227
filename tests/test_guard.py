"""The step budget that stops collapsing adaptive solves (mbs_models.guard)."""

from mbs_models.guard import MINIMUM_STEP_BUDGET, StepBudget, step_budget


def test_budget_grows_with_end_time_and_has_a_floor():
    assert step_budget(0.001) == MINIMUM_STEP_BUDGET
    assert step_budget(100.0) > step_budget(10.0) >= MINIMUM_STEP_BUDGET


def test_budget_stops_after_max_steps_and_explains():
    budget = StepBudget(3)
    assert [budget(None, 0.1 * i) for i in range(1, 6)] == [True, True, True, False, False]
    assert budget.exhausted_at == 0.4
    assert "step budget of 3 steps" in budget.explanation("DOPRI5", 1.0)
