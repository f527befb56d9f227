"""A step budget for adaptive solves: a chattering contact fails clearly instead of running for hours.

Some scenes make an adaptive solver's step collapse: e.g. the ``compression_only`` reading of the
paper switches the contact force off at maximum compression while the springs push the bodies back
together, so the force switches on and off at every step (a sticking contact that a force law cannot
represent; the event-driven reference handles it with a sliding mode).  Exudyn would then take
millions of 1e-8 s steps.  :class:`StepBudget` is installed as Exudyn's pre-step function for
scenes with a contact; when the budget is spent it stops the solve, and ``simulate`` raises a
:class:`~mbs_models.errors.SimulationError` that says why.

Cost: the engine's pre-step function counts the steps itself and calls :meth:`StepBudget.advance` only at
the budget's checkpoints (:attr:`StepBudget.next_check`: every :data:`STALL_WINDOW_STEPS`-th step and the
budget's end), so a step pays one integer increment and comparison, inside a pre-step call it makes anyway.
"""

from __future__ import annotations

#: Steps allowed per simulated second (the presets use 200-1500 steps/s on the paper cases).
STEPS_PER_SIMULATED_SECOND = 50_000
#: Steps allowed at least, whatever the end time.
MINIMUM_STEP_BUDGET = 200_000
#: A stall: this many consecutive steps ...
STALL_WINDOW_STEPS = 20_000
#: ... advancing the time by less than this in total (mean step < 1e-7 s; the stiffest contacts
#: tested, k_c = 1e12 on a 1 kg absorber, need steps of about 1e-6 s).
STALL_WINDOW_TIME = 2e-3


def step_budget(end_time: float) -> int:
    """The number of steps an adaptive solve to ``end_time`` (s) may take."""
    return max(MINIMUM_STEP_BUDGET, int(STEPS_PER_SIMULATED_SECOND * end_time))


class StepBudget:
    """Exudyn pre-step user function that stops the solve after ``max_steps`` steps, or earlier when
    :data:`STALL_WINDOW_STEPS` consecutive steps advance the time by less than :data:`STALL_WINDOW_TIME`."""

    def __init__(self, max_steps: int):
        self.max_steps = int(max_steps)
        self.steps = 0
        self.exhausted_at: float | None = None
        self.stalled = False
        self._window_start = 0.0

    def __call__(self, mbs, t: float) -> bool:
        """Count one step at time ``t`` (s); False once the budget is spent (and on every later call)."""
        return self.advance(self.steps + 1, t)

    def advance(self, steps: int, t: float) -> bool:
        """The budget after ``steps`` steps in all, the last at time ``t`` (s): the same as calling it once per
        step, provided no checkpoint (:attr:`next_check`) was skipped since the last call -- between two
        checkpoints a call only counts.  False once the budget is spent (and on every later call)."""
        self.steps = steps
        if self.exhausted_at is not None:
            return False
        if steps % STALL_WINDOW_STEPS == 0:
            if t - self._window_start < STALL_WINDOW_TIME:
                self.stalled = True
                self.exhausted_at = float(t)
                return False
            self._window_start = t
        if steps > self.max_steps:
            self.exhausted_at = float(t)
            return False
        return True

    @property
    def next_check(self) -> int:
        """The smallest step count at which :meth:`advance` can do more than count: the end of the current
        stall window or the first step beyond the budget (the next step once the budget is spent)."""
        if self.exhausted_at is not None:
            return self.steps + 1
        return min((self.steps // STALL_WINDOW_STEPS + 1) * STALL_WINDOW_STEPS, self.max_steps + 1)

    def explanation(self, solver: str, end_time: float) -> str:
        """Why the solve was stopped, for the SimulationError message."""
        if self.stalled:
            cause = (f"the step size collapsed: {STALL_WINDOW_STEPS} steps advanced less than "
                     f"{STALL_WINDOW_TIME:g} s (step budget stopped the solve)")
        else:
            cause = (f"the step budget of {self.max_steps} steps was spent (mean step "
                     f"{self.exhausted_at / self.max_steps:.2g} s)")
        return (f"Exudyn {solver} stopped at t = {self.exhausted_at:.6g} s of {end_time:g} s: {cause}. "
                "Typically a contact that switches on and off at every step (sticking or chattering); the "
                "event-driven reference (validation.reference) handles such scenes")
